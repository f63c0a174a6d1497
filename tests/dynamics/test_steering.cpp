#include <algorithm>
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include "analytic_fields.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/dynamics/steering.h"

namespace fieldpath::dynamics {
namespace {

using testing::LatticeField;
using testing::PlaneField;
using testing::ringNodes;
using testing::StepField;
using testing::straightPass;
using testing::SumField;

constexpr double kRadius = 3.0;
constexpr double kDeg = std::numbers::pi / 180.0;
constexpr double kGain = 2e-4;  ///< sets the settled tilt beside a wall 1 mm away to a few degrees

const std::vector<Vec3>& toolNodes() {
  static const std::vector<Vec3> nodes = ringNodes(kRadius);
  return nodes;
}

/// A wall parallel to the straight pass at y = y_mm; normal towards the pass.
std::shared_ptr<PlaneField> wallAt(double y_mm, double gain = kGain) {
  return std::make_shared<PlaneField>(Vec3(0, y_mm, 0), Vec3(0, y_mm > 0 ? -1.0 : 1.0, 0), gain);
}

std::shared_ptr<SumField> channel(double y_left_mm, double y_right_mm) {
  auto sum = std::make_shared<SumField>();
  sum->parts = {wallAt(y_left_mm), wallAt(y_right_mm)};
  return sum;
}

SteeringRequest requestFor(const field::ForceField* field) {
  SteeringRequest r;
  r.field = field;
  r.nodes_tool_frame_mm = toolNodes();
  r.ball_radius_mm = kRadius;
  r.step_mm = 1.0;
  return r;
}

void expectAllFinite(const SteeringResult& result) {
  ASSERT_FALSE(result.samples.empty());
  for (const PostureSample& s : result.samples) {
    ASSERT_TRUE(std::isfinite(s.lead_rad) && std::isfinite(s.tilt_rad)) << "s = " << s.s_mm;
    ASSERT_TRUE(std::isfinite(s.lead_rate_rad_per_s) && std::isfinite(s.tilt_rate_rad_per_s)) << "s = " << s.s_mm;
    ASSERT_TRUE(s.moment.allFinite() && s.posture.tip_mm.allFinite() && s.posture.axis.allFinite())
        << "s = " << s.s_mm;
    ASSERT_NEAR(s.posture.axis.norm(), 1.0, 1e-12);
  }
}

double maxAngleDifference(const SteeringResult& a, const SteeringResult& b) {
  EXPECT_EQ(a.samples.size(), b.samples.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(a.samples.size(), b.samples.size()); ++i) {
    worst = std::max(worst, std::abs(a.samples[i].lead_rad - b.samples[i].lead_rad));
    worst = std::max(worst, std::abs(a.samples[i].tilt_rad - b.samples[i].tilt_rad));
  }
  return worst;
}

/// Runs the request at its tolerances and at 100× tighter ones: both finite, angles within 0.01°.
SteeringResult runToleranceStable(const Pass& pass, SteeringRequest request) {
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

/// Tilt where k (θ - θ0) = τ(θ) beside a straight pass, by bisection on the directly summed moment.
double staticTilt(const field::ForceField& field, double stiffness, double lo_rad, double hi_rad) {
  PassFrame pf = straightPass(1.0).frameAt(0.0);
  const LocalFrame fr = localFrame(pf);
  auto residual = [&](double tilt) {
    // τ summed here independently of steerPass: nodes turned about f (= the minimal rotation for a
    // pure tilt), offsets from the ball centre.
    const Eigen::Matrix3d rot = Eigen::AngleAxisd(tilt, fr.f).toRotationMatrix();
    Vec3 m = Vec3::Zero();
    for (const Vec3& p : toolNodes()) {
      const Vec3 r = rot * (p - Vec3(0, 0, kRadius));
      m += r.cross(field.at(pf.centre_mm + r));
    }
    return stiffness * tilt - m.dot(fr.f);
  };
  EXPECT_LT(residual(lo_rad), 0.0);
  EXPECT_GT(residual(hi_rad), 0.0);
  for (int i = 0; i < 100; ++i) {
    const double mid = 0.5 * (lo_rad + hi_rad);
    (residual(mid) < 0.0 ? lo_rad : hi_rad) = mid;
  }
  return 0.5 * (lo_rad + hi_rad);
}

// ---- closed form first: no field, the free damped oscillator ------------------------------------

struct OscillatorCase {
  const char* name;
  double damping;  ///< c; negative = critical
};

class FreeResponse : public ::testing::TestWithParam<OscillatorCase> {};

/// θ(t) of J θ'' + c θ' + k θ = 0 from θ(0) = θi, θ'(0) = 0.
double analyticAngle(double J, double c, double k, double theta_i, double t) {
  const double w0 = std::sqrt(k / J);
  const double zeta = c / (2.0 * std::sqrt(k * J));
  if (std::abs(zeta - 1.0) < 1e-12) return theta_i * (1.0 + w0 * t) * std::exp(-w0 * t);
  if (zeta < 1.0) {
    const double wd = w0 * std::sqrt(1.0 - zeta * zeta);
    return std::exp(-zeta * w0 * t) * theta_i * (std::cos(wd * t) + zeta * w0 / wd * std::sin(wd * t));
  }
  const double root = std::sqrt(zeta * zeta - 1.0);
  const double r1 = -w0 * (zeta - root), r2 = -w0 * (zeta + root);
  return theta_i * (r2 * std::exp(r1 * t) - r1 * std::exp(r2 * t)) / (r2 - r1);
}

TEST_P(FreeResponse, MatchesTheAnalyticDampedOscillator) {
  SteeringRequest request = requestFor(nullptr);
  request.params.inertia = 0.5;
  request.params.stiffness = 2.0;
  request.params.damping = GetParam().damping;
  request.initial_lead_rad = 0.1;
  request.initial_tilt_rad = 0.2;
  const Pass pass = straightPass(200.0);
  const SteeringResult result = runToleranceStable(pass, request);
  ASSERT_EQ(result.status, Status::Ok) << result.message;
  const DynamicsParams& p = request.params;
  const double v = p.feed_mm_per_min / 60.0;
  double worst = 0.0;
  for (const PostureSample& s : result.samples) {
    const double t = s.s_mm / v;
    worst = std::max(worst, std::abs(s.lead_rad - analyticAngle(p.inertia, p.effectiveDamping(), p.stiffness, 0.1, t)));
    worst = std::max(worst, std::abs(s.tilt_rad - analyticAngle(p.inertia, p.effectiveDamping(), p.stiffness, 0.2, t)));
    EXPECT_EQ(s.moment, Vec3::Zero());
  }
  EXPECT_LT(worst, 1e-4 * 0.2) << GetParam().name;
  EXPECT_EQ(result.stats.restarts, 0);
  EXPECT_GT(result.stats.steps, 0);
  EXPECT_GT(result.stats.jacobian_evals, 0);
}

INSTANTIATE_TEST_SUITE_P(Dynamics, FreeResponse,
                         ::testing::Values(OscillatorCase{"under", 0.4}, OscillatorCase{"critical", -1.0},
                                           OscillatorCase{"over", 5.0}),
                         [](const auto& info) { return std::string(info.param.name); });

TEST(FreeResponse, DefaultsAreCriticalAndDoNotOvershoot) {
  SteeringRequest request = requestFor(nullptr);
  request.initial_tilt_rad = 0.2;
  const SteeringResult result = steerPass(straightPass(200.0), request);
  ASSERT_EQ(result.status, Status::Ok);
  for (std::size_t i = 1; i < result.samples.size(); ++i) {
    EXPECT_GE(result.samples[i].tilt_rad, -1e-9);  // never crosses the nominal
    EXPECT_LE(result.samples[i].tilt_rad, result.samples[i - 1].tilt_rad + 1e-12);  // monotone
  }
}

// ---- one wall beside a straight pass: static equilibrium ----------------------------------------

TEST(PlaneWall, SettlesAtTheStaticEquilibrium) {
  const auto wall = wallAt(4.0);  // shank surface 1 mm from the wall
  const double expected = staticTilt(*wall, 1.0, 0.0, 0.5);
  SteeringRequest request = requestFor(wall.get());
  const SteeringResult result = runToleranceStable(straightPass(300.0), request);
  ASSERT_EQ(result.status, Status::Ok) << result.message;
  const PostureSample& last = result.samples.back();
  std::printf("equilibrium tilt %.6f deg, settled %.6f deg\n", expected / kDeg, last.tilt_rad / kDeg);
  EXPECT_GT(expected, 1.0 * kDeg);  // a real deflection, away from the wall (towards -b = -y)
  EXPECT_NEAR(last.tilt_rad, expected, 1e-6);
  EXPECT_NEAR(last.lead_rad, 0.0, 1e-12);  // a wall along the feed gives no lead moment
  EXPECT_LT(last.posture.axis.y(), 0.0);
  EXPECT_NEAR(last.tilt_torque, request.params.stiffness * last.tilt_rad, 1e-5);

  request.params.integrator = Integrator::Erk;  // the explicit reference agrees on a non-stiff case
  const SteeringResult erk = steerPass(straightPass(300.0), request);
  ASSERT_EQ(erk.status, Status::Ok) << erk.message;
  EXPECT_LT(maxAngleDifference(result, erk), 1e-4);
}

}  // namespace
}  // namespace fieldpath::dynamics
