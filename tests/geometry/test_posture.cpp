#include <random>

#include <gtest/gtest.h>

#include "fieldpath/geometry/posture.h"

using namespace fieldpath::geometry;

namespace {

void expectProperRotationMappingZTo(const Eigen::Matrix3d& r, const Vec3& axis) {
  EXPECT_LT((r.transpose() * r - Eigen::Matrix3d::Identity()).norm(), 1e-14);
  EXPECT_NEAR(r.determinant(), 1.0, 1e-14);
  EXPECT_LT((r * Vec3::UnitZ() - axis.normalized()).norm(), 1e-14);
}

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

}  // namespace

TEST(Posture, RandomAxesGiveProperRotations) {
  std::mt19937_64 rng(1);
  for (int t = 0; t < 2000; ++t) {
    const Vec3 a = randomUnit(rng);
    expectProperRotationMappingZTo(rotationFromZ(a), a);
  }
}

TEST(Posture, AxesNearPlusZ) {
  std::mt19937_64 rng(2);
  for (double eps : {1e-9, 1e-12, 1e-15, 0.0}) {
    for (int t = 0; t < 100; ++t) {
      const Vec3 d = randomUnit(rng);
      const Vec3 a = (Vec3::UnitZ() + eps * Vec3(d.x(), d.y(), 0)).normalized();
      const Eigen::Matrix3d r = rotationFromZ(a);
      expectProperRotationMappingZTo(r, a);
      // Minimal rotation: near identity when the axis is near +z.
      EXPECT_LT((r - Eigen::Matrix3d::Identity()).norm(), 10 * eps + 1e-15);
    }
  }
}

TEST(Posture, AxesNearMinusZ) {
  std::mt19937_64 rng(3);
  for (double eps : {1e-6, 1e-9, 1e-12, 0.0}) {
    for (int t = 0; t < 100; ++t) {
      const Vec3 d = randomUnit(rng);
      const Vec3 a = (-Vec3::UnitZ() + eps * Vec3(d.x(), d.y(), 0)).normalized();
      expectProperRotationMappingZTo(rotationFromZ(a), a);
    }
  }
  const Eigen::Matrix3d r = rotationFromZ(-Vec3::UnitZ());
  expectProperRotationMappingZTo(r, -Vec3::UnitZ());
  // Horizontal parts so small that i² + j² underflows: still a finite proper rotation.
  for (const Vec3& a : {Vec3(1e-160, 0, -1), Vec3(1e-200, -1e-200, -1), Vec3(0, 5e-324, -1)}) {
    const Eigen::Matrix3d m = rotationFromZ(a);
    ASSERT_TRUE(m.allFinite()) << a.transpose();
    expectProperRotationMappingZTo(m, a);
  }
}

TEST(Posture, MinimalRotationFixesTheCommonPerpendicular) {
  // The rotation is about e_z × a, so that vector is left unchanged.
  std::mt19937_64 rng(4);
  for (int t = 0; t < 200; ++t) {
    const Vec3 a = randomUnit(rng);
    const Vec3 w = Vec3::UnitZ().cross(a);
    if (w.norm() < 1e-6) continue;
    EXPECT_LT((rotationFromZ(a) * w - w).norm(), 1e-14);
  }
}

TEST(Posture, TransformRoundTripsPoints) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-100, 100);
  for (int t = 0; t < 500; ++t) {
    Posture p;
    p.tip_mm = Vec3(u(rng), u(rng), u(rng));
    p.axis = randomUnit(rng);
    const Eigen::Isometry3d m = toolToWorld(p);
    const Vec3 x(u(rng), u(rng), u(rng));
    EXPECT_LT((m.inverse() * (m * x) - x).norm(), 1e-12);
    EXPECT_LT((m * Vec3::Zero() - p.tip_mm).norm(), 1e-12);
    const Posture back = postureFromTransform(m);
    EXPECT_LT((back.tip_mm - p.tip_mm).norm(), 1e-12);
    EXPECT_LT((back.axis - p.axis).norm(), 1e-14);
  }
}

// Closed form: the ball centre sits at (0, 0, R) in the tool frame, so toolToWorld places it at
// C, and the tip is R below it along the axis.
TEST(Posture, BallEndTipIsTheCentreLessRAlongTheAxis) {
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-100, 100);
  const double radius_mm = 3.0;
  for (int t = 0; t < 200; ++t) {
    const Vec3 centre(u(rng), u(rng), u(rng));
    const Vec3 a = randomUnit(rng);
    const Posture p = ballEndPosture(centre, a, radius_mm);
    EXPECT_EQ(p.axis, a);
    EXPECT_LT((toolToWorld(p) * Vec3(0, 0, radius_mm) - centre).norm(), 1e-12);
    EXPECT_NEAR((p.tip_mm - centre).norm(), radius_mm, 1e-12);
    EXPECT_LT((ballCentre(p, radius_mm) - centre).norm(), 1e-12);
  }
  const Posture upright = ballEndPosture(Vec3(1, 2, 3), Vec3::UnitZ(), radius_mm);
  EXPECT_EQ(upright.tip_mm, Vec3(1, 2, 0));
}

// The stamps of a motion (forEachPoseBetween) are at most a step apart for every point within the
// reach of the tip: |Δtip| + reach · Δθ between neighbours, ends included, whatever the turn (the
// axis, linear and renormalised, turns 2 tan(θ/2) / θ faster midway than on average: counted by
// θ, a 90 deg turn's middle stamps were 1.27 steps apart).
TEST(Posture, StampsOfATurningMotionAreAStepApartEverywhere) {
  const double reach_mm = 50.0, step_mm = 0.5;
  for (const double turn_deg : {10.0, 90.0, 150.0, 178.0}) {
    const double turn = turn_deg * M_PI / 180.0;
    const Posture a{Vec3(0, 0, 0), Vec3(0, 0, 1)};
    const Posture b{Vec3(3, -2, 1), Vec3(std::sin(turn), 0, std::cos(turn))};
    std::vector<Posture> poses{a};
    forEachPoseBetween(a, b, reach_mm, step_mm, [&](const Posture& p) { poses.push_back(p); });
    poses.push_back(b);
    double widest_mm = 0.0;
    for (std::size_t k = 1; k < poses.size(); ++k)
      widest_mm = std::max(widest_mm, (poses[k].tip_mm - poses[k - 1].tip_mm).norm() +
                                          reach_mm * axisAngle(poses[k - 1].axis, poses[k].axis));
    EXPECT_LE(widest_mm, step_mm * (1.0 + 1e-9))
        << turn_deg << " deg, " << poses.size() << " poses";
    // Not wastefully many: within 2 tan(θ/2) / θ of the even count (1.27 at 90 deg).
    EXPECT_LE(static_cast<double>(poses.size() - 1),
              motionSweepMm(a, b, reach_mm) / step_mm * 2.0 * std::tan(0.5 * turn) / turn + 1.0);
  }
}
