/// The voxel builds against each other: the CPU block build (field.backend: cpu) and the CUDA
/// build give the per-node reference build's node values (FieldBackend::Reference) to 1e-6
/// relative, on a plane (whose plane-ratio closed form the nodes also meet) and on the
/// impeller's blades, uniform and refined.
#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/field/law.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/impeller.h"
#include "meshes.h"

using namespace fieldpath::field;

namespace {

using Key = std::tuple<int, long, long, long>;  // level, node index

std::map<Key, StoredNode> byNode(const VoxelField& field) {
  std::map<Key, StoredNode> out;
  const double h = field.voxelSizeMm();
  for (const StoredNode& n : field.storedNodes()) {
    const double hl = std::ldexp(h, -n.level);
    out[{n.level, std::lround(n.x_mm.x() / hl), std::lround(n.x_mm.y() / hl),
         std::lround(n.x_mm.z() / hl)}] = n;
  }
  return out;
}

/// The same active nodes, values to 1e-6 relative (of the larger, floored at 1e-6 of the
/// largest value of the grid), closeness to 1e-5 mm, the same over/under flags; at most
/// `ties` nodes may differ (a node equidistant from two samples may take either as its
/// nearest: the reference takes the first the point index lists).
void expectSameNodes(const VoxelField& expected, const VoxelField& actual, std::size_t ties = 0) {
  const auto a = byNode(expected), b = byNode(actual);
  ASSERT_EQ(a.size(), b.size());
  double largest = 0.0;
  for (const auto& [key, n] : a) largest = std::max(largest, n.value.norm());
  std::size_t differ = 0, compared = 0;
  double worst = 0.0;
  for (const auto& [key, n] : a) {
    const auto it = b.find(key);
    ASSERT_NE(it, b.end()) << "node missing at " << n.x_mm.transpose();
    const StoredNode& m = it->second;
    const double scale = std::max({n.value.norm(), m.value.norm(), 1e-6 * largest});
    const double error = (n.value - m.value).norm() / scale;
    worst = std::max(worst, error);
    ++compared;
    if (error > 1e-6 || std::abs(n.closeness_mm - m.closeness_mm) > 1e-5 || n.over != m.over)
      ++differ;
  }
  EXPECT_LE(differ, ties) << "of " << compared << " nodes; worst relative error " << worst;
}

VoxelRequest requestOn(double h, FieldBackend backend, StoredQuantity stored,
                       double tolerance = 0) {
  VoxelRequest r;
  r.voxel_size_mm = h;
  r.stored = stored;
  r.backend = backend;
  r.refine_tolerance = tolerance;
  return r;
}

DirectField impellerField(double step_mm) {
  const fieldpath::pathgen::Impeller impeller{fieldpath::pathgen::ImpellerParams{}};
  const auto blades = fieldpath::pathgen::bladeMeshes(impeller);
  FieldParams p;
  p.sample_step_mm = step_mm;
  return DirectField(sampleObstacles(blades, step_mm, Weights::Area), p);
}

}  // namespace

TEST(VoxelBuild, BlockBuildEqualsTheReferenceOnAPlaneAndMeetsItsClosedForm) {
  const auto plane = test::squarePlane(20.0);
  FieldParams p;
  const DirectField direct(sampleObstacles({&plane, 1}, 0.5, Weights::Area), p);
  for (const StoredQuantity stored : {StoredQuantity::PlaneRatio, StoredQuantity::Force})
    for (const double h : {1.0, 0.5}) {
      SCOPED_TRACE(h);
      const VoxelField reference(direct, requestOn(h, FieldBackend::Reference, stored));
      const VoxelField block(direct, requestOn(h, FieldBackend::Cpu, stored));
      EXPECT_EQ(block.stats().backend, "cpu");
      EXPECT_EQ(reference.stats().backend, "reference");
      // Regular samples: nodes over the middle of a sample grid's cell tie; both take the
      // lowest index, but r² rounds differently in the lanes and in Eigen (5 of 31 k nodes).
      expectSameNodes(reference, block, reference.stats().active_nodes / 5000);
      if (stored != StoredQuantity::PlaneRatio) continue;
      // The closed form: over the middle of the plane, 1-4 mm up, s is the height and G the
      // normal (P(s)·G is the plane's field; the sampled plane departs from it by < 1e-3).
      const PlaneLaw law(p);
      for (const StoredNode& n : block.storedNodes()) {
        const Vec3& x = n.x_mm;
        if (std::abs(x.x()) > 5 || std::abs(x.y()) > 5 || x.z() < 1 || x.z() > 4) continue;
        const double s = p.r0_mm - n.closeness_mm;
        EXPECT_NEAR(s, x.z(), 2e-3 * x.z()) << x.transpose();
        EXPECT_NEAR(n.value.z(), 1.0, 2e-3) << x.transpose();
      }
    }
}

TEST(VoxelBuild, BlockBuildEqualsTheReferenceOnTheImpellerUniformAndRefined) {
  const DirectField direct = impellerField(1.0);
  {
    const VoxelField reference(direct, requestOn(1.0, FieldBackend::Reference,
                                                 StoredQuantity::PlaneRatio));
    const VoxelField block(direct, requestOn(1.0, FieldBackend::Cpu, StoredQuantity::PlaneRatio));
    expectSameNodes(reference, block, reference.stats().active_nodes / 10000);
  }
  {
    const VoxelField reference(
        direct, requestOn(1.0, FieldBackend::Reference, StoredQuantity::PlaneRatio, 0.02));
    const VoxelField block(direct,
                           requestOn(1.0, FieldBackend::Cpu, StoredQuantity::PlaneRatio, 0.02));
    EXPECT_GT(reference.stats().levels, 1);
    EXPECT_EQ(reference.stats().refined_cells, block.stats().refined_cells);
    expectSameNodes(reference, block, reference.stats().active_nodes / 10000);
  }
}

TEST(VoxelBuild, BlockBuildEqualsTheReferenceOnRandomScenes) {
  // Shapes no example has, for the block build's rounds (nodes lifted off their leaf's box,
  // sums answered from the cell list, shells, nodes inside closed boxes): random boxes and
  // loose triangles, r0, r_min, sample step and voxel size drawn at random; both stored
  // quantities, uniform and refined. Fixed seed: the same scenes every run.
  std::mt19937 rng(20261125);
  auto uniform = [&](double lo, double hi) {
    return std::uniform_real_distribution<double>(lo, hi)(rng);
  };
  for (int scene = 0; scene < 12; ++scene) {
    std::vector<fieldpath::geometry::TriangleMesh> meshes;
    const int boxes = 1 + scene % 3;
    for (int b = 0; b < boxes; ++b) {
      const Vec3 lo(uniform(-6, 4), uniform(-6, 4), uniform(-6, 4));
      meshes.push_back(test::box(lo, lo + Vec3(uniform(0.5, 5), uniform(0.5, 5), uniform(0.5, 5))));
    }
    fieldpath::geometry::TriangleMesh loose;  // open triangles, either way round
    for (int t = 0; t < 3; ++t) {
      const int first = static_cast<int>(loose.vertices.size());
      for (int v = 0; v < 3; ++v)
        loose.vertices.emplace_back(uniform(-8, 8), uniform(-8, 8), uniform(-8, 8));
      loose.triangles.emplace_back(first, first + 1, first + 2);
    }
    meshes.push_back(loose);
    FieldParams p;
    p.r0_mm = uniform(1.5, 5.0);
    p.r_min_mm = uniform(0.05, 0.3 * p.r0_mm);
    p.sample_step_mm = uniform(0.4, 1.2);
    p.gain = scene % 2 ? 1.0 : 2.5;
    const DirectField direct(sampleObstacles(meshes, p.sample_step_mm, Weights::Area), p);
    const double h = uniform(0.4, 1.2);
    const StoredQuantity stored = scene % 2 ? StoredQuantity::Force : StoredQuantity::PlaneRatio;
    const double tolerance = scene % 6 >= 4 && stored == StoredQuantity::PlaneRatio ? 0.05 : 0.0;
    SCOPED_TRACE("scene " + std::to_string(scene) + ": r0 " + std::to_string(p.r0_mm) + ", r_min " +
                 std::to_string(p.r_min_mm) + ", step " + std::to_string(p.sample_step_mm) +
                 ", h " + std::to_string(h));
    const VoxelField reference(direct, requestOn(h, FieldBackend::Reference, stored, tolerance));
    const VoxelField block(direct, requestOn(h, FieldBackend::Cpu, stored, tolerance));
    EXPECT_GT(reference.stats().active_nodes, 100u);
    expectSameNodes(reference, block, reference.stats().active_nodes / 10000);
  }
}

TEST(VoxelBuild, AVoxelSizePastR0IsRefusedNamingTheKey) {
  const auto plane = test::squarePlane(10.0);
  FieldParams p;  // r0 5 mm
  const DirectField direct(sampleObstacles({&plane, 1}, 1.0, Weights::Area), p);
  EXPECT_GT(VoxelField(direct, requestOn(5.0, FieldBackend::Cpu, StoredQuantity::PlaneRatio))
                .stats()
                .active_nodes,
            0u);
  try {
    (void)VoxelField(direct, requestOn(10.0, FieldBackend::Cpu, StoredQuantity::PlaneRatio));
    ADD_FAILURE() << "a 10 mm grid was built for a field that ends 5 mm from the surface";
  } catch (const fieldpath::common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("field.voxel_size"), std::string::npos) << e.what();
  }
}

TEST(VoxelBuild, CudaBuildEqualsTheCpuBuild) {
  if (!cudaFieldBackendAvailable()) GTEST_SKIP() << "no CUDA build or no GPU here";
  const DirectField direct = impellerField(1.0);
  for (const double tolerance : {0.0, 0.02}) {
    const VoxelField cpu(direct,
                         requestOn(0.5, FieldBackend::Cpu, StoredQuantity::PlaneRatio, tolerance));
    const VoxelField cuda(
        direct, requestOn(0.5, FieldBackend::Cuda, StoredQuantity::PlaneRatio, tolerance));
    EXPECT_EQ(cuda.stats().backend, "cuda");
    expectSameNodes(cpu, cuda, cpu.stats().active_nodes / 10000);
  }
  // The thin-wall rule's search (its far faces uploaded with the samples).
  const auto plate = test::plateSampledApart(20.0, 0.2);
  const DirectField thin(sampleObstacles({&plate, 1}, 1.0, Weights::Area), FieldParams{});
  const VoxelField cpu(thin, requestOn(0.2, FieldBackend::Cpu, StoredQuantity::PlaneRatio));
  const VoxelField cuda(thin, requestOn(0.2, FieldBackend::Cuda, StoredQuantity::PlaneRatio));
  expectSameNodes(cpu, cuda, cpu.stats().active_nodes / 10000);
}

TEST(VoxelBuild, BesideAThinPlateTheBuildsAgreeAndPushOut) {
  // A 0.2 mm plate whose faces are sampled apart (every 1 mm): beside a face the nearest sample
  // may be the other face's; law.h's thin-wall rule reads such a node as outside, in the
  // reference, the block build's replay and (above) the CUDA kernel alike. At h 0.2 (the
  // plate's thickness: a node layer on each face) the field interpolated 0.02-0.5 mm off either
  // face points away from the plate (before the rule, nodes on the top face read inside through
  // the bottom's samples: -7 at 0.02 mm over it).
  const auto plate = test::plateSampledApart(20.0, 0.2);
  const DirectField direct(sampleObstacles({&plate, 1}, 1.0, Weights::Area), FieldParams{});
  for (const StoredQuantity stored : {StoredQuantity::PlaneRatio, StoredQuantity::Force}) {
    const VoxelField reference(direct, requestOn(0.2, FieldBackend::Reference, stored));
    const VoxelField block(direct, requestOn(0.2, FieldBackend::Cpu, stored));
    expectSameNodes(reference, block, reference.stats().active_nodes / 5000);
    if (stored != StoredQuantity::PlaneRatio) continue;
    for (double x = 3.0; x <= 17.0; x += 0.37)
      for (double y = 3.0; y <= 17.0; y += 0.41)
        for (const double off : {0.02, 0.1, 0.5}) {
          EXPECT_GT(block.at(Vec3(x, y, 0.2 + off)).z(), 0.0) << x << " " << y << " +" << off;
          EXPECT_LT(block.at(Vec3(x, y, -off)).z(), 0.0) << x << " " << y << " -" << off;
        }
  }
}

TEST(VoxelBuild, CudaBackendIsRefusedWithoutAGpu) {
  if (cudaFieldBackendAvailable()) GTEST_SKIP() << "a GPU is here";
  const auto plane = test::squarePlane(5.0);
  const DirectField direct(sampleObstacles({&plane, 1}, 1.0, Weights::Area), FieldParams{});
  EXPECT_THROW(VoxelField(direct, requestOn(1.0, FieldBackend::Cuda, StoredQuantity::PlaneRatio)),
               fieldpath::common::InputError);
  EXPECT_EQ(VoxelField(direct, requestOn(1.0, FieldBackend::Auto, StoredQuantity::PlaneRatio))
                .stats()
                .backend,
            "cpu");
}
