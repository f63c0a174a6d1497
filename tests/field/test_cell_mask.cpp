/// CellMask against what its users rely on, from a brute-force Chebyshev distance in mm: every
/// point within core_mm (outer_mm) of a marked point is in the core (the mask), and nothing is
/// more than a cell beyond those distances (the rounding to whole cells, wherever the cells
/// are aligned).
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/field/cell_mask.h"

using namespace fieldpath::field;

namespace {

double chebyshevToNearest(const std::vector<Vec3>& points, const Vec3& x) {
  double nearest = HUGE_VAL;
  for (const Vec3& p : points) nearest = std::min(nearest, (x - p).cwiseAbs().maxCoeff());
  return nearest;
}

}  // namespace

TEST(CellMask, CoversItsDistancesAndNoMoreThanACellBeyond) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 10.0);
  std::vector<Vec3> points;
  for (int i = 0; i < 12; ++i) points.emplace_back(u(rng), u(rng), 0.5 * u(rng));
  const double cell = 0.5, core_mm = 0.5, outer_mm = 1.25;
  const CellMask mask(points, cell, core_mm, outer_mm);
  ASSERT_EQ(mask.cellMm(), cell);
  std::size_t core_hits = 0, outer_hits = 0;
  std::uniform_real_distribution<double> q(-2.0, 12.0);
  for (int k = 0; k < 20000; ++k) {
    const Vec3 x(q(rng), q(rng), q(rng) * 0.5);
    const double d = chebyshevToNearest(points, x);
    if (d <= core_mm) EXPECT_TRUE(mask.inCore(x)) << x.transpose() << " at " << d;
    if (d <= outer_mm) EXPECT_TRUE(mask.contains(x)) << x.transpose() << " at " << d;
    // Whole cells: the core reaches ceil(0.5 / 0.5) = 1 cell, the mask ceil(1.25 / 0.5) = 3
    // cells around a marked one, so never further than one more cell in mm.
    if (mask.inCore(x)) EXPECT_LT(d, (1 + 1) * cell) << x.transpose();
    if (mask.contains(x)) EXPECT_LT(d, (3 + 1) * cell) << x.transpose();
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
  for (const Vec3& p : points) EXPECT_TRUE(clipped.inCore(p)) << p.transpose();
  // No point, no cell; bad sizes refused.
  EXPECT_FALSE(CellMask({}, 1.0, 1.0, 2.0).contains(Vec3::Zero()));
  EXPECT_THROW(CellMask(points, 0.0, 1.0, 2.0), std::invalid_argument);
  EXPECT_THROW(CellMask(points, 1.0, 2.0, 1.0), std::invalid_argument);
}
