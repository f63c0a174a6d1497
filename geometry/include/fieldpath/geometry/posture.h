#pragma once
/// Postures (DESIGN.md "Conventions of data"): tool tip p and unit axis a from the tip to the
/// spindle, and the rigid transform that places a tool-frame object (tip at origin, axis +z) at a
/// posture.
#include <Eigen/Core>
#include <Eigen/Geometry>

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

}  // namespace fieldpath::geometry
