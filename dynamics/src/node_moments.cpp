#include "node_moments.h"

#include "fieldpath/geometry/posture.h"

namespace fieldpath::dynamics {
namespace detail {

void placeNodes(std::span<const Vec3> offsets_mm, const Vec3& centre_mm, const Vec3& axis,
                std::vector<Vec3>& nodes_mm) {
  const Eigen::Matrix3d rotation = geometry::rotationFromZ(axis);
  nodes_mm.resize(offsets_mm.size());
  for (std::size_t i = 0; i < offsets_mm.size(); ++i)
    nodes_mm[i] = centre_mm + rotation * offsets_mm[i];
}

AxisMoment momentOfNodes(const field::ForceField& field, std::span<const Vec3> offsets_mm,
                         const LocalFrame& frame, const Vec3& centre_mm, double lead_rad,
                         double tilt_rad, std::vector<Vec3>& nodes_mm, std::vector<Vec3>& forces) {
  placeNodes(offsets_mm, centre_mm, axisFromAngles(frame, lead_rad, tilt_rad), nodes_mm);
  forces.resize(offsets_mm.size());
  field.evaluate(nodes_mm, forces);
  AxisMoment out;
  for (std::size_t i = 0; i < offsets_mm.size(); ++i)
    out.moment += (nodes_mm[i] - centre_mm).cross(forces[i]);
  out.lead_torque = out.moment.dot(frame.b);
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
