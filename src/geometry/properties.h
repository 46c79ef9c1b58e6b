// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Access to the property maps named in geometry/property_names.h (the table
// of every map surftex puts on a Mesh). Include in .cpp files only (it pulls
// in CGAL through mesh.h).

#include <string>
#include <type_traits>
#include <utility>

#include "geometry/mesh.h"
#include "geometry/property_names.h"

namespace surftex {

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
