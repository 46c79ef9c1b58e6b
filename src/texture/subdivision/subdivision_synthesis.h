// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Texture synthesis on surfaces by graph matching over a sqrt(2)-subdivision
// hierarchy (Bangay & Morkel 2006, sections 3 and 4): the whole pipeline.
//
// 1. Scale (3.3.2), from the inputs (choose_subdivision_scale): `repeats`
//    exemplar widths across the object (default), texels_per_edge, or r_scale;
//    the fewest uniform levels whose vertex spacing is one texel, within
//    max_vertices (else the exemplar is reduced, or, for the default
//    repeats, fewer repeats shown where reducing would lose its detail).
// 2. Adaptive sqrt(2)-subdivision of the base (3.2.2).
// 3. Orientation and sweep fields (3.1.1), carried and re-diffused per level.
// 4. Levels: the base, then `levels` uniform sqrt(2) steps (3.2.1).
// 5. Order (3.1.2): by sweep on the base level, random later; fill passes
//    colour the skipped vertices (section 4's two passes).
// 6. Per vertex (3.3): its k-region, exhaustive or coherence match, graph-cut
//    transfer (3.4), at the vertex's stack level (3.3.4).
// Wrap: periodic only when the exemplar tiles (wrap_threshold); repetition
// penalty against exemplar areas shown too often nearby. Every step in
// detail: docs/decisions/206-subdiv-synthesis-pipeline.md.
//
// Writes kVertexColor (linear RGB), kVertexDirection, kVertexSweep on the
// final (finest) mesh, which replaces `mesh`. Throws InvalidInputError (bad
// options, empty mesh or exemplar), TopologyError (from the subdivision).

#include <cstddef>
#include <cstdint>
#include <array>
#include <random>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"
#include "geometry/progress.h"
#include "texture/subdivision/turk_orientation_field.h"
#include "texture/subdivision/k_region_matching.h"

namespace surftex {

enum class ExemplarWrap {
  Auto,      ///< periodic when wrap_verdict(exemplar, wrap_threshold, region) finds the wrap seamless
  Periodic,  ///< always wrap (the exemplar is a seamless tile)
  Bounded    ///< never wrap
};

struct SubdivisionSynthesisOptions {
  /// Scale, the first of these that is set (step 1): r_scale > 0 = texels per
  /// object unit; texels_per_edge > 0 = exemplar texels per mean edge of the
  /// input mesh; else `repeats` exemplar widths across the longest
  /// bounding-box side (> 0, default 3).
  double r_scale = 0;
  bool normalize_units = true;  ///< object unit = longest bounding-box side
  double texels_per_edge = 0;
  double repeats = 3;
  /// The default scale's trade: when max_vertices forces the exemplar's
  /// reduction and that keeps less than this share of the detail the
  /// unreduced exemplar keeps (detail_kept(e, s) / detail_kept(e, 1)), fewer
  /// repeats are shown (down to one) so it is reduced less: a fine gingham
  /// reduced 2.6x shows no check at all, only moire. Only for `repeats`
  /// not given by the user (repeats_fixed false); 0 = off. Default 1/3
  /// (decision 209).
  double min_relative_detail = 1.0 / 3.0;
  bool repeats_fixed = false;  ///< `repeats` was asked for: never lowered
  /// Uniform sqrt(2) steps after the base level, 0..12; -1 (default) = chosen
  /// (step 1: vertex spacing <= one texel within max_vertices).
  int levels = -1;
  /// Most vertices of the finest level when levels are chosen, >= 1000.
  /// Default 300000 (a 6K-face mesh keeps a 512 px exemplar at 87-99 px; decision 208).
  std::size_t max_vertices = 300000;
  double adaptive_factor = 1.5; ///< f of 3.2.2 (the paper's choice); 0 = no adaptive subdivision
  int adaptive_steps = 4;       ///< adaptive steps when adaptive_factor > 0, 0..32
  int passes = 1;               ///< passes per level, 1..16 (default 1; docs/decisions/204)
  ExemplarWrap wrap = ExemplarWrap::Auto;
  /// Auto wrap: the exemplar counts as periodic when its wrap-seam ratio
  /// (texture/wrap_seam_ratio.h: jump across its wrap / jump inside) is at
  /// most this, or, when a feature runs along the wrap, its wrap lines and
  /// region-sized windows across the wrap look like its interior ones
  /// (wrap_verdict, the window ratio at most this; decision 207), > 0.
  /// Default 1.3 (the tileable-tile criterion of Ray 2009 s.1).
  double wrap_threshold = 1.3;
  /// n: neighbourhood edge length in texels, > 0. Default 9 (the paper's 3 is
  /// too small for structured exemplars; decision 206).
  double region_texels = 9;
  bool pyramid = false;         ///< Gaussian pyramid (a = 2) instead of the stack (a = 1)
  bool antialias = true;        ///< per-vertex stack level (3.3.4)
  bool averaging = true;        ///< oversampling groups (3.3.3)
  bool graph_cut = true;        ///< graph-cut transfer (3.4), else P alone
  bool skip_patched = true;     ///< do not re-match vertices patched in the same pass
  /// Count region_texels in texels of the centre's stack level m (a region of
  /// n 2^m level-0 texels, about n x n vertices per level). Off = the paper's
  /// a = 1 (coarse levels then see only the 1-ring). Default on.
  bool level_relative_region = true;
  /// Repetition term lambda * sigma^2 * samples * max(0, R - 1) added to a
  /// candidate's SSD (R: nearby use of its exemplar bin over the mean). >= 0, 0 = off.
  double repetition_penalty = 0.3;
  /// Mesh levels from the base that use the exhaustive search (Algorithm 1),
  /// 0..13; later levels use the coherence search (2.3; Ashikhmin 2001).
  /// Default 1; 13 = exhaustive everywhere (figures: decision 204).
  int exhaustive_levels = 1;
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
  std::size_t searched_all = 0;  ///< matches that searched the whole candidate box (no coherent candidate fitted)
  std::size_t recomputed = 0;  ///< speculative jobs redone at commit (their region changed)
  std::size_t wasted = 0;      ///< speculative jobs dropped (an earlier commit of their chunk patched the vertex)
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

/// Where a vertex's colour was read: stack (or pyramid) level and position in
/// that level's texels, read bilinearly as the level wraps or clamps
/// (texel_bilinear; integer positions for single-texel reads). Level -1 =
/// not read from the exemplar (a face point's averaged colour).
struct ExemplarLookup {
  int level = -1;
  double x = 0, y = 0;
};

/// The scale and depth chosen from the inputs (step 1), reported by the CLI.
struct SubdivisionScale {
  const char* scale_from = "repeats";  ///< "rscale", "texels_per_edge" or "repeats"
  double repeats = 0;          ///< exemplar widths across the longest bounding-box side
  double repeats_requested = 0;  ///< before keeping the exemplar's detail (min_relative_detail)
  /// detail_kept at exemplar_scale over detail_kept at 1 (1 = unreduced or
  /// not measured: the scale was given, or the budget did not reduce it).
  double relative_detail = 1;
  double texels_per_edge = 0;  ///< exemplar texels per mean edge of the input mesh
  double r_scale = 0;          ///< exemplar texels per object unit
  double texel_size = 0;       ///< mesh units per synthesis texel
  double exemplar_scale = 1;   ///< synthesis texels per exemplar pixel (< 1: reduced for max_vertices)
  int exemplar_width = 0, exemplar_height = 0;  ///< the exemplar as synthesised
  int levels = 0;              ///< uniform sqrt(2) steps
  bool levels_chosen = false;  ///< chosen (levels = -1) rather than given
  bool budget_limited = false; ///< the vertex budget, not the texel size, set the depth
  double spacing_texels = 0;   ///< predicted final vertex spacing, synthesis texels
  std::size_t predicted_vertices = 0;
};

struct SubdivisionSynthesisResult {
  std::vector<SynthesisLevelStats> levels;
  std::vector<double> adaptive_area_std_percent;  ///< before + after each adaptive step
  double object_unit = 1;  ///< mesh units per object unit
  int stack_levels = 0;
  SubdivisionScale scale;
  double wrap_seam_ratio = 0;  ///< of the input exemplar (RGB, at its own resolution)
  /// wrap_verdict (texture/wrap_seam_ratio.h) of the input exemplar (a
  /// periodic one is then reduced wrapping, so it tiles as well),
  /// with windows of region_texels (odd): its line check, window ratio (-1 =
  /// not computed) and verdict (what ExemplarWrap::Auto follows).
  bool wrap_lines_within_interior = false;
  double wrap_window_ratio = -1;
  bool wrap_seamless = true;
  bool periodic = true;        ///< treated as periodic (wrapped)
  int bounded_levels = 0;      ///< stack levels matched without wrapping (ExemplarLevels)
  Image exemplar;              ///< the exemplar as synthesised (RGB, reduced if exemplar_scale < 1)
  /// Per final vertex: the exemplar texel (level 0 of `exemplar`) its colour
  /// was read from, {-1, -1} if none (a face point never matched or patched).
  std::vector<std::array<int, 2>> source;
  /// Per final vertex: the exact lookup its colour came from, so that other
  /// maps of the exemplar can be read the same way (subdivision_exemplar_maps.h).
  std::vector<ExemplarLookup> lookup;
  bool pyramid = false;  ///< the exemplar levels were a pyramid (options.pyramid)
  double seconds_total = 0;
};

/// Step 1 alone: the scale and depth synthesize_on_subdivision would use on
/// `mesh` (after adaptive subdivision) for an exemplar of w x h pixels.
/// `input_mean_edge` is the mean edge of the mesh as given (texels_per_edge).
/// With the exemplar's pixels (w x h), the default repeats may be lowered to
/// keep its detail (min_relative_detail). Throws InvalidInputError (options
/// out of range, no extent, an exemplar not w x h).
SubdivisionScale choose_subdivision_scale(const Mesh& mesh, int w, int h, double input_mean_edge,
                                          const SubdivisionSynthesisOptions& opt,
                                          const Image* exemplar = nullptr);

SubdivisionSynthesisResult synthesize_on_subdivision(Mesh& mesh, const Image& exemplar,
                                                     const SubdivisionSynthesisOptions& opt = {});

/// The report's figures of a run with options `opt`: the chosen scale and
/// levels, the wrap decision, the hierarchy and, per level, its passes
/// (matched, patched, skipped regions and timings).
nlohmann::json to_json(const SubdivisionSynthesisResult& result, const SubdivisionSynthesisOptions& opt);

/// An image of the input exemplar's size resampled as the exemplar was for
/// the synthesis (SubdivisionScale: reduced when exemplar_scale < 1: halved
/// with the binomial blur while more than twice the target, then bilinear;
/// `periodic`: blurred and resampled around the borders, so an image that
/// tiles still does, as for an exemplar treated as periodic), any channel
/// count, float. Throws InvalidInputError if `img` is empty.
Image resample_as_synthesised(const Image& img, const SubdivisionScale& scale, bool periodic = false);

/// Share of `img`'s luminance detail (its variance about the mean) that
/// survives at periods of at least four synthesis texels when the exemplar is
/// reduced by `scale` (synthesis texels per exemplar pixel, <= 1): the image
/// reduced as for the synthesis to scale / 2, enlarged back bilinearly,
/// 1 - squared error / variance, in [0, 1] (1 for a flat image). A vertex
/// spacing of about one texel carries features of 4 texels and more; finer
/// ones alias (moire). Throws InvalidInputError if `img` is empty.
double detail_kept(const Image& img, double scale);

/// The per-level geometry a pass reads: vertex frames and the region graph.
/// Built once per mesh level and shared by all its passes (they do not move
/// vertices), instead of once per pass.
struct PassGeometry {
  SurfaceFrames frames;
  RegionGraph graph;
  int mesh_level = 0;  ///< mesh level in the hierarchy (0 = base): chooses the search (exhaustive_levels)
};
PassGeometry make_pass_geometry(const Mesh& mesh);

/// One synthesis pass over `order` on a mesh that already has
/// kVertexDirection (for the benchmark and tests): `colored` flags which
/// vertices have a colour in kVertexColor (updated). `hierarchy_level` is the
/// stack level used without anti-aliasing. `r_scale` here is texels per MESH
/// unit. Returns the pass statistics.
///
/// Sequential in effect, computed speculatively in parallel (chunks matched
/// with TBB, committed in order, a vertex recomputed if its region changed);
/// independent of the thread count.
SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const std::vector<std::size_t>& order,
                                  std::vector<char>& colored, double r_scale, int hierarchy_level,
                                  const SubdivisionSynthesisOptions& opt, std::mt19937_64& rng);
/// The same with a prebuilt index of `ex` (reused across passes).
/// Optional, one entry per vertex, updated:
/// `color_level` (stack level each colour was read from; samples compare at
/// it), `source` (level-0 texel, {-1,-1} none; needed by the repetition
/// penalty), `lookup`; `geometry`: make_pass_geometry(mesh), null = built here.
SynthesisPassStats synthesis_pass(Mesh& mesh, const ExemplarLevels& ex, const ExemplarIndex& index,
                                  const std::vector<std::size_t>& order, std::vector<char>& colored, double r_scale,
                                  int hierarchy_level, const SubdivisionSynthesisOptions& opt,
                                  std::mt19937_64& rng, std::vector<int>* color_level = nullptr,
                                  std::vector<std::array<int, 2>>* source = nullptr,
                                  const PassGeometry* geometry = nullptr,
                                  std::vector<ExemplarLookup>* lookup = nullptr);

}  // namespace surftex
