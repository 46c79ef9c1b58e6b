// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/embed_in_shell.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/self_intersections.h"

namespace surftex {

EmbedInShellResult embed_in_shell(Mesh& mesh, const ShellMap& map, const EmbedInShellOptions& opt) {
  EmbedInShellResult r;
  std::vector<VertexIndex> verts(mesh.vertices().begin(), mesh.vertices().end());
  std::vector<Vec3> out(verts.size());
  std::vector<char> outside(verts.size(), 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, verts.size()), [&](const tbb::blocked_range<std::size_t>& rg) {
    for (std::size_t i = rg.begin(); i != rg.end(); ++i) {
      const Point3& p = mesh.point(verts[i]);
      const Vec3 uvw{p.x(), p.y(), p.z()};
      ShellMap::Location loc = map.locate_texture(uvw, false);
      if (!loc.inside) {
        outside[i] = 1;
        if (opt.outside_policy == EmbedInShellOptions::Outside::kExtrapolate) loc = map.locate_texture(uvw, true);
      }
      if (loc.tet >= 0) out[i] = map.shell_point(loc);
    }
  });
  for (std::size_t i = 0; i < verts.size(); ++i) {
    if (!outside[i]) continue;
    ++r.outside;
    if (opt.outside_policy == EmbedInShellOptions::Outside::kRefuse) {
      const Point3& p = mesh.point(verts[i]);
      throw InvalidInputError("embed in shell: vertex " + std::to_string(verts[i].idx()) + " at (u,v,w) = (" +
                              std::to_string(p.x()) + ", " + std::to_string(p.y()) + ", " + std::to_string(p.z()) +
                              ") is outside the texture space");
    }
  }
  for (std::size_t i = 0; i < verts.size(); ++i) mesh.point(verts[i]) = Point3(out[i][0], out[i][1], out[i][2]);
  r.vertices = verts.size();
  if (opt.check_self_intersections) {
    r.self_intersecting_pairs = count_self_intersections(mesh);
    r.checked = true;
  }
  return r;
}

}  // namespace surftex
