// SPDX-License-Identifier: AGPL-3.0-or-later
#include "geometry/render_view.h"

#include "geometry/errors.h"
#include "geometry/properties.h"
#include "geometry/render_mesh.h"

namespace surftex {

Image render_view(const Mesh& mesh, const ViewOptions& o) {
  using Colors = ViewOptions::Colors;
  Colors colors = o.colors;
  if (colors == Colors::Auto)
    colors = o.texture ? Colors::Texture : find(mesh, kVertexColor).second ? Colors::VertexColors : Colors::Constant;
  if (colors == Colors::Texture && !o.texture)
    throw InvalidInputError("render_view: Colors::Texture needs a texture image");
  RenderMeshOptions rmo;
  rmo.corner_uvs = colors == Colors::Texture;
  rmo.vertex_colors = colors == Colors::VertexColors;
  RenderMesh rm = make_render_mesh(mesh, rmo);
  if (o.up == ViewOptions::Up::Z) {
    for (auto& p : rm.positions) p = {p[0], p[2], -p[1]};
    for (auto& n : rm.vertex_normals) n = {n[0], n[2], -n[1]};
  }
  RenderOptions ro;
  ro.width = ro.height = o.size;
  ro.color_source = colors == Colors::Texture        ? RenderOptions::ColorSource::Texture
                    : colors == Colors::VertexColors ? RenderOptions::ColorSource::VertexColors
                                                     : RenderOptions::ColorSource::Constant;
  ro.texture = o.texture;
  ro.wrap = o.wrap;
  return render(rm, fit_camera(bounding_box(rm), o.azimuth_deg, o.elevation_deg), ro).color;
}

}  // namespace surftex
