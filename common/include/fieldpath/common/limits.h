#pragma once
/// The coordinate range beyond which a number cannot come from any machine, and the other bounds
/// on what a number read can be; the memory limit is in memory.h (included: its users came here).
#include <cmath>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/memory.h"

namespace fieldpath::common {

/// |x| above this (mm) is outside any machine tool: refused as a typo or a corrupt file.
inline constexpr double kMaxCoordinateMm = 1e6;

/// A machine's feed (mm/min): the scene's `dynamics.feed`, and the FEDRAT an APT output is given.
/// The fastest linear-motor machines reach ~1.2e5; 1e300 was written as `FEDRAT/MMPM,1e+300`.
inline constexpr double kMinFeedMmPerMin = 1e-3;
inline constexpr double kMaxFeedMmPerMin = 1e6;

/// The spring-damper's constants (`dynamics.inertia`, `stiffness`, `damping`) within these: their
/// ratios set the steering's time scale, and 1e300 over 1e-300 made it infinite (a crash, then
/// a settling that never ended: a diff review's). The tests' stiffest case is inertia 1e-12.
inline constexpr double kMinSpringConstant = 1e-12;
inline constexpr double kMaxSpringConstant = 1e12;

/// Beyond this distance from the origin (mm) a float's step passes 1 um (2^13 mm: 0.98 um): where
/// single-precision files (meshes read, STL written) stop carrying micron figures.
inline constexpr double kFloatExactMm = 8192.0;

/// The step of a float at x (its distance to the next float up), mm.
inline double floatStepMm(double x) {
  const float f = static_cast<float>(std::abs(x));
  return double(std::nextafter(f, HUGE_VALF) - f);
}

}  // namespace fieldpath::common
