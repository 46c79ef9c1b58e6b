// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/embed_surface_quilt.h"

#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/timer.h"
#include "shell/shell_map.h"
#include "shell/shell_space.h"

namespace surftex {

EmbedSurfaceQuiltResult embed_surface_quilt(const Mesh& base, const SurfaceQuilt& quilt, Mesh& out,
                                            const EmbedSurfaceQuiltOptions& opt) {
  if (!(opt.shell_height > 0) || !std::isfinite(opt.shell_height))
    throw InvalidInputError("embed_surface_quilt: shell_height must be > 0 (" + std::to_string(opt.shell_height) + ")");
  const double h = opt.shell_height * (quilt.z_max - quilt.z_min) * quilt.scale;
  if (!(h > 0)) throw InvalidInputError("embed_surface_quilt: the quilt has zero height or scale");
  EmbedSurfaceQuiltResult res;
  Timer t;
  Mesh atlas_mesh = base;
  report_progress(opt.progress, "atlas", 0.0);
  res.atlas = compute_base_mesh_atlas(atlas_mesh, opt.atlas);
  res.seconds_atlas = t.seconds();
  t.reset();
  report_progress(opt.progress, "shell", 0.0);
  ShellSpaceOptions so;
  so.height = h;
  so.relative_height = false;
  ShellSpace shell = build_shell_space(atlas_mesh, so);
  res.tets = shell.tets.size();
  res.clamped_vertices = shell.clamped_vertices;
  res.shell_height = shell.height;
  res.seconds_shell = t.seconds();
  t.reset();
  report_progress(opt.progress, "stretch", 0.0);
  res.stretch = shell_map_minimize_stretch(shell, opt.stretch);
  res.seconds_stretch = t.seconds();
  t.reset();
  report_progress(opt.progress, "embed", 0.0);
  const ShellMap map(shell);
  surface_quilt_to_texture(atlas_mesh, quilt, out);
  res.seconds_map = t.seconds();
  t.reset();
  EmbedInShellOptions eo;
  eo.check_self_intersections = opt.check_self_intersections;
  res.embed = embed_in_shell(out, map, eo);
  res.seconds_embed = t.seconds();
  report_progress(opt.progress, "embed", 1.0);
  return res;
}

}  // namespace surftex
