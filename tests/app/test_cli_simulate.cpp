/// `fieldpath simulate`, run as a program: one vertical ball posture cuts a spherical dimple whose
/// depth is the exact sphere; lines out of the tool's reach keep the stock; bad input → exit 1.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/geometry/mesh_io.h"
#include "files.h"

namespace fieldpath::app::test {
namespace {

/// The float32 data of a version-1 .npy file (the header is checked by the zbuffer tests).
std::vector<float> npyFloats(const std::string& bytes) {
  if (bytes.size() < 10) return {};
  const std::size_t header =
      static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  const std::size_t start = 10 + header;
  std::vector<float> data((bytes.size() - start) / sizeof(float));
  std::memcpy(data.data(), bytes.data() + start, data.size() * sizeof(float));
  return data;
}

TEST(CliSimulate, BallDimpleIsTheExactSphere) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n");
  // 41 × 41 lines 0.1 mm apart, centred on the tip: line (ix, iy) at (-2 + 0.1 ix, -2 + 0.1 iy).
  const Outcome run =
      runFieldpath(dir,
                   "simulate --tool ball:2:8 --path path.cl --grid 41x41 "
                   "--region -2.05,-2.05,2.05,2.05 --stock 5 --backend cpu --out out");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::vector<float> h = npyFloats(slurp(dir.path() / "out" / "heights.npy"));
  ASSERT_EQ(h.size(), 41u * 41u);
  const double radius_mm = 2.0;
  int inside = 0;
  for (int iy = 0; iy < 41; ++iy) {
    for (int ix = 0; ix < 41; ++ix) {
      const double x = -2.0 + 0.1 * ix, y = -2.0 + 0.1 * iy, r = std::hypot(x, y);
      const float z = h[static_cast<std::size_t>(iy) * 41 + ix];
      if (r < 1.9) {
        // Ball centre at (0, 0, R): the lowest point of the sphere over (x, y).
        EXPECT_NEAR(z, radius_mm - std::sqrt(radius_mm * radius_mm - r * r), 1e-4)
            << x << ", " << y;
        ++inside;
      } else if (r > 2.01) {
        EXPECT_EQ(z, 5.0f) << x << ", " << y;  // out of reach: the stock
      }
    }
  }
  EXPECT_GT(inside, 1000);
  for (const char* file : {"heights.json", "surface.stl", "heights.png"})
    EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / file)) << file;
}

// A tool mesh wound inward (each triangle the other way round) cut nothing with a vertical axis
// (its downward faces were its top); turned outward with a note, it cuts as the same mesh wound
// outward, bit for bit.
TEST(CliSimulate, AToolMeshWoundInwardCutsAsWoundOutward) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n0.5 0 0 0.3 0 0.953939\n");
  ASSERT_EQ(runFieldpath(dir, "tool --shape ball:2:8 --out outward.stl").exit_code, 0);
  geometry::TriangleMesh mesh = geometry::loadMesh(dir.path() / "outward.stl");
  for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  geometry::saveMesh(mesh, dir.path() / "inward.stl");
  std::string heights[2];
  for (int k = 0; k < 2; ++k) {
    const std::string tool = k == 0 ? "outward.stl" : "inward.stl";
    const Outcome run = runFieldpath(dir, "simulate --tool " + tool + " --path path.cl --grid 41x41 "
                                     "--region -2.05,-2.05,2.55,2.05 --stock 5 --backend cpu --out o" +
                                     std::to_string(k));
    ASSERT_EQ(run.exit_code, 0) << run.err;
    EXPECT_EQ(run.err.find("wound inward") != std::string::npos, k == 1) << run.err;
    heights[k] = slurp(dir.path() / ("o" + std::to_string(k)) / "heights.npy");
  }
  const std::vector<float> h = npyFloats(heights[0]);
  ASSERT_EQ(h.size(), 41u * 41u);
  EXPECT_LT(*std::min_element(h.begin(), h.end()), 0.01f);  // it cuts down to the tip
  EXPECT_EQ(heights[0], heights[1]);
}

TEST(CliSimulate, BadInputIsExitOneWithOneLineAndNoOutputs) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n");
  // An open tool mesh (a square sheet: an open tool cut nothing).
  dir.write("open_tool.stl", squareStl(2, 1));
  for (const std::string args :
       {"--tool cone:2", "--tool ball:2 --grid 0x10", "--tool ball:2 --region 1,2,3",
        "--tool ball:2 --backend gpu", "--tool missing.stl", "--tool open_tool.stl"}) {
    const Outcome run = runFieldpath(dir, "simulate " + args + " --path path.cl --out out");
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << args << ": " << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out")) << args;
  }
}

}  // namespace
}  // namespace fieldpath::app::test
