// SPDX-License-Identifier: AGPL-3.0-or-later
// Exemplar maps through the subdivision synthesis's lookups (see subdivision_exemplar_maps.h).
#include "texture/subdivision/subdivision_exemplar_maps.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "geometry/errors.h"
#include "geometry/mesh.h"
#include "geometry/properties.h"
#include "texture/subdivision/k_region_matching.h"

namespace surftex {

namespace {

// Vertices without a value take the mean of their valued neighbours, ring by
// ring from the valued ones (breadth first, in index order).
void fill_from_neighbours(const Mesh& mesh, std::vector<char>& has, std::vector<float>& val, int C) {
  std::vector<std::size_t> front;
  for (VertexIndex v : mesh.vertices())
    if (has[v.idx()]) front.push_back(v.idx());
  while (!front.empty()) {
    std::vector<std::size_t> next;
    for (std::size_t f : front) {
      const VertexIndex fv(static_cast<Mesh::size_type>(f));
      if (mesh.is_isolated(fv)) continue;
      for (VertexIndex w : mesh.vertices_around_target(mesh.halfedge(fv)))
        if (!has[w.idx()]) {
          has[w.idx()] = 2;  // queued: valued once its ring is done
          next.push_back(w.idx());
        }
    }
    for (std::size_t w : next) {
      std::vector<double> acc(C, 0.0);
      int n = 0;
      for (VertexIndex u : mesh.vertices_around_target(mesh.halfedge(VertexIndex(static_cast<Mesh::size_type>(w)))))
        if (has[u.idx()] == 1) {
          for (int c = 0; c < C; ++c) acc[c] += val[u.idx() * C + c];
          ++n;
        }
      for (int c = 0; c < C; ++c) val[w * C + c] = static_cast<float>(acc[c] / n);  // n >= 1: queued from one
    }
    for (std::size_t w : next) has[w] = 1;
    front = std::move(next);
  }
}

}  // namespace

VertexMapValues read_map_at_vertices(const Mesh& mesh, const SubdivisionSynthesisResult& r, const Image& map,
                                     int input_width, int input_height) {
  if (map.empty()) throw InvalidInputError("read_map_at_vertices: the map is empty");
  if (map.width != input_width || map.height != input_height)
    throw InvalidInputError("read_map_at_vertices: the map is " + std::to_string(map.width) + " x " +
                            std::to_string(map.height) + ", the exemplar " + std::to_string(input_width) + " x " +
                            std::to_string(input_height));
  const std::size_t nv = mesh.num_vertices();
  if (r.lookup.size() != nv || mesh.has_garbage())
    throw InvalidInputError("read_map_at_vertices: the synthesis result has " + std::to_string(r.lookup.size()) +
                            " lookups for " + std::to_string(nv) + " vertices");
  const Image as_synthesised = resample_as_synthesised(map, r.scale, r.periodic);
  const ExemplarLevels lv = make_exemplar_levels(as_synthesised, r.pyramid, 0, r.bounded_levels);
  VertexMapValues out;
  out.channels = map.channels >= 3 ? 3 : 1;
  const int C = out.channels;
  out.values.assign(nv * C, 0.f);
  std::vector<char> has(nv, 0);
  for (VertexIndex v : mesh.vertices()) {
    const ExemplarLookup& l = r.lookup[v.idx()];
    if (l.level < 0 || l.level >= static_cast<int>(lv.levels.size())) continue;
    const auto t = texel_bilinear(lv, l.level, l.x, l.y);
    for (int c = 0; c < C; ++c) out.values[v.idx() * C + c] = t[c];
    has[v.idx()] = 1;
  }
  for (char h : has) out.filled += h == 0;
  if (out.filled == nv) {  // nothing read: the map's mean everywhere
    const Image& l0 = lv.levels[0];
    std::vector<double> mean(C, 0.0);
    for (int y = 0; y < l0.height; ++y)
      for (int x = 0; x < l0.width; ++x)
        for (int c = 0; c < C; ++c) mean[c] += l0.at(x, y, c);
    for (std::size_t i = 0; i < out.values.size(); ++i)
      out.values[i] = static_cast<float>(mean[i % C] / (double(l0.width) * l0.height));
    return out;
  }
  if (out.filled > 0) fill_from_neighbours(mesh, has, out.values, C);
  return out;
}

std::vector<std::array<float, 3>> object_normals_from_map(const Mesh& mesh, const VertexMapValues& m) {
  if (m.channels < 3)
    throw InvalidInputError("object_normals_from_map: a normal map needs 3 channels, got " +
                            std::to_string(m.channels));
  if (m.values.size() != 3 * mesh.num_vertices())
    throw InvalidInputError("object_normals_from_map: values for another mesh");
  const SurfaceFrames fr = compute_surface_frames(mesh);  // the synthesis's frames
  std::vector<std::array<float, 3>> out(mesh.num_vertices(), {0.f, 0.f, 1.f});
  for (VertexIndex v : mesh.vertices()) {
    const std::size_t i = v.idx();
    const auto& n = fr.normal[i];
    const auto& d = fr.direction[i];
    const std::array<double, 3> b{n[1] * d[2] - n[2] * d[1], n[2] * d[0] - n[0] * d[2], n[0] * d[1] - n[1] * d[0]};
    double t[3];
    for (int c = 0; c < 3; ++c) t[c] = 2.0 * m.values[3 * i + c] - 1.0;
    double o[3], l = 0;
    for (int k = 0; k < 3; ++k) {
      o[k] = t[0] * d[k] + t[1] * b[k] + t[2] * n[k];
      l += o[k] * o[k];
    }
    l = std::sqrt(l);
    if (!(l > 1e-12)) {  // a zero normal in the map: the surface's
      out[i] = {static_cast<float>(n[0]), static_cast<float>(n[1]), static_cast<float>(n[2])};
      continue;
    }
    out[i] = {static_cast<float>(o[0] / l), static_cast<float>(o[1] / l), static_cast<float>(o[2] / l)};
  }
  return out;
}

std::vector<float> vertex_luminance(const VertexMapValues& v) {
  if (v.channels == 1) {
    std::vector<float> out = v.values;
    for (float& x : out) x = std::clamp(x, 0.f, 1.f);
    return out;
  }
  std::vector<float> out(v.values.size() / 3);
  for (std::size_t i = 0; i < out.size(); ++i)
    out[i] = clamped_luminance({v.values[3 * i], v.values[3 * i + 1], v.values[3 * i + 2]});
  return out;
}

float clamped_luminance(const std::array<float, 3>& c) {
  return std::clamp(0.2126f * c[0] + 0.7152f * c[1] + 0.0722f * c[2], 0.f, 1.f);  // as height_from_luminance
}

struct SurfaceExemplarSource::Data {
  ExemplarLevels ex;
  std::vector<std::array<double, 3>> position, u_axis, v_axis;
  std::vector<ExemplarLookup> lookup;
  std::vector<std::array<float, 3>> fallback;
  double texels_per_unit = 1;  // synthesis texels per mesh unit
  double scale_x = 1, scale_y = 1;
};

SurfaceExemplarSource::SurfaceExemplarSource(const Mesh& mesh, const SubdivisionSynthesisResult& r, const Image& map,
                                             std::vector<std::array<float, 3>> fallback,
                                             const ExemplarReadOptions& read) {
  const std::size_t nv = mesh.number_of_vertices();
  if (r.lookup.size() != nv || fallback.size() != nv || mesh.has_garbage())
    throw InvalidInputError("SurfaceExemplarSource: " + std::to_string(r.lookup.size()) + " lookups and " +
                            std::to_string(fallback.size()) + " fallback values for " + std::to_string(nv) +
                            " vertices");
  if (!(r.scale.texel_size > 0)) throw InvalidInputError("SurfaceExemplarSource: the result has no texel size");
  if (!(read.scale_x > 0 && read.scale_y > 0 && std::isfinite(read.scale_x) && std::isfinite(read.scale_y)) ||
      read.levels < 1 || read.levels > 8 || (r.pyramid && (read.scale_x != 1 || read.scale_y != 1)))
    throw InvalidInputError("SurfaceExemplarSource: read scale " + std::to_string(read.scale_x) + " x " +
                            std::to_string(read.scale_y) + " and " + std::to_string(read.levels) +
                            " levels (> 0, 1..8, scale 1 for a pyramid)");
  auto d = std::make_shared<Data>();
  // A stack read as the synthesis read it (bounded: clamped at every level
  // read); a pyramid whole.
  const int L = read.levels;
  d->ex = r.pyramid ? make_exemplar_levels(map, true, 0, r.bounded_levels)
                    : make_exemplar_levels(map, false, L, r.bounded_levels > 0 ? L : 0);
  const SurfaceFrames fr = compute_surface_frames(mesh);
  d->position.resize(nv);
  d->u_axis = fr.direction;
  d->v_axis.resize(nv);
  for (VertexIndex v : mesh.vertices()) {
    const Point3& p = mesh.point(v);
    const std::size_t i = v.idx();
    d->position[i] = {p.x(), p.y(), p.z()};
    const auto& n = fr.normal[i];
    const auto& u = fr.direction[i];
    d->v_axis[i] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
  }
  d->lookup = r.lookup;
  d->fallback = std::move(fallback);
  d->texels_per_unit = 1.0 / r.scale.texel_size;
  d->scale_x = read.scale_x, d->scale_y = read.scale_y;
  d_ = std::move(d);
}

SurfaceExemplarSource::~SurfaceExemplarSource() = default;

SurfaceExemplarSource SurfaceExemplarSource::at_level(int level) const {
  SurfaceExemplarSource s = *this;
  s.level_ = d_->ex.pyramid ? 0 : std::clamp(level, 0, levels() - 1);
  return s;
}

int SurfaceExemplarSource::levels() const { return static_cast<int>(d_->ex.levels.size()); }

double SurfaceExemplarSource::scale() const { return d_->scale_x; }

std::array<float, 3> SurfaceExemplarSource::operator()(const std::array<std::size_t, 3>& vertex,
                                                       const std::array<double, 3>& bary) const {
  const Data& d = *d_;
  std::array<double, 3> p{0, 0, 0};
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 3; ++j) p[j] += bary[k] * d.position[vertex[k]][j];
  std::array<float, 3> c{0, 0, 0};
  for (int k = 0; k < 3; ++k) {
    const std::size_t v = vertex[k];
    const ExemplarLookup& l = d.lookup[v];
    std::array<float, 3> t = d.fallback[v];
    if (l.level >= 0) {
      const auto& q = d.position[v];
      const std::array<double, 3> o{p[0] - q[0], p[1] - q[1], p[2] - q[2]};
      const auto& a = d.u_axis[v];
      const auto& b = d.v_axis[v];
      // In level-l texels: the match's offsets are level-0 texels over a^l (sample_offset).
      const double s = d.texels_per_unit / d.ex.scale(d.ex.pyramid ? l.level : 0);
      const double x = l.x + s * (o[0] * a[0] + o[1] * a[1] + o[2] * a[2]);
      const double y = l.y - s * (o[0] * b[0] + o[1] * b[1] + o[2] * b[2]);
      if (d.ex.pyramid)
        t = texel_bilinear(d.ex, l.level, x, y);
      else  // synthesis texel centres onto the map's pixel centres
        t = texel_bilinear(d.ex, level_, (x + 0.5) * d.scale_x - 0.5, (y + 0.5) * d.scale_y - 0.5);
    }
    for (int j = 0; j < 3; ++j) c[j] += static_cast<float>(bary[k]) * t[j];
  }
  return c;
}

}  // namespace surftex
