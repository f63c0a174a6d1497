/// Steering's limits, reports and input: angle limits reported or clamped with the path
/// position, bad settings naming their key, samples, progress and interruption, and field
/// failures reaching the caller (never a NaN sample).
#include <cmath>

#include <gtest/gtest.h>

#include "analytic_fields.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/dynamics/steering.h"
#include "steering_support.h"

namespace fieldpath::dynamics {
namespace {

using namespace steering_test;  // with analytic_fields.h's fields

// ---- limits, reports, input -------------------------------------------------------------------

TEST(Limits, TiltLimitIsReportedWithThePathPosition) {
  const auto wall = wallAt(4.0);
  SteeringRequest request = requestFor(wall.get());
  request.params.max_tilt_deg = 3.0;  // the wall wants 4.6°
  request.params.on_limit = LimitPolicy::Fail;
  const SteeringResult result = steerPass(straightPass(300.0), request);
  ASSERT_EQ(result.status, Status::TiltLimit);
  EXPECT_NE(result.message.find("s = "), std::string::npos) << result.message;
  EXPECT_NE(result.message.find("dynamics.max_tilt_deg"), std::string::npos) << result.message;
  EXPECT_GT(result.samples.back().tilt_rad, 3.0 * kDeg);  // the offending sample is included
  EXPECT_LT(result.samples.size(), 301u);
  for (std::size_t i = 0; i + 1 < result.samples.size(); ++i)
    EXPECT_LE(result.samples[i].tilt_rad, 3.0 * kDeg);
}

TEST(Limits, ClampHoldsTheAxisAtTheLimit) {
  const auto wall = wallAt(4.0);
  SteeringRequest request = requestFor(wall.get());
  request.params.max_tilt_deg = 3.0;
  request.params.on_limit = LimitPolicy::Clamp;
  const SteeringResult result = runToleranceStable(straightPass(300.0), request);
  ASSERT_EQ(result.status, Status::Ok) << result.message;
  EXPECT_GT(result.clamped_samples, 0);
  // A restart at every clamp (and at every station, where the critical damping follows the
  // field).
  EXPECT_GE(result.stats.restarts, result.clamped_samples);
  for (const PostureSample& s : result.samples) EXPECT_LE(s.tilt_rad, 3.0 * kDeg * (1 + 1e-12));
  EXPECT_NEAR(result.samples.back().tilt_rad, 3.0 * kDeg, 1e-12);
  EXPECT_TRUE(result.samples.back().limited);
}

// Clamped either way and on either angle: a wall on the -y side tilts the axis negative, held at
// -3°; a wall ahead leans it back, held at the lead limit -1°; at a held sample the stop has
// absorbed the motion (rate 0). (Only a positive tilt was ever clamped: a clamp to +limit, or
// to the tilt's limit for the lead, or one leaving the rate, passed: a test audit.)
TEST(Limits, ClampHoldsEitherSignAndEitherAngleAtRest) {
  const auto below = wallAt(-4.0);
  SteeringRequest request = requestFor(below.get());
  request.params.max_tilt_deg = 3.0;
  request.params.on_limit = LimitPolicy::Clamp;
  const SteeringResult tilt = runToleranceStable(straightPass(300.0), request);
  ASSERT_EQ(tilt.status, Status::Ok) << tilt.message;
  EXPECT_NEAR(tilt.samples.back().tilt_rad, -3.0 * kDeg, 1e-12);
  auto ahead = std::make_shared<PlaneField>(Vec3(4.0, 0, 0), -Vec3::UnitX(), kGain);
  SteeringRequest lean = requestFor(ahead.get());
  lean.params.max_lead_deg = 1.0;  // the wall wants more than 1° (PlaneWall.WallAhead...)
  lean.params.on_limit = LimitPolicy::Clamp;
  const SteeringResult lead = runToleranceStable(dwell(300.0), lean);
  ASSERT_EQ(lead.status, Status::Ok) << lead.message;
  EXPECT_NEAR(lead.samples.back().lead_rad, -1.0 * kDeg, 1e-12);
  EXPECT_NEAR(lead.samples.back().tilt_rad, 0.0, 1e-12);
  for (const SteeringResult* r : {&tilt, &lead}) {
    EXPECT_GT(r->clamped_samples, 0);
    for (const PostureSample& s : r->samples) {
      EXPECT_LE(std::abs(s.tilt_rad), 3.0 * kDeg * (1 + 1e-12));
      EXPECT_LE(std::abs(s.lead_rad), 20.0 * kDeg);
      if (!s.limited) continue;
      EXPECT_EQ(r == &tilt ? s.tilt_rate_rad_per_s : s.lead_rate_rad_per_s, 0.0) << s.s_mm;
    }
  }
}

// The rate limit is per mm of path whatever the step: stations every 0.5 mm turn half as much a
// step; and it reads the lead too. Clamp goes on and marks the samples.
TEST(Limits, AngleChangePerMmIsPerMmOnEitherAngle) {
  for (const bool on_lead : {false, true}) {
    SteeringRequest request = requestFor(nullptr);
    request.step_mm = 0.5;
    request.params.on_limit = LimitPolicy::Fail;
    (on_lead ? request.initial_lead_rad : request.initial_tilt_rad) = 0.2;
    // The free return's fastest turn, degrees per mm, from its samples (no limit set).
    const SteeringResult free = steerPass(straightPass(100.0), request);
    double fastest = 0.0;
    for (std::size_t i = 1; i < free.samples.size(); ++i)
      fastest = std::max(
          fastest, std::abs(on_lead ? free.samples[i].lead_rad - free.samples[i - 1].lead_rad
                                    : free.samples[i].tilt_rad - free.samples[i - 1].tilt_rad) /
                       (free.samples[i].s_mm - free.samples[i - 1].s_mm) / kDeg);
    ASSERT_GT(fastest, 0.1);
    request.max_angle_change_deg_per_mm = 0.9 * fastest;
    EXPECT_EQ(steerPass(straightPass(100.0), request).status, Status::RateLimit) << on_lead;
    request.max_angle_change_deg_per_mm = 1.1 * fastest;
    EXPECT_EQ(steerPass(straightPass(100.0), request).status, Status::Ok) << on_lead;
    request.max_angle_change_deg_per_mm = 0.9 * fastest;
    request.params.on_limit = LimitPolicy::Clamp;
    const SteeringResult marked = steerPass(straightPass(100.0), request);
    ASSERT_EQ(marked.status, Status::Ok) << marked.message;
    int limited = 0;
    for (const PostureSample& s : marked.samples) limited += s.limited;
    EXPECT_GT(limited, 0) << on_lead;
  }
}

TEST(Limits, AngleChangePerMmIsReported) {
  SteeringRequest request = requestFor(nullptr);
  request.params.on_limit = LimitPolicy::Fail;
  request.initial_tilt_rad = 0.2;
  request.max_angle_change_deg_per_mm = 0.1;  // the free return turns ≈ 0.35°/mm at its fastest
  const SteeringResult result = steerPass(straightPass(100.0), request);
  EXPECT_EQ(result.status, Status::RateLimit);
  EXPECT_NE(result.message.find("s = "), std::string::npos) << result.message;
  request.max_angle_change_deg_per_mm = 1.0;
  EXPECT_EQ(steerPass(straightPass(100.0), request).status, Status::Ok);
}

TEST(Inputs, BadSettingsNameTheirKey) {
  const Pass pass = straightPass(10.0);
  auto expectKey = [&](SteeringRequest request, const std::string& key) {
    try {
      steerPass(pass, request);
      ADD_FAILURE() << "no error for " << key;
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  };
  SteeringRequest r = requestFor(nullptr);
  r.params.inertia = 0.0;
  expectKey(r, "dynamics.inertia");
  r = requestFor(nullptr);
  r.params.feed_mm_per_min = NAN;
  expectKey(r, "dynamics.feed");
  r = requestFor(nullptr);
  r.params.rtol = -1.0;
  expectKey(r, "dynamics.rtol");
  r = requestFor(nullptr);
  r.step_mm = 0.0;
  expectKey(r, "path.step");
  r = requestFor(nullptr);
  r.params.max_tilt_deg = 0.0;
  expectKey(r, "dynamics.max_tilt_deg");
  EXPECT_THROW(steerPass(Pass{10.0, {}}, requestFor(nullptr)), common::InputError);

  const Pass base = straightPass(10.0);
  const Pass broken{10.0, [&](double s_mm) {
                      PassFrame f = base.frameAt(s_mm);
                      if (s_mm > 5.0) f.normal = Vec3::Zero();
                      return f;
                    }};
  for (Integrator integrator : {Integrator::Bdf, Integrator::Erk}) {
    SteeringRequest request = requestFor(nullptr);
    request.params.integrator = integrator;
    try {
      steerPass(broken, request);
      ADD_FAILURE() << "no error for a zero normal";
    } catch (const common::InputError& e) {
      EXPECT_NE(std::string(e.what()).find("s = 5."), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("normal"), std::string::npos) << e.what();
    }
  }
}

TEST(Outputs, SamplesEveryStepEndingOnTheLength) {
  SteeringRequest request = requestFor(nullptr);
  request.step_mm = 0.4;
  const SteeringResult result = steerPass(straightPass(10.0), request);
  ASSERT_EQ(result.samples.size(), 26u);  // 0, 0.4, ..., 9.6, 10
  EXPECT_DOUBLE_EQ(result.samples[1].s_mm, 0.4);
  EXPECT_DOUBLE_EQ(result.samples.back().s_mm, 10.0);
  const PostureSample& s = result.samples.back();
  EXPECT_NEAR((s.posture.tip_mm + kRadius * s.posture.axis - Vec3(10.0, 0, kRadius)).norm(), 0.0,
              1e-12);
  EXPECT_TRUE(std::isnan(s.clearance_mm));  // no clearance hook
  EXPECT_EQ(steerPass(straightPass(0.0), request).samples.size(), 1u);
}

TEST(Outputs, ProgressReachesTheEndAndCanInterrupt) {
  SteeringRequest request = requestFor(nullptr);
  double last = -1.0;
  request.progress = [&](double fraction, std::string_view) {
    EXPECT_GE(fraction, last);
    last = fraction;
    return true;
  };
  steerPass(straightPass(50.0), request);
  EXPECT_DOUBLE_EQ(last, 1.0);
  request.progress = [](double fraction, std::string_view) { return fraction < 0.5; };
  EXPECT_THROW(steerPass(straightPass(50.0), request), common::Interrupted);
}

/// A field that fails part-way: the exception must cross the C solver and reach the caller.
struct FailingField final : field::ForceField {
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    if (points[0].x() > 20.0) throw std::runtime_error("field lookup failed");
    for (Vec3& f : forces) f.setZero();
  }
};

/// A field that returns NaN beyond x = from_x_mm.
struct NanField final : field::ForceField {
  double from_x_mm = 0.0;
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    for (std::size_t i = 0; i < points.size(); ++i)
      forces[i] = points[i].x() > from_x_mm ? Vec3::Constant(NAN) : Vec3::Zero();
  }
};

TEST(Outputs, NonFiniteFieldIsASolverFailureNeverANanSample) {
  NanField field;
  for (double from_x_mm : {20.0, -100.0}) {  // part-way, and from the very start
    field.from_x_mm = from_x_mm;
    for (Integrator integrator : {Integrator::Bdf, Integrator::Erk}) {
      SteeringRequest request = requestFor(&field);
      request.params.integrator = integrator;
      const SteeringResult result = steerPass(straightPass(50.0), request);
      EXPECT_EQ(result.status, Status::SolverFailed);
      EXPECT_NE(result.message.find("s = "), std::string::npos) << result.message;
      for (const PostureSample& s : result.samples) {
        EXPECT_TRUE(s.moment.allFinite() && std::isfinite(s.tilt_rad)) << "s = " << s.s_mm;
        EXPECT_LT(s.s_mm, 20.0);
      }
    }
  }
}

TEST(Outputs, FieldErrorsPropagateThroughTheSolver) {
  const FailingField field;
  for (Integrator integrator : {Integrator::Bdf, Integrator::Erk}) {
    SteeringRequest request = requestFor(&field);
    request.params.integrator = integrator;
    EXPECT_THROW(steerPass(straightPass(50.0), request), std::runtime_error);
  }
}

}  // namespace
}  // namespace fieldpath::dynamics
