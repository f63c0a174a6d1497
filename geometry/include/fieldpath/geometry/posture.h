#pragma once
/// Postures (DESIGN.md "Conventions of data"): tool tip p and unit axis a from the tip to the
/// spindle, and the rigid transform that places a tool-frame object (tip at origin, axis +z) at a
/// posture.
#include <cmath>
#include <cstddef>
#include <numbers>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "fieldpath/geometry/units.h"

namespace fieldpath::geometry {

using Vec3 = Eigen::Vector3d;

/// One tool posture, APT tool end point. Millimetres, world frame.
struct Posture {
  Vec3 tip_mm = Vec3::Zero();
  Vec3 axis = Vec3::UnitZ();  ///< unit, from tip towards spindle
  double spindle_rad = 0.0;   ///< optional 7th `.cl` column; meaningful only if has_spindle
  bool has_spindle = false;
};

/// The posture of a ball-end tool whose ball centre is C (mm, world frame), `axis` a unit: tip
/// p = C − R a (the ball centre sits at (0, 0, R) in the tool frame). Not normalised here: the
/// callers' axes are unit by construction, and a second normalisation would move the last bit.
inline Posture ballEndPosture(const Vec3& centre_mm, const Vec3& axis, double ball_radius_mm) {
  Posture p;
  p.axis = axis;
  p.tip_mm = centre_mm - ball_radius_mm * axis;
  return p;
}

/// The ball centre C = p + R a of a ball-end posture (mm, world frame).
inline Vec3 ballCentre(const Posture& posture, double ball_radius_mm) {
  return posture.tip_mm + ball_radius_mm * posture.axis;
}

/// Minimal rotation (about e_z × a) that maps e_z onto `axis` (normalised first).
/// Exact as a → e_z: uses 1/(1+k), and for k < 0 the equivalent (1-k)/(i²+j²), which has no
/// cancellation near -e_z. a = -e_z exactly: rotation by π about x (diag(1,-1,-1)).
Eigen::Matrix3d rotationFromZ(const Vec3& axis);

/// Tool frame → world frame: x_world = R x_tool + tip.
Eigen::Isometry3d toolToWorld(const Posture& posture);

/// Inverse of toolToWorld for a rigid transform (spindle angle is not recovered).
Posture postureFromTransform(const Eigen::Isometry3d& tool_to_world);

/// The pose at fraction t of the motion a → b as every check reads it (DESIGN.md "Links and
/// motion"): tip linear, axis linear and renormalised (for opposite axes, turned through the
/// plane of the first axis and any perpendicular).
Posture alongMotion(const Posture& a, const Posture& b, double t);

/// The angle between two axes (rad), exact for small and near-opposite ones.
inline double axisAngle(const Vec3& a, const Vec3& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

/// How far (mm) any point within `reach_mm` of the tip moves at most along the motion a → b:
/// |Δtip| + reach · Δθ.
inline double motionSweepMm(const Posture& a, const Posture& b, double reach_mm) {
  return (b.tip_mm - a.tip_mm).norm() + reach_mm * axisAngle(a.axis, b.axis);
}

/// The equal steps (in t) of the motion a → b in which no point within `reach_mm` of the tip moves
/// more than `step_mm` (0 for no motion), as a double: a count estimated before the poses are
/// made. The axis, linear and renormalised, turns fastest midway: 2 tan(Δθ/2) a unit of t against
/// Δθ on average (1.27x at 90 deg: counted by Δθ, the stamps of a 90 deg turn were up to 1.27
/// steps apart, a reviewer's finding). Turns past 179 deg count as 179 (an axis turned over is
/// refused or marked by its own check; tan would ask for millions of stamps).
inline double motionSteps(const Posture& a, const Posture& b, double reach_mm, double step_mm) {
  const double turn_rad = std::min(axisAngle(a.axis, b.axis), 179.0 * kDegToRad);
  return std::ceil(((b.tip_mm - a.tip_mm).norm() + reach_mm * 2.0 * std::tan(0.5 * turn_rad)) /
                   step_mm);
}

/// Calls `visit(pose)` for the poses strictly inside the motion a → b, one step of motionSteps
/// apart, in order: the stamps every sweeping check cuts or tests between two postures.
template <class Visit>
void forEachPoseBetween(const Posture& a, const Posture& b, double reach_mm, double step_mm,
                        Visit&& visit) {
  const auto steps = static_cast<std::size_t>(motionSteps(a, b, reach_mm, step_mm));
  for (std::size_t k = 1; k < steps; ++k)
    visit(alongMotion(a, b, static_cast<double>(k) / static_cast<double>(steps)));
}

/// The same pose: tips within 1e-9 mm, axes within 1e-12 (a posture written twice).
inline bool samePose(const Posture& a, const Posture& b) {
  return (a.tip_mm - b.tip_mm).norm() < 1e-9 && (a.axis - b.axis).norm() < 1e-12;
}

}  // namespace fieldpath::geometry
