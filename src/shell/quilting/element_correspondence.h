// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Element correspondences between the output elements and the placed input
// elements (Zhou et al. 2006, section 2.5).
//
// 1. For every output vertex in the overlap region, its "nearest" input face
//    f_in^i and the closest point h_in^i on it. Equation 2 takes the face
//    minimising D (eq. 1) = (1 + lambda Dist)(1 + |n_v - n_f|); we take the face
//    of smallest Dist (AABB tree closest point) and report D for it: since
//    D >= 1 + lambda Dist, this face is the true minimiser whenever the normal
//    term does not dominate, and it is what an AABB query can give (a careful
//    approximation the paper's octree also implies).
// 2. Pruning (paper: "normals opposite", "distance much larger than the local
//    edge length average of the input mesh"): a pair is dropped if
//    n_v . n_f < 0, or if Dist > prune_factor * (mean edge length of f_in).
// 3. Relation: C_out is related to C_in if a surviving pair links them.
// 4. Projection check: the triangles of both elements are projected onto the
//    xy plane; if no two projected triangles intersect (exact CGAL predicate),
//    the relation and its pairs are removed.
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
