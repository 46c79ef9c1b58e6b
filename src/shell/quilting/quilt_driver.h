// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The mesh-quilting drivers (Zhou et al. 2006) that the `quilt` command, the
// demo and bench_quilt call: a swatch mesh quilted over a plane (section 2)
// or over a base mesh and embedded through the shell map (section 3), with
// the size checks, the element colours and the figures of their reports
// (to_json in quilt_json.h).
#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>

#include "geometry/mesh_fwd.h"
#include "geometry/work_budget.h"
#include "shell/quilting/embed_surface_quilt.h"
#include "shell/quilting/mesh_quilting.h"
#include "shell/quilting/quilt_coverage.h"
#include "shell/quilting/surface_quilting.h"
#include "shell/swatch.h"

namespace surftex {

/// true for the swatches the project generates: chainmail, weave, scatter, tori.
bool is_generated_swatch(const std::string& name);

/// The swatch mesh: one of the generated swatches at its defaults (seeded by
/// `seed`), else the file `name` (read_mesh). Throws as read_mesh.
Mesh load_or_generate_swatch(const std::string& name, std::uint64_t seed);

/// Largest output a quilt may build (faces), and most grid cells across the swatch.
constexpr double kMaxQuiltFaces = 5e7;
constexpr double kMaxSwatchCells = 200;

/// Refuses runs whose output could not be held: `placements` swatch copies
/// (the plane's W x H, or the base area over the swatch's) of its faces above
/// kMaxQuiltFaces (the message names `what`, e.g. "--plane 4x4"), or a
/// `cell` (swatch units, 0 = automatic) cutting the swatch into more than
/// kMaxSwatchCells cells across (the message names --cell). Throws InvalidInputError.
void check_quilt_size(const Swatch& swatch, double cell, double placements, const std::string& what);

/// Mean and largest element length of a planar quilt: each kFaceElement
/// element's larger xy bounding-box side, in units of `unit` (> 0); a
/// thread-length measure (threads ending at patch seams are short). {0, 0}
/// without kFaceElement or elements.
std::pair<double, double> element_lengths(const Mesh& mesh, double unit);

struct QuiltSwatchOnPlaneOptions {
  /// Factor applied to the swatch first (the paper's s); > 0. Default 1.
  double scale = 1;
  /// The swatch's thin axis, turned onto z (make_swatch). Default kAuto.
  SwatchAxis swatch_up = SwatchAxis::kAuto;
  /// quilt_plane's options; cell_size in the scaled swatch's units. Its seed
  /// is replaced by `seed`.
  PlanarQuiltOptions quilt;
  /// Seed of the quilt and of the element colours.
  std::uint64_t seed = 1;
  /// The plane as the messages name it ("4x4").
  std::string plane_name;
  /// Called with the run's work estimate before the quilting; may throw to
  /// refuse it (the CLI's memory budget). Empty = not checked.
  std::function<void(const WorkEstimate&)> check_work;
};

struct QuiltSwatchOnPlaneResult {
  QuiltResult quilt;
  Swatch swatch;                  ///< the scaled swatch that was quilted
  double width = 0, height = 0;   ///< the plane, in swatch sizes
  double element_length_mean = 0, element_length_max = 0;  ///< element_lengths over the swatch's larger side
};

/// Planar mesh quilting (section 2) of `swatch_mesh`, scaled, over width x
/// height swatch sizes into `out` (cleared), coloured by element
/// (kVertexColor, kFaceElement). Throws InvalidInputError (check_quilt_size,
/// make_swatch, quilt_plane, no element placed).
QuiltSwatchOnPlaneResult quilt_swatch_on_plane(const Mesh& swatch_mesh, double width, double height, Mesh& out,
                                               const QuiltSwatchOnPlaneOptions& opt = {});

struct QuiltSwatchOnSurfaceOptions {
  /// The swatch's thin axis, turned onto z (make_swatch). Default kAuto.
  SwatchAxis swatch_up = SwatchAxis::kAuto;
  /// quilt_surface's options (relative_size at most 10; 0 = default_surface_quilt_size
  /// of the swatch); its seed is replaced by `seed`.
  SurfaceQuiltOptions quilt;
  /// embed_surface_quilt's options; its stretch seed is replaced by `seed`.
  EmbedSurfaceQuiltOptions embed;
  /// Seed of the quilt, of the shell map's stretch minimisation and of the element colours.
  std::uint64_t seed = 1;
  /// The base mesh and the swatch as the messages name them.
  std::string mesh_name, swatch_name = "the swatch";
  /// As QuiltSwatchOnPlaneOptions::check_work.
  std::function<void(const WorkEstimate&)> check_work;
  /// Swatch edges longer than this many of its median edges are split
  /// (flat: the shape is kept) before quilting; 0 = none. The shell map moves
  /// vertices only, so a long edge cuts across the curved shell instead of
  /// following it, and stays longer than the output's 4-median shard bound
  /// (spot + bread.obj: 5.77 median edges). Default 2.5: the embedding's
  /// floor (1.5 swatch longest edges) then stays under 4 medians; the
  /// generated swatches and the rocks (1.3-2.0) are untouched.
  double split_edges_over_median = 2.5;
  /// Fill what the embedded quilt leaves bare (EmbedSurfaceQuiltOptions::fill):
  /// with whole rigid copies of the swatch's compact elements (rings, tubes,
  /// pebbles; the quilt scatter's gap kept, a swatch scattered alone in the up
  /// field's orientation; decision 102, session 45), else with pieces of its
  /// threads (thread_fill_templates); then the quilt's refill rounds, left
  /// to the swatch (SurfaceQuiltOptions::refill_rounds -1), are
  /// kRefillRoundsBeforeEmbeddedFill instead of six. Default true (session 44).
  bool fill_embedded = true;
  /// For a swatch scattered alone (scattered_alone): split the base's edges
  /// longer than its element spacing (scaled) before quilting
  /// (split_long_base_edges): the fills try one place per base face. Default
  /// true (decision 102, session 45).
  bool split_base_edges = true;
  /// Whole copies of compact elements: where the full size rests nowhere (a
  /// leg or a horn narrower than an element, a rim), the embedded fill tries
  /// copies scaled by these factors in turn, each in (0, 1)
  /// (EmbeddedFillOptions::smaller). Empty: full size only. Default 0.7, 0.5,
  /// 0.35 (decision 102, session 46: triceratops + torus_ring 10.9% of a band
  /// bare -> 1.1%, coffee_cup + chain mail 3.0% -> 1.0%).
  std::vector<double> fill_smaller{0.7, 0.5, 0.35};
};

/// The base with its edges longer than `bound` split (PMP::split_long_edges,
/// midpoints: the surface unchanged), in `fine`; returns the vertices added
/// (0: none was longer, `fine` untouched).
std::size_t split_long_base_edges(const Mesh& base, double bound, Mesh& fine);

/// The refill rounds of a swatch of threads that the embedding's fill follows.
inline constexpr int kRefillRoundsBeforeEmbeddedFill = 3;

struct QuiltSwatchOnSurfaceResult {
  SurfaceQuiltResult quilt;
  EmbedSurfaceQuiltResult embedding;
  SurfaceQuilt local;  ///< the quilt in the base's local coordinates (3.1)
  Swatch swatch;
  std::size_t base_faces = 0, faces = 0, vertices = 0;
  /// The bare area of `out` (output_bare_area, radius half the swatch's
  /// element spacing, bands along `up`): after the embedding removed and cut
  /// elements, unlike quilt.bare_fraction (the quilt before it).
  BareArea bare;
  /// The options the report echoes: relative size, up, field, largest turn.
  SurfaceQuiltOptions::Field field = SurfaceQuiltOptions::Field::kUp;
  std::array<double, 3> up{0, 1, 0};
  double relative_size = 0, rotation_max_deg = 0;
  double seconds_quilt = 0, seconds_embed = 0;  ///< the two stages, wall clock
  /// Vertices added to the swatch by split_edges_over_median.
  std::size_t swatch_vertices_split = 0;
  std::size_t base_vertices_split = 0;  ///< split_base_edges: vertices added to the base
};

/// Surface mesh quilting (section 3.1) of `swatch_mesh` over `base` (a
/// triangle mesh), embedded through the stretch-minimised shell map (3.2)
/// into `out`, coloured by element. Throws InvalidInputError (relative size
/// above 10, check_quilt_size, make_swatch, no element placed) and as
/// quilt_surface and embed_surface_quilt.
QuiltSwatchOnSurfaceResult quilt_swatch_on_surface(const Mesh& base, const Mesh& swatch_mesh, Mesh& out,
                                                   const QuiltSwatchOnSurfaceOptions& opt = {});

/// The scene a surface quilt is rendered in: `base` in grey (its own vertex
/// colours if it has them) with `quilt` joined.
void surface_quilt_scene(const Mesh& base, const Mesh& quilt, Mesh& scene);

}  // namespace surftex
