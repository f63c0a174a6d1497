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

using fieldpath::test::npyFloats;

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

// A path that cuts nothing says why and what to give (a newcomer's raster on a floor read "0
// lines touched" without a word): with the default stock (the highest tip) and with --part, whose
// advice names --stock instead of --part (the two exclude each other); a cut says nothing.
TEST(CliSimulate, APathThatCutsNothingSaysWhy) {
  const TempDir dir;
  dir.write("flat.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0 1\n");
  geometry::TriangleMesh floor;
  floor.vertices = {{-10, -10, 0}, {10, -10, 0}, {10, 10, 0}, {-10, 10, 0}};
  floor.triangles = {{0, 1, 2}, {0, 2, 3}};
  geometry::saveMesh(floor, dir.path() / "floor.stl");
  const Outcome stock =
      runFieldpath(dir, "simulate --tool ball:2 --path flat.cl --grid 20x20 --out a");
  ASSERT_EQ(stock.exit_code, 0) << stock.err;
  EXPECT_NE(stock.err.find("warning: no line was cut"), std::string::npos) << stock.err;
  EXPECT_NE(stock.err.find("the stock at the highest tip"), std::string::npos) << stock.err;
  const Outcome part = runFieldpath(
      dir, "simulate --tool ball:2 --path flat.cl --grid 20x20 --part floor.stl --out b");
  ASSERT_EQ(part.exit_code, 0) << part.err;
  EXPECT_NE(part.err.find("--stock Z above the path's lowest tips instead of --part"),
            std::string::npos)
      << part.err;
  const Outcome cut =
      runFieldpath(dir, "simulate --tool ball:2 --path flat.cl --grid 20x20 --stock 1 --out c");
  ASSERT_EQ(cut.exit_code, 0) << cut.err;
  EXPECT_EQ(cut.err.find("no line was cut"), std::string::npos) << cut.err;
  // From the part's top, a path 0.01 mm into it cuts few of the lines (its gouge): said, with the
  // way to see the cusps (a CAM engineer's raster changed 0.2 % of them, unsaid); 4 % is few.
  dir.write("dip.cl", "0 0 -0.01 0 0 1\n1 0 -0.01 0 0 1\n2 0 -0.01 0 0 1\n");
  const Outcome dip = runFieldpath(
      dir, "simulate --tool ball:2 --path dip.cl --grid 100x100 --part floor.stl --out d");
  ASSERT_EQ(dip.exit_code, 0) << dip.err;
  EXPECT_NE(dip.err.find("of the lines were cut: the heights start on --part's top"),
            std::string::npos)
      << dip.err;
  const Outcome deep =
      runFieldpath(dir, "simulate --tool ball:2 --path flat.cl --grid 20x20 --stock 1 --out e");
  EXPECT_EQ(deep.err.find("heights start on"), std::string::npos) << deep.err;
}

// A tool mesh wound inward (each triangle the other way round) cut nothing with a vertical axis
// (its downward faces were its top); turned outward with a note, it cuts as the same mesh wound
// outward, bit for bit. So does one with every other facet flipped (still closed: it cut 77 034
// of 262 144 lines up to 0.98 mm too high, without a word) and one with triangles of no area
// written into it (refused as non-manifold where the same file as an obstacle was read).
TEST(CliSimulate, AToolMeshWoundInwardOrMixedOrWithSliversCutsAsWoundOutward) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n0.5 0 0 0.3 0 0.953939\n");
  ASSERT_EQ(runFieldpath(dir, "tool --shape ball:2:8 --out outward.stl").exit_code, 0);
  const geometry::TriangleMesh outward = geometry::loadMesh(dir.path() / "outward.stl");
  geometry::TriangleMesh inward = outward, mixed = outward, slivers = outward;
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  for (std::size_t i = 0; i < mixed.triangles.size(); i += 2)
    std::swap(mixed.triangles[i][1], mixed.triangles[i][2]);
  for (std::size_t i = 0; i < outward.triangles.size(); i += 7) {
    const Eigen::Vector3i& t = outward.triangles[i];
    slivers.triangles.emplace_back(t[0], t[1], t[0]);
  }
  geometry::saveMesh(inward, dir.path() / "inward.stl");
  geometry::saveMesh(mixed, dir.path() / "mixed.stl");
  geometry::saveMesh(slivers, dir.path() / "slivers.stl");
  const char* tools[] = {"outward.stl", "inward.stl", "mixed.stl", "slivers.stl"};
  const char* notes[] = {nullptr, "wound inward", "facets turned", "triangles of no area"};
  std::string heights[4];
  for (int k = 0; k < 4; ++k) {
    const Outcome run = runFieldpath(dir, std::string("simulate --tool ") + tools[k] +
                                              " --path path.cl --grid 41x41 "
                                              "--region -2.05,-2.05,2.55,2.05 --stock 5 "
                                              "--backend cpu --out o" +
                                              std::to_string(k));
    ASSERT_EQ(run.exit_code, 0) << tools[k] << ": " << run.err;
    if (notes[k]) EXPECT_NE(run.err.find(notes[k]), std::string::npos) << run.err;
    heights[k] = slurp(dir.path() / ("o" + std::to_string(k)) / "heights.npy");
  }
  const std::vector<float> h = npyFloats(heights[0]);
  ASSERT_EQ(h.size(), 41u * 41u);
  EXPECT_LT(*std::min_element(h.begin(), h.end()), 0.01f);  // it cuts down to the tip
  for (int k = 1; k < 4; ++k) EXPECT_EQ(heights[0], heights[k]) << tools[k];
}

// The default region holds the whole cut of a tilted tool. A ball R 3 along x, its axis a tilted
// 45° towards +y, stock 2 mm over the tips: the shank's points A(t) + R u, u = (0, c, -c), c =
// cos 45°, lie below z = 2 while c t <= 2 + R c, so the cut reaches y = 2 + 2 R c = 2 + 3√2 =
// 6.24 mm. The region was the tips' range + R (y up to 3): the cut beyond was not in the heights.
TEST(CliSimulate, TheDefaultRegionHoldsATiltedShanksCut) {
  const TempDir dir;
  const double c = std::sqrt(0.5);
  std::string path;
  for (int k = 0; k <= 100; ++k)
    path +=
        std::to_string(0.1 * k) + " 0 0 0 " + std::to_string(c) + " " + std::to_string(c) + "\n";
  dir.write("t45.cl", path);
  const Outcome run = runFieldpath(
      dir,
      "simulate --tool ball:3:20 --path t45.cl --grid 200x400 --stock 2 --backend cpu --out o");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const std::string json = slurp(dir.path() / "o" / "heights.json");
  const std::vector<float> h = npyFloats(slurp(dir.path() / "o" / "heights.npy"));
  ASSERT_EQ(h.size(), 200u * 400u);
  // origin and spacing from heights.json: "origin": [x0, y0], "spacing": [dx, dy]
  auto pair = [&](const char* key) {
    const std::size_t at = json.find(key);
    EXPECT_NE(at, std::string::npos) << json;
    double a = 0, b = 0;
    std::sscanf(json.c_str() + json.find('[', at), "[%lf,%lf", &a, &b);
    return std::pair{a, b};
  };
  const auto [x0, y0] = pair("\"origin\"");
  const auto [dx, dy] = pair("\"spacing\"");
  double cut_y_max = -1e9, y_max = y0 + 399 * dy;
  for (int iy = 0; iy < 400; ++iy)
    for (int ix = 0; ix < 200; ++ix)
      if (h[static_cast<std::size_t>(iy) * 200 + ix] < 2.0f - 1e-5f)
        cut_y_max = std::max(cut_y_max, y0 + iy * dy);
  EXPECT_NEAR(cut_y_max, 2.0 + 3.0 * std::sqrt(2.0), 2 * dy);  // 6.24 mm, reached
  EXPECT_GT(y_max, cut_y_max + 0.5);  // and stock left beyond it: the whole cut is in
  EXPECT_NEAR(x0, -3.0, 1e-9);
}

// The Z-buffer cuts in floats: 9e5 mm from the origin they step by 0.0625 mm, coarser than a
// 0.05 mm grid, and the heights are that far off (a raster there cut 37.6 um off its cut at the
// origin: a helper's finding; the note said heights.npy held them exactly). Said whatever the
// outputs; near the origin no note.
TEST(CliSimulate, ASurfaceStlFarFromTheOriginIsSaidToBeCoarse) {
  const TempDir dir;
  dir.write("far.cl", "900000 0 0 0 0 1\n");
  dir.write("near.cl", "0 0 0 0 0 1\n");
  const Outcome far =
      runFieldpath(dir, "simulate --tool ball:2 --path far.cl --grid 20x20 --stock 1 --out far");
  ASSERT_EQ(far.exit_code, 0) << far.err;
  EXPECT_NE(far.err.find("note: the path and the grid lie up to 9e+05 mm from the origin; the "
                         "Z-buffer cuts in single precision, in steps of 0.062 mm there"),
            std::string::npos)
      << far.err;
  const Outcome near =
      runFieldpath(dir, "simulate --tool ball:2 --path near.cl --grid 20x20 --stock 1 --out near");
  ASSERT_EQ(near.exit_code, 0) << near.err;
  EXPECT_EQ(near.err.find("note:"), std::string::npos) << near.err;
  // Without surface.stl, the same: the heights themselves are the floats'.
  const Outcome npy_only = runFieldpath(
      dir, "simulate --tool ball:2 --path far.cl --grid 20x20 --stock 1 --outputs npy --out npy");
  ASSERT_EQ(npy_only.exit_code, 0) << npy_only.err;
  EXPECT_NE(npy_only.err.find("note: the path and the grid lie up to 9e+05 mm"), std::string::npos)
      << npy_only.err;
  // Into a folder of an earlier run with every output: those not written now are removed (a
  // folder never mixes two runs: `view --surface` read the earlier heights.png's run).
  const Outcome again = runFieldpath(
      dir, "simulate --tool ball:2 --path far.cl --grid 20x20 --stock 1 --outputs npy --out near");
  ASSERT_EQ(again.exit_code, 0) << again.err;
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "near/heights.npy"));
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "near/heights.json"));  // its grid, with it
  for (const char* stale : {"surface.stl", "heights.png"})
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "near" / stale)) << stale;
  // One line each way is a profile: heights, yes; a surface (STL) of no triangles, no.
  EXPECT_EQ(runFieldpath(dir,
                         "simulate --tool ball:2 --path near.cl --grid 1x1 --stock 1 "
                         "--outputs npy --out one")
                .exit_code,
            0);
  const Outcome stl =
      runFieldpath(dir, "simulate --tool ball:2 --path near.cl --grid 1x1 --stock 1 --out one");
  EXPECT_EQ(stl.exit_code, 1) << stl.err;
  EXPECT_NE(stl.err.find("surface.stl needs 2 lines each way"), std::string::npos) << stl.err;
}

// A tool under a shelf of --part (a plate, and a shelf 8 mm over it): the Z-buffer keeps each
// line's lowest cut, so the surface shows the shelf cut through there; said (a helper's
// mushroom: its cap read cut from 30 to 12.6 mm, silently). A pass clear of the shelf: no word.
TEST(CliSimulate, ACutBeneathAnOverhangOfThePartIsSaid) {
  const TempDir dir;
  const std::string plate = boxStl(-10, -15, -5, 30, 15, 0), shelf = boxStl(-10, 5, 8, 30, 15, 10);
  const auto body = [](const std::string& solid) {  // between `solid box` and `endsolid`
    const std::size_t from = solid.find('\n') + 1;
    return solid.substr(from, solid.rfind("endsolid") - from);
  };
  dir.write("part.stl", "solid part\n" + body(plate) + body(shelf) + "endsolid part\n");
  const double tilt = 60.0 * M_PI / 180.0, ay = -std::sin(tilt), az = std::cos(tilt);
  const auto pass = [&](double centre_y) {  // the ball's centre at z 3 (on the plate), tilted 60°
    std::string cl = "# pass 1\n";
    for (int i = 0; i <= 40; ++i)
      cl += std::to_string(0.5 * i) + ' ' + std::to_string(centre_y - 3.0 * ay) + ' ' +
            std::to_string(3.0 - 3.0 * az) + " 0 " + std::to_string(ay) + ' ' + std::to_string(az) +
            '\n';
    return cl;
  };
  dir.write("under.cl", pass(6.0));
  dir.write("open.cl", pass(-8.0));
  const std::string args = "simulate --tool ball:3:40 --grid 200x200 --part part.stl --out ";
  const Outcome under = runFieldpath(dir, args + "u --path under.cl");
  ASSERT_EQ(under.exit_code, 0) << under.output();
  EXPECT_NE(under.err.find("lines were cut beneath the top layer of --part"), std::string::npos)
      << under.err;
  const Outcome clear = runFieldpath(dir, args + "o --path open.cl");
  ASSERT_EQ(clear.exit_code, 0) << clear.output();
  EXPECT_EQ(clear.err.find("beneath the top layer"), std::string::npos) << clear.err;
}

TEST(CliSimulate, BadInputIsExitOneWithOneLineAndNoOutputs) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n");
  // An open tool mesh (a square sheet: an open tool cut nothing).
  dir.write("open_tool.stl", squareStl(2, 1));
  for (const std::string args :
       {"--tool cone:2", "--tool ball:2 --grid 0x10", "--tool ball:2 --region 1,2,3",
        "--tool ball:2 --backend gpu", "--tool missing.stl", "--tool open_tool.stl",
        "--tool ball:2 --block 0", "--tool ball:2 --outputs npy,png,npy"}) {
    const Outcome run = runFieldpath(dir, "simulate " + args + " --path path.cl --out out");
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << args << ": " << run.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "out")) << args;
  }
  // A shape without its sizes is said to be one (it read as a missing mesh file).
  const Outcome bare = runFieldpath(dir, "simulate --tool torus --path path.cl --out out");
  EXPECT_EQ(bare.exit_code, 1);
  EXPECT_NE(bare.err.find("--tool torus: the shape needs its sizes: torus:R:r[:L]"),
            std::string::npos)
      << bare.err;
}

// The spindle angle (a .cl's 7th column) turns a mesh tool about its own axis before it is placed
// (README): a flat blade 3 mm along +x turned by pi/2 cuts what the blade along +y cuts, 6
// columns (the heights to float rounding), and not what the unturned blade cuts. (A test audit:
// the 7th column never reached a simulation in any test.)
TEST(CliSimulate, TheSpindleAngleTurnsAMeshToolAboutItsAxis) {
  const TempDir dir;
  dir.write("blade_x.stl", boxStl(0, -0.3, 0, 3, 0.3, 5));
  dir.write("blade_y.stl", boxStl(-0.3, 0, 0, 0.3, 3, 5));
  dir.write("turned.cl", "0 0 0 0 0 1 1.5707963267948966\n0.01 0 0 0 0 1 1.5707963267948966\n");
  dir.write("plain.cl", "0 0 0 0 0 1\n0.01 0 0 0 0 1\n");
  const std::string common = " --region -4,-4,4,4 --grid 64x64 --stock 1 --outputs npy";
  const auto heights = [&](const std::string& tool, const std::string& path) {
    const Outcome run =
        runFieldpath(dir, "simulate --tool " + tool + " --path " + path + common + " --out o");
    EXPECT_EQ(run.exit_code, 0) << run.output();
    return npyFloats(slurp(dir.path() / "o" / "heights.npy"));
  };
  const std::vector<float> turned = heights("blade_x.stl", "turned.cl");
  const std::vector<float> along_y = heights("blade_y.stl", "plain.cl");
  const std::vector<float> along_x = heights("blade_x.stl", "plain.cl");
  ASSERT_EQ(turned.size(), 64u * 64u);
  ASSERT_EQ(along_y.size(), turned.size());
  std::size_t cut = 0, differs = 0;
  for (std::size_t i = 0; i < turned.size(); ++i) {
    EXPECT_NEAR(turned[i], along_y[i], 1e-4) << i;
    cut += turned[i] < 0.5f;
    differs += std::abs(turned[i] - along_x[i]) > 0.5f;
  }
  EXPECT_GT(cut, 20u);
  EXPECT_GT(differs, 20u);
}

}  // namespace
}  // namespace fieldpath::app::test
