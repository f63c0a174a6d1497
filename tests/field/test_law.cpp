/// Eq. 1 against its closed forms: one point, superposition, an area-weighted plane; sampling; the
/// surface rule; brute force against the indexed direct sum.
#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/law.h"
#include "fieldpath/field/sampling.h"
#include "fieldpath/geometry/mesh.h"
#include "meshes.h"

using namespace fieldpath::field;
using fieldpath::geometry::TriangleMesh;

namespace {

Vec3 randomUnit(std::mt19937_64& rng) {
  std::normal_distribution<double> n;
  return Vec3(n(rng), n(rng), n(rng)).normalized();
}

ObstacleSamples onePoint(const Vec3& q, const Vec3& normal, double weight) {
  ObstacleSamples s;
  s.add(q, normal, weight);
  return s;
}

/// Eq. 1 written out for one sample, independently of law.h.
Vec3 eq1(const Vec3& x, const Vec3& q, double w, const FieldParams& p) {
  const double r = (x - q).norm();
  if (r >= p.r0_mm) return Vec3::Zero();
  const double rc = std::max(r, p.r_min_mm);
  return p.gain * w * (1.0 / rc - 1.0 / p.r0_mm) / (rc * rc) * (x - q) / r;
}

}  // namespace

TEST(Law, OnePointMatchesEq1AtRandomDistances) {
  FieldParams p;
  p.r0_mm = 5.0;
  p.r_min_mm = 0.25;
  p.gain = 1.7;
  const Vec3 q(1.0, -2.0, 3.0), n(0, 0, 1);
  const DirectField direct(onePoint(q, n, 0.8), p);
  const BruteForceField brute(onePoint(q, n, 0.8), p);
  std::mt19937_64 rng(4);
  std::uniform_real_distribution<double> radius(p.r_min_mm, p.r0_mm);
  for (int t = 0; t < 500; ++t) {
    const Vec3 u = randomUnit(rng);
    const Vec3 x = q + radius(rng) * u;
    if ((x - q).dot(n) < p.r_min_mm) continue;  // the surface rule holds the field below r_min
    const Vec3 expected = eq1(x, q, 0.8, p);
    EXPECT_LT((direct.at(x) - expected).norm(), 1e-12 * expected.norm()) << t;
    EXPECT_LT((brute.at(x) - expected).norm(), 1e-12 * expected.norm()) << t;
  }
}

TEST(Law, ZeroBeyondR0) {
  FieldParams p;
  const Vec3 q(0, 0, 0);
  const DirectField direct(onePoint(q, Vec3::UnitZ(), 1.0), p);
  std::mt19937_64 rng(5);
  for (int t = 0; t < 200; ++t) {
    const Vec3 x = q + (p.r0_mm * (1.0 + 1e-9) + 3.0 * t / 200.0) * randomUnit(rng);
    EXPECT_EQ(direct.at(x), Vec3::Zero());
  }
  EXPECT_EQ(phi(p.r0_mm, p.r0_mm, p.r_min_mm), 0.0);
}

TEST(Law, HeldAtRMinAndFiniteOnTheSample) {
  FieldParams p;
  const Vec3 q(0, 0, 0), n(0, 0, 1);
  const double held = (1.0 / p.r_min_mm - 1.0 / p.r0_mm) / (p.r_min_mm * p.r_min_mm);
  for (double r : {p.r_min_mm, 0.2, 0.1, 1e-3, 1e-9, 0.0}) {
    EXPECT_EQ(phi(r, p.r0_mm, p.r_min_mm), held) << r;
    const Vec3 x = q + r * Vec3(0.6, 0.0, 0.8);
    const Vec3 f = sampleTerm(x - q, (x - q).squaredNorm(), n, 1.0, p);  // the sum's own term
    EXPECT_NEAR(f.norm(), held, 1e-12 * held) << r;
    EXPECT_NEAR(f.normalized().dot(r > 0 ? Vec3(0.6, 0.0, 0.8) : n), 1.0, 1e-12) << r;
  }
  // The whole field near the sample: finite, bounded by the held value, pointing out.
  const DirectField direct(onePoint(q, n, 1.0), p);
  for (double r : {0.2, 1e-3, 0.0}) {
    const Vec3 f = direct.at(q + r * Vec3(0.6, 0.0, 0.8));
    EXPECT_TRUE(f.allFinite());
    EXPECT_LE(f.norm(), held * (1 + 1e-12));
    EXPECT_GT(f.z(), 0.0);
  }
  EXPECT_NEAR(direct.at(q).z(), held, 1e-12 * held);  // on the sample: along its normal, r_min off
}

TEST(Law, Superposition) {
  FieldParams p;
  std::mt19937_64 rng(6);
  std::uniform_real_distribution<double> u(-3.0, 3.0), w(0.2, 2.0);
  ObstacleSamples all;
  std::vector<ObstacleSamples> each;
  for (int j = 0; j < 12; ++j) {  // samples below z = 0, normals +z: queries above are outside
    const Vec3 q(u(rng), u(rng), -std::abs(u(rng)) / 3.0);
    const double wj = w(rng);
    all.add(q, Vec3::UnitZ(), wj);
    each.push_back(onePoint(q, Vec3::UnitZ(), wj));
  }
  const DirectField direct(all, p);
  for (int t = 0; t < 200; ++t) {
    const Vec3 x(u(rng), u(rng), 0.3 + std::abs(u(rng)));  // more than r_min above
    Vec3 sum = Vec3::Zero();
    for (const auto& s : each) sum += DirectField(s, p).at(x);
    EXPECT_LT((direct.at(x) - sum).norm(), 1e-12 * (1.0 + sum.norm())) << t;
  }
}

TEST(Sampling, AreaWeightsPartitionTheSurfaceWithOutwardNormals) {
  const TriangleMesh cube = test::box(Vec3(0, 0, 0), Vec3(10, 20, 30));
  const double area = 2.0 * (10 * 20 + 20 * 30 + 10 * 30);
  for (double step : {2.0, 1.0, 0.5}) {
    const ObstacleSamples s = sampleObstacles({&cube, 1}, step, Weights::Area);
    double total = 0.0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      total += s.weights[j];
      EXPECT_LE(s.weights[j], step * step * (1 + 1e-12));
      EXPECT_NEAR(s.normals[j].norm(), 1.0, 1e-12);
      // outward: the normal points away from the box centre
      EXPECT_GT((s.points_mm[j] - Vec3(5, 10, 15)).dot(s.normals[j]), 0.0);
    }
    EXPECT_NEAR(total, area, 1e-9 * area);
    EXPECT_NEAR(s.area_mm2, area, 1e-9 * area);
    // about one sample per step² (between 1 and 3 given the n×n split of right triangles)
    EXPECT_GE(s.size(), area / (step * step));
    EXPECT_LE(s.size(), 3.0 * area / (step * step));
  }
  const ObstacleSamples unit = sampleObstacles({&cube, 1}, 1.0, Weights::Unit);
  for (double w : unit.weights) EXPECT_EQ(w, 1.0);
  EXPECT_THROW(sampleObstacles({&cube, 1}, 0.0, Weights::Area), fieldpath::common::InputError);
}

TEST(Law, PlaneIsIndependentOfSamplingDensityAndMatchesClosedForm) {
  FieldParams p;  // r0 = 5: a 2×(5+1) mm wide square acts as an infinite plane at its centre
  const TriangleMesh plane = test::squarePlane(8.0);
  const DirectField coarse(sampleObstacles({&plane, 1}, 1.0, Weights::Area), p);
  const DirectField fine(sampleObstacles({&plane, 1}, 0.5, Weights::Area), p);
  for (double d : {1.0, 1.5, 2.0, 3.0, 4.0, 4.5}) {
    const Vec3 x(0.3, -0.2, d);
    const double exact = planeFieldMagnitude(d, p);
    const Vec3 fc = coarse.at(x), ff = fine.at(x);
    EXPECT_NEAR(ff.z(), exact, 0.01 * exact) << d;  // quadrature error of the 0.5 mm sampling
    EXPECT_NEAR(fc.z(), exact, 0.02 * exact) << d;
    EXPECT_NEAR(fc.z(), ff.z(), 0.02 * exact) << d;
    EXPECT_LT(ff.head<2>().norm(), 0.01 * exact) << d;  // along the normal
  }
}

/// The square [-a, a]² at height z, cut into 2 k² triangles, normal +z or (flipped) -z.
TriangleMesh finePlane(double a, int k, double z, bool flipped = false) {
  TriangleMesh m;
  for (int j = 0; j <= k; ++j)
    for (int i = 0; i <= k; ++i) m.vertices.emplace_back(-a + 2 * a * i / k, -a + 2 * a * j / k, z);
  for (int j = 0; j < k; ++j)
    for (int i = 0; i < k; ++i) {
      const int v = j * (k + 1) + i;
      if (flipped) {
        m.triangles.push_back({v, v + k + 2, v + 1});
        m.triangles.push_back({v, v + k + 1, v + k + 2});
      } else {
        m.triangles.push_back({v, v + 1, v + k + 2});
        m.triangles.push_back({v, v + k + 2, v + k + 1});
      }
    }
  return m;
}

// A surface tessellated finer than the sample step (CAD exports: 1 M triangles on 10^4 mm² gave
// 1 M samples, 100× the density asked, and a 200 s field) is sampled about once per step²: its
// small triangles merged per cell and normal direction, the area an exact partition still, the
// field the plane's closed form as from two triangles.
// A cube written twice is sampled once: the field of one cube, not twice it (a review's).
TEST(Sampling, ATriangleWrittenAgainIsSampledOnce) {
  const TriangleMesh once = test::box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 10));
  TriangleMesh twice = once;
  for (const auto& t : once.triangles) twice.triangles.emplace_back(t[2], t[0], t[1]);
  const ObstacleSamples a = sampleObstacles({&once, 1}, 1.0, Weights::Area);
  const ObstacleSamples b = sampleObstacles({&twice, 1}, 1.0, Weights::Area);
  EXPECT_EQ(a.size(), b.size());
  EXPECT_NEAR(a.area_mm2, b.area_mm2, 1e-9);
}

// A plate thinner than its sample step is found at its thickness (its two faces' samples face
// apart, each behind the other); a thick one's faces are farther apart than the search, and a
// box's faces meeting at its edges do not face apart.
TEST(Sampling, TheThinnestWallIsFoundAtItsThickness) {
  const TriangleMesh thin = test::box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 0.2));
  const ThinWall wall = thinnestWall(sampleObstacles({&thin, 1}, 1.0, Weights::Area), 1.0);
  EXPECT_NEAR(wall.thickness_mm, 0.2, 1e-9);
  EXPECT_TRUE(wall.at_mm.z() < 1e-9 || wall.at_mm.z() > 0.2 - 1e-9) << wall.at_mm.transpose();
  const TriangleMesh thick = test::box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 3));
  EXPECT_EQ(thinnestWall(sampleObstacles({&thick, 1}, 1.0, Weights::Area), 1.0).thickness_mm,
            HUGE_VAL);
  // A 20° wedge 10 mm long (a sharp edge, thin only at its crease): no wall.
  TriangleMesh wedge;
  const double h = 10 * std::tan(10 * M_PI / 180);
  wedge.vertices = {{0, 0, 0}, {10, 0, h}, {10, 0, -h}, {0, 10, 0}, {10, 10, h}, {10, 10, -h}};
  wedge.triangles = {{0, 1, 2}, {3, 5, 4}, {0, 3, 4}, {0, 4, 1},
                     {0, 2, 5}, {0, 5, 3}, {1, 4, 5}, {1, 5, 2}};
  EXPECT_EQ(thinnestWall(sampleObstacles({&wedge, 1}, 1.0, Weights::Area), 1.0).thickness_mm,
            HUGE_VAL);
}

TEST(Sampling, FarFacesAreTheFacesOfAThinPlateAndNoneOfAThickBox) {
  const auto plate = test::plateSampledApart(10.0, 0.2);
  const ObstacleSamples thin = sampleObstacles({&plate, 1}, 1.0, Weights::Area);
  const std::vector<std::uint8_t> far = farFaces(thin, kThinReachSteps);
  std::size_t faces = 0;
  for (std::size_t j = 0; j < thin.size(); ++j) {
    if (std::abs(thin.normals[j].z()) < 0.99) continue;
    ++faces;
    EXPECT_TRUE(far[j]) << thin.points_mm[j].transpose();
  }
  EXPECT_GT(faces, 100u);
  const TriangleMesh thick = test::box(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(10, 10, 3));
  const ObstacleSamples box = sampleObstacles({&thick, 1}, 1.0, Weights::Area);
  for (const std::uint8_t flag : farFaces(box, kThinReachSteps)) EXPECT_FALSE(flag);
}

TEST(Field, AThinPlateSampledApartPushesOutOnBothSidesAndFromWithin) {
  // A 0.2 mm plate whose faces are sampled apart every 1 mm: beside a face the nearest sample
  // may be the other face's, and the surface rule alone read the point as inside and mirrored
  // it through the plate (Fz -25 at 0.1 mm over it, +5.9 at 0.5 mm under it). With law.h's
  // thin-wall rule the field points away from the plate on both sides, and out of the nearer
  // face from within; brute force and the indexed sum agree.
  const auto plate = test::plateSampledApart(20.0, 0.2);
  FieldParams p;
  const ObstacleSamples samples = sampleObstacles({&plate, 1}, 1.0, Weights::Area);
  const DirectField direct(samples, p);
  const BruteForceField brute(samples, p);
  for (double x = 3.0; x <= 17.0; x += 0.37)
    for (double y = 3.0; y <= 17.0; y += 0.41)
      for (const double z : {-2.0, -0.5, -0.1, -0.02, 0.05, 0.15, 0.22, 0.3, 0.7, 2.2}) {
        const Vec3 at(x, y, z);
        const Vec3 f = direct.at(at);
        EXPECT_EQ(f.z() > 0.0, z > 0.1) << at.transpose() << ": " << f.transpose();
        EXPECT_LE((brute.at(at) - f).norm(), 1e-12 * f.norm()) << at.transpose();
      }
  // 1 mm over it, the two faces' planes: P(1) + P(1.2) (the plane law), within the sampling's 5 %.
  const double both = planeFieldMagnitude(1.0, p) + planeFieldMagnitude(1.2, p);
  EXPECT_NEAR(direct.at(Vec3(10.1, 9.7, 1.2)).z(), both, 0.05 * both);
}

TEST(Field, InsideABlockBesideAThinFlangeThePushIsOutOfTheBlock) {
  // A block with a 0.2 mm flange beside it, its top flush with the block's (0.3 mm apart): the
  // block's top samples have the flange's underside behind them, facing the other way (far
  // faces), and a plane extended from the underside passes under points inside the block. The
  // thin-wall rule takes a near face only where its samples round the point's foot: inside the
  // block, within a step of the flange, the field points up, out of the block's top (the rule
  // without that test pushed such points down into it: -7.5 at 0.3 mm deep, a review's).
  const std::vector<TriangleMesh> parts{
      test::box(Eigen::Vector3d(-10, -10, -10), Eigen::Vector3d(0, 10, 0)),
      test::box(Eigen::Vector3d(0.3, -10, -0.2), Eigen::Vector3d(10, 10, 0))};
  FieldParams p;
  const DirectField direct(sampleObstacles(parts, 1.0, Weights::Area), p);
  for (double x = -1.5; x <= -0.25; x += 0.25)
    for (const double z : {-0.3, -0.5, -0.8})
      for (const double y : {0.1, 0.35, -2.2}) {
        const Vec3 at(x, y, z);
        if (-x < -z + 0.2) continue;  // not clearly nearer the top than the side
        EXPECT_GT(direct.at(at).z(), 0.0) << at.transpose();
      }
}

TEST(Sampling, AFineTessellationIsSampledAtTheStepAsked) {
  FieldParams p;
  const TriangleMesh fine = finePlane(8.0, 160, 0.0);  // 51 200 triangles of 0.005 mm²
  const ObstacleSamples s = sampleObstacles({&fine, 1}, 1.0, Weights::Area);
  const double area = 256.0;
  EXPECT_NEAR(s.area_mm2, area, 1e-9 * area);
  double total = 0.0;
  for (std::size_t j = 0; j < s.size(); ++j) {
    total += s.weights[j];
    EXPECT_NEAR(s.normals[j].z(), 1.0, 1e-12);
  }
  EXPECT_NEAR(total, area, 1e-9 * area);
  EXPECT_LE(s.size(), 2.0 * area);  // 256 cells of 1 mm² (was 51 200 samples)
  EXPECT_GE(s.size(), area);
  const DirectField direct(s, p);
  for (double d : {1.0, 1.5, 2.0, 3.0, 4.0, 4.5}) {
    const Vec3 x(0.3, -0.2, d);
    const double exact = planeFieldMagnitude(d, p);
    EXPECT_NEAR(direct.at(x).z(), exact, 0.02 * exact) << d;  // as the coarse plane above
  }
  // A sheet 0.3 mm thick, both faces fine and in the same layer of cells: its faces are not
  // merged into each other (their normals would cancel): the force points away on each side.
  std::vector<TriangleMesh> sheet{finePlane(8.0, 160, 0.65), finePlane(8.0, 160, 0.35, true)};
  const ObstacleSamples both = sampleObstacles(sheet, 1.0, Weights::Area);
  std::size_t up = 0, down = 0;
  for (const Vec3& n : both.normals) (n.z() > 0.999 ? up : n.z() < -0.999 ? down : up) += 1;
  EXPECT_EQ(up + down, both.size());
  EXPECT_GE(up, std::size_t{256});
  EXPECT_GE(down, std::size_t{256});
  const DirectField sheet_field(both, p);
  for (double d : {0.5, 1.0, 2.0}) {
    EXPECT_GT(sheet_field.at(Vec3(0.3, -0.2, 0.65 + d)).z(), 0.0) << d;
    EXPECT_LT(sheet_field.at(Vec3(0.3, -0.2, 0.35 - d)).z(), 0.0) << d;
  }
}

// A cylinder R 1.5 tessellated finer than the step (128 x 100 facets): its merged samples keep
// the field radial and even around it, 1 mm off, against the same mesh sampled every 0.05 mm (no
// merging there). Merged across 90 deg sectors they swung it 2.7 deg and by 12 % (at 0.3 mm off,
// 17.8 deg: a reviewer's case).
TEST(Sampling, AFineCurvedSurfaceKeepsItsFieldRadial) {
  FieldParams p;
  TriangleMesh cylinder;
  const int around = 128, rings = 100;
  for (int j = 0; j <= rings; ++j)
    for (int i = 0; i < around; ++i) {
      const double a = 2.0 * M_PI * i / around;
      cylinder.vertices.emplace_back(1.5 * std::cos(a), 1.5 * std::sin(a), 20.0 * j / rings);
    }
  for (int j = 0; j < rings; ++j)
    for (int i = 0; i < around; ++i) {
      const int a = j * around + i, b = j * around + (i + 1) % around;
      cylinder.triangles.push_back({a, b, b + around});
      cylinder.triangles.push_back({a, b + around, a + around});
    }
  const DirectField merged(sampleObstacles({&cylinder, 1}, 1.0, Weights::Area), p);
  const DirectField dense(sampleObstacles({&cylinder, 1}, 0.05, Weights::Area), p);
  for (int k = 0; k < 13; ++k) {
    const double a = 7.5 * k * M_PI / 180.0;
    const Vec3 radial(std::cos(a), std::sin(a), 0.0);
    const Vec3 x = 2.5 * radial + Vec3(0, 0, 10);
    const Vec3 f = merged.at(x), exact = dense.at(x);
    EXPECT_NEAR(f.norm(), exact.norm(), 0.05 * exact.norm()) << k;
    EXPECT_GT(f.normalized().dot(radial), std::cos(2.0 * M_PI / 180.0)) << k;
  }
}

TEST(Law, InsideAnObstacleTheForceIsFiniteAndOutward) {
  FieldParams p;
  const TriangleMesh cube = test::box(Vec3(-5, -5, -5), Vec3(5, 5, 5));
  const ObstacleSamples samples = sampleObstacles({&cube, 1}, 0.5, Weights::Area);
  const DirectField direct(samples, p);
  const BruteForceField brute(samples, p);
  for (double depth : {1e-6, 0.1, 0.3, 1.0, 2.0}) {
    const Vec3 x(0.4, -0.3, 5.0 - depth);  // below the top face
    const Vec3 f = direct.at(x);
    ASSERT_TRUE(f.allFinite()) << depth;
    EXPECT_GT(f.z(), 0.9 * f.norm()) << depth;
    EXPECT_GT(f.norm(), 0.0) << depth;
    EXPECT_LT((brute.at(x) - f).norm(), 1e-12 * f.norm()) << depth;
  }
  // Deeper than r_min the field is mirrored out of the wall: even in the height.
  for (double depth : {0.3, 1.0, 2.0}) {
    const Vec3 in = direct.at(Vec3(0.4, -0.3, 5.0 - depth)),
               out = direct.at(Vec3(0.4, -0.3, 5.0 + depth));
    EXPECT_LT((in - out).norm(), 1e-12 * out.norm()) << depth;
  }
  // Continuous across the surface: just inside and just outside agree.
  const Vec3 in = direct.at(Vec3(0.4, -0.3, 5.0 - 1e-7)),
             out = direct.at(Vec3(0.4, -0.3, 5.0 + 1e-7));
  EXPECT_LT((in - out).norm(), 1e-4 * out.norm());
  // Exactly on a sample point: finite and along the outward normal.
  for (std::size_t j = 0; j < samples.size(); j += 97) {
    const Vec3 f = direct.at(samples.points_mm[j]);
    ASSERT_TRUE(f.allFinite());
    EXPECT_GT(f.dot(samples.normals[j]), 0.0);
  }
}

TEST(Law, DirectEqualsBruteForceInParallel) {
  FieldParams p;
  const TriangleMesh a = test::box(Vec3(-6, -6, -4), Vec3(-2, 6, 4));
  const TriangleMesh b = test::box(Vec3(2, -6, -4), Vec3(6, 6, 4));
  const std::vector<TriangleMesh> walls{a, b};
  const ObstacleSamples samples = sampleObstacles(walls, 1.0, Weights::Unit);
  const DirectField direct(samples, p);
  const BruteForceField brute(samples, p);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-10.0, 10.0);
  std::vector<Vec3> x(5000);
  for (auto& v : x) v = Vec3(u(rng), u(rng), u(rng));
  std::vector<Vec3> fd(x.size()), fb(x.size());
  direct.evaluate(x, fd);
  brute.evaluate(x, fb);
  for (std::size_t i = 0; i < x.size(); ++i) {
    ASSERT_TRUE(fd[i].allFinite());
    EXPECT_LT((fd[i] - fb[i]).norm(), 1e-9 * (1.0 + fb[i].norm())) << i;
    if (i % 500 == 0) EXPECT_EQ(direct.at(x[i]), fd[i]);  // one at a time = batched
  }
}

TEST(Law, BadParametersAreInputErrors) {
  const ObstacleSamples s = onePoint(Vec3::Zero(), Vec3::UnitZ(), 1.0);
  auto with = [](auto change) {
    FieldParams p;
    change(p);
    return p;
  };
  using fieldpath::common::InputError;
  EXPECT_THROW(DirectField(s, with([](FieldParams& p) { p.r0_mm = -1; })), InputError);
  EXPECT_THROW(DirectField(s, with([](FieldParams& p) { p.r_min_mm = 5; })), InputError);
  EXPECT_THROW(DirectField(s, with([](FieldParams& p) { p.voxel.voxel_size_mm = 0; })), InputError);
}
