// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/quilting/quilt_driver.h"

#include <CGAL/Polygon_mesh_processing/remesh.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <string>
#include <tuple>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/timer.h"
#include "shell/element_colors.h"
#include "shell/element_mesh.h"
#include "shell/swatch_generators.h"

namespace surftex {

bool is_generated_swatch(const std::string& s) {
  return s == "chainmail" || s == "weave" || s == "scatter" || s == "tori";
}

Mesh load_or_generate_swatch(const std::string& name, std::uint64_t seed) {
  Mesh sm;
  if (name == "chainmail") {
    ChainmailOptions o;
    o.seed = seed;
    make_chainmail_swatch(sm, o);
  } else if (name == "weave") {
    WeaveOptions o;
    o.seed = seed;
    make_weave_swatch(sm, o);
  } else if (name == "scatter") {
    ScatterOptions o;
    o.seed = seed;
    make_scatter_swatch(sm, o);
  } else if (name == "tori") {
    ToriOptions o;
    o.seed = seed;
    make_tori_swatch(sm, o);
  } else {
    read_mesh(name, sm);
  }
  return sm;
}

void check_quilt_size(const Swatch& s, double cell, double placements, const std::string& what) {
  const double faces = placements * static_cast<double>(s.mesh.tris.size());
  if (!(faces <= kMaxQuiltFaces))
    throw InvalidInputError("quilt: " + what + " needs about " + std::to_string(static_cast<long long>(std::min(placements, 9e18))) +
                            " copies of the " + std::to_string(s.mesh.tris.size()) +
                            "-face swatch, more than the " + std::to_string(static_cast<long long>(kMaxQuiltFaces)) +
                            " output faces this tool will build (use a smaller area or a larger --scale)");
  const double across = std::max(s.length(), s.width()) / cell;
  if (cell > 0 && !(across <= kMaxSwatchCells))
    throw InvalidInputError("quilt: --cell " + std::to_string(cell) + " cuts the swatch into " +
                            std::to_string(static_cast<long long>(std::min(across, 9e18))) + " cells across, more than " +
                            std::to_string(static_cast<int>(kMaxSwatchCells)) + " (0 = automatic, a tenth of the swatch)");
}

std::pair<double, double> element_lengths(const Mesh& m, double unit) {
  const auto el = find(m, kFaceElement);
  if (!el.second || !(unit > 0)) return {0, 0};
  std::map<int, std::array<double, 4>> box;  // id -> xmin, xmax, ymin, ymax
  for (FaceIndex f : m.faces())
    for (VertexIndex v : m.vertices_around_face(m.halfedge(f))) {
      const Point3& p = m.point(v);
      auto it = box.try_emplace(el.first[f], std::array<double, 4>{p.x(), p.x(), p.y(), p.y()}).first;
      auto& b = it->second;
      b = {std::min(b[0], p.x()), std::max(b[1], p.x()), std::min(b[2], p.y()), std::max(b[3], p.y())};
    }
  double sum = 0, mx = 0;
  for (const auto& [id, b] : box) {
    const double l = std::max(b[1] - b[0], b[3] - b[2]) / unit;
    sum += l;
    mx = std::max(mx, l);
  }
  return {box.empty() ? 0 : sum / static_cast<double>(box.size()), mx};
}

QuiltSwatchOnPlaneResult quilt_swatch_on_plane(const Mesh& swatch_mesh, double w, double h, Mesh& out,
                                               const QuiltSwatchOnPlaneOptions& opt) {
  Mesh sm = swatch_mesh;
  const double sc = opt.scale;
  for (VertexIndex v : sm.vertices()) {
    const Point3 p = sm.point(v);
    sm.point(v) = Point3(p.x() * sc, p.y() * sc, p.z() * sc);
  }
  QuiltSwatchOnPlaneResult r;
  r.swatch = make_swatch(sm, opt.swatch_up);
  const Swatch& s = r.swatch;
  check_quilt_size(s, opt.quilt.cell_size, w * h, "--plane " + opt.plane_name);
  if (opt.check_work) opt.check_work(estimate_quilt(0, w * h * static_cast<double>(s.mesh.tris.size())));
  PlanarQuiltOptions o = opt.quilt;
  o.seed = opt.seed;
  r.quilt = quilt_plane(s, w * s.length(), h * s.width(), out, o);
  if (out.number_of_faces() == 0)
    throw InvalidInputError("quilt: no element was placed on the " + opt.plane_name + " plane");
  color_by_element(out, opt.seed);
  r.width = w;
  r.height = h;
  std::tie(r.element_length_mean, r.element_length_max) = element_lengths(out, std::max(s.length(), s.width()));
  return r;
}

namespace {

// The swatch's size on the base, checked before the work: relative size at
// most 10, the output's faces and the grid (check_quilt_size), the budget.
void check_surface_quilt_size(const Mesh& base, const Swatch& s, const SurfaceQuiltOptions& qo,
                              const std::function<void(const WorkEstimate&)>& check_work) {
  const double rel = qo.relative_size;
  if (!(rel <= 10))
    throw InvalidInputError("quilt: --scale must be <= 10 on a mesh (got " + std::to_string(rel) + ")");
  const double placements = surface_quilt_placements(base, s, rel);
  check_quilt_size(s, qo.cell_size, placements, "--scale " + std::to_string(rel));
  if (check_work)
    check_work(estimate_quilt(base.number_of_faces(), placements * static_cast<double>(s.mesh.tris.size())));
}

// The edges of `m` longer than `bound`.
std::vector<EdgeIndex> edges_longer_than(const Mesh& m, double bound) {
  std::vector<EdgeIndex> out;
  for (auto e : m.edges())
    if (CGAL::squared_distance(m.point(m.source(m.halfedge(e))), m.point(m.target(m.halfedge(e)))) > bound * bound)
      out.push_back(e);
  return out;
}

// The swatch's edges split (PMP::split_long_edges: midpoints on the edge,
// faces kept triangles and flat) until none is longer than `medians` of its
// median edge, the median taken again after each round (splitting adds short
// edges); at most 8 rounds. Returns the vertices added.
std::size_t split_long_swatch_edges(Mesh& m, double medians) {
  const std::size_t before = m.number_of_vertices();
  for (int round = 0; round < 8; ++round) {
    std::vector<double> len;
    len.reserve(m.number_of_edges());
    for (auto e : m.edges()) len.push_back(std::sqrt(CGAL::squared_distance(m.point(m.source(m.halfedge(e))),
                                                                            m.point(m.target(m.halfedge(e))))));
    if (len.empty()) break;
    const double longest = *std::max_element(len.begin(), len.end());
    std::nth_element(len.begin(), len.begin() + static_cast<std::ptrdiff_t>(len.size() / 2), len.end());
    const double bound = medians * len[len.size() / 2];
    if (!(bound > 0) || longest <= bound) break;
    CGAL::Polygon_mesh_processing::split_long_edges(edges_longer_than(m, bound), bound, m);
  }
  return m.number_of_vertices() - before;
}

// Compact elements placed whole by the embedded fill, as the quilt's scatter
// places them: its gap kept to every element; a swatch scattered alone in the
// guidance field's orientation (the up field's, unsmoothed) only; resting on
// the base, floating at most the shell's height over where the shell would
// hold it (its bottom stays in the shell; decision 102, session 45); then
// smaller copies where the full size rests nowhere (session 46).
void set_rigid_fill(const Swatch& sw, const SurfaceQuiltOptions& qo, double scale, const std::vector<double>& smaller,
                    EmbeddedFillOptions& f) {
  f.rigid = true;
  f.clearance = scatter_gap(sw, qo) * scale;
  f.max_float = sw.height() * scale;
  f.smaller = smaller;
  if (!scattered_alone(sw, qo)) return;
  f.turns = 1;
  if (qo.field == SurfaceQuiltOptions::Field::kUp) f.up = qo.up;
}

}  // namespace

std::size_t split_long_base_edges(const Mesh& base, double bound, Mesh& fine) {
  if (!(bound > 0)) return 0;
  std::vector<EdgeIndex> long_edges = edges_longer_than(base, bound);
  if (long_edges.empty()) return 0;
  fine = base;  // (a copy: the same edge indices)
  // The faces split get new edges, which may be long too: again, at most 8 rounds.
  for (int round = 0; round < 8 && !long_edges.empty(); ++round) {
    CGAL::Polygon_mesh_processing::split_long_edges(long_edges, bound, fine);
    long_edges = edges_longer_than(fine, bound);
  }
  return fine.number_of_vertices() - base.number_of_vertices();
}

QuiltSwatchOnSurfaceResult quilt_swatch_on_surface(const Mesh& input_base, const Mesh& swatch_mesh, Mesh& out,
                                                   const QuiltSwatchOnSurfaceOptions& opt) {
  QuiltSwatchOnSurfaceResult r;
  if (!(opt.split_edges_over_median == 0 || opt.split_edges_over_median >= 1.5))
    throw InvalidInputError("quilt: split_edges_over_median must be 0 (never) or at least 1.5, got " +
                            std::to_string(opt.split_edges_over_median));
  if (opt.split_edges_over_median > 0) {
    Mesh fine = swatch_mesh;
    r.swatch_vertices_split = split_long_swatch_edges(fine, opt.split_edges_over_median);
    r.swatch = make_swatch(fine, opt.swatch_up);
  } else {
    r.swatch = make_swatch(swatch_mesh, opt.swatch_up);
  }
  // Before the estimate and any work: a flat swatch gives a shell of no
  // thickness (embed_surface_quilt would refuse it after the quilting).
  if (!(r.swatch.height() > 0))
    throw InvalidInputError("quilt: " + opt.swatch_name + " has zero height: its thinnest extent (its " +
                            axis_name(r.swatch.up_axis) +
                            " axis, see --swatch-up) is 0, so the shell over the mesh would have no thickness; "
                            "a flat swatch quilts a plane (--plane WxH)");
  SurfaceQuiltOptions qo = opt.quilt;
  if (!(qo.relative_size > 0)) qo.relative_size = default_surface_quilt_size(r.swatch);
  check_surface_quilt_size(input_base, r.swatch, qo, opt.check_work);
  // A swatch scattered alone: base faces wider than its element spacing
  // split (the surface unchanged), as both fills try one place per face and
  // the bare measure samples four points per face: a chair leg's long
  // triangles stayed bare (decision 102, session 45). Quilted swatches cover
  // faces by patches and are left alone.
  Mesh fine_base;
  if (opt.split_base_edges && scattered_alone(r.swatch, qo)) {
    const double spacing = swatch_element_spacing(r.swatch) * surface_quilt_scale(input_base, r.swatch, qo.relative_size);
    r.base_vertices_split = split_long_base_edges(input_base, spacing, fine_base);
  }
  const Mesh& base = r.base_vertices_split > 0 ? fine_base : input_base;
  qo.seed = opt.seed;
  // The embedded fill places the swatch's compact elements whole, else
  // pieces of its threads. A swatch of threads gets six refill rounds in the
  // quilt (its only fill there); filled again after the embedding, three do
  // (decision 102, session 44).
  std::vector<ElementMesh> fill_templates;
  if (opt.fill_embedded && qo.scatter_attempts > 0) fill_templates = compact_swatch_elements(r.swatch);
  const bool fill_rigid = !fill_templates.empty();
  if (!fill_rigid && opt.fill_embedded) fill_templates = thread_fill_templates(r.swatch, qo);
  if (qo.refill_rounds < 0 && !fill_rigid && !fill_templates.empty()) qo.refill_rounds = kRefillRoundsBeforeEmbeddedFill;
  Timer t;
  r.quilt = quilt_surface(base, r.swatch, r.local, qo);
  r.seconds_quilt = t.seconds();
  if (r.local.elements == 0 || r.local.tris.empty())
    throw InvalidInputError("quilt: no element was placed on '" + opt.mesh_name + "' at --scale " +
                            std::to_string(qo.relative_size) +
                            " (the swatch may be too large for the mesh: lower --scale)");
  EmbedSurfaceQuiltOptions eo = opt.embed;
  eo.stretch.seed = opt.seed;
  const double swatch_longest = longest_edge_length(r.swatch.mesh) * r.local.scale;
  if (eo.max_edge == 0) eo.max_edge = qo.max_edge_stretch * swatch_longest;
  if (eo.min_edge_bound == 0) eo.min_edge_bound = 1.5 * swatch_longest;
  eo.swatch_self_crossings = r.swatch.element_self_crossings;
  eo.whole_copy_sources = swatch_element_meshes(r.swatch);
  const double bare_radius = 0.5 * swatch_element_spacing(r.swatch) * r.local.scale;
  if (eo.fill.templates.empty()) eo.fill.templates = std::move(fill_templates);
  eo.fill.scale = r.local.scale;
  eo.fill.z0 = r.swatch.bbox_min[2];
  eo.fill.radius = bare_radius;
  eo.fill.max_stretch = qo.scatter_max_stretch;
  eo.fill.own_crossings = r.swatch.element_self_crossings;
  eo.fill.seed = opt.seed;
  if (fill_rigid) set_rigid_fill(r.swatch, qo, r.local.scale, opt.fill_smaller, eo.fill);
  t.reset();
  r.embedding = embed_surface_quilt(base, r.local, out, eo);
  r.seconds_embed = t.seconds();
  color_by_element(out, opt.seed);
  r.bare = output_bare_area(base, out, bare_radius, qo.up);
  r.base_faces = base.number_of_faces();
  r.faces = out.number_of_faces();
  r.vertices = out.number_of_vertices();
  r.field = qo.field;
  r.up = qo.up;
  r.relative_size = qo.relative_size;
  r.rotation_max_deg = qo.rotation_max_deg;
  return r;
}

void surface_quilt_scene(const Mesh& base, const Mesh& quilt, Mesh& scene) {
  scene = base;
  get_or_add(scene, kVertexColor, Color3f{0.72f, 0.72f, 0.75f});
  scene.join(quilt);
}

}  // namespace surftex
