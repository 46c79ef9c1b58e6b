// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/rotated_exemplars.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "texture/image_ops.h"

namespace surftex {

int rotation_index(double radians, int rotations) {
  if (rotations < 1)
    throw InvalidInputError("rotations " + std::to_string(rotations) + " must be >= 1");
  if (!std::isfinite(radians))
    throw InvalidInputError("angle " + std::to_string(radians) + " is not finite");
  const double t = radians / (2.0 * M_PI) * rotations;
  long long k = std::llround(t) % rotations;
  if (k < 0) k += rotations;
  return static_cast<int>(k);
}

int RotatedExemplarSet::index_for_angle(double radians) const {
  return rotation_index(radians, rotations);
}

RotatedExemplar rotate_exemplar(const Image& exemplar, double radians, bool periodic, int margin) {
  if (exemplar.empty()) throw InvalidInputError("rotate_exemplar: exemplar is empty");
  if (margin < 0) throw InvalidInputError("rotate_exemplar: margin " + std::to_string(margin) + " < 0");
  RotatedExemplar r;
  r.angle = radians;
  const int w = exemplar.width, h = exemplar.height;
  const bool identity = radians == 0.0;
  if (periodic) {
    const int ow = w + 2 * margin, oh = h + 2 * margin;
    if (identity) {
      r.image = crop(exemplar, -margin, -margin, ow, oh, true);
      r.valid = Image(ow, oh, 1, 1.f);
    } else {
      r.image = rotate_image(exemplar, radians, ow, oh, true, &r.valid);
    }
    return r;
  }
  if (identity) {
    r.image = exemplar;
    r.valid = Image(w, h, 1, 1.f);
    return r;
  }
  const double c = std::abs(std::cos(radians)), s = std::abs(std::sin(radians));
  int ow = static_cast<int>(std::ceil((w - 1) * c + (h - 1) * s - 1e-9)) + 1;
  int oh = static_cast<int>(std::ceil((w - 1) * s + (h - 1) * c - 1e-9)) + 1;
  if ((ow - w) % 2 != 0) ++ow;  // keep the centres on the same pixel grid
  if ((oh - h) % 2 != 0) ++oh;
  r.image = rotate_image(exemplar, radians, ow, oh, false, &r.valid);
  return r;
}

namespace {

Image turn_image(const Image& img) {
  Image out(img.height, img.width, img.channels);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      int tx = x, ty = y;
      quarter_turn_position(img.width, tx, ty);
      std::copy_n(img.pixel(x, y), img.channels, out.pixel(tx, ty));
    }
  return out;
}

}  // namespace

RotatedExemplar turn_quarters(const RotatedExemplar& r, int q) {
  RotatedExemplar t = r;
  for (int i = 0; i < ((q % 4) + 4) % 4; ++i) {
    t.image = turn_image(t.image);
    t.valid = turn_image(t.valid);
    t.angle += M_PI / 2;
  }
  return t;
}

bool quarter_turns_shared(const Image& exemplar, int rotations, bool periodic) {
  return rotations % 4 == 0 && !periodic && (exemplar.width - exemplar.height) % 2 == 0;
}

int quarter_turns_of(const Image& exemplar, int k, int rotations, bool periodic) {
  return quarter_turns_shared(exemplar, rotations, periodic) ? k / (rotations / 4) : 0;
}

RotatedExemplar rotate_exemplar_step(const Image& exemplar, int k, int rotations, bool periodic, int margin) {
  if (rotations < 1 || k < 0 || k >= rotations)
    throw InvalidInputError("rotate_exemplar_step: orientation " + std::to_string(k) + " of " +
                            std::to_string(rotations));
  const int q = quarter_turns_of(exemplar, k, rotations, periodic);
  if (q == 0) return rotate_exemplar(exemplar, 2.0 * M_PI * k / rotations, periodic, margin);
  RotatedExemplar r = turn_quarters(
      rotate_exemplar(exemplar, 2.0 * M_PI * (k % (rotations / 4)) / rotations, periodic, margin), q);
  r.angle = 2.0 * M_PI * k / rotations;
  return r;
}

RotatedExemplarSet rotated_exemplars(const Image& exemplar, const RotatedExemplarOptions& opt) {
  if (exemplar.empty()) throw InvalidInputError("rotated_exemplars: exemplar is empty");
  if (opt.rotations < 1 || opt.rotations > 128)
    throw InvalidInputError("rotated_exemplars: rotations " + std::to_string(opt.rotations) +
                            " outside 1..128");
  if (opt.margin < 0)
    throw InvalidInputError("rotated_exemplars: margin " + std::to_string(opt.margin) + " < 0");
  RotatedExemplarSet set;
  set.rotations = opt.rotations;
  set.periodic = opt.periodic;
  set.items.resize(opt.rotations);
  std::vector<int> which = opt.only;
  if (which.empty())
    for (int k = 0; k < opt.rotations; ++k) which.push_back(k);
  for (int k : which) {
    if (k < 0 || k >= opt.rotations)
      throw InvalidInputError("rotated_exemplars: orientation index " + std::to_string(k) +
                              " outside 0.." + std::to_string(opt.rotations - 1));
    if (!set.items[k].image.empty()) continue;
    const double a = 2.0 * M_PI * k / opt.rotations;
    set.items[k] = rotate_exemplar(exemplar, a, opt.periodic, opt.margin);
  }
  return set;
}

}  // namespace surftex
