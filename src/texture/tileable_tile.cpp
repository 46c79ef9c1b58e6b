// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/tileable_tile.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "texture/image_ops.h"
#include "texture/wrap_seam_ratio.h"

namespace surftex {

TorusCut choose_torus_cut(const Image& img) {
  if (img.empty() || img.width < 2 || img.height < 2)
    throw InvalidInputError("choose_torus_cut: the image must be at least 2x2, got " +
                            std::to_string(img.width) + "x" + std::to_string(img.height));
  return choose_torus_cut(line_jump_profile(img, /*periodic=*/true));
}

TorusCut choose_torus_cut(const LineJumpProfile& p) {
  if (!p.periodic) throw InvalidInputError("choose_torus_cut: the line profile is not of a periodic image");
  TorusCut c;
  for (std::size_t x = 1; x < p.column.size(); ++x)
    if (p.column[x] < p.column[static_cast<std::size_t>(c.shift_x)]) c.shift_x = static_cast<int>(x);
  for (std::size_t y = 1; y < p.row.size(); ++y)
    if (p.row[y] < p.row[static_cast<std::size_t>(c.shift_y)]) c.shift_y = static_cast<int>(y);
  c.column_jump = p.column[static_cast<std::size_t>(c.shift_x)];
  c.row_jump = p.row[static_cast<std::size_t>(c.shift_y)];
  return c;
}

GraphcutOptions tileable_graphcut_options(const Image& exemplar, int size, const TileOptions& o) {
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
  g.repetition_penalty = o.repetition_penalty;
  g.periodic_output = true;
  g.straight_seam_steps = o.straight_seam_steps;
  g.straight_seam_ratio = o.straight_seam_ratio;
  g.straight_seam_cost_tolerance = o.straight_seam_cost_tolerance;
  g.seed = o.seed;
  g.progress = o.progress;
  return g;
}

TileResult make_tileable_detailed(const Image& exemplar, int size, const TileOptions& o) {
  const GraphcutOptions g = tileable_graphcut_options(exemplar, size, o);
  GraphcutResult r = graphcut_synthesize_detailed(exemplar, size, size, g);
  TileResult t;
  t.tile = std::move(r.image);
  t.wrap_seam_ratio_at_synthesis_cut = wrap_seam_ratio(t.tile);
  const LineJumpProfile prof = line_jump_profile(t.tile, true);
  t.worst_line_ratio = prof.worst_ratio;
  auto below = [](const std::vector<double>& v, double x) {
    return static_cast<double>(std::count_if(v.begin(), v.end(), [x](double e) { return e < x; })) /
           static_cast<double>(v.size() - 1);
  };
  t.synthesis_column_percentile = below(prof.column, prof.column[0]);
  t.synthesis_row_percentile = below(prof.row, prof.row[0]);
  const SourceMatchedLineProfile sm = source_matched_line_profile(t.tile, exemplar, r.source_x, r.source_y);
  t.source_matched_wrap_ratio_at_synthesis_cut = sm.wrap_ratio;
  t.source_matched_worst_line_ratio = sm.worst_ratio;
  if (o.choose_cut) {
    const TorusCut c = choose_torus_cut(prof);
    t.shift_x = c.shift_x;
    t.shift_y = c.shift_y;
    if (c.shift_x != 0 || c.shift_y != 0) t.tile = crop(t.tile, c.shift_x, c.shift_y, size, size, true);
  }
  t.source_x.resize(std::size_t(size) * size);
  t.source_y.resize(t.source_x.size());
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const std::size_t from = std::size_t((y + t.shift_y) % size) * size + (x + t.shift_x) % size;
      t.source_x[std::size_t(y) * size + x] = r.source_x[from];
      t.source_y[std::size_t(y) * size + x] = r.source_y[from];
    }
  t.wrap_seam_ratio = wrap_seam_ratio(t.tile);
  t.seam_cost = r.seam_cost_final;
  return t;
}

Image make_tileable(const Image& exemplar, int size, const TileOptions& options) {
  return make_tileable_detailed(exemplar, size, options).tile;
}

}  // namespace surftex
