/// The sparse voxel field against the direct one: equal at the nodes, trilinear error of order 2,
/// quadratic more accurate, finite outward force inside, the memory refusal, the .vdb output.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/field/metrics.h"
#include "fieldpath/field/voxel_field.h"
#include "meshes.h"

using namespace fieldpath::field;
using fieldpath::geometry::TriangleMesh;

namespace {

DirectField cubeField(const FieldParams& p) {
  const TriangleMesh cube = test::box(Vec3(-5, -5, -5), Vec3(5, 5, 5));
  return DirectField(sampleObstacles({&cube, 1}, 1.0, Weights::Area), p);
}

VoxelRequest request(double h, Interpolation interpolation = Interpolation::Trilinear) {
  VoxelRequest r;
  r.voxel_size_mm = h;
  r.interpolation = interpolation;
  return r;
}

std::vector<Vec3> evaluate(const ForceField& field, const std::vector<Vec3>& x) {
  std::vector<Vec3> f(x.size());
  field.evaluate(x, f);
  return f;
}

}  // namespace

TEST(Voxel, EqualsDirectAtTheNodes) {
  const FieldParams p;
  const DirectField direct = cubeField(p);
  for (auto interpolation : {Interpolation::Trilinear, Interpolation::Quadratic}) {
    const VoxelField voxel(direct, request(0.5, interpolation));
    const std::vector<Vec3> nodes = voxel.activeNodes();
    ASSERT_EQ(nodes.size(), voxel.stats().active_nodes);
    const std::vector<Vec3> fv = evaluate(voxel, nodes), fd = evaluate(direct, nodes);
    std::size_t nonzero = 0;
    for (std::size_t i = 0; i < nodes.size(); ++i) {
      ASSERT_LE((fv[i] - fd[i]).norm(), 2e-6 * fd[i].norm() + 1e-12) << nodes[i].transpose();
      nonzero += fd[i].norm() > 0.0;
    }
    EXPECT_GT(nonzero, nodes.size() * 9 / 10);
  }
}

TEST(Voxel, SparseBandAndEstimate) {
  const FieldParams p;
  const DirectField direct = cubeField(p);
  const VoxelField voxel(direct, request(0.5));
  const VoxelStats& s = voxel.stats();
  // Outside band: the cube grown by r0 (rounded corners) minus the cube shrunk by the inside band.
  const double band_in = 2 * 0.5 + p.r_min_mm;
  const double outer = 1000.0 + 600.0 * 5 + 3 * M_PI * 10 * 25 + 4.0 / 3.0 * M_PI * 125;
  const double inner = std::pow(10.0 - 2 * band_in, 3);
  const double expected_nodes = (outer - inner) / 0.125;
  EXPECT_NEAR(double(s.active_nodes), expected_nodes, 0.1 * expected_nodes);
  EXPECT_GE(s.estimated_nodes, s.active_nodes);
  EXPECT_GE(s.dense_box_nodes, s.active_nodes);
  EXPECT_GT(s.memory_bytes, s.active_nodes * 12);
  EXPECT_EQ(estimateVoxelNodes(direct.samples(), p, request(0.5)), s.estimated_nodes);
  // Beyond r0 of every sample: zero (background), never built.
  EXPECT_EQ(voxel.at(Vec3(0, 0, 5 + p.r0_mm + 1.0)), Vec3::Zero());
}

TEST(Voxel, RefusesBeyondTheMemoryLimitWithTheEstimate) {
  const DirectField direct = cubeField(FieldParams{});
  VoxelRequest r = request(0.01);
  r.max_memory_bytes = std::size_t{1} << 30;
  try {
    VoxelField voxel(direct, r);
    FAIL() << "expected a refusal";
  } catch (const fieldpath::common::InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("estimated"), std::string::npos) << what;
    EXPECT_NE(what.find(std::to_string(estimateVoxelNodes(direct.samples(), FieldParams{}, r))),
              std::string::npos)
        << what;
  }
  EXPECT_THROW(VoxelField(direct, request(0.0)), fieldpath::common::InputError);
  VoxelRequest tiny = request(1e-9);  // index coordinates beyond 32 bits
  tiny.max_memory_bytes = std::size_t(-1);
  EXPECT_THROW(VoxelField(direct, tiny), fieldpath::common::InputError);
  EXPECT_THROW(VoxelField(direct, request(-1.0)), fieldpath::common::InputError);
}

TEST(Voxel, TrilinearErrorIsOfOrderTwoAndQuadraticIsMoreAccurate) {
  // One sample (the closed form), r0 large and the points 12-16 mm away so that no interpolation
  // cell reaches r_min or r0 (where φ has kinks); only a region around the points is built.
  FieldParams p;
  p.r0_mm = 60.0;
  ObstacleSamples one;
  one.add(Vec3::Zero(), Vec3::UnitZ(), 1.0);
  const DirectField direct(one, p);
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Vec3> x(2000);
  for (auto& v : x) v = Vec3(8.2, 0.6, 11.4) + Vec3(u(rng), u(rng), u(rng));
  const std::vector<Vec3> exact = evaluate(direct, x);
  double previous = 0.0;
  for (double h : {2.0, 1.0, 0.5, 0.25}) {
    VoxelRequest r = request(h);
    r.region_mm = Eigen::AlignedBox3d(Vec3(8.2, 0.6, 11.4) - Vec3::Constant(1 + 2 * h),
                                      Vec3(8.2, 0.6, 11.4) + Vec3::Constant(1 + 2 * h));
    const VoxelField trilinear(direct, r);
    r.interpolation = Interpolation::Quadratic;
    const VoxelField quadratic(direct, r);
    const FieldError et = relativeError(evaluate(trilinear, x), exact, 0.0);
    const FieldError eq = relativeError(evaluate(quadratic, x), exact, 0.0);
    ASSERT_EQ(et.count, x.size());
    EXPECT_LT(eq.max_relative, 0.5 * et.max_relative) << h;
    EXPECT_LT(eq.rms_relative, 0.5 * et.rms_relative) << h;
    if (previous > 0.0) {
      const double order = std::log2(previous / et.max_relative);
      EXPECT_GT(order, 1.7) << h;
      EXPECT_LT(order, 2.3) << h;
    }
    previous = et.max_relative;
  }
}

TEST(Voxel, NodeInsideAnObstacleIsPushedOut) {
  const FieldParams p;
  const DirectField direct = cubeField(p);
  for (auto interpolation : {Interpolation::Trilinear, Interpolation::Quadratic}) {
    const VoxelField voxel(direct, request(0.5, interpolation));
    for (double depth : {0.0, 0.1, 0.3, 0.6, 1.0}) {
      for (const Vec3& dir : {Vec3(0, 0, 1), Vec3(1, 0, 0), Vec3(0, -1, 0)}) {
        const Vec3 x = (5.0 - depth) * dir + 0.37 * dir.unitOrthogonal();
        const Vec3 f = voxel.at(x);
        ASSERT_TRUE(f.allFinite()) << depth;
        EXPECT_GT(f.dot(dir), 0.8 * f.norm()) << depth << " " << dir.transpose();
        EXPECT_GT(f.norm(), 0.1 * direct.at(x).norm()) << depth;
      }
    }
  }
}

TEST(Voxel, SavesAVdbFile) {
  const DirectField direct = cubeField(FieldParams{});
  const VoxelField voxel(direct, request(1.0));
  const auto file = std::filesystem::temp_directory_path() / "fieldpath_test_field.vdb";
  voxel.save(file);
  std::ifstream in(file, std::ios::binary);
  char magic[4] = {};
  in.read(magic, 4);  // OPENVDB_MAGIC 0x56444220, little-endian: " BDV"
  EXPECT_EQ(std::string(magic, 4), std::string(" BDV"));
  EXPECT_GT(std::filesystem::file_size(file), voxel.stats().active_nodes * 12 / 2);
  EXPECT_FALSE(std::filesystem::exists(file.string() + ".tmp"));
  std::filesystem::remove(file);
}

TEST(Voxel, NoObstacleGivesAZeroField) {
  const DirectField direct(ObstacleSamples{}, FieldParams{});
  const VoxelField voxel(direct, request(0.5));
  EXPECT_EQ(voxel.stats().active_nodes, 0u);
  EXPECT_EQ(voxel.stats().estimated_nodes, 0u);
  EXPECT_EQ(direct.at(Vec3(1, 2, 3)), Vec3::Zero());
  EXPECT_EQ(voxel.at(Vec3(1, 2, 3)), Vec3::Zero());
}
