/// The steering's torques are the generalised forces of its angles: τ = -∂U/∂θ for a field that
/// is a potential's gradient (each sample's 1/r law is radial, so the direct field is), checked
/// through the field's stiffness K = -∂τ/∂θ against the Hessian of U computed here from a closed
/// form. Taken about b itself (seed 004's small-angle torque), the lead torque at a large tilt held
/// a share of the moment about n: K was not symmetric, no energy was lowered, and along a wall
/// the lead ran to its limit with the holder nearer the wall (reliability.md 42).
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "analytic_fields.h"
#include "fieldpath/dynamics/frame.h"
#include "fieldpath/dynamics/steering.h"
#include "fieldpath/geometry/tool_model.h"

namespace fieldpath::dynamics {
namespace {

constexpr double kRadius = 3.0;

/// PlaneField's potential: V(d) with -V'(d) = its magnitude, 0 from r0 on; linear below r_min,
/// where the magnitude is held.
double planePotential(const testing::PlaneField& field, double d_mm) {
  const double r0 = field.r0_mm;
  const double scale = std::numbers::pi * field.gain / (r0 * r0);
  const auto primitive = [&](double s) {
    return r0 * r0 * std::log(s) - 2.0 * r0 * s + 0.5 * s * s;
  };
  if (d_mm >= r0) return 0.0;
  if (d_mm >= field.r_min_mm) return scale * (primitive(r0) - primitive(d_mm));
  return planePotential(field, field.r_min_mm) + field.magnitude(d_mm) * (field.r_min_mm - d_mm);
}

// Nodes on the tool's axis (no twist about it can matter), a wall oblique to every axis of the
// frame, the axis at lead 10°, tilt 35°: K from the steering's torques equals the Hessian of the
// field's energy at the nodes, and so is symmetric.
TEST(Torques, AreTheGeneralisedForcesOfTheAnglesAtALargeTilt) {
  std::vector<Vec3> nodes;  // tool frame: tip at 0, up the axis
  for (double z = 0.0; z <= 40.0 + 1e-9; z += 0.5) nodes.emplace_back(0.0, 0.0, z);
  const PassFrame pass = testing::straightPass(1.0, kRadius).frameAt(0.0);
  const LocalFrame frame = localFrame(pass);
  const double lead = 10.0 * std::numbers::pi / 180.0, tilt = 35.0 * std::numbers::pi / 180.0;
  const Vec3 a0 = axisFromAngles(frame, lead, tilt);
  const Vec3 normal = (a0.cross(frame.f) + 0.05 * a0 + 0.3 * frame.f).normalized();
  // The wall 3 mm from the axis 20 mm above the ball centre; the nodes' heights over it change
  // by a0·normal (~0.1) a mm: all lie between r_min and r0.
  const testing::PlaneField wall(pass.centre_mm + 20.0 * a0 - 3.0 * normal, normal, 1.0);
  const auto energy = [&](double l, double t) {
    const Vec3 a = axisFromAngles(frame, l, t);
    double u = 0.0;
    for (const Vec3& p : nodes) {
      const Vec3 x = pass.centre_mm + (p.z() - kRadius) * a;
      const double d = (x - wall.point_mm).dot(wall.normal);
      EXPECT_GT(d, wall.r_min_mm + 0.1);  // away from the held law's kink
      u += planePotential(wall, d);
    }
    return u;
  };
  const double h = 2e-4;
  Eigen::Matrix2d hessian;
  hessian(0, 0) =
      (energy(lead + h, tilt) - 2.0 * energy(lead, tilt) + energy(lead - h, tilt)) / (h * h);
  hessian(1, 1) =
      (energy(lead, tilt + h) - 2.0 * energy(lead, tilt) + energy(lead, tilt - h)) / (h * h);
  hessian(0, 1) = hessian(1, 0) = (energy(lead + h, tilt + h) - energy(lead + h, tilt - h) -
                                   energy(lead - h, tilt + h) + energy(lead - h, tilt - h)) /
                                  (4.0 * h * h);
  const Eigen::Matrix2d k =
      fieldStiffness(wall, nodes, kRadius, frame, pass.centre_mm, lead, tilt, 1e-4);
  const double scale = hessian.cwiseAbs().maxCoeff();
  ASSERT_GT(scale, 1.0);  // the wall pushes: the comparison is not of zeros
  EXPECT_GT(std::abs(hessian(0, 1)), 0.05 * scale);  // and it couples the angles
  EXPECT_LT((k - hessian).cwiseAbs().maxCoeff(), 1e-4 * scale) << "K\n" << k << "\nH\n" << hessian;
  EXPECT_LT(std::abs(k(0, 1) - k(1, 0)), 1e-4 * scale) << k;
}

// Beside a straight wall parallel to the pass, whatever the pass's heading, the lead stays at the
// nominal 0 while the tilt leans the holder away: the wall is its own mirror across the plane
// normal to the feed, and so are the nodes placed along the feed (even rings). With the exact
// lead torque and the nodes placed by the minimal rotation from e_z (rings of odd counts, their
// stagger turned with the heading) the lead settled 2-3° off beside such walls.
TEST(Torques, BesideAStraightWallTheLeadStaysNominalAtAnyHeading) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, kRadius, 0.0, 15.0};
  const geometry::HolderProfile holder = {{15, 6}, {30, 6}, {30, 12}, {70, 12}};
  std::vector<Vec3> nodes;  // the program's density: ~500 nodes (pathgen's kTargetNodes)
  for (const auto& n : geometry::surfaceNodes(tool, holder, 3.08)) nodes.push_back(n.position_mm);
  for (const double heading_deg : {0.0, 37.0, 90.0, 143.0}) {
    const double h = heading_deg * std::numbers::pi / 180.0;
    const Vec3 along(std::cos(h), std::sin(h), 0.0), left = Vec3::UnitZ().cross(along);
    // The wall 1.5 mm from the ball, on the left: the holder (r 6 from 15 mm up) reaches into it.
    const testing::PlaneField wall(4.5 * left, -left, 1.0);
    const Pass pass{60.0, [=](double s_mm) {
                      PassFrame f;
                      f.centre_mm = s_mm * along + Vec3(0.0, 0.0, kRadius);
                      f.feed = along;
                      f.normal = Vec3::UnitZ();
                      return f;
                    }};
    SteeringRequest request;
    request.field = &wall;
    request.nodes_tool_frame_mm = nodes;
    request.ball_radius_mm = kRadius;
    request.step_mm = 1.0;
    const SteeringResult result = steerPass(pass, request);
    ASSERT_EQ(result.status, Status::Ok) << result.message;
    double largest_lead = 0.0;
    for (const PostureSample& p : result.samples)
      largest_lead = std::max(largest_lead, std::abs(p.lead_rad));
    EXPECT_LT(largest_lead * 180.0 / std::numbers::pi, 0.01) << heading_deg;
    EXPECT_GT(std::abs(result.samples.back().tilt_rad) * 180.0 / std::numbers::pi, 10.0)
        << heading_deg;
  }
}

}  // namespace
}  // namespace fieldpath::dynamics
