// SPDX-License-Identifier: AGPL-3.0-or-later
#include "shell/swatch_generators.h"
#include "geometry/constants.h"

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/primitive_meshes.h"
#include "shell/element_mesh.h"

namespace surftex {
namespace {

void check(bool ok, const std::string& what, double value) {
  if (!ok) throw InvalidInputError("swatch generator: " + what + " out of range (" + std::to_string(value) + ")");
}

double uniform(std::mt19937_64& g, double a, double b) {
  // Not std::uniform_real_distribution: its output is implementation-defined;
  // this keeps the swatches the same bytes across standard libraries.
  return a + (b - a) * (static_cast<double>(g() >> 11) * (1.0 / 9007199254740992.0));
}

/// Torus of major radius R, minor r in the plane spanned by e1, e2 (normal e3 = e1 x e2).
ElementMesh torus(const P3& c, const P3& e1, const P3& e2, double R, double r, int nu, int nv, double phase) {
  const P3 e3{e1[1] * e2[2] - e1[2] * e2[1], e1[2] * e2[0] - e1[0] * e2[2], e1[0] * e2[1] - e1[1] * e2[0]};
  ElementMesh m;
  for (int i = 0; i < nu; ++i) {
    double a = phase + 2 * kPi * i / nu;
    P3 radial{std::cos(a) * e1[0] + std::sin(a) * e2[0], std::cos(a) * e1[1] + std::sin(a) * e2[1],
              std::cos(a) * e1[2] + std::sin(a) * e2[2]};
    for (int j = 0; j < nv; ++j) {
      double b = 2 * kPi * j / nv;
      P3 p;
      for (int d = 0; d < 3; ++d) p[d] = c[d] + (R + r * std::cos(b)) * radial[d] + r * std::sin(b) * e3[d];
      m.points.push_back(p);
    }
  }
  for (int i = 0; i < nu; ++i)
    for (int j = 0; j < nv; ++j) {
      int a = i * nv + j, b = ((i + 1) % nu) * nv + j, cc = ((i + 1) % nu) * nv + (j + 1) % nv,
          d = i * nv + (j + 1) % nv;
      m.tris.push_back({a, b, cc});
      m.tris.push_back({a, cc, d});
    }
  return m;
}

/// Capped tube along a centre line given by points (open polyline); circular
/// cross-section of radius r in the plane normal to the tangent, the frame's
/// side axis kept close to `side_hint`.
ElementMesh tube(const std::vector<P3>& line, double r, int sides, const P3& side_hint) {
  ElementMesh m;
  const int n = static_cast<int>(line.size());
  for (int i = 0; i < n; ++i) {
    const P3& a = line[i > 0 ? i - 1 : 0];
    const P3& b = line[i + 1 < n ? i + 1 : n - 1];
    P3 t{b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    for (double& x : t) x /= tl;
    // s = hint projected orthogonal to t; u = t x s.
    double dp = side_hint[0] * t[0] + side_hint[1] * t[1] + side_hint[2] * t[2];
    P3 s{side_hint[0] - dp * t[0], side_hint[1] - dp * t[1], side_hint[2] - dp * t[2]};
    double sl = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    for (double& x : s) x /= sl;
    P3 u{t[1] * s[2] - t[2] * s[1], t[2] * s[0] - t[0] * s[2], t[0] * s[1] - t[1] * s[0]};
    for (int j = 0; j < sides; ++j) {
      double ang = 2 * kPi * j / sides;
      P3 p;
      for (int d = 0; d < 3; ++d) p[d] = line[i][d] + r * (std::cos(ang) * s[d] + std::sin(ang) * u[d]);
      m.points.push_back(p);
    }
  }
  for (int i = 0; i + 1 < n; ++i)
    for (int j = 0; j < sides; ++j) {
      int a = i * sides + j, b = (i + 1) * sides + j, c = (i + 1) * sides + (j + 1) % sides,
          d = i * sides + (j + 1) % sides;
      m.tris.push_back({a, d, c});
      m.tris.push_back({a, c, b});
    }
  // Caps: a centre vertex at each end.
  const int c0 = static_cast<int>(m.points.size());
  m.points.push_back(line.front());
  const int c1 = static_cast<int>(m.points.size());
  m.points.push_back(line.back());
  for (int j = 0; j < sides; ++j) {
    m.tris.push_back({c0, (j + 1) % sides, j});
    m.tris.push_back({c1, (n - 1) * sides + j, (n - 1) * sides + (j + 1) % sides});
  }
  // Orientation: outward if the cross-section runs counter-clockwise seen along
  // t. Check with the signed volume and flip everything if negative.
  double vol = 0;
  for (const Tri& t : m.tris) {
    const P3 &a = m.points[t[0]], &b = m.points[t[1]], &c = m.points[t[2]];
    vol += a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0]) +
           a[2] * (b[0] * c[1] - b[1] * c[0]);
  }
  if (vol < 0)
    for (Tri& t : m.tris) std::swap(t[1], t[2]);
  return m;
}
}  // namespace

void make_chainmail_swatch(Mesh& out, const ChainmailOptions& o) {
  check(o.rings_x >= 1 && o.rings_x <= 64, "rings_x", o.rings_x);
  check(o.rings_y >= 1 && o.rings_y <= 64, "rings_y", o.rings_y);
  check(o.ring_radius > 0 && std::isfinite(o.ring_radius), "ring_radius", o.ring_radius);
  check(o.wire_radius > 0 && o.wire_radius <= 0.2 * o.ring_radius, "wire_radius", o.wire_radius);
  check(o.segments >= 6 && o.segments <= 256, "segments", o.segments);
  check(o.sides >= 3 && o.sides <= 64, "sides", o.sides);
  std::mt19937_64 g(o.seed);
  const double R = o.ring_radius, d = 2.8 * R;
  std::vector<ElementMesh> rings;
  auto ring = [&](const P3& c, const P3& e1, const P3& e2) {
    const double phase = uniform(g, 0, 2 * kPi / o.segments);
    const double rr = R * uniform(g, 0.98, 1.02);
    rings.push_back(torus(c, e1, e2, rr, o.wire_radius, o.segments, o.sides, phase));
  };
  for (int j = 0; j < o.rings_y; ++j)
    for (int i = 0; i < o.rings_x; ++i) {
      ring({i * d, j * d, 0}, {1, 0, 0}, {0, 1, 0});
      if (i + 1 < o.rings_x) ring({(i + 0.5) * d, j * d, 0}, {0, 0, 1}, {1, 0, 0});  // axis y
      if (j + 1 < o.rings_y) ring({i * d, (j + 0.5) * d, 0}, {0, 1, 0}, {0, 0, 1});  // axis x
    }
  mesh_from_elements(rings, out);
}

void make_weave_swatch(Mesh& out, const WeaveOptions& o) {
  check(o.threads_x >= 1 && o.threads_x <= 64, "threads_x", o.threads_x);
  check(o.threads_y >= 1 && o.threads_y <= 64, "threads_y", o.threads_y);
  check(o.spacing > 0 && std::isfinite(o.spacing), "spacing", o.spacing);
  check(o.radius > 0 && o.radius <= 0.4 * o.spacing, "radius", o.radius);
  check(o.amplitude > o.radius * 1.06 && o.amplitude < o.spacing, "amplitude", o.amplitude);
  check(o.segments_per_spacing >= 2 && o.segments_per_spacing <= 64, "segments_per_spacing",
        o.segments_per_spacing);
  check(o.sides >= 3 && o.sides <= 64, "sides", o.sides);
  std::mt19937_64 g(o.seed);
  const double s = o.spacing;
  std::vector<ElementMesh> threads;
  // Threads along x (row j at y = j s) span the columns plus half a spacing each side.
  for (int j = 0; j < o.threads_y; ++j) {
    const double y = j * s + uniform(g, -0.04, 0.04) * s, r = o.radius * uniform(g, 0.95, 1.05);
    const int n = (o.threads_x) * o.segments_per_spacing + 1;
    std::vector<P3> line;
    for (int k = 0; k < n; ++k) {
      double x = -0.5 * s + s * k / o.segments_per_spacing;
      line.push_back({x, y, o.amplitude * std::cos(kPi * x / s) * ((j % 2) ? -1 : 1)});
    }
    threads.push_back(tube(line, r, o.sides, {0, 1, 0}));
  }
  for (int i = 0; i < o.threads_x; ++i) {
    const double x = i * s + uniform(g, -0.04, 0.04) * s, r = o.radius * uniform(g, 0.95, 1.05);
    const int n = (o.threads_y) * o.segments_per_spacing + 1;
    std::vector<P3> line;
    for (int k = 0; k < n; ++k) {
      double y = -0.5 * s + s * k / o.segments_per_spacing;
      line.push_back({x, y, -o.amplitude * std::cos(kPi * y / s) * ((i % 2) ? -1 : 1)});
    }
    threads.push_back(tube(line, r, o.sides, {1, 0, 0}));
  }
  mesh_from_elements(threads, out);
}

void make_scatter_swatch(Mesh& out, const ScatterOptions& o) {
  check(o.min_radius > 0, "min_radius", o.min_radius);
  check(o.max_radius >= o.min_radius && std::isfinite(o.max_radius), "max_radius", o.max_radius);
  check(o.size > 4 * o.max_radius && std::isfinite(o.size), "size", o.size);
  check(o.subdivisions >= 0 && o.subdivisions <= 4, "subdivisions", o.subdivisions);
  check(o.max_elements >= 1 && o.max_elements <= 100000, "max_elements", o.max_elements);
  check(o.attempts >= 1, "attempts", o.attempts);
  std::mt19937_64 g(o.seed);
  Mesh ico;
  make_icosphere(ico, o.subdivisions, 1.0);
  const ElementMesh unit = element_mesh_from(ico);
  const double min_dist = 2.3 * o.max_radius;
  std::vector<P3> centres;
  std::vector<ElementMesh> blobs;
  for (int a = 0; a < o.attempts && static_cast<int>(blobs.size()) < o.max_elements; ++a) {
    P3 c{uniform(g, o.max_radius, o.size - o.max_radius), uniform(g, o.max_radius, o.size - o.max_radius), 0};
    bool ok = true;
    for (const P3& q : centres)
      if ((q[0] - c[0]) * (q[0] - c[0]) + (q[1] - c[1]) * (q[1] - c[1]) < min_dist * min_dist) {
        ok = false;
        break;
      }
    if (!ok) continue;
    centres.push_back(c);
    const double r = uniform(g, o.min_radius, o.max_radius);
    // Smooth bump: 1 + 0.1 * (b . n)^2-ish low-frequency term, bounded by 10%.
    P3 b{uniform(g, -1, 1), uniform(g, -1, 1), uniform(g, -1, 1)};
    const double bl = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) + 1e-12;
    const double ph = uniform(g, 0, 2 * kPi);
    ElementMesh m = unit;
    for (P3& p : m.points) {
      double dp = (p[0] * b[0] + p[1] * b[1] + p[2] * b[2]) / bl;
      double f = r * (1.0 + 0.05 * (std::sin(3 * dp + ph) + dp * dp));
      p = {c[0] + f * p[0], c[1] + f * p[1], c[2] + 0.6 * f * p[2]};
    }
    blobs.push_back(std::move(m));
  }
  mesh_from_elements(blobs, out);
}

void make_tori_swatch(Mesh& out, const ToriOptions& o) {
  check(o.tori_x >= 1 && o.tori_x <= 64, "tori_x", o.tori_x);
  check(o.tori_y >= 1 && o.tori_y <= 64, "tori_y", o.tori_y);
  check(o.major_radius > 0 && std::isfinite(o.major_radius), "major_radius", o.major_radius);
  check(o.minor_radius > 0 && o.minor_radius <= 0.5 * o.major_radius, "minor_radius", o.minor_radius);
  check(std::isfinite(o.spacing) && 0.94 * o.spacing > 2 * (o.major_radius + o.minor_radius), "spacing", o.spacing);
  check(o.tilt_max_deg >= 0 && o.tilt_max_deg <= 80, "tilt_max_deg", o.tilt_max_deg);
  check(o.segments >= 6 && o.segments <= 256, "segments", o.segments);
  check(o.sides >= 3 && o.sides <= 64, "sides", o.sides);
  std::mt19937_64 g(o.seed);
  std::vector<ElementMesh> rings;
  for (int j = 0; j < o.tori_y; ++j)
    for (int i = 0; i < o.tori_x; ++i) {
      const P3 c{(i + uniform(g, -0.03, 0.03)) * o.spacing, (j + uniform(g, -0.03, 0.03)) * o.spacing, 0};
      // The ring's plane: xy turned by `tilt` about the horizontal axis at angle `az`.
      const double az = uniform(g, 0, kPi), tilt = uniform(g, 0, o.tilt_max_deg) * kPi / 180.0;
      const P3 a{std::cos(az), std::sin(az), 0}, b0{-std::sin(az), std::cos(az), 0};
      const P3 b{b0[0] * std::cos(tilt), b0[1] * std::cos(tilt), std::sin(tilt)};
      rings.push_back(torus(c, a, b, o.major_radius, o.minor_radius, o.segments, o.sides, uniform(g, 0, kPi)));
    }
  mesh_from_elements(rings, out);
}

}  // namespace surftex
