// SPDX-License-Identifier: AGPL-3.0-or-later
// `surftex info MESH`: what a mesh file holds and what reading it repaired.
#include <cstdio>
#include <numeric>

#include "geometry/mesh.h"
#include "geometry/read_mesh.h"
#include "geometry/repair_mesh_json.h"
#include "geometry/timer.h"
#include "geometry/union_find.h"
#include "surftex/command.h"

namespace surftex::cli {
namespace {
namespace info_command {  // named: the unity build joins these files

struct MeshTopology {
  std::size_t components = 0, boundary_loops = 0, boundary_edges = 0;
  long long euler = 0;
  bool closed = true;
};

MeshTopology topology(const Mesh& m) {
  MeshTopology t;
  // Components: union-find over vertices joined by edges.
  UnionFind<std::size_t> sets(m.num_vertices());
  for (EdgeIndex e : m.edges()) sets.unite(m.vertex(e, 0).idx(), m.vertex(e, 1).idx());
  for (VertexIndex v : m.vertices())
    if (!m.is_isolated(v) && sets.find(v.idx()) == v.idx()) ++t.components;
  // Boundary loops: cycles of border halfedges.
  std::vector<char> seen(m.num_halfedges(), 0);
  for (HalfedgeIndex h : m.halfedges()) {
    if (!m.is_border(h) || seen[h.idx()]) continue;
    ++t.boundary_loops;
    HalfedgeIndex g = h;
    do {
      seen[g.idx()] = 1;
      ++t.boundary_edges;
      g = m.next(g);
    } while (g != h && !seen[g.idx()]);
  }
  t.closed = t.boundary_loops == 0;
  t.euler = static_cast<long long>(m.number_of_vertices()) - static_cast<long long>(m.number_of_edges()) +
            static_cast<long long>(m.number_of_faces());
  return t;
}

SubcommandRegistrar reg{
    {"info", "Print the counts, topology, materials and repairs of a mesh file (OFF, OBJ, PLY, STL, GLB, glTF)",
     [](CLI::App& app) -> std::function<int()> {
       auto input = std::make_shared<std::string>();
       auto common = std::make_shared<CommonOptions>();
       auto no_tri = std::make_shared<bool>(false);
       app.add_option("mesh", *input, "Mesh file to inspect (.off, .obj, .ply, .stl, .glb, .gltf; other names by content)")
           ->required();
       app.add_flag("--no-triangulate", *no_tri,
                    "Keep polygons as they are instead of triangulating them (default: triangulate)");
       add_common_options(app, *common);
       return [input, common, no_tri] {
         auto limit = apply_thread_limit(common->threads);
         require_input_file(*input, "mesh");
         Timer timer;
         Mesh mesh;
         SoupToMeshOptions opt;
         opt.triangulate = !*no_tri;
         const MeshFileContents in = read_mesh_file(*input, mesh, opt);
         const SoupRepairCounts& c = in.counts;
         const double seconds = timer.seconds();
         MeshTopology t = topology(mesh);
         std::printf("mesh:            %s\n", input->c_str());
         std::printf("points:          %zu (in file)\n", c.input_points);
         std::printf("polygons:        %zu (in file)\n", c.input_polygons);
         std::printf("vertices:        %zu (after repair)\n", c.output_vertices);
         std::printf("faces:           %zu (after repair%s)\n", c.output_faces,
                     opt.triangulate ? " and triangulation" : "");
         std::printf("edges:           %zu\n", static_cast<std::size_t>(mesh.number_of_edges()));
         std::printf("components:      %zu\n", t.components);
         std::printf("boundary loops:  %zu (%zu boundary edges)\n", t.boundary_loops, t.boundary_edges);
         if (t.closed && (2 * static_cast<long long>(t.components) - t.euler) % 2 == 0)
           std::printf("genus:           %lld (closed; total over components)\n",
                       (2 * static_cast<long long>(t.components) - t.euler) / 2);
         else
           std::printf("genus:           - (open surface)\n");
         std::printf("repair:          %zu duplicate points merged, %zu degenerate polygons removed,\n"
                     "                 %zu duplicate polygons removed, %zu isolated points removed,\n"
                     "                 %zu polygons simplified, %zu pinched polygons split, %zu points duplicated to orient (%s),\n"
                     "                 %zu faces triangulated (%zu as fans), %zu faces with < 3 vertices dropped\n",
                     c.duplicate_points_merged, c.degenerate_polygons_removed, c.duplicate_polygons_removed,
                     c.isolated_points_removed, c.polygons_simplified, c.pinched_polygons_split, c.points_duplicated_to_orient,
                     c.oriented ? "orientable as given" : "non-manifold or non-orientable spots split",
                     c.faces_triangulated, c.faces_fan_triangulated, c.short_polygons_dropped);
         if (c.uv_corners + c.uv_corners_dropped > 0)
           std::printf("uv corners:      %zu mapped, %zu without a UV\n", c.uv_corners, c.uv_corners_dropped);
         for (const MeshMaterial& m : in.materials)
           std::printf("material:        %s, colour %.3g %.3g %.3g%s%s\n", m.name.c_str(), m.base_color[0],
                       m.base_color[1], m.base_color[2], m.has_texture() ? ", texture " : "",
                       m.texture_file.empty() ? (m.texture_bytes.empty() ? "" : "embedded") : m.texture_file.c_str());
         for (const std::string& w : in.warnings) std::printf("warning:         %s\n", w.c_str());
         std::printf("read time:       %.3f s\n", seconds);
         nlohmann::json r;
         r["mesh"] = *input;
         r["points"] = c.input_points;
         r["polygons"] = c.input_polygons;
         r["vertices"] = c.output_vertices;
         r["faces"] = c.output_faces;
         r["edges"] = mesh.number_of_edges();
         r["components"] = t.components;
         r["boundary_loops"] = t.boundary_loops;
         r["boundary_edges"] = t.boundary_edges;
         r["closed"] = t.closed;
         if (t.closed) r["genus"] = (2 * static_cast<long long>(t.components) - t.euler) / 2;
         else r["genus"] = nullptr;
         r["repair"] = to_json(c);
         r["materials"] = nlohmann::json::array();
         for (const MeshMaterial& m : in.materials)
           r["materials"].push_back({{"name", m.name},
                                     {"base_color", m.base_color},
                                     {"texture", m.texture_file.empty() ? (m.texture_bytes.empty() ? "" : "embedded")
                                                                        : m.texture_file}});
         r["warnings"] = in.warnings;
         r["seconds"] = {{"read", seconds}};
         write_report(*common, "info", r, {in.files_read, {}});
         return 0;
       };
     }}};

}  // namespace info_command
}  // namespace
}  // namespace surftex::cli
