/// CellMask: the cells of points grown into cubes (core and outer), against a brute-force
/// Chebyshev distance.
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/field/cell_mask.h"

using namespace fieldpath::field;

TEST(CellMask, CubesAroundThePointsCellsAsABruteForceSays) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 12; ++i) points.emplace_back(u(rng), u(rng), 0.5 * u(rng));
  const double cell = 0.5, core_mm = 0.5, outer_mm = 1.25;  // 1 and 3 cells
  const CellMask mask(points, cell, core_mm, outer_mm);
  ASSERT_EQ(mask.cellMm(), cell);
  std::size_t core_hits = 0, outer_hits = 0;
  std::uniform_real_distribution<double> q(-2.0, 12.0);
  for (int k = 0; k < 20000; ++k) {
    const Vec3 x(q(rng), q(rng), q(rng) * 0.5);
    // The mask's grid starts at the points' box less whole cells (the dilation's 3 and one):
    // cells are aligned to it; compare away from a cell face.
    const Vec3 lo = [&] {
      Vec3 m = points[0];
      for (const Vec3& p : points) m = m.cwiseMin(p);
      return Vec3(m.array() - 4 * cell);
    }();
    bool aligned = true;
    for (int a = 0; a < 3; ++a) {
      const double f = (x[a] - lo[a]) / cell;
      aligned &= std::abs(f - std::round(f)) > 1e-9;
    }
    if (!aligned) continue;
    // Brute force: the query's cell against each point's cell, in whole cells (Chebyshev).
    double own = 1e9;
    for (const Vec3& p : points) {
      double d = 0;
      for (int a = 0; a < 3; ++a)
        d = std::max(
            d, std::abs(std::floor((x[a] - lo[a]) / cell) - std::floor((p[a] - lo[a]) / cell)));
      own = std::min(own, d);
    }
    EXPECT_EQ(mask.inCore(x), own <= 1) << x.transpose();
    EXPECT_EQ(mask.contains(x), own <= 3) << x.transpose();
    core_hits += mask.inCore(x);
    outer_hits += mask.contains(x);
  }
  EXPECT_GT(core_hits, 50u);
  EXPECT_GT(outer_hits, 2 * core_hits);
  EXPECT_GT(mask.cells(), mask.coreCells());
  // Only the relevant box is masked: a point beyond it marks nothing, and beyond it every point
  // counts as inside (nothing is refined there, the voxels are exact).
  const Eigen::AlignedBox3d relevant(Vec3(-1, -1, -1), Vec3(5, 11, 6));
  const CellMask clipped(points, cell, core_mm, outer_mm, relevant);
  EXPECT_TRUE(clipped.inCore(Vec3(8, 5, 2)));  // beyond the box
  EXPECT_LT(clipped.cells(), mask.cells());
  for (const Vec3& p : points)
    EXPECT_EQ(clipped.inCore(p), true) << p.transpose();  // marked inside, or beyond the box
  // No point, no cell; bad sizes refused.
  EXPECT_FALSE(CellMask({}, 1.0, 1.0, 2.0).contains(Vec3::Zero()));
  EXPECT_THROW(CellMask(points, 0.0, 1.0, 2.0), std::invalid_argument);
  EXPECT_THROW(CellMask(points, 1.0, 2.0, 1.0), std::invalid_argument);
}
