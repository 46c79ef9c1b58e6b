// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/tileable_tile.h"

#include <algorithm>
#include <string>

#include "geometry/errors.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex {

TileResult make_tileable_detailed(const Image& exemplar, int size, const TileOptions& o) {
  if (size < 8) throw InvalidInputError("make_tileable: size must be >= 8, got " + std::to_string(size));
  if (exemplar.empty()) throw InvalidInputError("make_tileable: the exemplar is empty");
  GraphcutOptions g;
  g.placement = o.placement;
  g.patch_size = o.patch_size > 0
                     ? o.patch_size
                     : std::max(4, std::min(size * 7 / 8, std::min(exemplar.width, exemplar.height) * 3 / 4));
  if (o.patch_size != 0 && o.patch_size < 4)
    throw InvalidInputError("make_tileable: patch_size must be 0 (auto) or >= 4, got " +
                            std::to_string(o.patch_size));
  g.overlap = o.overlap;
  if (o.overlap >= g.patch_size)
    throw InvalidInputError("make_tileable: overlap (" + std::to_string(o.overlap) +
                            ") must be smaller than the patch size (" + std::to_string(g.patch_size) + ")");
  g.refinement_passes = o.refinement_passes;
  g.k = o.k;
  g.periodic_output = true;
  g.seed = o.seed;
  g.progress = o.progress;
  GraphcutResult r = graphcut_synthesize_detailed(exemplar, size, size, g);
  TileResult t;
  t.tile = std::move(r.image);
  t.wrap_seam_ratio = wrap_seam_ratio(t.tile);
  t.seam_cost = r.seam_cost_final;
  return t;
}

Image make_tileable(const Image& exemplar, int size, const TileOptions& options) {
  return make_tileable_detailed(exemplar, size, options).tile;
}

}  // namespace surftex
