/// The refined voxel field: where it splits, what it gains, continuity across levels, its
/// settings (split out of test_voxel.cpp).
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/field/law.h"
#include "fieldpath/field/metrics.h"
#include "fieldpath/field/voxel_field.h"
#include "meshes.h"
#include "voxel_requests.h"

using namespace fieldpath::field;
using namespace fieldpath::field::test;
using fieldpath::geometry::TriangleMesh;

namespace {

/// Points around the cube, `lo` to `hi` mm off its surface.
std::vector<Vec3> aroundCube(std::size_t count, double lo, double hi, unsigned seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> u(-5.0 - hi, 5.0 + hi);
  std::vector<Vec3> x;
  while (x.size() < count) {
    const Vec3 v(u(rng), u(rng), u(rng));
    const double off = (v.cwiseAbs().array() - 5.0).max(0.0).matrix().norm();
    if (off >= lo && off <= hi) x.push_back(v);
  }
  return x;
}

VoxelRequest refined(double h, double tolerance, int levels,
                     StoredQuantity stored = StoredQuantity::PlaneRatio) {
  VoxelRequest r = request(h, Interpolation::Trilinear, stored);
  r.refine_tolerance = tolerance;
  r.refine_levels = levels;
  return r;
}

}  // namespace

/// The cube sampled every 0.5 mm: its field is smooth from about 1 mm off (the samples' ripple
/// decays like exp(-2π d / step)), so what remains is the grid's own error.
DirectField fineCubeField(const FieldParams& p) {
  const TriangleMesh cube = test::box(Vec3(-5, -5, -5), Vec3(5, 5, 5));
  return DirectField(sampleObstacles({&cube, 1}, 0.5, Weights::Area), p);
}

TEST(VoxelRefinement, SplitsWhereTheGridMissesAndComesCloseToItsFinestSize) {
  // Around the cube (faces, edges, corners) 1 to 3.5 mm off: a 2 mm grid refined down to 0.5 mm
  // against the direct field, beside the uniform 2 mm and 0.5 mm grids. The faces are planes
  // (exact for the plane ratio at any size), so the splits follow the edges and corners: fewer
  // nodes than the uniform 0.5 mm grid for an error close to it; a lower tolerance is better.
  FieldParams p;
  p.sample_step_mm = 0.5;
  const DirectField direct = fineCubeField(p);
  const std::vector<Vec3> x = aroundCube(3000, 1.0, 3.5, 21);
  const std::vector<Vec3> exact = evaluate(direct, x);
  auto errorOf = [&](const VoxelRequest& r, VoxelStats* stats) {
    const VoxelField voxel(direct, r);
    if (stats) *stats = voxel.stats();
    return relativeErrorAboveFloor(evaluate(voxel, x), exact, 0.01);
  };
  VoxelStats coarse_stats, fine_stats, refined_stats, tighter_stats;
  const FieldError coarse = errorOf(request(2.0), &coarse_stats);
  const FieldError fine = errorOf(request(0.5), &fine_stats);
  const FieldError one = errorOf(refined(2.0, 0.02, 1), nullptr);
  const FieldError two = errorOf(refined(2.0, 0.02, 2), &refined_stats);
  const FieldError tighter = errorOf(refined(2.0, 0.005, 2), &tighter_stats);
  std::printf(
      "cube, max / RMS relative error: 2 mm %.4f / %.5f (%zu nodes); refined at 2 %% to "
      "1 mm %.4f, to 0.5 mm %.4f / %.5f (%zu nodes, %zu cells split); at 0.5 %% to 0.5 "
      "mm %.4f (%zu nodes); uniform 0.5 mm %.4f / %.5f (%zu nodes)\n",
      coarse.max_relative, coarse.rms_relative, coarse_stats.active_nodes, one.max_relative,
      two.max_relative, two.rms_relative, refined_stats.active_nodes, refined_stats.refined_cells,
      tighter.max_relative, tighter_stats.active_nodes, fine.max_relative, fine.rms_relative,
      fine_stats.active_nodes);
  EXPECT_EQ(coarse_stats.levels, 1);
  EXPECT_EQ(coarse_stats.refined_nodes, 0u);
  EXPECT_EQ(refined_stats.levels, 3);
  EXPECT_GT(refined_stats.refined_cells, 0u);
  EXPECT_EQ(refined_stats.active_nodes, coarse_stats.active_nodes + refined_stats.refined_nodes);
  EXPECT_LT(refined_stats.active_nodes, fine_stats.active_nodes);
  EXPECT_LT(one.max_relative, 0.7 * coarse.max_relative);
  EXPECT_LT(two.max_relative, one.max_relative);
  EXPECT_LT(two.rms_relative, 0.5 * coarse.rms_relative);
  EXPECT_LT(tighter.max_relative, 1.5 * fine.max_relative);
  EXPECT_LE(tighter.max_relative, two.max_relative);
}

TEST(VoxelRefinement, NeverSplitsACellWhollyInsideTheObstacle) {
  // Inside the cube the plane height s kinks where the nearest face changes (its medial
  // planes), which the estimate reads as curvature; a cell whose corners are all deeper than
  // half its diagonal lies inside the solid and is not split. So every refined node lies within
  // a split cell of the level above, one of whose built corners is above that depth: s >
  // -(√3/2 + √3) h_parent (s is 1-Lipschitz across the cell's diagonal). Outside, the
  // refinement is that of before (the same split around the edges and corners).
  FieldParams p;
  p.sample_step_mm = 0.5;
  const DirectField direct = fineCubeField(p);
  const VoxelField voxel(direct, refined(1.0, 0.005, 2));
  ASSERT_EQ(voxel.stats().levels, 3);
  std::size_t refined_outside = 0, refined_inside = 0;
  for (const StoredNode& n : voxel.storedNodes()) {
    if (n.level == 0) continue;
    const double s = p.r0_mm - n.closeness_mm;
    const double h_parent = std::ldexp(1.0, -(n.level - 1));
    (s > 0 ? refined_outside : refined_inside)++;
    if (n.over)
      EXPECT_GT(s, -1.5 * std::sqrt(3.0) * h_parent - 1e-3)
          << "refined node at " << n.x_mm.transpose() << ", level " << n.level;
  }
  EXPECT_GT(refined_outside, 1000u);
  // Cells that straddle the faces are split, so some refined nodes lie just inside.
  EXPECT_GT(refined_inside, 0u);
}

TEST(VoxelRefinement, TheFieldIsContinuousAcrossLevels) {
  // Lines over the top face of the cube and past its edge, 1 to 3 mm above the face, sampled
  // every 1 µm: refined (2 mm down to 0.5 mm at 5 %), the lines cross level boundaries. Hanging
  // nodes take the coarser level's value, so no step between neighbouring samples exceeds a few
  // times what the exact field's own slope gives (≈ 1.5e-3 per µm here), where a jump of a coarse
  // cell's error (up to about the tolerance) would.
  FieldParams p;
  p.sample_step_mm = 0.5;
  const DirectField direct = fineCubeField(p);
  const VoxelField voxel(direct, refined(2.0, 0.05, 2));
  ASSERT_GT(voxel.stats().refined_cells, 0u);
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double step_mm = 1e-3;
  double worst_step = 0.0, worst_exact_step = 0.0;
  for (int line = 0; line < 60; ++line) {
    // Along x from over the top face to past its edge at x = 5, 1 to 3 mm above the face.
    const Vec3 start(1.0, 4.0 * u(rng), 7.0 + 0.9 * u(rng));
    const Vec3 dir = Vec3(1.0, 0.1 * u(rng), 0.05 * u(rng)).normalized();
    std::vector<Vec3> x;
    for (int i = 0; i <= 7000; ++i) x.push_back(start + (i * step_mm) * dir);
    const std::vector<Vec3> fv = evaluate(voxel, x), fd = evaluate(direct, x);
    for (std::size_t i = 0; i + 1 < x.size(); ++i) {
      const double scale = std::max(fd[i].norm(), 0.01 * planeFieldMagnitude(1.0, p));
      worst_step = std::max(worst_step, (fv[i + 1] - fv[i]).norm() / scale);
      worst_exact_step = std::max(worst_exact_step, (fd[i + 1] - fd[i]).norm() / scale);
    }
  }
  std::printf(
      "largest relative step between samples 1 µm apart: refined voxels %.2e, direct "
      "%.2e\n",
      worst_step, worst_exact_step);
  EXPECT_LT(worst_step, 3 * worst_exact_step);
}

TEST(VoxelRefinement, RefusesQuadraticAndBadSettings) {
  const DirectField direct = cubeField(FieldParams{});
  VoxelRequest quadratic = refined(1.0, 0.01, 2);
  quadratic.interpolation = Interpolation::Quadratic;
  EXPECT_THROW(VoxelField(direct, quadratic), fieldpath::common::InputError);
  EXPECT_THROW(VoxelField(direct, refined(1.0, -0.01, 2)), fieldpath::common::InputError);
  EXPECT_THROW(VoxelField(direct, refined(1.0, 0.01, 7)), fieldpath::common::InputError);
  // A tolerance of 0 is a uniform grid.
  EXPECT_EQ(VoxelField(direct, refined(1.0, 0.0, 2)).stats().levels, 1);
}

TEST(VoxelRefinement, RefiningAUniformLevelZeroIsTheRefinedBuild) {
  // A job steers on the uniform grid first, then refines that grid (pathgen): its nodes, every
  // level, are those of the refined build made at once; a grid of another size is refused.
  FieldParams p;
  p.sample_step_mm = 0.5;
  const DirectField direct = fineCubeField(p);
  const VoxelRequest r = refined(2.0, 0.02, 2);
  const VoxelField at_once(direct, r);
  VoxelField uniform(direct, levelZeroRequest(r, p.r_min_mm));
  EXPECT_EQ(uniform.stats().levels, 1);
  // The job has read some of its blocks (filled then), not all: the refinement fills the rest.
  const std::vector<Vec3> read = {Vec3(0, 0, 6), Vec3(6, 0, 0), Vec3(0, -7, 0)};
  EXPECT_GT(evaluate(uniform, read)[0].norm(), 0.0);
  const VoxelField from_uniform(direct, r, std::move(uniform));
  const std::vector<StoredNode> a = at_once.storedNodes(), b = from_uniform.storedNodes();
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(from_uniform.stats().levels, 3);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a[i].x_mm, b[i].x_mm) << i;
    ASSERT_EQ(a[i].level, b[i].level) << i;
    ASSERT_EQ(a[i].value, b[i].value) << i;
    ASSERT_EQ(a[i].closeness_mm, b[i].closeness_mm) << i;
  }
  // Without the refined build's near band the uniform grid's level 0 differs: the helper is
  // what makes them equal (and a grid of another voxel size is refused outright).
  VoxelRequest plain = r;
  plain.refine_tolerance = 0.0;
  const VoxelField from_plain(direct, r, VoxelField(direct, plain));
  const std::vector<StoredNode> c = from_plain.storedNodes();
  std::size_t differ = 0;
  for (std::size_t i = 0; i < std::min(a.size(), c.size()); ++i)
    differ += a[i].level == 0 && !(a[i].value == c[i].value);
  EXPECT_GT(differ, 0u);
  VoxelField other(direct, request(1.0));
  EXPECT_THROW(VoxelField(direct, r, std::move(other)), std::invalid_argument);
}
