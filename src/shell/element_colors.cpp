// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/element_colors.h"

#include <cmath>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "geometry/render_view.h"

namespace surftex {

void color_by_element(Mesh& mesh, std::uint64_t seed) {
  auto elem = find(mesh, kFaceElement);
  if (!elem.second) throw InvalidInputError("color_by_element: the mesh has no f:element map");
  auto col = get_or_add(mesh, kVertexColor, Color3f{0.8f, 0.8f, 0.8f});
  for (FaceIndex f : mesh.faces()) {
    // SplitMix64 of (seed, id) -> a hue; saturated, fairly bright colours.
    std::uint64_t z = seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(elem.first[f]) + 1;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    z ^= z >> 31;
    const double h = static_cast<double>(z % 360000) / 1000.0;
    auto channel = [&](double n) {
      const double k = std::fmod(n + h / 60.0, 6.0);
      return static_cast<float>(0.85 - 0.6 * std::max(0.0, std::min({k, 4.0 - k, 1.0})));
    };
    const Color3f c{channel(5), channel(3), channel(1)};
    for (VertexIndex v : mesh.vertices_around_face(mesh.halfedge(f))) col[v] = c;
  }
}

Image render_preview(const Mesh& mesh, float azimuth, float elevation, int size) {
  ViewOptions v;
  v.size = size;
  v.azimuth_deg = azimuth;
  v.elevation_deg = elevation;
  v.colors = find(mesh, kVertexColor).second ? ViewOptions::Colors::VertexColors : ViewOptions::Colors::Constant;
  v.up = ViewOptions::Up::Z;
  return render_view(mesh, v);
}

}  // namespace surftex
