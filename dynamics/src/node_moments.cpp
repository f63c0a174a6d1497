#include "node_moments.h"

#include <cmath>

#include "fieldpath/geometry/posture.h"

namespace fieldpath::dynamics {
namespace detail {

void placeNodes(std::span<const Vec3> offsets_mm, const Vec3& centre_mm, const Vec3& axis,
                const Vec3& feed, std::vector<Vec3>& nodes_mm) {
  const Vec3 along = feed - feed.dot(axis) * axis;
  Eigen::Matrix3d rotation;
  if (along.norm() > 1e-9 * feed.norm()) {
    const Vec3 x = along.normalized();
    rotation.col(0) = x;
    rotation.col(1) = axis.cross(x);
    rotation.col(2) = axis;
  } else {
    rotation = geometry::rotationFromZ(axis);
  }
  nodes_mm.resize(offsets_mm.size());
  for (std::size_t i = 0; i < offsets_mm.size(); ++i)
    nodes_mm[i] = centre_mm + rotation * offsets_mm[i];
}

AxisMoment momentOfNodes(const field::ForceField& field, std::span<const Vec3> offsets_mm,
                         const LocalFrame& frame, const Vec3& centre_mm, double lead_rad,
                         double tilt_rad, std::vector<Vec3>& nodes_mm, std::vector<Vec3>& forces) {
  placeNodes(offsets_mm, centre_mm, axisFromAngles(frame, lead_rad, tilt_rad), frame.f, nodes_mm);
  forces.resize(offsets_mm.size());
  field.evaluate(nodes_mm, forces);
  AxisMoment out;
  for (std::size_t i = 0; i < offsets_mm.size(); ++i)
    out.moment += (nodes_mm[i] - centre_mm).cross(forces[i]);
  // The torques conjugate to the angles of axisFromAngles (a = R_f(tilt) R_b(lead) n): the tilt
  // turns a about f, the lead about b turned by the tilt, R_f(tilt) b = cos(tilt) b + sin(tilt) n
  // (∂a/∂lead = that axis × a). Taken about b itself, as seed 004 writes it for small angles, the
  // lead torque at a large tilt holds a share of the moment about n that no lead relieves: it
  // drove the lead to its limit along a wall and the holder nearer to it (reliability.md 42).
  out.lead_torque = out.moment.dot(std::cos(tilt_rad) * frame.b + std::sin(tilt_rad) * frame.n);
  out.tilt_torque = out.moment.dot(frame.f);
  return out;
}

std::vector<Vec3> offsetsFromCentre(std::span<const Vec3> nodes_tool_frame_mm,
                                    double ball_radius_mm) {
  std::vector<Vec3> out(nodes_tool_frame_mm.begin(), nodes_tool_frame_mm.end());
  for (Vec3& p : out) p.z() -= ball_radius_mm;
  return out;
}

}  // namespace detail

using detail::centralStiffness;
using detail::momentOfNodes;
using detail::offsetsFromCentre;

Eigen::Matrix2d fieldStiffness(const field::ForceField& field,
                               std::span<const Vec3> nodes_tool_frame_mm, double ball_radius_mm,
                               const LocalFrame& frame, const Vec3& centre_mm, double lead_rad,
                               double tilt_rad, double delta_rad) {
  const std::vector<Vec3> offsets = offsetsFromCentre(nodes_tool_frame_mm, ball_radius_mm);
  std::vector<Vec3> nodes_mm, forces;
  return centralStiffness(
      [&](double lead, double tilt) {
        return momentOfNodes(field, offsets, frame, centre_mm, lead, tilt, nodes_mm, forces);
      },
      lead_rad, tilt_rad, delta_rad);
}

}  // namespace fieldpath::dynamics
