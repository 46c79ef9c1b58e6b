// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Texture synthesis on surfaces by graph matching over a sqrt(2)-subdivision
// hierarchy (Bangay & Morkel 2006, sections 3 and 4): the whole pipeline.
//
// 1. Units (3.3.2): r_scale is texels per object unit. With normalize_units
//    (default) one object unit is the longest side of the mesh's bounding box,
//    so r_scale means "texels across the object" whatever the file's units.
// 2. Optional adaptive sqrt(2)-subdivision of the base mesh (3.2.2).
// 3. Orientation field (Turk diffusion from key vertices) and sweep field on
//    the base mesh (3.1.1); after every subdivision step both are carried to
//    the new vertices and re-diffused (coarse to fine).
// 4. Levels: the base mesh, then `levels` uniform sqrt(2) steps (3.2.1).
//    Old vertices keep their colours; face points start with the average of
//    their face's colours ("missing entries filled by interpolation", 4).
// 5. Order (3.1.2): on the base level vertices are visited in increasing sweep
//    value; on every later level in a random order (std::mt19937_64 from
//    `seed`). On the base level the first pass skips vertices whose region has
//    no coloured vertex yet; the very first vertex gets a random texel; after
//    the first pass, fill passes visit the skipped vertices until all are
//    coloured (section 4's two-pass process); then passes 2..P refine.
// 6. Per vertex P (3.3): k from region_k at P's mean edge length and P's
//    stack level m (the region spans region_texels texels OF LEVEL m, i.e.
//    n 2^m level-0 texels, about n x n vertices at every mesh level: see
//    level_relative_region; the graph cut's r is that span), its
//    k-region with local (u,v), samples = the coloured region vertices other
//    than P, each at its anti-aliasing level (or, without anti-aliasing, the
//    level max(0, levels - level index): coarse mesh <-> coarse stack image),
//    exhaustive match (match_region), then transfer: graph cut over the whole
//    region (graph_cut_transfer, r = 2^m n texels) or P alone. With
//    skip_patched, vertices that received colour from a cut earlier in the
//    same pass are not matched again in that pass (the speed-up of section 4).
// Colours are read from the stack level of each vertex (3.3.4); each colour
// remembers that level and is compared against it when it serves as a sample
// (old vertices carry coarse, blurred colours into the next mesh level).
//
// Writes kVertexColor (linear RGB), kVertexDirection, kVertexSweep on the
// final (finest) mesh, which replaces `mesh`. Throws InvalidInputError (bad
// options, empty mesh or exemplar), TopologyError (from the subdivision).

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "geometry/turk_orientation_field.h"
#include "texture/k_region_matching.h"

namespace surftex {

struct SubdivisionSynthesisOptions {
  double r_scale = 100;         ///< texels per object unit, > 0
  bool normalize_units = true;  ///< object unit = longest bounding-box side
  int levels = 3;               ///< uniform sqrt(2) steps after the base level, 0..12
  double adaptive_factor = 0;   ///< f of 3.2.2; 0 = no adaptive subdivision
  int adaptive_steps = 4;       ///< adaptive steps when adaptive_factor > 0, 0..32
  int passes = 2;               ///< passes per level, 1..16
  /// n: neighbourhood edge length in texels, > 0. 3 is the paper's Table-1 (timing)
  /// setting; it is too small for structured exemplars at the fine stack levels,
  /// where SSD favours the most uniform exemplar areas (dark seams of a brick
  /// wall grow into blobs). 9 keeps brick structure on brick_small_96.
  double region_texels = 9;
  bool pyramid = false;         ///< Gaussian pyramid (a = 2) instead of the stack (a = 1)
  bool antialias = true;        ///< per-vertex stack level (3.3.4)
  bool averaging = true;        ///< oversampling groups (3.3.3)
  bool graph_cut = true;        ///< graph-cut transfer (3.4), else P alone
  bool skip_patched = true;     ///< do not re-match vertices patched in the same pass
  /// Count region_texels in texels of the centre's stack level m, i.e. the
  /// region spans n 2^m level-0 texels (a = 2 in section 3.3.2's formula, as
  /// for a pyramid), so every level matches about n x n vertices. Default on.
  /// Off = the paper's a = 1 for a stack: a region of n level-0 texels at
  /// every level, which at coarse levels (edges longer than n texels) is only
  /// the 1-ring; its samples are blurred together by the level's stack
  /// filter, the match then merely continues the colour around it, and the
  /// structure laid down is far coarser than the exemplar's (on a deep
  /// hierarchy: cells several times too large, or one uniform colour) which
  /// the fine levels, whose regions are smaller than those features, cannot
  /// break. Stack levels still give every sample its own anti-aliased level.
  bool level_relative_region = true;
  double sigma = 1.0;           ///< sigma of equation (1), > 0
  int max_k = 24;               ///< cap on k, 1..64
  LocalCoordinates coordinates = LocalCoordinates::kUnfolding;
  /// Orientation keys; empty = vertex 0 with the world x axis (projected).
  std::vector<OrientationKey> keys;
  std::uint64_t seed = 1;
  ProgressCallback progress;
};

struct SynthesisPassStats {
  std::size_t matched = 0;   ///< vertices matched (Algorithm 1 runs)
  std::size_t patched = 0;   ///< extra vertices coloured by cuts
  std::size_t skipped = 0;   ///< no coloured neighbour yet (left for a fill pass)
  std::size_t seeded = 0;    ///< random texel (nothing coloured at all)
  double mean_k = 0;
  double mean_region = 0;    ///< vertices per region
  double mean_groups = 0;    ///< compared groups per match (after averaging)
  std::size_t candidates = 0;  ///< exemplar texels scored over all matches (branch and bound)
  std::size_t recomputed = 0;  ///< speculative jobs redone at commit (their region changed)
  /// Thread time summed over vertices (so it can exceed the wall time).
  double seconds_match = 0, seconds_transfer = 0, seconds_region = 0;
  double seconds_setup = 0;    ///< frames, region graph (wall)
};

struct SynthesisLevelStats {
  int level = 0;
  std::size_t vertices = 0, faces = 0;
  int passes = 0;       ///< passes run, fill passes included
  int fill_passes = 0;
  std::vector<SynthesisPassStats> pass_stats;
  double seconds_subdivide = 0, seconds_fields = 0, seconds_synthesis = 0;
};

struct SubdivisionSynthesisResult {
  std::vector<SynthesisLevelStats> levels;
  std::vector<double> adaptive_area_std_percent;  ///< before + after each adaptive step
  double object_unit = 1;  ///< mesh units per object unit
  int stack_levels = 0;
  double seconds_total = 0;
};

SubdivisionSynthesisResult synthesize_on_subdivision(Mesh& mesh, const Image& exemplar,
                                                     const SubdivisionSynthesisOptions& opt = {});

/// One synthesis pass over `order` on a mesh that already has
/// kVertexDirection (for the benchmark and tests): `colored` flags which
/// vertices have a colour in kVertexColor (updated). `hierarchy_level` is the
/// stack level used without anti-aliasing. `r_scale` here is texels per MESH
/// unit. Returns the pass statistics.
///
/// The pass is the sequential one (each vertex matched against the colours
/// left by the vertices before it in `order`), computed speculatively in
/// parallel: chunks of consecutive vertices are matched with TBB against the
/// colours at the chunk's start and committed in order; a vertex whose region
/// was written by an earlier commit of its chunk is recomputed. Results do
/// not depend on the thread count.
SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const std::vector<std::size_t>& order,
                                  std::vector<char>& colored, double r_scale, int hierarchy_level,
                                  const SubdivisionSynthesisOptions& opt, std::mt19937_64& rng);
/// The same with a prebuilt index of `ex` (reused across passes).
/// `color_level` (optional, one entry per vertex, updated): the stack level
/// each vertex's current colour was read from. A sample is compared against
/// that level, not the vertex's current anti-aliasing level: colours carried
/// from a coarser mesh level are blurred, and comparing them against sharper
/// texels makes SSD prefer the exemplar's extreme (dark) texels, which then
/// grow into blobs. Null = every colour belongs to its vertex's current level.
SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const ExemplarIndex& index,
                                  const std::vector<std::size_t>& order, std::vector<char>& colored, double r_scale,
                                  int hierarchy_level, const SubdivisionSynthesisOptions& opt,
                                  std::mt19937_64& rng, std::vector<int>* color_level = nullptr);

}  // namespace surftex
