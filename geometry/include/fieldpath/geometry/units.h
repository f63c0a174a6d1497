#pragma once
/// Angle units: the scene, the outputs and the tables are in degrees, the math in radians.
#include <numbers>

namespace fieldpath::geometry {

inline constexpr double kDegToRad = std::numbers::pi / 180.0;
inline constexpr double kRadToDeg = 180.0 / std::numbers::pi;

}  // namespace fieldpath::geometry
