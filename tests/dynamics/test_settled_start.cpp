/// A pass started from the axis settled under the field at its start (settleAtStart,
/// dynamics.start): the static equilibrium k θ = τ(θ) found here by bisection, independently;
/// the pass then starts at rest there (no swing), and where no rest exists the caller is told.
#include <cmath>

#include <gtest/gtest.h>

#include "analytic_fields.h"
#include "fieldpath/dynamics/steering.h"
#include "steering_support.h"

namespace fieldpath::dynamics {
namespace {

using namespace steering_test;  // with analytic_fields.h's fields

/// The largest change of either angle between consecutive samples (rad).
double largestStep(const SteeringResult& r) {
  double worst = 0.0;
  for (std::size_t i = 1; i < r.samples.size(); ++i)
    worst = std::max({worst, std::abs(r.samples[i].tilt_rad - r.samples[i - 1].tilt_rad),
                      std::abs(r.samples[i].lead_rad - r.samples[i - 1].lead_rad)});
  return worst;
}

TEST(SettledStart, IsTheStaticEquilibriumAndThePassStartsAtRestThere) {
  const auto wall = wallAt(3.1);  // the shank starts 0.1 mm from the wall, inside r_min
  SteeringRequest request = requestFor(wall.get());
  const Pass pass = straightPass(300.0);  // 18 decay times at the default feed
  const SettledStart settled = settleAtStart(pass, request);
  ASSERT_TRUE(settled.settled) << settled.why;
  const double expected = staticTilt(*wall, request.params.stiffness, 0.0, 0.6);
  EXPECT_GT(expected, 2.0 * kDeg);
  EXPECT_NEAR(settled.tilt_rad, expected, 1e-6);
  EXPECT_NEAR(settled.lead_rad, 0.0, 1e-12);  // a wall along the feed gives no lead moment

  const SteeringResult from_nominal = steerPass(pass, request);
  request.initial_lead_rad = settled.lead_rad;
  request.initial_tilt_rad = settled.tilt_rad;
  const SteeringResult from_rest = runToleranceStable(pass, request);
  ASSERT_EQ(from_rest.status, Status::Ok) << from_rest.message;
  // The nominal start moves (0.4° in its first 0.5 mm here, damped critically with the wall's
  // stiffness: it swung 1° when the spring's alone); the settled one stays.
  EXPECT_GT(largestStep(from_nominal), 0.03 * expected);
  EXPECT_LT(largestStep(from_rest), 1e-6);
  for (const PostureSample& s : from_rest.samples) EXPECT_NEAR(s.tilt_rad, expected, 2e-6);
  // Both end at rest at the same place.
  EXPECT_NEAR(from_nominal.samples.back().tilt_rad, from_rest.samples.back().tilt_rad, 1e-6);
}

TEST(SettledStart, ReportsProgressAsNoneOfThePassAndCanBeInterrupted) {
  // The settling ran with no progress hook: over a dense direct field a minute of silence (a
  // blisk helper's). It reports now, as 0 of the pass (it comes before it), and stops when asked.
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  std::size_t calls = 0;
  double largest = -1.0;
  request.progress = [&](double fraction, std::string_view) {
    ++calls;
    largest = std::max(largest, fraction);
    return true;
  };
  const SettledStart settled = settleAtStart(straightPass(300.0), request);
  ASSERT_TRUE(settled.settled) << settled.why;
  EXPECT_GT(calls, 0u);
  EXPECT_EQ(largest, 0.0);
  request.progress = [](double, std::string_view) { return false; };
  EXPECT_THROW((void)settleAtStart(straightPass(300.0), request), common::Interrupted);
}

TEST(SettledStart, NoFieldNoDeflection) {
  SteeringRequest request = requestFor(nullptr);
  const SettledStart settled = settleAtStart(straightPass(10.0), request);
  ASSERT_TRUE(settled.settled) << settled.why;
  EXPECT_EQ(settled.tilt_rad, 0.0);
  EXPECT_EQ(settled.lead_rad, 0.0);
}

TEST(SettledStart, HeldAtALimitTheRestLiesBeyond) {
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  request.params.max_tilt_deg = 2.0;  // the equilibrium lies beyond it
  ASSERT_GT(staticTilt(*wall, 1.0, 0.0, 0.6), 2.0 * kDeg);
  for (const LimitPolicy policy : {LimitPolicy::Clamp, LimitPolicy::Fail}) {
    request.params.on_limit = policy;
    const SettledStart held = settleAtStart(straightPass(10.0), request);
    ASSERT_TRUE(held.settled) << held.why;
    EXPECT_NEAR(held.tilt_rad, 2.0 * kDeg, 1e-12);
  }
}

// The swing on the way to rest is not machined: it may pass a limit the rest lies within, with
// on_limit: fail too (a helper's finding: the settling failed there and the pass started at the
// nominal axis, swinging 44° past the limit and failing).
TEST(SettledStart, TheSwingToRestIsNotAFailure) {
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  const double rest = staticTilt(*wall, 1.0, 0.0, 0.6);
  const Pass pass = straightPass(20.0);
  request.params.max_tilt_deg = 1.2 * rest / kDeg;  // above the rest, below the nominal swing
  request.params.on_limit = LimitPolicy::Fail;
  request.params.damping = 2.0;  // critical for the spring alone: the wall's stiffness rings
  ASSERT_EQ(steerPass(pass, request).status, Status::TiltLimit);  // from the nominal axis
  const SettledStart settled = settleAtStart(pass, request);
  ASSERT_TRUE(settled.settled) << settled.why;
  EXPECT_NEAR(settled.tilt_rad, rest, 1e-6);
  request.initial_lead_rad = settled.lead_rad;
  request.initial_tilt_rad = settled.tilt_rad;
  EXPECT_EQ(steerPass(pass, request).status, Status::Ok);
}

// A slow spring-damper settles over fewer stations than its decay holds steps (kSettleStations:
// inertia 1e10 over stiffness 1e-10 ran out of memory after 49 s, a diff review's), to the same
// rest; one whose decay runs past kMaxSettleMm of path has none to start from, and says so.
TEST(SettledStart, ASlowDecayIsSettledInBoundedWork) {
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  request.params.inertia = 1e4;  // critical c = 2 sqrt(k J) = 200: a decay of 100 s, 1667 mm
  request.step_mm = 0.5;
  ASSERT_GT(2.0 * request.params.inertia / request.params.effectiveDamping() *
                request.params.feed_mm_per_min / 60.0,
            kSettleStations * request.step_mm);
  const SettledStart slow = settleAtStart(straightPass(10.0), request);
  ASSERT_TRUE(slow.settled) << slow.why;
  EXPECT_NEAR(slow.tilt_rad, staticTilt(*wall, request.params.stiffness, 0.0, 0.6), 1e-6);
  // The work: at most kSettleStations (and the chunk's end) a decay, where the pass's 0.5 mm
  // would make 3334 of them.
  EXPECT_GT(slow.stations, 0u);
  EXPECT_LE(double(slow.stations), kSettleDecays * (kSettleStations + 2.0));

  request.params.inertia = 1.0;
  request.params.damping = 1e-9;  // a decay of 2e9 s
  const SettledStart never = settleAtStart(straightPass(10.0), request);
  EXPECT_FALSE(never.settled);
  EXPECT_NE(never.why.find("no rest to start from (dynamics.damping)"), std::string::npos)
      << never.why;
}

// Heavy damping: the axis creeps to rest over c/k, not 2J/c (with damping 100 it moved little
// in each 2J/c and was called settled 20 of them later, far from its rest).
TEST(SettledStart, AnOverdampedAxisIsSettledAtItsRest) {
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  request.params.damping = 100.0;  // 2J/c = 0.02 s, c/k = 100 s
  const SettledStart settled = settleAtStart(straightPass(10.0), request);
  ASSERT_TRUE(settled.settled) << settled.why;
  EXPECT_NEAR(settled.tilt_rad, staticTilt(*wall, request.params.stiffness, 0.0, 0.6), 1e-6);
}

TEST(SettledStart, WithoutDampingThereIsNoRest) {
  const auto wall = wallAt(3.1);
  SteeringRequest request = requestFor(wall.get());
  request.params.damping = 0.0;
  const SettledStart settled = settleAtStart(straightPass(10.0), request);
  EXPECT_FALSE(settled.settled);
  EXPECT_NE(settled.why.find("dynamics.damping"), std::string::npos) << settled.why;
}

/// A vortex about the vertical through the pass's first ball centre: F = κ ẑ × (p - c), which
/// pushes a node square to its lean, so that the axis circles: J θ'' + c θ' + k θ = q J₉₀ θ with
/// q = κ L² for a node L above the centre (J₉₀ the quarter turn of (lead, tilt)). Its modes
/// J s² + c s + k ∓ i q = 0 grow where q > c sqrt(k / J) (c = 2 sqrt(k J): q > 2 k).
struct VortexField final : field::ForceField {
  Vec3 centre_mm;
  double kappa = 0.0;
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    for (std::size_t i = 0; i < points.size(); ++i)
      forces[i] = kappa * Vec3::UnitZ().cross(points[i] - centre_mm);
  }
};

// An axis that never comes to rest: a vortex pumping faster than the damping takes (q = 5 k),
// the axis circling out to its limits and round them. Each decay then moved as much as the last,
// and all kSettleDecays ran, each clamped at every station (a helper's pocket corner: 3 M
// evaluations of the field, 40 s of a 2-pass job). It stops once kSettleCycleDecays decays in a
// row move no less than the least before, within the limits; a vortex the damping outruns
// (q = k) still settles, at rest.
TEST(SettledStart, AnAxisThatCyclesIsNotRunForEveryDecay) {
  const double node_mm = 30.0;
  VortexField vortex;
  // (1 mm aside of the first centre: the nominal axis is then no equilibrium to sit on)
  vortex.centre_mm = straightPass(1.0).frameAt(0.0).centre_mm + Vec3(0.0, 1.0, 0.0);
  SteeringRequest request = requestFor(&vortex);
  const std::vector<Vec3> node = {Vec3(0, 0, kRadius + node_mm)};
  request.nodes_tool_frame_mm = node;
  request.params.inertia = 1.0;
  request.params.stiffness = 1.0;
  request.params.damping = 2.0;  // critical for the spring
  request.params.max_lead_deg = 10.0;
  request.params.max_tilt_deg = 10.0;
  request.step_mm = 0.5;
  const Pass pass = dwell(10.0);
  const double decay_stations = 2.0 * request.params.inertia / request.params.damping *
                                request.params.feed_mm_per_min / 60.0 / request.step_mm;

  vortex.kappa = 5.0 / (node_mm * node_mm);
  const SettledStart cycling = settleAtStart(pass, request);
  ASSERT_TRUE(cycling.settled) << cycling.why;
  EXPECT_LE(double(cycling.stations), 12.0 * (decay_stations + 2.0));
  EXPECT_LE(std::abs(cycling.lead_rad), 10.0 * kDeg * (1.0 + 1e-12));
  EXPECT_LE(std::abs(cycling.tilt_rad), 10.0 * kDeg * (1.0 + 1e-12));
  // It does cycle: dwelling on from there, the axis still swings.
  request.initial_lead_rad = cycling.lead_rad;
  request.initial_tilt_rad = cycling.tilt_rad;
  EXPECT_GT(largestStep(steerPass(dwell(30.0), request)), 0.1 * kDeg);

  vortex.kappa = 1.0 / (node_mm * node_mm);
  request.initial_lead_rad.reset();
  request.initial_tilt_rad.reset();
  const SettledStart damped = settleAtStart(pass, request);
  ASSERT_TRUE(damped.settled) << damped.why;
  request.initial_lead_rad = damped.lead_rad;
  request.initial_tilt_rad = damped.tilt_rad;
  EXPECT_GT(std::hypot(damped.lead_rad, damped.tilt_rad), 0.5 * kDeg);  // pushed off the nominal
  EXPECT_LT(largestStep(steerPass(dwell(30.0), request)), 1e-6);        // and at rest there
}

}  // namespace
}  // namespace fieldpath::dynamics
