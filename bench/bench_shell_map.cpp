// SPDX-License-Identifier: AGPL-3.0-or-later
// Benchmark of the shell embedding of mesh quilting (Zhou et al. 2006, section
// 3.2) on the bunny: atlas, shell build, stretch before/after minimisation,
// shell map, embedding of a layer of small boxes with the exact
// self-intersection check. Prints one JSON object per stage.
// Usage: bench_shell_map [mesh] [output folder for OBJ/PNG previews] [atlas normal cone (deg)]
//                        [shell height in mean edge lengths]
//   default mesh: $SURFTEX_SHARED_DATA_DIR/meshes/bunny_6k.obj (6598 faces).
#include <nlohmann/json.hpp>

#include <cstdlib>
#include <iostream>
#include <string>

#include "geometry/base_mesh_atlas.h"
#include "geometry/image_io.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/read_mesh.h"
#include "geometry/render_view.h"
#include "geometry/timer.h"
#include "geometry/write_mesh.h"
#include "shell/embed_in_shell.h"
#include "shell/shell_map.h"
#include "shell/shell_space.h"
#include "shell/shell_stretch.h"

using namespace surftex;
using json = nlohmann::json;

namespace {
void line(const json& j) { std::cout << j.dump() << std::endl; }

void add_box(Mesh& out, double u, double v, double a, double w0, double w1) {
  VertexIndex q[8];
  for (int i = 0; i < 8; ++i)
    q[i] = out.add_vertex(Point3(i & 1 ? u + a : u - a, i & 2 ? v + a : v - a, i & 4 ? w1 : w0));
  const int f[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (auto& s : f) {
    out.add_face(q[s[0]], q[s[1]], q[s[2]]);
    out.add_face(q[s[0]], q[s[2]], q[s[3]]);
  }
}

void render_png(const Mesh& m, const std::string& path, float azimuth) {
  ViewOptions view;
  view.size = 900;
  view.azimuth_deg = azimuth;
  view.elevation_deg = 15.f;
  view.colors = ViewOptions::Colors::VertexColors;
  write_image(path, render_view(m, view));
}
}  // namespace

int main(int argc, char** argv) {
  try {
    const std::string path = argc > 1 ? argv[1] : std::string(SURFTEX_SHARED_DATA_DIR) + "/meshes/bunny_6k.obj";
    const std::string outdir = argc > 2 ? argv[2] : "";
    Timer total;
    Mesh base;
    Timer t;
    read_mesh(path, base);
    line({{"stage", "read"}, {"mesh", path}, {"faces", base.number_of_faces()},
          {"vertices", base.number_of_vertices()}, {"seconds", t.seconds()}});

    t.reset();
    BaseMeshAtlasOptions ao;
    if (argc > 3) ao.max_normal_angle_deg = std::atof(argv[3]);
    const BaseMeshAtlasResult atlas = compute_base_mesh_atlas(base, ao);
    line({{"stage", "atlas"}, {"charts", atlas.num_charts}, {"flipped_faces", atlas.flipped_faces},
          {"area_distortion", atlas.mean_area_distortion}, {"packing", atlas.packing_efficiency},
          {"seconds", t.seconds()}});

    t.reset();
    ShellSpaceOptions so;
    if (argc > 4) so.height = std::atof(argv[4]);
    ShellSpace shell = build_shell_space(base, so);
    const ShellOrientationCheck o0 = check_shell_orientation(shell);
    line({{"stage", "shell"}, {"tets", shell.tets.size()}, {"shell_vertices", shell.shell_points.size()},
          {"height", shell.height}, {"clamped_vertices", shell.clamped_vertices},
          {"shell_not_positive", o0.shell_not_positive}, {"texture_not_positive", o0.texture_not_positive},
          {"seconds", t.seconds()}});

    t.reset();
    MinimizeStretchOptions mo;
    const MinimizeStretchResult mr = shell_map_minimize_stretch(shell, mo);
    const ShellOrientationCheck o1 = check_shell_orientation(shell);
    const ShellStretch st = shell_stretch(shell);
    line({{"stage", "minimize_stretch"}, {"stretch_before", mr.stretch_before}, {"stretch_after", mr.stretch_after},
          {"max_tet_after", st.max_tet}, {"sweeps", mr.sweeps}, {"free_vertices", mr.free_vertices},
          {"moves_accepted", mr.moves_accepted}, {"moves_tried", mr.moves_tried}, {"colors", mr.colors},
          {"texture_not_positive", o1.texture_not_positive}, {"seconds", t.seconds()}});

    t.reset();
    const ShellMap map(shell);
    const double map_s = t.seconds();
    t.reset();
    const double spacing = 1.2 * shell.w_scale, half = 0.3 * spacing;
    Mesh layer;
    std::size_t boxes = 0;
    for (double u = 0; u <= 1; u += spacing)
      for (double v = 0; v <= 1; v += spacing) {
        bool inside = true;
        for (int i = 0; i < 8 && inside; ++i)
          inside = map.locate_texture({i & 1 ? u + half : u - half, i & 2 ? v + half : v - half, i & 4 ? 0.9 : 0.1})
                       .inside;
        if (inside) add_box(layer, u, v, half, 0.1, 0.9), ++boxes;
      }
    const double layer_s = t.seconds();
    t.reset();
    Mesh embedded = layer;
    const EmbedInShellResult er = embed_in_shell(embedded, map);
    line({{"stage", "embed"}, {"shell_map_seconds", map_s}, {"layer_seconds", layer_s}, {"boxes", boxes},
          {"faces", embedded.number_of_faces()}, {"outside", er.outside},
          {"self_intersecting_pairs", er.self_intersecting_pairs}, {"seconds", t.seconds()}});

    if (!outdir.empty()) {
      WriteMeshOptions wo;
      wo.write_uvs = false;
      write_mesh(outdir + "/shell_elements.obj", embedded, wo);
      Mesh offset = base;
      for (std::size_t i = 0; i < shell.shell_points.size(); ++i)
        if (shell.layer[i] == 1) {
          const Vec3& p = shell.shell_points[i];
          offset.point(VertexIndex(static_cast<Mesh::size_type>(shell.base_vertex[i]))) = Point3(p[0], p[1], p[2]);
        }
      write_mesh(outdir + "/shell_offset.obj", offset, wo);
      Mesh scene = base;
      auto col = get_or_add(scene, kVertexColor, Color3f{0.75f, 0.75f, 0.78f});
      Mesh el = embedded;
      auto ecol = get_or_add(el, kVertexColor, Color3f{0.9f, 0.45f, 0.1f});
      (void)ecol;
      scene.join(el);
      (void)col;
      render_png(scene, outdir + "/shell_elements.png", 0.f);
      render_png(scene, outdir + "/shell_elements_side.png", 90.f);
    }
    line({{"stage", "total"}, {"seconds", total.seconds()}});
  } catch (const std::exception& e) {
    std::cerr << "error: " << e.what() << "\n";
    return 2;
  }
  return 0;
}
