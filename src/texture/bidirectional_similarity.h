// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Bidirectional similarity between a synthesised image and its exemplar
// (Simakov, Caspi, Shechtman & Irani 2008, "Summarizing visual data using
// bidirectional similarity", equation 1), used as a quality figure:
//  - coherence   = mean over every k x k patch Q of the output of
//                  min over exemplar patches P of D(P, Q)
//                  (no output patch is foreign to the exemplar; 0 when the
//                  output is a patchwork of verbatim exemplar copies);
//  - completeness = mean over every exemplar patch P of min over output
//                  patches Q of D(P, Q) (the output shows all of the exemplar);
//  - total = coherence + completeness.
// D is the SSD over the patch divided by k*k*channels (mean squared
// difference per value, in squared image units), so figures compare across
// image and patch sizes.
//
// Nearest neighbours are exact (up to rounding): a kd-tree over PCA
// projections, every offered point re-ranked with the full distance and the
// subspace distance (a lower bound) used to prune.
//
// Throws InvalidInputError on empty images, different channel counts,
// patch outside 1..31 or larger than an image, stride < 1, or a mask of the
// wrong size or without any valid patch.

#include <cstddef>
#include <vector>

#include "geometry/image.h"

namespace surftex {

/// The approximate search of the reports' figures (surface fidelity,
/// `surftex synth`): BidirectionalOptions::max_candidates and search_eps
/// (docs/decisions/201-surface-fidelity.md).
inline constexpr int kReportMaxCandidates = 256;
inline constexpr float kReportSearchEps = 3.f;

struct BidirectionalOptions {
  /// Patch side k, 1..31. Default 7.
  int patch = 7;
  /// Exemplar patches wrap around its edges (periodic exemplar): every
  /// exemplar pixel starts a patch. Default off (patches fully inside).
  bool periodic_exemplar = false;
  /// Step between output patch positions (1 = every patch), >= 1. Larger
  /// steps subsample big outputs.
  int stride = 1;
  /// Step between the exemplar patches that query the output for
  /// completeness (1 = every patch), >= 1; coherence always searches every
  /// exemplar patch. Larger steps subsample big exemplars.
  int exemplar_stride = 1;
  /// Dimensions kept by the PCA projection for the kd-tree (1..k*k*channels,
  /// clamped), default 16. Affects speed only, not the result.
  int pca_dims = 16;
  /// 0 (default) = exact. > 0 = approximate: at most this many full distances per
  /// query, the best seen kept (figures can only be too high).
  int max_candidates = 0;
  /// 0 (default) = exact. > 0 = approximate: the kd-tree skips a node
  /// unless (1 + search_eps) times its PCA bound stays within the best full
  /// distance so far (nanoflann's eps); figures can only be too high.
  float search_eps = 0.f;
  /// Brute-force search instead of the kd-tree (reference; slow).
  bool brute_force = false;
  /// Optional validity mask of the output (width*height; empty = all valid):
  /// only patches of valid pixels compared, both ways (surface_fidelity.h's
  /// charts). At least one valid patch is required.
  std::vector<char> output_valid{};
};

struct BidirectionalResult {
  double coherence = 0.0;
  double completeness = 0.0;
  double total = 0.0;
  std::size_t output_patches = 0;
  std::size_t exemplar_patches = 0;
  /// The search's work, both ways (deterministic): full patch distances
  /// computed, and kd-tree nodes plus offered points looked at.
  std::size_t evaluations = 0;
  std::size_t visits = 0;
};

BidirectionalResult bidirectional_similarity(const Image& output, const Image& exemplar,
                                             const BidirectionalOptions& opt = {});

}  // namespace surftex
