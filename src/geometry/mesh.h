// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// The one mesh type of surftex: CGAL::Surface_mesh over the
// Exact_predicates_inexact_constructions_kernel (exact predicates, double
// constructions). Include this in .cpp files only; headers use mesh_fwd.h.

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include "geometry/mesh_fwd.h"

namespace surftex {
using Vector3 = Kernel::Vector_3;
using Point2 = Kernel::Point_2;
using Vector2 = Kernel::Vector_2;
using VertexIndex = Mesh::Vertex_index;
using FaceIndex = Mesh::Face_index;
using EdgeIndex = Mesh::Edge_index;
using HalfedgeIndex = Mesh::Halfedge_index;
}  // namespace surftex
