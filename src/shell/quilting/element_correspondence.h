// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Element correspondences between the output elements and the placed input
// elements (Zhou et al. 2006, section 2.5).
//
// 1. Per output vertex in the overlap, the input face of smallest Dist (BVH
//    closest point; D of eq. 1 reported for it, the minimiser unless the normal
//    term dominates). 2. Pruned for opposite normals or Dist > prune_factor
//    local edges. 3. Surviving pairs relate elements. 4. Relations whose xy
//    projections do not intersect (exact) are removed. Detail: decision 103.
#include <functional>
#include <utility>
#include <vector>

#include "shell/element_mesh.h"

namespace surftex {

struct VertexFacePair {
  int out_element = -1, vertex = -1;  ///< output element (index into `out`) and its vertex
  int in_element = -1, face = -1;     ///< input element (index into `in`) and its triangle
  P3 bary{0, 0, 0};                   ///< (alpha, beta, gamma) of h_in on the face
  P3 closest{0, 0, 0};                ///< h_in
  double distance = 0;                ///< Dist(v, f)
  double cost = 0;                    ///< D(v, f), eq. 1
};

struct CorrespondenceOptions {
  double lambda = 1.0;        ///< eq. 1 weight of the distance (paper: 1), >= 0
  double prune_factor = 3.0;  ///< "much larger than the local edge length": factor, > 0
};

struct ElementCorrespondences {
  std::vector<VertexFacePair> pairs;             ///< surviving pairs (set S)
  std::vector<std::pair<int, int>> related;      ///< (out element, in element), sorted, unique
  std::size_t candidates = 0;                    ///< vertices considered
  std::size_t pruned_normal = 0, pruned_distance = 0, pruned_projection = 0;
};

/// `in_overlap(p)` says whether an output vertex lies in the overlap region.
/// Only output elements listed in `out_ids` are considered (all if empty).
ElementCorrespondences find_element_correspondences(const std::vector<ElementMesh>& out,
                                                    const std::vector<int>& out_ids,
                                                    const std::vector<ElementMesh>& in,
                                                    const std::function<bool(const P3&)>& in_overlap,
                                                    const CorrespondenceOptions& opt = {});

/// True if some triangle of `a` projected to z = 0 intersects some triangle of
/// `b` projected likewise (exact predicates; degenerate projections skipped).
bool projections_overlap(const ElementMesh& a, const ElementMesh& b);

}  // namespace surftex
