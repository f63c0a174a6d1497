#pragma once
/// Internal to dynamics/: the field's moment at the tool and holder nodes placed at an axis
/// (steering.cpp's right-hand side and damping, the public fieldStiffness).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "fieldpath/dynamics/frame.h"
#include "fieldpath/dynamics/steering.h"
#include "fieldpath/field/force_field.h"

namespace fieldpath::dynamics::detail {

/// Places the nodes (offsets from the ball centre, tool frame) at axis a: world frame, mm. The
/// tool frame's x goes to the feed `f` made square to a, y to a × that, z to a (the minimal
/// rotation from e_z where a ∥ f): the nodes then mirror with the axis across the plane normal
/// to the feed, so that a wall symmetric about that plane gives no lead torque at lead 0 (placed by
/// the minimal rotation from e_z, the rings' stagger turned with the pass's heading and a lone
/// node nearest the wall pushed the lead 2-3° beside a straight wall: dynamics.md 2026-12-01).
void placeNodes(std::span<const Vec3> offsets_mm, const Vec3& centre_mm, const Vec3& axis,
                const Vec3& feed, std::vector<Vec3>& nodes_mm);

/// Places the nodes at the axis of (lead, tilt) and sums their moment about the ball centre.
AxisMoment momentOfNodes(const field::ForceField& field, std::span<const Vec3> offsets_mm,
                         const LocalFrame& frame, const Vec3& centre_mm, double lead_rad,
                         double tilt_rad, std::vector<Vec3>& nodes_mm, std::vector<Vec3>& forces);

/// Node offsets from the ball centre in the tool frame: x - (0, 0, R).
std::vector<Vec3> offsetsFromCentre(std::span<const Vec3> nodes_tool_frame_mm,
                                    double ball_radius_mm);

/// The field's stiffness -∂τ/∂θ about (lead, tilt) by central differences of `delta_rad`
/// (column: the angle moved; row: lead, tilt torque); `moment(lead, tilt)` gives the AxisMoment.
/// One for fieldStiffness and the critical damping (SteeringSystem::updateDamping).
template <class Moment>
Eigen::Matrix2d centralStiffness(Moment&& moment, double lead_rad, double tilt_rad,
                                 double delta_rad) {
  Eigen::Matrix2d k;
  for (int column = 0; column < 2; ++column) {
    const double dl = column == 0 ? delta_rad : 0.0, dt = column == 1 ? delta_rad : 0.0;
    const AxisMoment plus = moment(lead_rad + dl, tilt_rad + dt);
    const AxisMoment minus = moment(lead_rad - dl, tilt_rad - dt);
    k(0, column) = -(plus.lead_torque - minus.lead_torque) / (2.0 * delta_rad);
    k(1, column) = -(plus.tilt_torque - minus.tilt_torque) / (2.0 * delta_rad);
  }
  return k;
}

}  // namespace fieldpath::dynamics::detail
