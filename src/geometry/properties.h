// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Every property map surftex puts on a Mesh, in one place (docs/STYLE.md 4): its
// name, the element it lives on and its value type. Algorithms take the maps
// they read and write as arguments; nothing picks up a map just because a name
// is present. Include in .cpp files only (it pulls in CGAL through mesh.h).
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
#include <string>
#include <type_traits>

#include "geometry/mesh.h"

namespace surftex {

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

template <class Index, class T>
using PropertyMap = typename Mesh::template Property_map<Index, T>;

/// A zero value of T for new map entries. CGAL's Vector_3 default
/// constructor leaves its coordinates uninitialised, so T() is not enough.
template <class T>
T zero_value() {
  if constexpr (std::is_same_v<T, Vector3>) return Vector3(0.0, 0.0, 0.0);
  else if constexpr (std::is_same_v<T, Point3>) return Point3(0.0, 0.0, 0.0);
  else return T{};
}

/// The map named by `p`, created with `init` for every element if absent
/// (default: zero, see zero_value).
template <class Index, class T>
PropertyMap<Index, T> get_or_add(Mesh& mesh, PropertyName<Index, T> p, const T& init = zero_value<T>()) {
  return mesh.template add_property_map<Index, T>(p.name, init).first;
}

/// The map named by `p` if present (std::optional-like: `.second` says found).
template <class Index, class T>
std::pair<PropertyMap<Index, T>, bool> find(const Mesh& mesh, PropertyName<Index, T> p) {
  return mesh.template property_map<Index, T>(p.name);
}

}  // namespace surftex
