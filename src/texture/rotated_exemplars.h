// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Pre-rotated exemplars for oriented synthesis (Gorla et al. 2003, section
// 3.3.2): the exemplar is rotated into K quantised orientations once, and the
// neighbourhood search for a pixel runs in the rotation closest to the
// direction the field asks for there.
//
// Angle convention (used by the whole synthesis code): an angle a (radians)
// rotates the texture counter-clockwise as displayed, i.e. the exemplar's +x
// axis is drawn along (cos a, -sin a) in pixel coordinates (x right, y down).
// Orientation k of K is the angle 2*pi*k/K; directions are not folded to
// [0, pi) because a direction field may distinguish a from a + pi.
//
// Cropping (left open by the paper): a non-periodic rotation is stored in its
// bounding box with a validity mask (bilinear footprint inside the source); a
// periodic one as a (W + 2m) x (H + 2m) wrapped block. Rotation 0 is an exact
// copy. In full: docs/decisions/505.

#include <vector>

#include "geometry/image.h"
#include "texture/image_ops.h"  // rotated_point / exemplar_point: rotate_exemplar's map

namespace surftex {

struct RotatedExemplarOptions {
  /// Number of orientations K over [0, 2 pi); 1..128, default 64 (Gorla used
  /// 64 to 128 and saw no gain beyond).
  int rotations = 64;
  /// The exemplar tiles seamlessly (wrap when sampling).
  bool periodic = false;
  /// Extra border around one period for periodic exemplars (pixels, >= 0).
  int margin = 0;
  /// Build only these orientation indices (empty = all K). Others stay empty.
  std::vector<int> only;
};

struct RotatedExemplar {
  double angle = 0.0;  ///< radians, 2 pi k / K
  Image image;         ///< same channels as the exemplar
  Image valid;         ///< 1 channel, 1 = usable sample, 0 = outside the source
};

struct RotatedExemplarSet {
  int rotations = 0;
  bool periodic = false;
  std::vector<RotatedExemplar> items;  ///< size K; unbuilt ones have empty images
  /// Index of the orientation closest to `radians` (any real value).
  int index_for_angle(double radians) const;
};

/// Index of the orientation closest to `radians` among K = `rotations`.
int rotation_index(double radians, int rotations);

/// One rotation of `exemplar` by `radians` (convention above).
RotatedExemplar rotate_exemplar(const Image& exemplar, double radians, bool periodic,
                                int margin = 0);

/// Position (x, y) of a w-wide image after one exact quarter turn (the
/// rotation by +pi/2 of the convention above; the turned image is h x w).
inline void quarter_turn_position(int w, int& x, int& y) {
  const int nx = y;
  y = w - 1 - x;
  x = nx;
}

/// Position (x, y) of a w x h image after q quarter turns (q = 0..3).
inline void quarter_turns_position(int w, int h, int q, int& x, int& y) {
  for (int t = 0; t < q; ++t) {
    quarter_turn_position(w, x, y);
    const int nw = h;
    h = w;
    w = nw;
  }
}

/// An offset (dx, dy) between two pixels after q quarter turns (q = 0..3):
/// quarter_turn_position sends (dx, dy) to (dy, -dx).
inline void quarter_turns_offset(int q, int& dx, int& dy) {
  for (int t = 0; t < q; ++t) {
    const int nx = dy;
    dy = -dx;
    dx = nx;
  }
}

/// `r` turned by q exact quarter turns (q = 0..3): the exemplar rotated by
/// r.angle + q pi/2, its samples permuted, not resampled.
RotatedExemplar turn_quarters(const RotatedExemplar& r, int q);

/// Whether the orientations of a K-rotation synthesis of `exemplar` are
/// shared by quarter turns: K a multiple of 4, not periodic, sides of equal
/// parity (so the turned canvas is the directly rotated one).
bool quarter_turns_shared(const Image& exemplar, int rotations, bool periodic);

/// The quarter turns by which orientation k of K is built from orientation
/// k mod K/4 (0: rotated directly): k / (K/4) when quarter_turns_shared.
int quarter_turns_of(const Image& exemplar, int k, int rotations, bool periodic);

/// Orientation k of K (angle 2 pi k / K) as the synthesis builds it: when
/// quarter_turns_shared, orientation k >= K/4 is orientation k mod K/4 turned
/// by k / (K/4) quarter turns (the samples of rotate_exemplar up to rounding,
/// one resampling for four orientations); else rotate_exemplar.
RotatedExemplar rotate_exemplar_step(const Image& exemplar, int k, int rotations, bool periodic, int margin);

/// All K rotations (or those in opt.only). Throws InvalidInputError on an
/// empty exemplar, rotations outside 1..128, margin < 0 or an index outside 0..K-1.
RotatedExemplarSet rotated_exemplars(const Image& exemplar, const RotatedExemplarOptions& opt = {});

}  // namespace surftex
