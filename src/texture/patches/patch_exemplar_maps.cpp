// SPDX-License-Identifier: AGPL-3.0-or-later
// Exemplar maps through the patch synthesis's coordinates (see patch_exemplar_maps.h).
#include "texture/patches/patch_exemplar_maps.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <map>
#include <string>

#include "geometry/errors.h"
#include "texture/rotated_exemplars.h"

namespace surftex {

namespace {


// Turns an encoded tangent-space normal by `a` (counter-clockwise, x right, y up).
void turn_normal(float* n, double a) {
  const double x = 2.0 * n[0] - 1, y = 2.0 * n[1] - 1, z = 2.0 * n[2] - 1;
  const double c = std::cos(a), s = std::sin(a);
  double rx = c * x - s * y, ry = s * x + c * y, rz = z;
  const double l = std::sqrt(rx * rx + ry * ry + rz * rz);
  if (l > 0) rx /= l, ry /= l, rz /= l;
  n[0] = static_cast<float>(0.5 * rx + 0.5);
  n[1] = static_cast<float>(0.5 * ry + 0.5);
  n[2] = static_cast<float>(0.5 * rz + 0.5);
}

}  // namespace

std::vector<Image> resample_patch_map(const PatchSynthesisResult& res, const Image& map,
                                      std::array<int, 2> exemplar_size, const ElOptions& el, bool tangent_normal) {
  if (map.empty() || map.width != exemplar_size[0] || map.height != exemplar_size[1])
    throw InvalidInputError("exemplar map is " + std::to_string(map.width) + " x " + std::to_string(map.height) +
                            ", the colour exemplar " + std::to_string(exemplar_size[0]) + " x " +
                            std::to_string(exemplar_size[1]) + ": give maps of the exemplar's size");
  if (tangent_normal && map.channels < 3)
    throw InvalidInputError("exemplar normal map has " + std::to_string(map.channels) + " channels, needs RGB");
  const int P = static_cast<int>(res.flat.patches.size());
  if (static_cast<int>(res.sources.size()) != P || static_cast<int>(res.images.size()) != P)
    throw InvalidInputError("resample_patch_map: the synthesis result holds no source coordinates");
  const int K = el.rotations, C = map.channels;
  // The rotations the synthesis used, built once each.
  std::vector<char> used(K, 0);
  for (const auto& src : res.sources)
    for (const ElSource& s : src) {
      if (s.exemplar > 0)
        throw InvalidInputError("exemplar maps apply to the first exemplar only (a pixel came from exemplar " +
                                std::to_string(s.exemplar) + ")");
      if (s.exemplar == 0) used[s.rotation] = 1;
    }
  std::vector<RotatedExemplar> rot(K);
  const int margin = el.window / 2;  // as efros_leung prepares its search images
  tbb::parallel_for(0, K, [&](int k) {
    if (used[k]) rot[k] = rotate_exemplar_step(map, k, K, el.periodic_exemplar, margin);
  });
  std::vector<float> mean(C, 0.f);
  for (std::size_t i = 0; i < map.data.size(); ++i) mean[i % C] += map.data[i];
  for (float& m : mean) m /= static_cast<float>(map.data.size() / C);

  std::vector<Image> out(P);
  tbb::parallel_for(0, P, [&](int p) {
    const FlatPatch& fp = res.flat.patches[p];
    Image img(fp.bw, fp.bh, C);
    for (std::size_t i = 0; i < fp.pixel.size(); ++i) {
      float* v = img.data.data() + i * C;
      const ElSource& s = res.sources[p][i];
      if (fp.pixel[i] != PatchPixel::Inside || s.exemplar < 0) {
        for (int c = 0; c < C; ++c) v[c] = mean[c];
        continue;
      }
      for (int c = 0; c < C; ++c) v[c] = rot[s.rotation].image.at(s.x, s.y, c);
      if (tangent_normal) turn_normal(v, 2.0 * M_PI * s.rotation / K);
    }
    out[p] = std::move(img);
  });
  // Boundary pixels from the neighbour patch (patch_synthesis.h step 7).
  std::vector<int> face_patch, face_slot;
  for (int q = 0; q < P; ++q)
    for (std::size_t t = 0; t < res.flat.patches[q].triangles.size(); ++t) {
      const int f = res.flat.patches[q].triangles[t].face;
      if (f >= static_cast<int>(face_patch.size())) face_patch.resize(f + 1, -1), face_slot.resize(f + 1, -1);
      face_patch[f] = q;
      face_slot[f] = static_cast<int>(t);
    }
  // A normal read from patch q is in q's plane frame; p's rotated copy of
  // the face gives the turn into p's frame.
  auto edge_angle = [](const FlatTriangle& t) {
    return std::atan2(t.corner[1][1] - t.corner[0][1], t.corner[1][0] - t.corner[0][0]);
  };
  for (int p = 0; p < P; ++p) {
    const FlatPatch& fp = res.flat.patches[p];
    std::map<int, const FlatTriangle*> ring;
    for (const FlatTriangle& t : fp.boundary) ring.emplace(t.face, &t);
    for (std::size_t i = 0; i < fp.pixel.size(); ++i) {
      if (fp.pixel[i] != PatchPixel::Boundary) continue;
      const int f = fp.pixel_face[i];
      if (f < 0 || f >= static_cast<int>(face_patch.size()) || face_patch[f] < 0) continue;
      const int q = face_patch[f];
      const FlatPatch& fq = res.flat.patches[q];
      const FlatTriangle& tq = fq.triangles[face_slot[f]];
      const auto& b = fp.pixel_bary[i];
      const double u = b[0] * tq.corner[0][0] + b[1] * tq.corner[1][0] + b[2] * tq.corner[2][0];
      const double v = b[0] * tq.corner[0][1] + b[1] * tq.corner[1][1] + b[2] * tq.corner[2][1];
      const auto pq = fq.to_pixel(u, v);
      float* value = &out[p].data[i * C];
      if (!sample_inside(fq, out[q], pq[0], pq[1], value) || !tangent_normal) continue;
      auto mine = ring.find(f);
      if (mine != ring.end()) turn_normal(value, edge_angle(*mine->second) - edge_angle(tq));
    }
  }
  return out;
}

}  // namespace surftex
