// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// k-region matching of a surface region against an exemplar image stack
// (Bangay & Morkel 2006, section 3.3: 3.3.1 matching, 3.3.2 scale, 3.3.3
// oversampling, 3.3.4 anti-aliasing).
//
// 1. k-region (3.3.1): the vertices at most k edges from the centre P.
// 2. Local (u,v), object units, u along kVertexDirection at P, v = n x u:
//    tangent projection, or unfolding (default) along shortest edge paths,
//    averaged over all of them ("averaged over all such paths").
// 3. offset_i = r_scale * uv_i (level-0 texels; r_scale: texels per object unit).
// 4. Size (3.3.2): k from (k+1)^2 + k^2 = (a^m n / (r_scale e))^2, rounded up,
//    in [1, max_k] (e: mean edge; the paper's formula with e made explicit).
// 5. Anti-aliasing (3.3.4): level round(log2(r_scale e_i)), clamped.
// 6. Matching (Algorithm 1): exhaustive SSD over every texel of the centre's
//    level, samples on one texel grouped (3.3.3, same best match), ties to the
//    lowest index; independent of the thread count. With a pyramid every
//    sample uses the centre's level. Details: docs/decisions/206.

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/image.h"
#include "geometry/mesh_fwd.h"

namespace surftex {

enum class LocalCoordinates { kTangentProjection, kUnfolding };

/// Per-vertex data the region code needs, computed once per mesh level.
struct SurfaceFrames {
  std::vector<std::array<double, 3>> normal;     ///< unit (Newell area-weighted)
  std::vector<std::array<double, 3>> direction;  ///< unit tangent (kVertexDirection, re-projected)
  std::vector<double> mean_edge;                 ///< mean incident edge length
  double mean_edge_length = 0;                   ///< over all edges
};

/// Reads kVertexDirection (throws InvalidInputError if absent) and positions.
SurfaceFrames compute_surface_frames(const Mesh& mesh);

struct KRegion {
  std::vector<std::size_t> vertices;          ///< centre first, then by hop distance
  std::vector<int> hops;                      ///< edges from the centre
  std::vector<std::array<double, 2>> uv;      ///< local coordinates, object units
  std::vector<std::array<int, 2>> edges;      ///< mesh edges inside the region (indices into vertices)
};

/// Flat adjacency of a mesh level for fast region building: CSR neighbour
/// lists, positions, and per directed edge p->w its unfolding step (the edge
/// in p's frame, u along p's field direction, v = n x u, rescaled to the 3D
/// edge length). Built once per pass; O(vertices + edges).
struct RegionGraph {
  std::vector<std::uint32_t> offset;                ///< nv + 1
  std::vector<std::uint32_t> neighbor;              ///< CSR targets
  std::vector<std::array<double, 2>> step;          ///< per CSR slot, object units
  std::vector<std::array<double, 3>> position;      ///< per vertex
  std::vector<std::array<double, 3>> normal, u_axis, v_axis;  ///< per-vertex frame
  std::size_t size() const { return position.size(); }
};

/// Throws InvalidInputError if `frames` do not belong to `mesh`.
RegionGraph make_region_graph(const Mesh& mesh, const SurfaceFrames& frames);

/// Per-thread scratch of k_region (an index per vertex, reset after use).
struct RegionScratch {
  std::vector<int> index;
  std::vector<double> paths;
};

/// The k-region of `center` (bounded BFS ring by ring, no allocation once the
/// buffers have grown) with local coordinates (see the header comment); the
/// unfolding is one pass from the centre: each new ring's uv from its
/// predecessors' uv and the precomputed edge steps, weighted by path counts.
/// `with_edges` = false skips KRegion::edges (only the graph cut needs them).
/// Throws InvalidInputError for center out of range or k < 0.
void k_region(const RegionGraph& graph, std::size_t center, int k, LocalCoordinates mode, KRegion& out,
              RegionScratch& scratch, bool with_edges = true);

/// Convenience overload (builds the RegionGraph: O(mesh) per call; tests).
void k_region(const Mesh& mesh, const SurfaceFrames& frames, std::size_t center, int k, LocalCoordinates mode,
              KRegion& out);

/// k from (k+1)^2 + k^2 = (a^m n / (r_scale e))^2, rounded up, clamped to [1, max_k].
/// `pyramid` selects a = 2 (n in texels of level m); subdivision synthesis
/// also passes true for a stack by default (SubdivisionSynthesisOptions::
/// level_relative_region).
int region_k(double region_texels, int level, bool pyramid, double r_scale, double mean_edge, int max_k = 32);

/// The exemplar as a Gaussian stack (default) or pyramid, RGB. Levels below
/// `bounded_levels` are blurred and read clamped, and matches there stay inside
/// (MatchBox; a non-periodic exemplar's wrap is never copied); the others wrap.
struct ExemplarLevels {
  std::vector<Image> levels;  ///< level 0 = the (RGB) exemplar
  bool pyramid = false;
  int bounded_levels = 0;
  bool wraps(int l) const { return l >= bounded_levels; }
  int width(int l) const { return levels[l].width; }
  int height(int l) const { return levels[l].height; }
  /// a^l: level-0 texels per texel of level l (1 for a stack).
  int scale(int l) const { return pyramid ? (1 << l) : 1; }
};

/// Builds the stack (or pyramid) of `exemplar` (1, 3 or 4 channels; grey is
/// expanded, alpha dropped). levels = 0: 1 + floor(log2(min(w, h))). Throws
/// InvalidInputError on an empty image.
ExemplarLevels make_exemplar_levels(const Image& exemplar, bool pyramid, int levels = 0, int bounded_levels = 0);

/// Stack level for a vertex with mean edge length e (section 3.3.4).
int antialias_level(const ExemplarLevels& ex, double r_scale, double mean_edge);

/// A coloured region vertex to compare: its offset from the centre in
/// level-0 texels, its stack level and its colour.
struct RegionSample {
  double du = 0, dv = 0;
  int level = 0;
  std::array<float, 3> color{};
};

/// Samples that land on the same texel (same level, same rounded offset)
/// merged: weight = count, color = mean (section 3.3.3).
struct SampleGroup {
  int dx = 0, dy = 0, level = 0;
  float weight = 0;
  std::array<float, 3> color{};
};

/// Integer texel offset of a sample at the level its region is compared at
/// (`center_level` for a pyramid, the sample's level for a stack).
std::array<int, 2> sample_offset(const ExemplarLevels& ex, const RegionSample& s, int center_level);

/// The oversampling groups of `samples` (order: by first occurrence).
std::vector<SampleGroup> group_samples(const ExemplarLevels& ex, const std::vector<RegionSample>& samples,
                                       int center_level);

/// d(Q) summed sample by sample (the naive metric, double precision).
double naive_distance(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level, int qx,
                      int qy);
/// d(Q) over groups, sum_g m_g |w_g - mean_g|^2 (double precision).
double grouped_distance(const ExemplarLevels& ex, const std::vector<SampleGroup>& groups, int center_level, int qx,
                        int qy);

struct MatchOptions {
  /// Merge samples on the same texel (3.3.3). Default on.
  bool averaging = true;
  /// Rows per parallel block (fixed so results do not depend on threads).
  int rows_per_block = 8;
};

/// What a match may choose besides the SSD: with `restricted`, only texels
/// x0..x1, y0..y1 (centre's level, clipped; else all of a wrapping level, or the
/// inside box at a bounded level); `bin_penalty` per exemplar bin (>= 0, null =
/// none) starts d(Q).
struct MatchBox {
  bool restricted = false;
  int x0 = 0, y0 = 0, x1 = -1, y1 = -1;
  const float* bin_penalty = nullptr;
  int bin = 1, bins_x = 0;
};

/// The box of candidates Q for which Q + o stays inside a w x h level for
/// every offset o in [min_dx, max_dx] x [min_dy, max_dy] (restricted; empty,
/// x1 < x0 or y1 < y0, when the offsets span more than the level).
MatchBox candidate_box(int w, int h, int min_dx, int max_dx, int min_dy, int max_dy);

struct MatchResult {
  bool found = false;   ///< false when there is no sample
  int qx = 0, qy = 0;   ///< best texel at the centre's level
  double distance = 0;  ///< d(Q_best) (without the constant C when averaging)
  std::size_t comparisons = 0;  ///< samples or groups compared per candidate
  std::size_t candidates = 0;   ///< candidates summed to the end, not abandoned (ExemplarIndex::match)
  /// A coherent candidate's sub-texel position (its vertex's lookup carried to
  /// the centre), where the match is one; else qx, qy are used.
  bool subtexel = false;
  double x = 0, y = 0;
};

/// Exhaustive best match (Algorithm 1) of the samples at `center_level`:
/// every texel is scored (the reference implementation).
MatchResult match_region(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                         const MatchOptions& opt = {});

/// The groups compared by match_region: grouped (averaging) or one per
/// sample, then stably sorted by decreasing weight (the order the SSD is
/// summed in). Uses a hash table in `scratch` (no std::map).
struct GroupScratch {
  std::vector<std::uint64_t> key;
  std::vector<int> slot;
  std::vector<std::array<double, 3>> sum;
};
/// The oversampling groups in order of first occurrence (group_samples
/// without allocation once `out` and `scratch` have grown).
void group_into(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                std::vector<SampleGroup>& out, GroupScratch& scratch);
void prepare_groups(const ExemplarLevels& ex, const std::vector<RegionSample>& samples, int center_level,
                    bool averaging, std::vector<SampleGroup>& out, GroupScratch& scratch);

/// Exact best match (bit for bit match_region's, ties to the lowest index),
/// single-threaded and allocation-free: R, G, B planes scanned row by row with
/// the region as a sparse stencil, heaviest groups first, rows and then
/// candidates abandoned once past the best. Immutable: match() is concurrent.
class ExemplarIndex {
 public:
  explicit ExemplarIndex(const ExemplarLevels& ex);
  /// `groups` as from prepare_groups (heaviest first). Throws
  /// InvalidInputError for a level out of range.
  MatchResult match(const std::vector<SampleGroup>& groups, int center_level) const;
  /// The same restricted to `box` (and with its penalty). An empty box gives
  /// found = false. At a bounded level the box must
  /// keeps every group inside the level (InvalidInputError otherwise).
  MatchResult match(const std::vector<SampleGroup>& groups, int center_level, const MatchBox& box) const;

 private:
  const ExemplarLevels* ex_;
  struct Level {
    std::array<std::vector<float>, 3> plane;  ///< R, G, B, row-major
  };
  std::vector<Level> levels_;
};

/// Bilinear colour of level l at continuous texel coordinates (x, y) (texel
/// centres at integers), wrapping, or clamped at a bounded level.
std::array<float, 3> texel_bilinear(const ExemplarLevels& ex, int level, double x, double y);

/// x wrapped into [0, n).
inline int wrap_coordinate(int x, int n) {
  if (x >= 0 && x < n) return x;  // within one period of the level: no division
  if (x < 0 && x >= -n) return x + n;
  if (x >= n && x < 2 * n) return x - n;
  x %= n;
  return x < 0 ? x + n : x;
}

/// The texel of level l at (x, y), wrapping, or clamped at a bounded level
/// (inline: the coherence search's inner loop).
inline const float* texel_pointer(const ExemplarLevels& ex, int level, int x, int y) {
  const Image& im = ex.levels[level];
  return ex.wraps(level) ? im.pixel(wrap_coordinate(x, im.width), wrap_coordinate(y, im.height))
                         : im.pixel(std::clamp(x, 0, im.width - 1), std::clamp(y, 0, im.height - 1));
}

/// Texel colour of level l at (x, y), as texel_pointer finds it.
inline std::array<float, 3> texel(const ExemplarLevels& ex, int level, int x, int y) {
  const float* p = texel_pointer(ex, level, x, y);
  return {p[0], p[1], p[2]};
}

}  // namespace surftex
