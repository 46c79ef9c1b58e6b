// SPDX-License-Identifier: AGPL-3.0-or-later
#include "texture/masked_ssd_fft.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <complex>
#include <memory>
#include <string>

#include "geometry/errors.h"

namespace surftex {
namespace {

using Complex = std::complex<double>;

// Smallest n' >= n whose only prime factors are 2, 3, 5 (fast for kissfft).
int smooth_size(int n) {
  for (int m = std::max(1, n);; ++m) {
    int r = m;
    for (int p : {2, 3, 5})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

// 2D real FFT of an nx * ny row-major array: rows real-to-half-complex, then
// columns complex. Spectrum layout: ny rows of hx = nx/2+1 coefficients.
struct Fft2 {
  int nx = 0, ny = 0, hx = 0;

  // Rows at and beyond `rows` are zero (a template in the corner): their row
  // transforms are zero and skipped.
  std::vector<Complex> forward(const std::vector<double>& in, int rows = -1) const {
    std::vector<Complex> spec(static_cast<std::size_t>(ny) * hx);
    const int nr = rows < 0 ? ny : std::min(rows, ny);
    tbb::parallel_for(tbb::blocked_range<int>(0, nr, 16), [&](const tbb::blocked_range<int>& r) {
      Eigen::FFT<double> fft;
      fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
      std::vector<Complex> tmp(static_cast<std::size_t>(nx));
      for (int y = r.begin(); y < r.end(); ++y) {
        fft.fwd(tmp.data(), in.data() + static_cast<std::size_t>(y) * nx, nx);
        std::copy(tmp.begin(), tmp.begin() + hx, spec.begin() + static_cast<std::ptrdiff_t>(y) * hx);
      }
    });
    columns(spec, true);
    return spec;
  }

  std::vector<double> inverse(std::vector<Complex> spec) const {
    columns(spec, false);
    std::vector<double> out(static_cast<std::size_t>(nx) * ny);
    tbb::parallel_for(tbb::blocked_range<int>(0, ny, 16), [&](const tbb::blocked_range<int>& r) {
      Eigen::FFT<double> fft;
      fft.SetFlag(Eigen::FFT<double>::HalfSpectrum);
      std::vector<Complex> tmp(static_cast<std::size_t>(nx));
      for (int y = r.begin(); y < r.end(); ++y) {
        std::copy(spec.begin() + static_cast<std::ptrdiff_t>(y) * hx,
                  spec.begin() + static_cast<std::ptrdiff_t>(y + 1) * hx, tmp.begin());
        fft.inv(out.data() + static_cast<std::size_t>(y) * nx, tmp.data(), nx);
      }
    });
    return out;
  }

 private:
  void columns(std::vector<Complex>& spec, bool fwd) const {
    tbb::parallel_for(tbb::blocked_range<int>(0, hx, 8), [&](const tbb::blocked_range<int>& r) {
      Eigen::FFT<double> fft;
      std::vector<Complex> a(static_cast<std::size_t>(ny)), b(static_cast<std::size_t>(ny));
      for (int k = r.begin(); k < r.end(); ++k) {
        for (int y = 0; y < ny; ++y) a[y] = spec[static_cast<std::size_t>(y) * hx + k];
        if (fwd)
          fft.fwd(b.data(), a.data(), ny);
        else
          fft.inv(b.data(), a.data(), ny);
        for (int y = 0; y < ny; ++y) spec[static_cast<std::size_t>(y) * hx + k] = b[y];
      }
    });
  }
};

void check_mask(const std::vector<float>& m, const Image& img, const char* what) {
  if (!m.empty() && m.size() != static_cast<std::size_t>(img.width) * img.height)
    throw InvalidInputError(std::string("masked SSD: ") + what + " has " +
                            std::to_string(m.size()) + " entries, expected " +
                            std::to_string(static_cast<std::size_t>(img.width) * img.height));
}

}  // namespace

struct MaskedSsdMatcher::Impl {
  Fft2 fft;
  int bw = 0, bh = 0, channels = 0;
  bool wrap = false;
  bool mask_trivial = true;       // all ones and not periodic: constant terms
  std::vector<Complex> s_b2;      // FFT(mb * |B|^2)
  std::vector<std::vector<Complex>> s_bc;  // FFT(mb * B_c)
  std::vector<Complex> s_mb;      // FFT(mb), only when !mask_trivial
};

MaskedSsdMatcher::MaskedSsdMatcher(const Image& big, std::vector<float> big_mask, bool wrap)
    : impl_(new Impl) {
  std::unique_ptr<Impl> guard(impl_);
  if (big.empty()) throw InvalidInputError("masked SSD: the searched image is empty");
  check_mask(big_mask, big, "big_mask");
  Impl& m = *impl_;
  m.bw = big.width;
  m.bh = big.height;
  m.channels = big.channels;
  m.wrap = wrap;
  m.mask_trivial = !wrap && std::all_of(big_mask.begin(), big_mask.end(),
                                        [](float v) { return v == 1.f; });
  m.fft.nx = wrap ? big.width : smooth_size(big.width);
  m.fft.ny = wrap ? big.height : smooth_size(big.height);
  m.fft.hx = m.fft.nx / 2 + 1;
  const std::size_t n = static_cast<std::size_t>(m.fft.nx) * m.fft.ny;
  std::vector<double> b2(n, 0.0), mb(n, 0.0);
  std::vector<std::vector<double>> bc(static_cast<std::size_t>(big.channels),
                                      std::vector<double>(n, 0.0));
  for (int y = 0; y < big.height; ++y)
    for (int x = 0; x < big.width; ++x) {
      std::size_t p = static_cast<std::size_t>(y) * m.fft.nx + x;
      double w = big_mask.empty() ? 1.0 : big_mask[static_cast<std::size_t>(y) * big.width + x];
      mb[p] = w;
      for (int c = 0; c < big.channels; ++c) {
        double v = big.at(x, y, c);
        b2[p] += w * v * v;
        bc[c][p] = w * v;
      }
    }
  m.s_b2 = m.fft.forward(b2);
  for (auto& ch : bc) m.s_bc.push_back(m.fft.forward(ch));
  if (!m.mask_trivial) m.s_mb = m.fft.forward(mb);
  guard.release();
}

MaskedSsdMatcher::~MaskedSsdMatcher() { delete impl_; }

SsdMap MaskedSsdMatcher::match(const Image& tmpl, const std::vector<float>& tmpl_mask) const {
  const Impl& m = *impl_;
  if (tmpl.empty()) throw InvalidInputError("masked SSD: template is empty");
  if (tmpl.channels != m.channels)
    throw InvalidInputError("masked SSD: template has " + std::to_string(tmpl.channels) +
                            " channels, the searched image " + std::to_string(m.channels));
  if (tmpl.width > m.bw || tmpl.height > m.bh)
    throw InvalidInputError("masked SSD: template " + std::to_string(tmpl.width) + "x" +
                            std::to_string(tmpl.height) + " larger than the searched image " +
                            std::to_string(m.bw) + "x" + std::to_string(m.bh));
  check_mask(tmpl_mask, tmpl, "tmpl_mask");
  const int nx = m.fft.nx, ny = m.fft.ny;
  const std::size_t n = static_cast<std::size_t>(nx) * ny;
  std::vector<double> mt(n, 0.0), t2(n, 0.0);
  std::vector<std::vector<double>> tc(static_cast<std::size_t>(m.channels),
                                      std::vector<double>(n, 0.0));
  double const_t2 = 0.0, const_mt = 0.0;
  for (int y = 0; y < tmpl.height; ++y)
    for (int x = 0; x < tmpl.width; ++x) {
      std::size_t p = static_cast<std::size_t>(y) * nx + x;
      double w = tmpl_mask.empty() ? 1.0 : tmpl_mask[static_cast<std::size_t>(y) * tmpl.width + x];
      mt[p] = w;
      const_mt += w;
      for (int c = 0; c < m.channels; ++c) {
        double v = tmpl.at(x, y, c);
        tc[c][p] = w * v;
        t2[p] += w * v * v;
      }
      const_t2 += t2[p];
    }
  // corr(f, g) = IFFT(F * conj(G)); all terms summed in frequency space.
  std::vector<Complex> s_mt = m.fft.forward(mt, tmpl.height);
  std::vector<Complex> prod(m.s_b2.size());
  for (std::size_t i = 0; i < prod.size(); ++i) prod[i] = m.s_b2[i] * std::conj(s_mt[i]);
  for (int c = 0; c < m.channels; ++c) {
    std::vector<Complex> s_tc = m.fft.forward(tc[c], tmpl.height);
    const auto& s_bc = m.s_bc[c];
    for (std::size_t i = 0; i < prod.size(); ++i) prod[i] -= 2.0 * s_bc[i] * std::conj(s_tc[i]);
  }
  std::vector<double> overlap_full;
  if (!m.mask_trivial) {
    std::vector<Complex> s_t2 = m.fft.forward(t2, tmpl.height);
    std::vector<Complex> ov(prod.size());
    for (std::size_t i = 0; i < prod.size(); ++i) {
      prod[i] += m.s_mb[i] * std::conj(s_t2[i]);
      ov[i] = m.s_mb[i] * std::conj(s_mt[i]);
    }
    overlap_full = m.fft.inverse(std::move(ov));
  }
  std::vector<double> ssd_full = m.fft.inverse(std::move(prod));

  SsdMap out;
  out.nx = m.wrap ? m.bw : m.bw - tmpl.width + 1;
  out.ny = m.wrap ? m.bh : m.bh - tmpl.height + 1;
  out.ssd.resize(static_cast<std::size_t>(out.nx) * out.ny);
  out.overlap.resize(out.ssd.size());
  for (int uy = 0; uy < out.ny; ++uy)
    for (int ux = 0; ux < out.nx; ++ux) {
      std::size_t q = static_cast<std::size_t>(uy) * out.nx + ux;
      std::size_t p = static_cast<std::size_t>(uy) * nx + ux;
      double s = ssd_full[p];
      double o = const_mt;
      if (m.mask_trivial)
        s += const_t2;
      else
        o = overlap_full[p];
      out.ssd[q] = std::max(0.0, s);
      out.overlap[q] = std::max(0.0, o);
    }
  return out;
}

SsdMap masked_ssd_brute_force(const Image& big, const std::vector<float>& big_mask,
                              const Image& tmpl, const std::vector<float>& tmpl_mask, bool wrap) {
  check_mask(big_mask, big, "big_mask");
  check_mask(tmpl_mask, tmpl, "tmpl_mask");
  if (tmpl.channels != big.channels || tmpl.width > big.width || tmpl.height > big.height)
    throw InvalidInputError("masked SSD: template does not fit the searched image");
  SsdMap out;
  out.nx = wrap ? big.width : big.width - tmpl.width + 1;
  out.ny = wrap ? big.height : big.height - tmpl.height + 1;
  out.ssd.assign(static_cast<std::size_t>(out.nx) * out.ny, 0.0);
  out.overlap.assign(out.ssd.size(), 0.0);
  for (int uy = 0; uy < out.ny; ++uy)
    for (int ux = 0; ux < out.nx; ++ux) {
      double s = 0.0, o = 0.0;
      for (int j = 0; j < tmpl.height; ++j)
        for (int i = 0; i < tmpl.width; ++i) {
          int bx = (ux + i) % big.width, by = (uy + j) % big.height;
          double w = (tmpl_mask.empty() ? 1.0 : tmpl_mask[static_cast<std::size_t>(j) * tmpl.width + i]) *
                     (big_mask.empty() ? 1.0 : big_mask[static_cast<std::size_t>(by) * big.width + bx]);
          o += w;
          for (int c = 0; c < big.channels; ++c) {
            double d = static_cast<double>(big.at(bx, by, c)) - tmpl.at(i, j, c);
            s += w * d * d;
          }
        }
      out.ssd[static_cast<std::size_t>(uy) * out.nx + ux] = s;
      out.overlap[static_cast<std::size_t>(uy) * out.nx + ux] = o;
    }
  return out;
}

}  // namespace surftex
