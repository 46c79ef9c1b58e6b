// SPDX-License-Identifier: AGPL-3.0-or-later
#pragma once
// Mathematical constants shared by the sources (one definition each: the
// unity build compiles several sources as one translation unit).

namespace surftex {

inline constexpr double kPi = 3.14159265358979323846;

}  // namespace surftex
