#pragma once
/// The steering tests' shared pieces (test_steering.cpp, test_steering_limits.cpp): a ring of tool
/// nodes, walls and channels beside a straight pass, a request for them, checks every result
/// must pass, and the static and swing angles computed here independently of steerPass.
#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include <gtest/gtest.h>

#include "analytic_fields.h"
#include "fieldpath/dynamics/steering.h"

namespace fieldpath::dynamics::steering_test {

using testing::LatticeField;
using testing::PlaneField;
using testing::ringNodes;
using testing::StepField;
using testing::straightPass;
using testing::SumField;

constexpr double kRadius = 3.0;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kGain = 2e-4;  ///< sets the settled tilt beside a wall 1 mm away to a few degrees

inline const std::vector<Vec3>& toolNodes() {
  static const std::vector<Vec3> nodes = ringNodes(kRadius);
  return nodes;
}

/// A wall parallel to the straight pass at y = y_mm; normal towards the pass.
inline std::shared_ptr<PlaneField> wallAt(double y_mm, double gain = kGain) {
  return std::make_shared<PlaneField>(Vec3(0, y_mm, 0), Vec3(0, y_mm > 0 ? -1.0 : 1.0, 0), gain);
}

inline std::shared_ptr<SumField> channel(double y_left_mm, double y_right_mm) {
  auto sum = std::make_shared<SumField>();
  sum->parts = {wallAt(y_left_mm), wallAt(y_right_mm)};
  return sum;
}

/// The tool dwelling at the start of the straight pass (the centre does not move; s still runs).
inline Pass dwell(double length_mm) {
  const PassFrame at_start = straightPass(1.0).frameAt(0.0);
  return Pass{length_mm, [at_start](double) { return at_start; }};
}

inline SteeringRequest requestFor(const field::ForceField* field) {
  SteeringRequest r;
  r.field = field;
  r.nodes_tool_frame_mm = toolNodes();
  r.ball_radius_mm = kRadius;
  r.step_mm = 1.0;
  return r;
}

inline void expectAllFinite(const SteeringResult& result) {
  ASSERT_FALSE(result.samples.empty());
  for (const PostureSample& s : result.samples) {
    ASSERT_TRUE(std::isfinite(s.lead_rad) && std::isfinite(s.tilt_rad)) << "s = " << s.s_mm;
    ASSERT_TRUE(std::isfinite(s.lead_rate_rad_per_s) && std::isfinite(s.tilt_rate_rad_per_s))
        << "s = " << s.s_mm;
    ASSERT_TRUE(s.moment.allFinite() && s.posture.tip_mm.allFinite() && s.posture.axis.allFinite())
        << "s = " << s.s_mm;
    ASSERT_NEAR(s.posture.axis.norm(), 1.0, 1e-12);
  }
}

inline double maxAngleDifference(const SteeringResult& a, const SteeringResult& b) {
  EXPECT_EQ(a.samples.size(), b.samples.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.samples.size(), b.samples.size()); ++i) {
    worst = std::max(worst, std::abs(a.samples[i].lead_rad - b.samples[i].lead_rad));
    worst = std::max(worst, std::abs(a.samples[i].tilt_rad - b.samples[i].tilt_rad));
  }
  return worst;
}

/// Runs the request at its tolerances and at 100× tighter ones: both finite, angles within 0.01°.
inline SteeringResult runToleranceStable(const Pass& pass, SteeringRequest request) {
  const SteeringResult loose = steerPass(pass, request);
  request.params.rtol /= 100.0;
  request.params.atol /= 100.0;
  const SteeringResult tight = steerPass(pass, request);
  expectAllFinite(loose);
  expectAllFinite(tight);
  EXPECT_EQ(loose.status, tight.status) << loose.message << " | " << tight.message;
  EXPECT_LT(maxAngleDifference(loose, tight), 0.01 * kDeg);
  return loose;
}

/// Torque M·e about the unit axis e (f for tilt, b for lead) on the nodes turned by `angle_rad`
/// about e, beside a straight pass at its start, summed here independently of steerPass: a pure
/// tilt or pure lead turns the axis about f or b, and that rotation is the minimal one from e_z.
inline double torqueAbout(const field::ForceField& field, const Vec3& e, double angle_rad) {
  const Vec3 centre = straightPass(1.0).frameAt(0.0).centre_mm;
  const Eigen::Matrix3d rot = Eigen::AngleAxisd(angle_rad, e).toRotationMatrix();
  Vec3 m = Vec3::Zero();
  for (const Vec3& p : toolNodes()) {
    const Vec3 r = rot * (p - Vec3(0, 0, kRadius));
    m += r.cross(field.at(centre + r));
  }
  return m.dot(e);
}

inline double tiltTorque(const field::ForceField& field, double tilt_rad) {
  return torqueAbout(field, Vec3::UnitX(), tilt_rad);
}

/// Angle about e where k θ = τ(θ) (θ0 = 0), by bisection in [lo, hi] (a sign change required).
inline double staticAngle(const field::ForceField& field, const Vec3& e, double stiffness,
                          double lo_rad, double hi_rad) {
  auto residual = [&](double angle) { return stiffness * angle - torqueAbout(field, e, angle); };
  const bool rising = residual(lo_rad) < 0.0;
  EXPECT_NE(rising, residual(hi_rad) < 0.0)
      << "no sign change in [" << lo_rad << ", " << hi_rad << "]";
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo_rad + hi_rad);
    ((residual(mid) < 0.0) == rising ? lo_rad : hi_rad) = mid;
  }
  return 0.5 * (lo_rad + hi_rad);
}

inline double staticTilt(const field::ForceField& field, double stiffness, double lo_rad,
                         double hi_rad) {
  return staticAngle(field, Vec3::UnitX(), stiffness, lo_rad, hi_rad);
}

/// Undamped swing from rest at tilt 0: the turning point θmax > 0 where the work of the field
/// equals the spring energy, ∫0^θmax (τ(φ) - k φ) dφ = 0 (trapezoids, linear interpolation of the
/// crossing).
inline double undampedTurningPoint(const field::ForceField& field, double stiffness,
                                   double hi_rad) {
  const int n = 5000;
  const double dphi = hi_rad / n;
  double energy = 0.0, prev = tiltTorque(field, 0.0);
  for (int j = 1; j <= n; ++j) {
    const double phi = j * dphi;
    const double g = tiltTorque(field, phi) - stiffness * phi;
    const double next = energy + 0.5 * (prev + g) * dphi;
    if (j > 1 && next < 0.0) return phi - dphi * next / (next - energy);
    energy = next;
    prev = g;
  }
  ADD_FAILURE() << "no turning point below " << hi_rad;
  return hi_rad;
}

}  // namespace fieldpath::dynamics::steering_test
