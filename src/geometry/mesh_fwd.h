// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Forward declarations of the one mesh type, for public headers that only pass
// meshes by reference. CGAL headers themselves are included in .cpp files only
// (through geometry/mesh.h), to keep compile times down on small machines.

namespace CGAL {
class Epick;
template <class R> class Point_3;
template <class P> class Surface_mesh;
}  // namespace CGAL

namespace surftex {
using Kernel = CGAL::Epick;  // Exact_predicates_inexact_constructions_kernel
using Point3 = CGAL::Point_3<Kernel>;
using Mesh = CGAL::Surface_mesh<Point3>;
}  // namespace surftex
