// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Every property map surftex puts on a Mesh, in one place (docs/STYLE.md 4): its
// name, the element it lives on and its value type. Algorithms take the maps
// they read and write as arguments; nothing picks up a map just because a name
// is present. This header is light (forward declarations only) so Options structs can
// hold typed names; properties.h adds the map accessors for .cpp files.
//
// | constant          | name           | element  | type      | meaning                                    |
// |-------------------|----------------|----------|-----------|--------------------------------------------|
// | kVertexNormal     | v:normal       | vertex   | Vector3   | unit area-weighted vertex normal           |
// | kFaceNormal       | f:normal       | face     | Vector3   | unit face normal                           |
// | kVertexColor      | v:color        | vertex   | Color3f   | linear RGB in [0,1]                        |
// | kCornerUV         | h:uv           | halfedge | UV        | texture coordinate of the corner at target |
// | kVertexKmax/Kmin  | v:kmax, v:kmin | vertex   | double    | principal curvatures, kmax >= kmin         |
// | kVertexDmax/Dmin  | v:dmax, v:dmin | vertex   | Vector3   | unit principal directions                  |
// | kFaceDirection    | f:dir          | face     | Vector3   | unit tangent direction d_s per face        |
// | kVertexScale      | v:scale        | vertex   | double    | texture scale S (> 0)                      |
// | kVertexMaterial   | v:material     | vertex   | double    | material coordinate m in [0,1]             |
// | kCornerSTM        | h:stm          | halfedge | STM       | (s,t,m) at the corner (target vertex)      |
// | kFacePatch        | f:patch        | face     | int       | patch / chart id, -1 = none                |
// | kVertexSweep      | v:sweep        | vertex   | double    | sweep value ordering vertices along a field|
// | kFaceElement      | f:element      | face     | int       | geometric-texture element id               |
// | kVertexLocked     | v:locked       | vertex   | bool      | vertex fixed by a constraint               |
// | kVertexDirection  | v:dir          | vertex   | Vector3   | unit tangent orientation (Turk field)      |
//
// A halfedge h stands for the corner of face(h) at target(h).

#include <array>

#include "geometry/mesh_fwd.h"

namespace CGAL {
template <class R> class Vector_3;
class SM_Vertex_index;
class SM_Halfedge_index;
class SM_Face_index;
}  // namespace CGAL

namespace surftex {

using Vector3 = CGAL::Vector_3<Kernel>;
using VertexIndex = CGAL::SM_Vertex_index;
using FaceIndex = CGAL::SM_Face_index;
using HalfedgeIndex = CGAL::SM_Halfedge_index;

using Color3f = std::array<float, 3>;
using UV = std::array<double, 2>;
using STM = std::array<double, 3>;

/// A typed property name: the element index type, the value type and the name.
template <class Index, class T>
struct PropertyName {
  const char* name;
};

inline constexpr PropertyName<VertexIndex, Vector3> kVertexNormal{"v:normal"};
inline constexpr PropertyName<FaceIndex, Vector3> kFaceNormal{"f:normal"};
inline constexpr PropertyName<VertexIndex, Color3f> kVertexColor{"v:color"};
inline constexpr PropertyName<HalfedgeIndex, UV> kCornerUV{"h:uv"};
inline constexpr PropertyName<VertexIndex, double> kVertexKmax{"v:kmax"};
inline constexpr PropertyName<VertexIndex, double> kVertexKmin{"v:kmin"};
inline constexpr PropertyName<VertexIndex, Vector3> kVertexDmax{"v:dmax"};
inline constexpr PropertyName<VertexIndex, Vector3> kVertexDmin{"v:dmin"};
inline constexpr PropertyName<FaceIndex, Vector3> kFaceDirection{"f:dir"};
inline constexpr PropertyName<VertexIndex, double> kVertexScale{"v:scale"};
inline constexpr PropertyName<VertexIndex, double> kVertexMaterial{"v:material"};
inline constexpr PropertyName<HalfedgeIndex, STM> kCornerSTM{"h:stm"};
inline constexpr PropertyName<FaceIndex, int> kFacePatch{"f:patch"};
inline constexpr PropertyName<VertexIndex, double> kVertexSweep{"v:sweep"};
inline constexpr PropertyName<FaceIndex, int> kFaceElement{"f:element"};
inline constexpr PropertyName<VertexIndex, bool> kVertexLocked{"v:locked"};
inline constexpr PropertyName<VertexIndex, Vector3> kVertexDirection{"v:dir"};

}  // namespace surftex
