// SPDX-License-Identifier: AGPL-3.0-or-later
// Near-planar patch partitioning (Gorla et al. 2003, section 3.1).
#include "texture/patches/partition_near_planar.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <string>

#include "geometry/mesh_util.h"
#include "geometry/properties.h"

namespace surftex {
namespace {

class Partitioner {
 public:
  Partitioner(const Mesh& mesh, const PartitionOptions& opt) : mesh_(mesh), opt_(opt) {}

  PartitionResult run(std::vector<int>& patch_of);

 private:
  // distance from the centroid of `face` to the farthest vertex of `seed` < max_dist
  bool near_seed(int face, int seed) const {
    double far2 = 0;
    for (const Point3& p : corners_[seed]) far2 = std::max(far2, (centroid_[face] - p).squared_length());
    return far2 < max_dist_ * max_dist_;
  }
  bool admissible(int face, int seed) const {
    return normal_[face] * normal_[seed] >= cos_max_ && near_seed(face, seed);
  }
  void measure_faces();
  void grow(int seed, int id, std::vector<int>& patch_of);
  void greedy(std::vector<int>& patch_of);
  bool merge_small_patches(std::vector<int>& patch_of, int small, PartitionResult& res);
  bool reassign_faces(std::vector<int>& patch_of, PartitionResult& res);
  bool regrow_disconnected(std::vector<int>& patch_of);
  void renumber(std::vector<int>& patch_of, PartitionResult& res) const;

  const Mesh& mesh_;
  const PartitionOptions& opt_;
  int nf_ = 0;
  double cos_max_ = 0, max_dist_ = 0;
  std::vector<Vector3> normal_;
  std::vector<Point3> centroid_;
  std::vector<std::array<Point3, 3>> corners_;
  std::vector<std::array<int, 3>> adj_;  // edge-adjacent faces, -1 = border
  std::vector<int> seed_;                // per patch id
  std::vector<int> size_;                // per patch id
};

void Partitioner::grow(int seed, int id, std::vector<int>& patch_of) {
  std::deque<int> q{seed};
  patch_of[seed] = id;
  int count = 1;
  while (!q.empty() && count < opt_.max_faces) {
    const int f = q.front();
    q.pop_front();
    for (int g : adj_[f]) {
      if (g < 0 || patch_of[g] != -1 || !admissible(g, seed)) continue;
      patch_of[g] = id;
      q.push_back(g);
      if (++count >= opt_.max_faces) break;
    }
  }
  size_[id] = count;
}

void Partitioner::greedy(std::vector<int>& patch_of) {
  for (int f = 0; f < nf_; ++f) {
    if (patch_of[f] != -1) continue;
    const int id = static_cast<int>(seed_.size());
    seed_.push_back(f);
    size_.push_back(0);
    grow(f, id, patch_of);
  }
}

/// Per face: normal, corners, centroid, edge neighbours; then the angle and
/// distance bounds (max_distance 0: the radius of a disc of max_faces mean faces).
void Partitioner::measure_faces() {
  nf_ = static_cast<int>(mesh_.num_faces());
  normal_.resize(nf_);
  centroid_.resize(nf_);
  corners_.resize(nf_);
  adj_.assign(nf_, {-1, -1, -1});
  double area = 0;
  std::size_t live = 0;
  for (FaceIndex f : mesh_.faces()) {
    const int i = static_cast<int>(f.idx());
    normal_[i] = robust_face_normal(mesh_, f);
    const auto v = face_vertices(mesh_, f);
    corners_[i] = {mesh_.point(v[0]), mesh_.point(v[1]), mesh_.point(v[2])};
    centroid_[i] = CGAL::centroid(corners_[i][0], corners_[i][1], corners_[i][2]);
    area += face_area(mesh_, f);
    ++live;
    HalfedgeIndex h = mesh_.halfedge(f);
    for (int k = 0; k < 3; ++k, h = mesh_.next(h)) {
      const FaceIndex g = mesh_.face(mesh_.opposite(h));
      adj_[i][k] = g == Mesh::null_face() ? -1 : static_cast<int>(g.idx());
    }
  }
  cos_max_ = std::cos(opt_.max_angle_deg * M_PI / 180.0);
  max_dist_ = opt_.max_distance > 0
                  ? opt_.max_distance
                  : std::sqrt(opt_.max_faces * (area / std::max<std::size_t>(live, 1)) / M_PI);
  if (!(max_dist_ > 0)) max_dist_ = 1e-300;  // fully degenerate mesh: one face per patch
}

/// Rule 1: merge small patches (fewer than `small` faces) into the
/// neighbouring patch, with room for all their faces, that every face is
/// admissible to and that is best aligned on average. Returns whether any merged.
bool Partitioner::merge_small_patches(std::vector<int>& patch_of, int small, PartitionResult& res) {
  bool changed = false;
  std::vector<std::vector<int>> members(seed_.size());
  for (int f = 0; f < nf_; ++f)
    if (patch_of[f] >= 0) members[patch_of[f]].push_back(f);
  for (int p = 0; p < static_cast<int>(seed_.size()); ++p) {
    if (size_[p] == 0 || size_[p] >= small) continue;
    std::vector<int> cands;
    for (int f : members[p])
      for (int g : adj_[f])
        if (g >= 0 && patch_of[g] >= 0 && patch_of[g] != p) cands.push_back(patch_of[g]);
    std::sort(cands.begin(), cands.end());
    cands.erase(std::unique(cands.begin(), cands.end()), cands.end());
    int best = -1;
    double best_align = -2;
    for (int q : cands) {
      if (size_[q] == 0 || size_[q] + size_[p] > opt_.max_faces) continue;
      double align = 0;
      bool ok = true;
      for (int f : members[p]) {
        if (!admissible(f, seed_[q])) { ok = false; break; }
        align += normal_[f] * normal_[seed_[q]];
      }
      align /= static_cast<double>(members[p].size());
      if (ok && align > best_align) { best_align = align; best = q; }
    }
    if (best < 0) continue;
    for (int f : members[p]) patch_of[f] = best;
    members[best].insert(members[best].end(), members[p].begin(), members[p].end());
    members[p].clear();
    size_[best] += size_[p];
    size_[p] = 0;
    ++res.merged_patches;
    changed = true;
  }
  return changed;
}

/// Rule 2: reassign each face (but a seed) to the better-aligned neighbouring
/// patch, within its distance bound and with room. Returns whether any moved.
bool Partitioner::reassign_faces(std::vector<int>& patch_of, PartitionResult& res) {
  bool changed = false;
  for (int f = 0; f < nf_; ++f) {
    const int p = patch_of[f];
    if (p < 0 || seed_[p] == f) continue;
    const double own = normal_[f] * normal_[seed_[p]];
    int best = -1;
    double best_align = own;
    for (int g : adj_[f]) {
      if (g < 0 || patch_of[g] < 0 || patch_of[g] == p) continue;
      const int q = patch_of[g];
      const double a = normal_[f] * normal_[seed_[q]];
      if (a > best_align && size_[q] < opt_.max_faces && near_seed(f, seed_[q])) {
        best_align = a;
        best = q;
      }
    }
    if (best < 0) continue;
    patch_of[f] = best;
    --size_[p];
    ++size_[best];
    ++res.reassigned_faces;
    changed = true;
  }
  return changed;
}

/// Rule 3: keep every patch connected: the faces a patch's seed does not
/// reach within it are freed and grown into new patches. Returns whether any was.
bool Partitioner::regrow_disconnected(std::vector<int>& patch_of) {
  std::vector<bool> reached(nf_, false);
  for (int p = 0; p < static_cast<int>(seed_.size()); ++p) {
    if (size_[p] == 0) continue;
    std::deque<int> q{seed_[p]};
    reached[seed_[p]] = true;
    while (!q.empty()) {
      const int f = q.front();
      q.pop_front();
      for (int g : adj_[f])
        if (g >= 0 && !reached[g] && patch_of[g] == p) {
          reached[g] = true;
          q.push_back(g);
        }
    }
  }
  bool orphans = false;
  for (int f = 0; f < nf_; ++f)
    if (patch_of[f] >= 0 && !reached[f]) {
      --size_[patch_of[f]];
      patch_of[f] = -1;
      orphans = true;
    }
  if (orphans) greedy(patch_of);
  return orphans;
}

/// Renumbers the live patches by seed face index; their seeds, normals, face
/// counts and the largest deviation of a face from its seed's normal.
void Partitioner::renumber(std::vector<int>& patch_of, PartitionResult& res) const {
  std::vector<int> order;
  for (int p = 0; p < static_cast<int>(seed_.size()); ++p)
    if (size_[p] > 0) order.push_back(p);
  std::sort(order.begin(), order.end(), [&](int a, int b) { return seed_[a] < seed_[b]; });
  std::vector<int> remap(seed_.size(), -1);
  for (int i = 0; i < static_cast<int>(order.size()); ++i) remap[order[i]] = i;
  res.patches = static_cast<int>(order.size());
  res.seed_face.resize(res.patches);
  res.normal.resize(res.patches);
  res.faces.assign(res.patches, 0);
  for (int i = 0; i < res.patches; ++i) {
    const int s = seed_[order[i]];
    res.seed_face[i] = s;
    res.normal[i] = {normal_[s].x(), normal_[s].y(), normal_[s].z()};
  }
  for (int f = 0; f < nf_; ++f) {
    if (patch_of[f] < 0) continue;
    patch_of[f] = remap[patch_of[f]];
    ++res.faces[patch_of[f]];
    const double c = std::clamp(normal_[f] * normal_[res.seed_face[patch_of[f]]], -1.0, 1.0);
    res.max_deviation_deg = std::max(res.max_deviation_deg, std::acos(c) * 180.0 / M_PI);
  }
}

/// Gorla et al. 2003 s.3.1: greedy growth of near-planar patches from seed
/// faces, then rounds of the three refinement rules until nothing changes.
PartitionResult Partitioner::run(std::vector<int>& patch_of) {
  measure_faces();
  const int small = opt_.small_faces > 0 ? opt_.small_faces : std::max(2, opt_.max_faces / 10);
  PartitionResult res;
  patch_of.assign(nf_, -1);
  // Faces that are not live (removed elements) never get a patch.
  std::vector<bool> is_live(nf_, false);
  for (FaceIndex f : mesh_.faces()) is_live[f.idx()] = true;
  for (int f = 0; f < nf_; ++f)
    if (!is_live[f]) patch_of[f] = -2;
  greedy(patch_of);
  res.greedy_patches = static_cast<int>(seed_.size());
  for (int it = 0; it < opt_.max_iterations; ++it) {
    bool changed = merge_small_patches(patch_of, small, res);
    changed = reassign_faces(patch_of, res) || changed;
    changed = regrow_disconnected(patch_of) || changed;
    res.iterations = it + 1;
    if (!changed) break;
  }
  renumber(patch_of, res);
  res.max_distance = max_dist_;
  return res;
}

}  // namespace

PartitionResult partition_near_planar(Mesh& mesh, const PartitionOptions& opt) {
  auto bad = [](const std::string& m) { throw InvalidInputError("partition_near_planar: " + m); };
  if (!(opt.max_angle_deg > 0 && opt.max_angle_deg <= 89))
    bad("max_angle_deg " + std::to_string(opt.max_angle_deg) + " outside (0, 89]");
  if (!(opt.max_distance >= 0) || !std::isfinite(opt.max_distance))
    bad("max_distance " + std::to_string(opt.max_distance) + " must be finite and >= 0");
  if (opt.max_faces < 1) bad("max_faces " + std::to_string(opt.max_faces) + " < 1");
  if (opt.small_faces < 0) bad("small_faces " + std::to_string(opt.small_faces) + " < 0");
  if (opt.max_iterations < 0) bad("max_iterations " + std::to_string(opt.max_iterations) + " < 0");
  if (mesh.number_of_faces() == 0) bad("the mesh has no faces");
  require_triangle_mesh(mesh, "partition_near_planar");
  std::vector<int> patch_of;
  Partitioner part(mesh, opt);
  PartitionResult res = part.run(patch_of);
  auto pm = get_or_add(mesh, kFacePatch, -1);
  for (FaceIndex f : mesh.faces()) pm[f] = patch_of[f.idx()];
  return res;
}

}  // namespace surftex
