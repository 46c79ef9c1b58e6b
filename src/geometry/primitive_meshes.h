// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Small meshes built in code: for unit tests (docs/STYLE.md 9), for the demo, and
// as base shapes. All are triangle meshes with outward (counter-clockwise seen
// from outside) orientation. Units are arbitrary; sizes are documented per shape.

#include "geometry/mesh_fwd.h"

namespace surftex {

/// Regular tetrahedron inscribed in the unit sphere. 4 vertices, 4 faces, closed.
void make_tetrahedron(Mesh& mesh);

/// Axis-aligned cube [-h,h]^3 with h = size/2, each square face split in 2
/// triangles. 8 vertices, 12 faces, closed.
void make_cube(Mesh& mesh, double size = 1.0);

/// Planar grid in z = 0 over [0,width] x [0,height] with nx x ny squares, each
/// split along the diagonal: (nx+1)(ny+1) vertices, 2 nx ny faces, one border.
/// Throws InvalidInputError if nx or ny < 1 or sizes are not positive.
void make_grid(Mesh& mesh, int nx, int ny, double width = 1.0, double height = 1.0);

/// Icosphere of the given radius: the icosahedron with each triangle split in 4
/// `subdivisions` times, vertices pushed to the sphere. 10*4^s + 2 vertices.
void make_icosphere(Mesh& mesh, int subdivisions, double radius = 1.0);

/// Torus around the z axis, major radius R, minor radius r, nu x nv quads split
/// in triangles: nu*nv vertices, 2*nu*nv faces, closed, genus 1.
void make_torus(Mesh& mesh, double R, double r, int nu, int nv);

/// Per-corner texture coordinates (kCornerUV) for a torus around the z axis
/// with major radius R (as made by make_torus): u = angle around z / 2 pi,
/// v = angle around the tube / 2 pi, each times its repeat count; corners of a
/// face across the angular seam get u or v beyond the seam (no wrap-around
/// triangle), so a periodic texture maps seamlessly. Throws InvalidInputError
/// if repeats are not positive.
void assign_torus_uvs(Mesh& mesh, double R, double repeats_u, double repeats_v);

/// Open cylinder around the z axis, radius r, z in [0,height], nu around, nv
/// along: nu*(nv+1) vertices, 2 nu nv faces, two border loops.
void make_cylinder(Mesh& mesh, double radius, double height, int nu, int nv);

/// Open cone: apex at (0,0,height), base circle of radius r at z = 0 (left
/// open). nu around, nv rings. One border loop.
void make_open_cone(Mesh& mesh, double radius, double height, int nu, int nv);

/// Ellipsoid x^2/a^2 + y^2/b^2 + z^2/c^2 = 1 (an icosphere scaled per axis).
void make_ellipsoid(Mesh& mesh, double a, double b, double c, int subdivisions);

}  // namespace surftex
