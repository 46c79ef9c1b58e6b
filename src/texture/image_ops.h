// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Small image utilities shared by the synthesis code: luminance, RGB
// conversion, crop, bilinear resize and rotation (with or without toroidal
// wrap).
//
// Inputs and outputs are surftex::Image (float, interleaved channels, (0,0)
// top-left). Every function but as_rgb throws InvalidInputError (naming the
// argument) on an empty image or an out-of-range parameter.

#include <array>

#include "geometry/image.h"

namespace surftex {

/// Rec. 709 luminance of an RGB(A) image (alpha ignored); a 1- or 2-channel
/// image returns its first channel. Output: 1 channel, same size.
Image luminance(const Image& img);

/// Three channels: the first three of an RGB(A) image (alpha dropped), a
/// grey (or grey + alpha) image's first channel replicated; an RGB image is
/// returned as it is, an empty image as an empty one.
Image as_rgb(const Image& img);

/// The w x h block starting at (x, y); coordinates wrap toroidally when
/// `wrap`, else the block must lie inside `img`.
Image crop(const Image& img, int x, int y, int w, int h, bool wrap = false);

/// A block of pixels: top-left corner and size.
struct PixelRect {
  int x = 0, y = 0, width = 0, height = 0;
  long long area() const { return static_cast<long long>(width) * height; }
};

/// Whether pixel (x, y) is transparent: alpha (the last channel of a 2- or
/// 4-channel image) below 0.5. Images of 1 or 3 channels have none.
bool is_transparent(const Image& img, int x, int y);

/// The largest axis-aligned block of `img` holding no transparent pixel (ties:
/// the one whose bottom row is highest, then leftmost); the whole image when
/// none is transparent; width 0 when all are. O(width x height).
PixelRect largest_opaque_rectangle(const Image& img);

/// Bilinear resize to w x h (pixel centres aligned: sample (i+0.5)*W/w-0.5,
/// clamped to the border, or read around it with `wrap`: a tile stays a
/// tile). Suitable for moderate scale changes; for strong minification build
/// a pyramid first.
Image resize_bilinear(const Image& img, int w, int h, bool wrap = false);

/// Bilinear sample at continuous pixel coordinates (x, y) (pixel centres at
/// integers). With `wrap`, coordinates wrap around; without, they are clamped.
/// Writes img.channels values to `out`.
void sample_bilinear(const Image& img, double x, double y, bool wrap, float* out);

/// Where exemplar point (x, y) (pixel coordinates of the w x h exemplar) lies
/// in its rotation by the angle of cosine c and sine s stored in an ow x oh
/// canvas: rotate_image's map, centre on centre (rotated_exemplars.h: the
/// quarter-turned orientations of rotate_exemplar_step share it). Wrapped
/// (periodic) canvases hold other copies too.
inline std::array<double, 2> rotated_point(int w, int h, int ow, int oh, double c, double s, double x, double y) {
  const double dx = x - (w - 1) * 0.5, dy = y - (h - 1) * 0.5;
  return {c * dx + s * dy + (ow - 1) * 0.5, -s * dx + c * dy + (oh - 1) * 0.5};
}

/// The inverse of rotated_point: the exemplar point of canvas point (i, j).
inline std::array<double, 2> exemplar_point(int w, int h, int ow, int oh, double c, double s, double i, double j) {
  const double u = i - (ow - 1) * 0.5, v = j - (oh - 1) * 0.5;
  return {c * u - s * v + (w - 1) * 0.5, s * u + c * v + (h - 1) * 0.5};
}

/// Rotates `img` by `radians` counter-clockwise as displayed (y down on
/// screen, so the exemplar +x axis maps to (cos a, -sin a) in pixel
/// coordinates) about its centre, bilinear. The output has size out_w x
/// out_h, centred on the same point. Pixels whose source lies outside the
/// image are 0 unless `wrap` (the image is treated as periodic).
/// `valid` (if non-null) receives a 1-channel mask: 1 where the bilinear
/// footprint lies fully inside the source (always 1 with `wrap`), else 0.
Image rotate_image(const Image& img, double radians, int out_w, int out_h, bool wrap,
                   Image* valid = nullptr);

}  // namespace surftex
