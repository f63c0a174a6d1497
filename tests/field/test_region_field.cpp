/// RegionField: voxels built in a box answer inside it (with their stencil), the exact field
/// outside; without it the voxels would give zero next to a wall the box left out.
#include <random>

#include <gtest/gtest.h>

#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/region_field.h"
#include "fieldpath/field/voxel_field.h"
#include "meshes.h"

using namespace fieldpath::field;

TEST(RegionField, VoxelsInsideTheRegionTheExactFieldOutside) {
  const FieldParams p;
  const auto cube = test::box(Vec3(-5, -5, -5), Vec3(5, 5, 5));
  const DirectField direct(sampleObstacles({&cube, 1}, 1.0, Weights::Area), p);
  const double h = 0.5;
  VoxelRequest request;
  request.voxel_size_mm = h;
  // Voxels on the -x side of the cube only (what a reach box around a pass there would give).
  request.region_mm = Eigen::AlignedBox3d(Vec3(-11, -11, -11), Vec3(-2, 11, 11));
  const VoxelField voxels(direct, request);
  Eigen::AlignedBox3d valid = *request.region_mm;
  valid.min().array() += 2 * h;
  valid.max().array() -= 2 * h;
  const RegionField field(voxels, direct, valid);

  // Points around the whole cube, 0.5 to 4 mm off its faces, in random order.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-9.0, 9.0);
  std::vector<Vec3> points;
  while (points.size() < 4000) {
    const Vec3 x(u(rng), u(rng), u(rng));
    const double out = (x.cwiseAbs().array() - 5.0).maxCoeff();
    if (out > 0.5 && out < 4.0) points.push_back(x);
  }
  std::vector<Vec3> f(points.size()), fv(points.size()), fd(points.size());
  field.evaluate(points, f);
  voxels.evaluate(points, fv);
  direct.evaluate(points, fd);
  std::size_t outside = 0, voxels_missed_a_wall = 0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (valid.contains(points[i])) {
      EXPECT_EQ(f[i], fv[i]) << "point " << i;
      continue;
    }
    ++outside;
    EXPECT_EQ(f[i], fd[i]) << "point " << i;
    voxels_missed_a_wall += fd[i].norm() > 0.0 && fv[i].norm() == 0.0;
  }
  EXPECT_EQ(field.outsidePoints(), outside);
  EXPECT_GT(outside, 1000u);
  EXPECT_GT(outside, points.size() - outside);  // both kinds, in one call
  // What the guard is for: beyond their box the voxels are zero where the walls push.
  EXPECT_GT(voxels_missed_a_wall, 500u);

  // A call all inside goes through to the voxels and counts nothing.
  const std::vector<Vec3> inside{Vec3(-6, 0, 0), Vec3(-7, 1, 2)};
  std::vector<Vec3> fi(2), fvi(2);
  field.evaluate(inside, fi);
  voxels.evaluate(inside, fvi);
  EXPECT_EQ(fi, fvi);
  EXPECT_EQ(field.outsidePoints(), outside);
}
