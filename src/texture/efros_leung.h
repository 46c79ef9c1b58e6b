// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Two-pass Efros-Leung pixel synthesis (Gorla, Interrante & Sapiro 2003,
// "Texture synthesis for 3D shape representation", section 3.3), with
// per-pixel orientation (3.3.2, pre-rotated exemplars) and per-pixel choice of
// exemplar (multi-texturing, section 5).
//
// Pass 1: a small unweighted window on every candidate (Exhaustive, the
// paper) or a short list (Approximate, default), `preselect` kept; pass 2:
// the full Gaussian-weighted window; the pixel copied from a random one of
// the best max(pick_min, pick_fraction * preselect) within (1 +
// error_tolerance) of the best (our addition). Fill order: onion peel or
// direction sweep; isolated pixels seeded. Same bytes for any thread count.
// In full: docs/decisions/505-efros-leung-details.md.
//
// Throws InvalidInputError naming the option or input on any invalid value.

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "geometry/image.h"
#include "geometry/progress.h"

namespace surftex {

enum class PixelState : std::uint8_t {
  Fill = 0,     ///< to synthesise
  Known = 1,    ///< boundary condition: read, never changed
  Outside = 2,  ///< not part of the domain: never read or written
};

/// How pass 1 finds its candidates.
enum class ElSearch {
  /// A short list independent of the exemplar size: the coherent candidates
  /// (Ashikhmin 2001) and the `ann_candidates` (`ann_coherent_candidates` when
  /// there are coherent ones) nearest by a kd-tree over PCA
  /// coefficients (partial_neighbourhood_index.h), ranked exactly by pass 1;
  /// widened by a sample of the whole exemplar when its best candidates tie
  /// and none of them continues a neighbour (flat regions; decision 501).
  Approximate,
  /// Every candidate position (Gorla's pass 1 as published; cost grows with
  /// the exemplar area). The reference.
  Exhaustive,
};

enum class FillOrder {
  OnionPeel,  ///< most constrained pixel first
  Direction,  ///< sweep along ElOptions::direction_x/y
};

struct ElOptions {
  /// Full (second-pass) neighbourhood diameter, pixels, 3..51. Default 11.
  int window = 11;
  /// First-pass window, 3..window; 0 = max(3, round(window * 5 / 12)) (Gorla's
  /// Figure 5 ratio).
  int first_pass_window = 0;
  /// Pass-1 candidates kept for pass 2, >= 0; 0 = the exemplar's width (Gorla:
  /// "one scanline"), clamped to the candidate count.
  int preselect = 0;
  /// Sigma of the pass-2 Gaussian weights, pixels, >= 0; 0 = window / 6.4
  /// (Efros & Leung 1999).
  double gaussian_sigma = 0.0;
  /// The pixel is copied from a random candidate among the best
  /// max(pick_min, ceil(pick_fraction * n)) of pass 2 (Gorla: 10 or 10%).
  /// pick_fraction in [0, 1], pick_min >= 1.
  double pick_fraction = 0.1;
  int pick_min = 10;
  /// Efros-Leung epsilon: candidates with error > (1 + eps) * best error are
  /// not picked. Negative = off (pure Gorla rule). Default 0.1.
  double error_tolerance = 0.1;
  /// Coherence (an addition to Gorla's rule, after Ashikhmin 2001 and
  /// Hertzmann et al. 2001): a candidate that continues a synthesised
  /// neighbour's source (its source shifted by the offset) is taken when its
  /// full-window error is at most (1 + coherence) times the best; the best
  /// such, ties by position; not where the window holds given (Known)
  /// pixels, whose boundary condition decides, unless the candidate continues
  /// a given pixel's source (ElInput::known_source). Larger features (bricks, tiles) then come out
  /// whole instead of in fragments. >= 0; 0 = off (the published rule).
  /// Default 5 (decision 506).
  double coherence = 5.0;
  /// Order in which Fill pixels are synthesised.
  FillOrder order = FillOrder::OnionPeel;
  /// Sweep direction for FillOrder::Direction (pixel coordinates, y down);
  /// need not be unit, must be non-zero.
  double direction_x = 1.0, direction_y = 0.0;
  /// Number of pre-rotated orientations when an angle field is given
  /// (Gorla 3.3.2), 1..128. Default 64.
  int rotations = 64;
  /// The exemplars tile: windows wrap, every pixel is a candidate (else only
  /// windows inside).
  bool periodic_exemplar = false;
  /// Pass-1 candidate search (see ElSearch). Default Approximate.
  ElSearch search = ElSearch::Approximate;
  /// Approximate search: kd-tree neighbours per pixel, 1..256. Default 16.
  int ann_candidates = 16;
  /// Approximate search: kd-tree neighbours for a pixel that has coherent
  /// candidates (they stand for part of the search; at most ann_candidates),
  /// 1..256. Default 8 (decision 501, session 28: 40% less search, BDS as
  /// good or better on the textures measured).
  int ann_coherent_candidates = 8;
  /// Approximate search: PCA coefficients of the first-pass neighbourhood,
  /// 1..first_pass_window^2 * channels (clamped); 0 = automatic
  /// (el_ann_pca_dims: 4, so the kd-tree stays shallow and pass 1 re-ranks
  /// the hits exactly; 6 for a 4-channel exemplar, whose alpha edges take
  /// most of the variance). Default 0.
  int ann_pca_dims = 0;
  /// Approximate search: (1 + eps)-approximate kd-tree distances, >= 0. Default 1.
  double ann_eps = 1.0;
  /// Approximate search: the kd-tree holds every ann_stride-th row and column,
  /// each hit standing for its block, 1..4. Default 2 (a quarter of the index cost).
  int ann_stride = 2;
  /// Reference mode: Efros-Leung's single exhaustive Gaussian pass. Slow.
  bool single_pass = false;
  /// Split each pixel's search over TBB threads (same result); off when
  /// syntheses already run in parallel. Default on.
  bool parallel_pixel_search = true;
  /// Seed of every random choice.
  std::uint64_t seed = 1;
  /// Called with stage "synthesis" and the filled fraction.
  ProgressCallback progress;
};

/// Exemplars prepared for the search: per (exemplar, orientation) the
/// rotated exemplar as channel planes and its candidate positions, built
/// lazily (on first use, thread-safe) and shared by every run given it.
/// Opaque; made by el_prepare_exemplars.
struct ElPreparedExemplars;

/// A point of exemplar `exemplar` in its own (unrotated) pixel coordinates.
struct ElExemplarPoint {
  int exemplar = -1;
  float x = 0.f, y = 0.f;
};

/// Everything a synthesis run reads besides the options.
struct ElInput {
  /// One or more exemplars (Gorla 5), same channels, each >= `window` per side
  /// unless periodic; empty when `prepared` is given.
  std::vector<Image> exemplars;
  /// Alternative to `exemplars`: prepared once for many runs (el_prepare_exemplars
  /// with the run's window, search and rotation options, else InvalidInputError).
  std::shared_ptr<const ElPreparedExemplars> prepared;
  /// Output canvas: size and channels of the result (channels must match the
  /// exemplars); values at Known pixels are the boundary conditions.
  Image target;
  /// Per-pixel state, row-major, width*height; empty = every pixel Fill.
  std::vector<PixelState> state;
  /// Optional per-pixel orientation (radians, rotated_exemplars.h convention),
  /// 1 channel, the target's size. Empty = none.
  Image angle;
  /// Alternative to `angle`: a function of the pixel (x, y). Used when
  /// `angle` is empty and this is set.
  std::function<double(int x, int y)> angle_fn;
  /// Optional per-pixel exemplar index (0-based, row-major, width*height);
  /// empty = exemplar 0 everywhere. Read at Fill pixels only.
  std::vector<int> exemplar_index;
  /// Optional, per pixel (row-major, width*height): where a Known pixel's value
  /// was read in the exemplars (ElExemplarPoint; exemplar -1 = not known). A Fill
  /// pixel next to it then gets the coherent candidate that continues it, which
  /// may win next to given pixels too (ElOptions::coherence): a patch continues
  /// its neighbours' texture across the seam instead of matching it anew.
  std::vector<ElExemplarPoint> known_source;
};

/// Where a synthesised pixel took its value: pixel (x, y) of `exemplar` rotated
/// by `rotation` (rotate_exemplar_step with K = rotations, margin window / 2); exemplar -1 = not synthesised.
struct ElSource {
  int exemplar = -1, rotation = 0, x = 0, y = 0;
  /// (x, y) in the unrotated exemplar's pixel coordinates (rotated_exemplars.h
  /// exemplar_point).
  float ex = 0.f, ey = 0.f;
};

struct ElResult {
  Image image;                 ///< the target with every Fill pixel synthesised
  std::vector<ElSource> source;  ///< per pixel, row-major: where its value came from
  std::size_t synthesized = 0; ///< pixels filled by the two-pass search
  std::size_t seeded = 0;      ///< pixels filled by random seed patches
  int window = 0;              ///< effective full window
  int first_pass_window = 0;   ///< effective first-pass window
  int rotations_used = 0;      ///< distinct (exemplar, orientation) pairs searched
  /// Distinct search images those pairs needed: with odd windows a quarter
  /// turn of an orientation is searched in it (ElPreparedExemplars), so 64
  /// orientations of a non-periodic exemplar with sides of equal parity need 16.
  int search_images = 0;
  /// Candidates ranked by pass 1, summed over the pixels.
  std::size_t pass1_candidates = 0;
  /// Approximate search: pixels whose short list was widened by a sample of
  /// the whole exemplar (its best candidates tied; efros_leung.cpp).
  std::size_t pass1_widened = 0;
  double seconds = 0.0;
};

/// Synthesises every Fill pixel of input.target. Throws InvalidInputError.
ElResult efros_leung_synthesize(const ElInput& input, const ElOptions& opt = {});

/// Convenience: a width x height image grown from one exemplar from scratch.
Image efros_leung_synthesize(const Image& exemplar, int width, int height,
                             const ElOptions& opt = {});

/// Validates and prepares `exemplars` for runs with opt's window, rotation and
/// search options (others not read); rotations built lazily, each once,
/// concurrently. Throws InvalidInputError.
std::shared_ptr<const ElPreparedExemplars> el_prepare_exemplars(const std::vector<Image>& exemplars,
                                                                const ElOptions& opt);

/// The effective first-pass window for `opt` (resolves the 0 default).
int el_first_pass_window(const ElOptions& opt);

/// The PCA coefficients the approximate search keeps for exemplars of
/// `channels` channels (resolves ElOptions::ann_pca_dims's 0 default).
int el_ann_pca_dims(const ElOptions& opt, int channels);

}  // namespace surftex
