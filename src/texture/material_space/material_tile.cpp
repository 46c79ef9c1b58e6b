// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/material_space/material_tile.h"

#include <tbb/parallel_invoke.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/timer.h"
#include "texture/tileable_tile.h"

namespace surftex {

namespace {

std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t tag) {
  std::uint64_t z = seed + 0x9E3779B97F4A7C15ull * (tag + 1);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

Image remap(const Image& src, const IndirectionMap& m) {
  Image out(m.width, m.height, src.channels);
  for (int j = 0; j < m.height; ++j)
    for (int i = 0; i < m.width; ++i) {
      const float* p = src.pixel(m.x(i, j), m.y(i, j));
      std::copy(p, p + src.channels, out.pixel(i, j));
    }
  return out;
}

// The keys' maps travel packed in one image per key and layer, channels
// [normal x y z][height][roughness] for the kinds present, through the very
// operations the colour goes through (each is per channel).
struct MapLayout {
  int normal = -1, height = -1, roughness = -1;  // first channel, -1 = absent
  int channels = 0;
};

MapLayout map_layout(const std::vector<MaterialKey>& keys) {
  MapLayout L;
  auto kind = [&](const char* name, const Image MaterialKey::*map, int width, int& slot) {
    std::size_t given = 0;
    for (const MaterialKey& k : keys) given += !(k.*map).empty();
    if (given == 0) return;
    if (given != keys.size())
      throw InvalidInputError(std::string(name) + " map given for " + std::to_string(given) + " of " +
                              std::to_string(keys.size()) + " keys (give one for every key, or none)");
    slot = L.channels;
    L.channels += width;
  };
  kind("normal", &MaterialKey::normal, 3, L.normal);
  kind("height", &MaterialKey::height, 1, L.height);
  kind("roughness", &MaterialKey::roughness, 1, L.roughness);
  return L;
}

Image pack_maps(const MaterialKey& key, const MapLayout& L, const std::string& what) {
  if (L.channels == 0) return {};
  const int W = key.texture.width, H = key.texture.height;
  Image out(W, H, L.channels);
  auto put = [&](const Image& m, int slot, const char* name) {
    if (slot < 0) return;
    if (m.width != W || m.height != H)
      throw InvalidInputError(what + ": " + name + " map " + std::to_string(m.width) + "x" +
                              std::to_string(m.height) + " differs from texture " + std::to_string(W) + "x" +
                              std::to_string(H));
    const bool normal = slot == L.normal;
    if (normal && m.channels < 3)
      throw InvalidInputError(what + ": normal map has " + std::to_string(m.channels) + " channels, needs RGB");
    for (int y = 0; y < H; ++y)
      for (int x = 0; x < W; ++x) {
        const float* p = m.pixel(x, y);
        float* o = out.pixel(x, y) + slot;
        if (normal)
          std::copy(p, p + 3, o);
        else  // grey, or the luminance of RGB (texture/pbr_maps.h's weights)
          *o = std::clamp(m.channels >= 3 ? 0.2126f * p[0] + 0.7152f * p[1] + 0.0722f * p[2] : p[0], 0.f, 1.f);
      }
  };
  put(key.normal, L.normal, "normal");
  put(key.height, L.height, "height");
  put(key.roughness, L.roughness, "roughness");
  return out;
}

// Unit normals again after a resample or a blend (encoded (n + 1) / 2; a
// vanishing vector becomes the flat normal).
void renormalise_normals(Image& maps, const MapLayout& L) {
  if (L.normal < 0 || maps.empty()) return;
  for (int y = 0; y < maps.height; ++y)
    for (int x = 0; x < maps.width; ++x) {
      float* p = maps.pixel(x, y) + L.normal;
      double n[3] = {2.0 * p[0] - 1, 2.0 * p[1] - 1, 2.0 * p[2] - 1};
      const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      if (l > 1e-12)
        for (double& c : n) c /= l;
      else
        n[0] = n[1] = 0, n[2] = 1;
      for (int c = 0; c < 3; ++c) p[c] = static_cast<float>(0.5 * n[c] + 0.5);
    }
}

// One channel range [first, first + n) of every packed layer.
std::vector<Image> unpack_layers(const std::vector<Image>& packed, int first, int n) {
  std::vector<Image> out;
  if (first < 0) return out;
  for (const Image& p : packed) {
    Image img(p.width, p.height, n);
    for (std::size_t i = 0; i < static_cast<std::size_t>(p.width) * p.height; ++i)
      std::copy(&p.data[i * p.channels + first], &p.data[i * p.channels + first + n], &img.data[i * n]);
    out.push_back(std::move(img));
  }
  return out;
}

// A size x size image of `src` read at the given source texels.
Image gather(const Image& src, const std::vector<int>& sx, const std::vector<int>& sy, int size) {
  Image out(size, size, src.channels);
  for (std::size_t i = 0; i < sx.size(); ++i) {
    if (sx[i] < 0 || sy[i] < 0) throw InvalidInputError("material tile: a key tile texel has no source");
    const float* p = src.pixel(sx[i], sy[i]);
    std::copy(p, p + src.channels, &out.data[i * src.channels]);
  }
  return out;
}

struct KeyTile {
  Image tile, mask;
  Image maps;  // packed (MapLayout), empty without maps
};

KeyTile prepare_key(const MaterialKey& key, std::size_t index, const MaterialTileOptions& opt, const MapLayout& L) {
  const std::string what = "key " + std::to_string(index) + (key.name.empty() ? "" : " ('" + key.name + "')");
  if (key.texture.empty()) throw InvalidInputError(what + ": empty texture");
  if (!key.mask.empty() && (key.mask.width != key.texture.width || key.mask.height != key.texture.height))
    throw InvalidInputError(what + ": mask " + std::to_string(key.mask.width) + "x" +
                            std::to_string(key.mask.height) + " differs from texture " +
                            std::to_string(key.texture.width) + "x" + std::to_string(key.texture.height));
  KeyTile k;
  k.tile = square_resample(key.texture, opt.size);
  if (L.channels > 0) {
    k.maps = square_resample(pack_maps(key, L, what), opt.size);
    renormalise_normals(k.maps, L);
  }
  if (!key.mask.empty()) k.mask = binarize_mask(square_resample(binarize_mask(key.mask), opt.size));
  if (!opt.keys_are_tileable && k.mask.empty()) {
    // Tileable version: graph-cut textures on the torus (the paper's [KdE*03]).
    TileOptions to;
    to.seed = derive_seed(opt.seed, 1000 + index);
    TileResult tr = make_tileable_detailed(k.tile, opt.size, to);
    k.tile = std::move(tr.tile);
    if (!k.maps.empty()) k.maps = gather(k.maps, tr.source_x, tr.source_y, opt.size);
  } else if (!opt.keys_are_tileable) {
    // Tileable version carrying a painted mask: unconstrained toroidal synthesis from the square itself.
    ConstrainedSynthesisOptions so = opt.synthesis;
    so.mask_weight = 0;
    so.random_first_layer = true;
    so.seed = derive_seed(opt.seed, 1000 + index);
    so.progress = nullptr;
    Image carried = k.mask.empty() ? Image(opt.size, opt.size, 1, 0.f) : k.mask;
    ConstrainedSynthesisResult r = synthesize_constrained_tiles(k.tile, carried, {carried}, so);
    const IndirectionMap& m = r.maps[0].back();
    k.tile = std::move(r.layers[0]);
    if (!k.mask.empty()) k.mask = remap(carried, m);
    if (!k.maps.empty()) k.maps = remap(k.maps, m);
  }
  if (k.mask.empty()) k.mask = compute_feature_mask(k.tile, opt.auto_mask).mask;
  return k;
}

void split_maps(MaterialTileResult& res, const std::vector<Image>& packed, const MapLayout& L) {
  if (L.channels == 0) return;
  res.normal_layers = unpack_layers(packed, L.normal, 3);
  res.height_layers = unpack_layers(packed, L.height, 1);
  res.roughness_layers = unpack_layers(packed, L.roughness, 1);
}

// One pair of consecutive keys (a, b), p its index among the K - 1 pairs:
// morph F_a into F_b (section 1.1), then the two constrained syntheses
// (section 1.2) side by side. Seeds depend on p only.
struct PairTile {
  MaskMorphResult morph;
  ConstrainedSynthesisResult ra, rb;
  double seconds_morph = 0, seconds_synthesis = 0;
};

PairTile make_pair_tile(const KeyTile& a, const KeyTile& b, std::size_t p, std::size_t K,
                        const MaterialTileOptions& opt) {
  PairTile pt;
  Timer t;
  MaskMorphOptions mo = opt.morph;
  mo.progress = nullptr;
  pt.morph = morph_feature_masks(a.mask, b.mask, opt.layers, mo);
  pt.seconds_morph = t.seconds();
  report_progress(opt.progress, "material tile: morph", double(p + 1) / (K - 1));
  t.reset();
  std::vector<Image> reversed(pt.morph.masks.rbegin(), pt.morph.masks.rend());
  ConstrainedSynthesisOptions sa = opt.synthesis, sb = opt.synthesis;
  sa.seed = derive_seed(opt.seed, 10 * p + 1);
  sb.seed = derive_seed(opt.seed, 10 * p + 2);
  sa.progress = [&opt, p, K](std::string_view, double f) {
    report_progress(opt.progress, "material tile: synthesis", (p + f) / (K - 1));
  };
  sb.progress = nullptr;
  tbb::parallel_invoke([&] { pt.ra = synthesize_constrained_tiles(a.tile, a.mask, pt.morph.masks, sa); },
                       [&] { pt.rb = synthesize_constrained_tiles(b.tile, b.mask, reversed, sb); });
  pt.seconds_synthesis = t.seconds();
  return pt;
}

}  // namespace

Image square_resample(const Image& img, int size) {
  if (img.empty()) throw InvalidInputError("square_resample: empty image");
  if (size < 1) throw InvalidInputError("square_resample: size " + std::to_string(size) + " < 1");
  const int side = std::min(img.width, img.height);
  const int x0 = (img.width - side) / 2, y0 = (img.height - side) / 2;
  Image out(size, size, img.channels);
  const double scale = double(side) / size;
  for (int j = 0; j < size; ++j)
    for (int i = 0; i < size; ++i) {
      double sx = std::clamp((i + 0.5) * scale - 0.5, 0.0, side - 1.0);
      double sy = std::clamp((j + 0.5) * scale - 0.5, 0.0, side - 1.0);
      int ix = std::min(static_cast<int>(sx), side - 2 < 0 ? 0 : side - 2);
      int iy = std::min(static_cast<int>(sy), side - 2 < 0 ? 0 : side - 2);
      double fx = side > 1 ? sx - ix : 0, fy = side > 1 ? sy - iy : 0;
      int ix1 = std::min(ix + 1, side - 1), iy1 = std::min(iy + 1, side - 1);
      for (int c = 0; c < img.channels; ++c) {
        double v = (1 - fx) * (1 - fy) * img.at(x0 + ix, y0 + iy, c) + fx * (1 - fy) * img.at(x0 + ix1, y0 + iy, c) +
                   (1 - fx) * fy * img.at(x0 + ix, y0 + iy1, c) + fx * fy * img.at(x0 + ix1, y0 + iy1, c);
        out.at(i, j, c) = static_cast<float>(v);
      }
    }
  return out;
}

MaterialTileResult make_material_tile(const std::vector<MaterialKey>& keys, const MaterialTileOptions& opt) {
  if (keys.empty()) throw InvalidInputError("make_material_tile: no key texture");
  if (opt.size < 16) throw InvalidInputError("make_material_tile: size " + std::to_string(opt.size) + " < 16");
  if (opt.layers < 1) throw InvalidInputError("make_material_tile: layers " + std::to_string(opt.layers) + " < 1");
  Timer total, t;
  MaterialTileResult res;
  const int M = opt.layers;
  const std::size_t K = keys.size();
  // Channel count: the largest among the keys (grey keys are broadcast).
  int channels = 0;
  for (const auto& k : keys) channels = std::max(channels, std::min(k.texture.channels, 4));
  const MapLayout L = map_layout(keys);
  std::vector<Image> packed;  // the map layers, packed as MapLayout
  std::vector<KeyTile> tiles(K);
  tbb::parallel_for(std::size_t(0), K, [&](std::size_t i) {
    MaterialKey k = keys[i];
    if (k.texture.channels != channels && !k.texture.empty()) {
      Image c(k.texture.width, k.texture.height, channels);
      for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x)
          for (int ch = 0; ch < channels; ++ch)
            c.at(x, y, ch) = ch < k.texture.channels ? k.texture.at(x, y, ch)
                             : ch == 3               ? 1.f
                                                     : k.texture.at(x, y, 0);
      k.texture = std::move(c);
    }
    tiles[i] = prepare_key(k, i, opt, L);
  });
  for (auto& k : tiles) {
    res.key_tiles.push_back(k.tile);
    res.key_masks.push_back(k.mask);
  }
  res.seconds_keys = t.seconds();
  report_progress(opt.progress, "material tile: keys", 1.0);

  if (K == 1) {  // same-mask mode (Figure 14)
    res.layers.assign(M + 1, Image());
    res.mask_agreement.assign(M + 1, 1.0);
    res.layers[0] = tiles[0].tile;
    packed.assign(M + 1, tiles[0].maps);
    t.reset();
    tbb::parallel_for(1, M + 1, [&](int m) {
      ConstrainedSynthesisOptions so = opt.synthesis;
      so.random_first_layer = true;
      // Same mask everywhere would let the synthesis rebuild the key itself;
      // refusing exemplar pixels near their own position forces a new tile.
      so.exclude_radius = opt.size / 8.0;
      so.seed = derive_seed(opt.seed, 2000 + m);
      so.progress = nullptr;
      ConstrainedSynthesisResult r = synthesize_constrained_tiles(tiles[0].tile, tiles[0].mask, {tiles[0].mask}, so);
      res.layers[m] = std::move(r.layers[0]);
      res.mask_agreement[m] = r.mask_agreement[0];
      if (!tiles[0].maps.empty()) packed[m] = remap(tiles[0].maps, r.maps[0].back());
    });
    res.seconds_synthesis = t.seconds();
    for (int m = 0; m <= M; ++m) {
      res.masks.push_back(tiles[0].mask);
      res.material.push_back(double(m) / M);
      res.sign_changes.push_back(0);
    }
    split_maps(res, packed, L);
    res.seconds_total = total.seconds();
    return res;
  }

  // Pairs of consecutive keys are independent: each morphs its masks and
  // runs its two syntheses (in parallel); the layers are assembled in order.
  std::vector<PairTile> pairs(K - 1);
  tbb::parallel_for(std::size_t(0), K - 1, [&](std::size_t p) {
    pairs[p] = make_pair_tile(tiles[p], tiles[p + 1], p, K, opt);
  });
  for (std::size_t p = 0; p + 1 < K; ++p) {
    const PairTile& pt = pairs[p];
    res.seconds_morph += pt.seconds_morph;
    res.seconds_synthesis += pt.seconds_synthesis;
    for (int m = (p == 0 ? 0 : 1); m <= M; ++m) {
      const Image& A = pt.ra.layers[m];
      const Image& B = pt.rb.layers[M - m];
      const float wb = static_cast<float>(double(m) / M), wa = 1.f - wb;
      Image out(A.width, A.height, A.channels);
      for (std::size_t i = 0; i < out.data.size(); ++i) out.data[i] = wa * A.data[i] + wb * B.data[i];
      res.layers.push_back(std::move(out));
      if (L.channels > 0) {  // the maps read where A_m and B_m read, blended alike
        const Image MA = remap(tiles[p].maps, pt.ra.maps[m].back());
        const Image MB = remap(tiles[p + 1].maps, pt.rb.maps[M - m].back());
        Image mo(MA.width, MA.height, MA.channels);
        for (std::size_t i = 0; i < mo.data.size(); ++i) mo.data[i] = wa * MA.data[i] + wb * MB.data[i];
        renormalise_normals(mo, L);
        packed.push_back(std::move(mo));
      }
      res.masks.push_back(pt.morph.masks[m]);
      res.material.push_back(double(p) + double(m) / M);
      res.sign_changes.push_back(m == 0 ? 0 : pt.morph.sign_changes[m - 1]);
      res.mask_agreement.push_back(std::min(pt.ra.mask_agreement[m], pt.rb.mask_agreement[M - m]));
    }
  }
  split_maps(res, packed, L);
  res.seconds_total = total.seconds();
  report_progress(opt.progress, "material tile", 1.0);
  return res;
}

}  // namespace surftex
