#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/dynamics/frame.h"

namespace fieldpath::dynamics {
namespace {

void expectOrthonormalRightHanded(const LocalFrame& fr) {
  EXPECT_NEAR(fr.f.norm(), 1.0, 1e-12);
  EXPECT_NEAR(fr.n.norm(), 1.0, 1e-12);
  EXPECT_NEAR(fr.f.dot(fr.n), 0.0, 1e-12);
  EXPECT_NEAR((fr.n.cross(fr.f) - fr.b).norm(), 0.0, 1e-12);
}

TEST(LocalFrame, OrthonormalisesASloppyFeed) {
  PassFrame pf;
  pf.feed = Vec3(2.0, 0.0, 0.5);  // not unit, not orthogonal to n
  pf.normal = Vec3(0.0, 0.0, 3.0);
  const LocalFrame fr = localFrame(pf);
  expectOrthonormalRightHanded(fr);
  EXPECT_FALSE(fr.degenerate);
  EXPECT_NEAR((fr.f - Vec3::UnitX()).norm(), 0.0, 1e-12);
  EXPECT_NEAR((fr.b - Vec3::UnitY()).norm(), 0.0, 1e-12);  // b = n × f = e_z × e_x
}

TEST(LocalFrame, FeedParallelToNormalFallsBack) {
  PassFrame pf;
  pf.feed = Vec3(0.0, 0.0, -2.0);
  pf.normal = Vec3::UnitZ();
  const LocalFrame fr = localFrame(pf);
  EXPECT_TRUE(fr.degenerate);
  expectOrthonormalRightHanded(fr);
  const LocalFrame hinted = localFrame(pf, Vec3(0.0, 1.0, 0.3));
  EXPECT_NEAR((hinted.f - Vec3::UnitY()).norm(), 0.0, 1e-12);
  pf.feed = Vec3::Zero();
  expectOrthonormalRightHanded(localFrame(pf));
}

TEST(LocalFrame, ZeroNormalIsBadInput) {
  PassFrame pf;
  pf.normal = Vec3::Zero();
  EXPECT_THROW(localFrame(pf), common::InputError);
  pf.normal = Vec3(NAN, 0, 1);
  EXPECT_THROW(localFrame(pf), common::InputError);
}

TEST(AxisFromAngles, MatchesRotationsAboutBThenF) {
  PassFrame pf;
  pf.feed = Vec3(1.0, 1.0, 0.0);
  pf.normal = Vec3(0.0, 0.0, 1.0);
  const LocalFrame fr = localFrame(pf);
  const double lead = 0.3, tilt = -0.7;
  const Vec3 expected = Eigen::AngleAxisd(tilt, fr.f) * (Eigen::AngleAxisd(lead, fr.b) * fr.n);
  const Vec3 a = axisFromAngles(fr, lead, tilt);
  EXPECT_NEAR((a - expected).norm(), 0.0, 1e-12);
  EXPECT_NEAR(a.norm(), 1.0, 1e-12);
  EXPECT_GT(axisFromAngles(fr, 0.1, 0.0).dot(fr.f), 0.0);  // positive lead leans forward
  EXPECT_LT(axisFromAngles(fr, 0.0, 0.1).dot(fr.b), 0.0);  // positive tilt leans towards -b
  EXPECT_NEAR((axisFromAngles(fr, 0.0, 0.0) - fr.n).norm(), 0.0, 0.0);  // nominal = normal, exactly
}

}  // namespace
}  // namespace fieldpath::dynamics

namespace fieldpath::dynamics {

// A state re-expressed in a frame turned 90° about the normal (a corner held by the steering):
// the same axis, and the same velocity of the axis (against a central difference of the axis
// along the state's rates in the first frame).
TEST(Frame, AStateReexpressedInATurnedFrameKeepsTheAxisAndItsVelocity) {
  LocalFrame from, to;
  from.f = Vec3::UnitX(), from.n = Vec3::UnitZ(), from.b = from.n.cross(from.f);
  to.f = Vec3::UnitY(), to.n = Vec3::UnitZ(), to.b = to.n.cross(to.f);
  const std::array<double, 4> state = {0.3, 0.2, 0.1, -0.2};
  const std::array<double, 4> out = reexpressState(from, to, state);
  EXPECT_LT((axisFromAngles(to, out[0], out[1]) - axisFromAngles(from, state[0], state[1])).norm(),
            1e-14);
  const double h = 1e-6;
  const auto along = [](const LocalFrame& frame, const std::array<double, 4>& y, double t) {
    return axisFromAngles(frame, y[0] + t * y[2], y[1] + t * y[3]);
  };
  const Vec3 velocity = (along(from, state, h) - along(from, state, -h)) / (2 * h);
  const Vec3 again = (along(to, out, h) - along(to, out, -h)) / (2 * h);
  EXPECT_LT((velocity - again).norm(), 1e-8);
  EXPECT_GT(velocity.norm(), 0.1);
}

}  // namespace fieldpath::dynamics
