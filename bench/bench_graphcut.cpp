// SPDX-License-Identifier: AGPL-3.0-or-later
// placeholder, replaced below
#include <cstdio>
#include <string>
#include "geometry/image_io.h"
#include "geometry/timer.h"
#include "texture/graphcut_synthesis.h"
#include "texture/tileable_tile.h"
#include "texture/wrap_seam_ratio.h"
using namespace surftex;
int main(int argc, char** argv) {
  Image ex = read_image(argv[1]);
  int n = std::stoi(argv[2]);
  GraphcutOptions o;
  if (argc > 4) o.refinement_passes = std::stoi(argv[4]);
  Timer t;
  auto r = graphcut_synthesize_detailed(ex, n, n, o);
  std::printf("synth %.3fs fill %d seam %.1f -> %.1f (%d/%d)\n", t.seconds(), r.fill_patches, r.seam_cost_after_fill, r.seam_cost_final, r.refinement_accepted, r.refinement_tried);
  write_image(std::string(argv[3]) + "_synth.png", r.image);
  t.reset();
  auto tr = make_tileable_detailed(ex, 128);
  std::printf("tile %.3fs ratio %.3f\n", t.seconds(), tr.wrap_seam_ratio);
  Image rep(256, 256, tr.tile.channels);
  for (int y = 0; y < 256; ++y) for (int x = 0; x < 256; ++x) for (int c = 0; c < rep.channels; ++c) rep.at(x,y,c) = tr.tile.at(x%128,y%128,c);
  write_image(std::string(argv[3]) + "_tile2x2.png", rep);
}
