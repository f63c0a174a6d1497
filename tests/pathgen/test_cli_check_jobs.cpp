/// `check` on small parts through the built `fieldpath`, each against a closed form or an
/// independent count: a torus end mill's cusp and gouge, a scallop on a slope between the contact
/// lines, an open obstacle mesh (no inside: said), unsafe and under-the-clearance marks, the motion
/// between two postures cut, a shank driven into a wall of the part, passes beside the part, and
/// the same job high up in z.
#include <array>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_scenes.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using namespace fieldpath;
using test::TempDir;

// `check` with a torus end mill (it took ball-end mills only): two straight passes along x over a
// plate (top at z = 0), tips on it, 5 mm apart in y. Midway (2.5 mm from each axis) a torus R 3
// r 1 leaves its corner's height there, r - sqrt(r² - (2.5 - (R - r))²) = 134 um, and no gouge;
// the same passes 0.3 mm lower gouge 300 um. A flat end mill is refused.
TEST(CheckSurface, TorusEndMillsAreCheckedAgainstTheirClosedFormAndFlatOnesRefused) {
  const TempDir dir;
  geometry::TriangleMesh part, wall;
  pathgen::test::addBox(part, -10, 30, -15, 15, -5, 0);
  pathgen::test::addBox(wall, 60, 70, -10, 10, 0, 5);  // an obstacle far away (a scene needs one)
  geometry::saveMesh(part, dir.path() / "part.stl");
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  auto passes = [](double z) {
    std::ostringstream cl;
    cl << "# pass 1\n";
    for (int k = 0; k <= 40; ++k) cl << 0.5 * k << " -2.5 " << z << " 0 0 1\n";
    cl << "# link\n20 -2.5 5 0 0 1\n0 2.5 5 0 0 1\n# pass 2\n";
    for (int k = 0; k <= 40; ++k) cl << 0.5 * k << " 2.5 " << z << " 0 0 1\n";
    return cl.str();
  };
  dir.write("on.cl", passes(0.0));
  dir.write("low.cl", passes(-0.3));
  auto surface = [&](const std::string& tool, const std::string& path) {
    dir.write("scene.yaml", "obstacles:\n  - mesh: wall.stl\npart: part.stl\ntool: " + tool +
                                "\nclearance: 0.5\n");
    const std::string out = "out_" + std::to_string(std::hash<std::string>{}(tool + path));
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path " + path + " --spacing 0.02 --backend cpu --out " + out);
    EXPECT_EQ(r.exit_code, 0) << r.output();
    return nlohmann::json::parse(test::slurp(dir.path() / out / "check.json"))["surface"];
  };
  const std::string torus = "{ shape: torus, radius: 3, corner_radius: 1, length: 20 }";
  const std::string flat = "{ shape: flat, radius: 3, length: 20 }";
  const double scallop_um = 1000.0 * (1.0 - std::sqrt(1.0 - 0.5 * 0.5));
  // Lines within half a spacing of the midline: the corner's slope there 0.5 / sqrt(0.75).
  const double tolerance_um = 1000.0 * 0.01 * 0.5 / std::sqrt(0.75) + 1.0;
  const auto t = surface(torus, "on.cl");
  EXPECT_NEAR(t["max_scallop_um"].get<double>(), scallop_um, tolerance_um) << t;
  EXPECT_LT(t["max_gouge_um"].get<double>(), 0.5) << t;
  const auto low = surface(torus, "low.cl");
  EXPECT_NEAR(low["max_gouge_um"].get<double>(), 300.0, 1.0) << low;
  // A flat end is refused, naming the line of tool.shape: its sharp rim tilted 10 deg along the
  // feed left a 10 um ridge 9.8 um proud between the stamps (a helper's), read as 4.6 um.
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: part.stl\ntool: " + flat + "\nclearance: 0.5\n");
  const auto refused = test::runFieldpath(dir, "check scene.yaml --path on.cl --out flat_out");
  EXPECT_EQ(refused.exit_code, 1) << refused.output();
  EXPECT_NE(refused.err.find("scene.yaml:4: tool.shape: check proves ball and torus tools"),
            std::string::npos)
      << refused.err;
  EXPECT_FALSE(fs::exists(dir.path() / "flat_out"));
}

// The scallop statistics are taken between the passes' contact lines, not their ball centres: on
// the plane z = 0.1 x + 0.4 y a vertical ball R 3 on six passes along x, contact lines 1.2 mm
// apart in y, leaves R - sqrt(R² - d²/4) across the centre lines' spacing d (70.3 um normal to
// the plane, as check tells it; 76.1 um in z); the band of the centres, 1.1 mm downhill of the
// first contact line, took in the ball's flank over unmachined stock (232.7 um, a helper's
// finding).
TEST(CheckSurface, ScallopOnASlopeIsBetweenTheContactLines) {
  const TempDir dir;
  const double sx = 0.1, sy = 0.4, R = 3.0, p = 1.2;
  auto z = [&](double x, double y) { return sx * x + sy * y; };
  geometry::TriangleMesh plane, wall;
  for (const auto& [x, y] : {std::pair{-5.0, -5.0}, {25.0, -5.0}, {25.0, 15.0}, {-5.0, 15.0}})
    plane.vertices.emplace_back(x, y, z(x, y));
  plane.triangles = {{0, 1, 2}, {0, 2, 3}};
  pathgen::test::addBox(wall, 60, 70, 60, 70, 0, 10);  // far away (a scene needs an obstacle)
  geometry::saveMesh(plane, dir.path() / "plane.stl");
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  const Eigen::Vector3d n = Eigen::Vector3d(-sx, -sy, 1.0).normalized();
  std::ostringstream cl;
  cl.precision(12);
  for (int k = 0; k < 6; ++k) {
    if (k > 0) cl << "# link\n20 " << (k - 1) * p << " 20 0 0 1\n0 " << k * p << " 20 0 0 1\n";
    cl << "# pass " << k + 1 << "\n";
    for (int i = 0; i <= 40; ++i) {  // the ball centre R along the normal from its contact
      const Eigen::Vector3d c = Eigen::Vector3d(0.5 * i, k * p, z(0.5 * i, k * p)) + R * n;
      cl << c.x() << " " << c.y() << " " << c.z() - R << " 0 0 1\n";
    }
  }
  dir.write("slope.cl", cl.str());
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: plane.stl\n"
            "tool: { shape: ball, radius: 3, length: 20 }\nclearance: 0.5\n");
  const auto r = test::runFieldpath(
      dir, "check scene.yaml --path slope.cl --spacing 0.02 --backend cpu --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto surface =
      nlohmann::json::parse(test::slurp(dir.path() / "out" / "check.json"))["surface"];
  // The centre lines' spacing: the step (0, p, sy p) less its part along the passes (1, 0, sx).
  const Eigen::Vector3d along = Eigen::Vector3d(1, 0, sx).normalized(), step(0, p, sy * p);
  const double d = (step - step.dot(along) * along).norm();
  const double scallop_um = 1000.0 * (R - std::sqrt(R * R - 0.25 * d * d));
  // Lines within half a spacing of a cusp's ridge: the ball's slope there (d/2) / sqrt(R² - d²/4).
  const double tolerance_um = 1000.0 * 0.01 * 0.5 * d / std::sqrt(R * R - 0.25 * d * d) + 1.0;
  EXPECT_NEAR(surface["max_scallop_um"].get<double>(), scallop_um, tolerance_um) << surface;
  EXPECT_LT(surface["max_gouge_um"].get<double>(), 0.5) << surface;
}

namespace {

/// `check` of two upright postures 30 mm inside the 100 mm box of `mesh` (in `dir`), a ball R 3:
/// the run and its check.json.
std::pair<test::Outcome, nlohmann::json> checkInsideBox(const TempDir& dir,
                                                        const std::string& mesh) {
  dir.write("in.cl", "# pass 1\n0 0 -20 0 0 1\n1 0 -20 0 0 1\n");
  dir.write("scene.yaml", "obstacles:\n  - mesh: " + mesh +
                              "\ntool: { shape: ball, radius: 3, length: 20 }\nclearance: 0.5\n");
  const auto r = test::runFieldpath(dir, "check scene.yaml --path in.cl --out out_" + mesh);
  EXPECT_EQ(r.exit_code, 0) << r.output();
  const fs::path file = dir.path() / ("out_" + mesh) / "check.json";
  return {r, fs::exists(file) ? nlohmann::json::parse(test::slurp(file)) : nlohmann::json()};
}

/// A part of a floor and a wall (boxes x0 x1 y0 y1 z0 z1, mm) and an obstacle far away.
void writeFloorAndWall(const TempDir& dir, const std::array<double, 6>& floor,
                       const std::array<double, 6>& wall) {
  pathgen::test::writeBoxPartScene(dir, {floor, wall});
}

}  // namespace

// A block missing one facet is an open shell: no inside, so a tool buried in it reads as clear
// (FCL measures surfaces; only closed shells have an inside). Said, naming the file, by `check`
// and `generate` and in check.json `obstacle_notes` (it was silent: a helper's finding); the
// closed block makes the same postures colliding and gets no note.
TEST(CheckClearance, AnOpenObstacleMeshIsSaidToHaveNoInside) {
  const TempDir dir;
  geometry::TriangleMesh closed;
  pathgen::test::addBox(closed, -50, 50, -50, 50, -50, 50);
  geometry::TriangleMesh holed = closed;
  holed.triangles.pop_back();
  geometry::saveMesh(closed, dir.path() / "closed.stl");
  geometry::saveMesh(holed, dir.path() / "holed.stl");
  for (const std::string mesh : {"closed.stl", "holed.stl"}) {
    const auto [r, check] = checkInsideBox(dir, mesh);
    const bool open = mesh == "holed.stl";
    EXPECT_EQ(check["obstacle_notes"].size(), open ? 1u : 0u) << check["obstacle_notes"];
    EXPECT_EQ(
        r.err.find("holed.stl: 1 shell is open (3 edges with one triangle)") != std::string::npos,
        open)
        << r.err;
    EXPECT_EQ(check["clearance"]["colliding_postures"].get<int>(), open ? 0 : 2);
  }
}

// The same box as exported solids often come: a T-junction on its top (a face split at a point
// on an edge its neighbour keeps whole), or one facet wound the wrong way. Read as open, a tool
// wholly inside read clear ("ok": true: a helper's finding); mended (said), its inside counts.
TEST(CheckClearance, ABoxWithExportDefectsIsMendedAndItsInsideCounts) {
  const TempDir dir;
  geometry::TriangleMesh box;
  pathgen::test::addBox(box, -50, 50, -50, 50, -50, 50);
  // addBox's top face: the two triangles whose vertices all have z = 50.
  std::vector<int> top;
  for (int t = 0; t < int(box.triangles.size()); ++t)
    if ((box.triangles[t].unaryExpr([&](int v) {
          return box.vertices[v].z() == 50 ? 1 : 0;
        })).sum() == 3)
      top.push_back(t);
  ASSERT_EQ(top.size(), 2u);
  geometry::TriangleMesh flipped = box;
  std::swap(flipped.triangles[top[0]][1], flipped.triangles[top[0]][2]);
  // The T-junction: the first top triangle split at the middle of one of its edges, alone.
  geometry::TriangleMesh split = box;
  const Eigen::Vector3i t = split.triangles[top[0]];
  split.vertices.push_back(0.5 * (split.vertices[t[0]] + split.vertices[t[1]]));
  const int m = int(split.vertices.size()) - 1;
  split.triangles[top[0]] = Eigen::Vector3i(t[0], m, t[2]);
  split.triangles.emplace_back(m, t[1], t[2]);
  ASSERT_GT(geometry::validateMesh(split).open_edges, 0u);
  geometry::saveMesh(flipped, dir.path() / "flipped.stl");
  geometry::saveMesh(split, dir.path() / "split.stl");
  for (const std::string mesh : {"flipped.stl", "split.stl"}) {
    const auto [r, check] = checkInsideBox(dir, mesh);
    EXPECT_NE(r.err.find(mesh + ": mended as exported solids need"), std::string::npos) << r.err;
    EXPECT_EQ(check["obstacle_notes"].size(), 0u) << check["obstacle_notes"];
    EXPECT_EQ(check["clearance"]["colliding_postures"].get<int>(), 2) << mesh;
    EXPECT_FALSE(check["ok"].get<bool>()) << mesh;
  }
}

// A path that is unsafe for one reason and under the required clearance for another carries
// both marks: a pass started upright beside a wall 0.3 mm from its holder (start: nominal, damped
// for the spring alone) swings so far (tilt limit 89°) that the holder goes into the part: UNSAFE;
// the first posture keeps 0.29 mm from the wall: UNDER THE REQUIRED CLEARANCE too (only the first
// was said: a helper's finding). A block of the part at the pass's end, on the side away from the
// wall, meets the upright holder too: the nominal pass is no way out (a pass the steering drives
// into the part is written nominal where the nominal is clear).
TEST(CheckClearance, UnsafeAndUnderTheClearanceAreBothMarked) {
  const TempDir dir;
  geometry::TriangleMesh wall, part;
  pathgen::test::addBox(wall, -20, 120, 12.3, 14, -2, 60);  // 0.3 mm from the holder's r 12
  pathgen::test::addBox(part, -30, 130, -40, 40, -5, 0);
  pathgen::test::addBox(part, 95, 130, -40, -11.5, 0, 60);  // 0.5 mm into the upright holder
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  geometry::saveMesh(part, dir.path() / "part.stl");
  std::string cl = "# pass 1\n";
  for (int i = 0; i <= 100; ++i) cl += std::to_string(i) + " 0 0 0 0 1\n";
  dir.write("nominal.cl", cl);
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\n"
            "holder: [[40, 6], [55, 6], [55, 12], [90, 12]]\nclearance: 0.5\n"
            "dynamics: { max_tilt_deg: 89, start: nominal, damping: 2 }\n"  // the spring's
            "path: { nominal: nominal.cl }\n");  // critical alone: the swing rings (damping 2)
  const auto r = test::runFieldpath(dir, "generate scene.yaml --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out" / "report.json"));
  ASSERT_FALSE(report["unsafe"].empty()) << report["unsafe"];  // the holder into the part
  ASSERT_EQ(report["kept_nominal"].size(), 0u);
  ASSERT_EQ(report["clearance"]["colliding_postures"].get<int>(), 0);
  ASSERT_LT(report["clearance"]["min_mm"].get<double>(), 0.5);
  const std::string cl_out = test::slurp(dir.path() / "out" / "path.cl");
  const std::string apt = test::slurp(dir.path() / "out" / "path.apt");
  for (const std::string& text : {cl_out, apt}) {
    EXPECT_NE(text.find("UNSAFE TO RUN"), std::string::npos) << text.substr(0, 400);
    EXPECT_NE(text.find("UNDER THE REQUIRED CLEARANCE"), std::string::npos) << text.substr(0, 400);
  }
  EXPECT_NE(r.err.find("warning: UNSAFE TO RUN"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("closer to the obstacles than `clearance`"), std::string::npos) << r.err;
  EXPECT_EQ(geometry::readPathFile(dir.path() / "out" / "path.cl").warnings.size(), 2u);
  // --fail-unsafe: exit 3, the same marked files written (`generate && post` posted them).
  const auto strict = test::runFieldpath(dir, "generate scene.yaml --fail-unsafe --out strict");
  EXPECT_EQ(strict.exit_code, 3) << strict.output();
  EXPECT_EQ(test::slurp(dir.path() / "strict" / "path.apt"), apt);
}

// An unsafe reason says where its first posture lies: its block (the link into pass K) and, for a
// path read from a file, its line; generate adds which keys place its links. Two passes finishing
// a wall with the axis horizontal under a bar: the approach comes straight down through the bar
// (the reason said "posture 0 to the next", a user counted through path.cl to learn it was a
// link's, and not what moves one).
TEST(CheckClearance, AnUnsafeLinkIsNamedWithItsBlockAndTheKeysThatPlaceIt) {
  const TempDir dir;
  geometry::TriangleMesh bar, part;
  // (1 m wide: no move sideways of the link gets out from under it)
  pathgen::test::addBox(bar, 30, 200, -500, 500, 25, 30);
  pathgen::test::addBox(part, -60, -3, -50, 50, -20, 20);
  geometry::saveMesh(bar, dir.path() / "bar.stl");
  geometry::saveMesh(part, dir.path() / "part.stl");
  std::string cl = "# pass 1\n";
  for (int i = 0; i <= 10; ++i) cl += "-3 " + std::to_string(i) + " 0 1 0 0\n";
  cl += "# pass 2\n";
  for (int i = 10; i >= 0; --i) cl += "-3 " + std::to_string(i) + " 5 1 0 0\n";
  dir.write("nominal.cl", cl);
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: bar.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\n"
            "holder: [[40, 6], [55, 6], [55, 12], [90, 12]]\nclearance: 0.5\n"
            "path: { nominal: nominal.cl }\nlinks: { retract: 10 }\n");
  const auto r = test::runFieldpath(dir, "generate scene.yaml --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out" / "report.json"));
  ASSERT_EQ(report["unsafe"].size(), 1u) << report["unsafe"];
  const std::string reason = report["unsafe"][0].get<std::string>();
  // generate names the line of its path.cl, as check names the file it reads.
  const std::string line =
      std::to_string(geometry::readPathFile(dir.path() / "out/path.cl").lines[0]);
  EXPECT_NE(reason.find("(first: posture 0 to the next (the link into pass 1, path.cl:" + line +
                        "): generate's link: `links.retract`"),
            std::string::npos)
      << reason;
  // check reads the user's links: the block and the line, no keys of generate's.
  const auto c = test::runFieldpath(dir, "check scene.yaml --path out/path.cl --out chk");
  ASSERT_EQ(c.exit_code, 0) << c.output();
  const auto checked = nlohmann::json::parse(test::slurp(dir.path() / "chk" / "check.json"));
  EXPECT_NE(checked["unsafe"][0].get<std::string>().find(
                "(first: posture 0 to the next (the link into pass 1, out/path.cl:" + line + "))"),
            std::string::npos)
      << checked["unsafe"];
  EXPECT_EQ(checked["unsafe"][0].get<std::string>().find("links.retract"), std::string::npos);
}

// `check` cuts along the motions, not only at the postures: two postures on a floor either side
// of a ridge 1 mm high, each clear of it, and the straight move between them through the ridge.
// The gouge is the ridge's height (1000 um; 2 mm wide, no line is deeper from its sides, less the
// sweep's bound); the same postures with the move lifted over the ridge
// (up, across 0.5 mm above it, down) gouge nothing.
TEST(CheckSurface, TheMotionBetweenTwoPosturesIsCut) {
  const TempDir dir;
  geometry::TriangleMesh part, wall;
  pathgen::test::addBox(part, -10, 20, -10, 10, -5, 0);  // the floor, top at z = 0
  pathgen::test::addBox(part, 4, 6, -10, 10, 0, 1);      // the ridge
  pathgen::test::addBox(wall, 60, 70, -10, 10, 0, 5);    // an obstacle far away (a scene needs one)
  geometry::saveMesh(part, dir.path() / "part.stl");
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\nclearance: 0.5\n");
  dir.write("through.cl", "# pass 1\n0 0 0 0 0 1\n10 0 0 0 0 1\n");
  dir.write("over.cl", "# pass 1\n0 0 0 0 0 1\n0 0 1.5 0 0 1\n10 0 1.5 0 0 1\n10 0 0 0 0 1\n");
  auto gouge = [&](const std::string& path) {
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path " + path + " --spacing 0.1 --out out_" + path);
    EXPECT_EQ(r.exit_code, 0) << r.output();
    const auto check =
        nlohmann::json::parse(test::slurp(dir.path() / ("out_" + path) / "check.json"));
    return check["surface"];
  };
  const auto through = gouge("through.cl");
  EXPECT_GT(through["max_gouge_um"].get<double>(), 1000.0 - 10.0);
  EXPECT_LE(through["max_gouge_um"].get<double>(), 1000.0 + 1.0);
  EXPECT_GT(through["gouged_lines"].get<int>(), 100);
  EXPECT_GT(through["simulated_postures"].get<int>(), 50);  // 10 mm at <= 0.17 mm
  const auto over = gouge("over.cl");
  EXPECT_EQ(over["gouged_lines"].get<int>(), 0);
}

// A tilted tool's shank cuts beside the ball's footprint: a pass on a floor with the axis tilted
// 20° towards a wall of the part 7 mm off drives the shank ~4 mm into the wall. The Z-buffer's
// region reached only the balls (0 um of gouge); it now reaches the shank's plan up to the
// part's top. The same pass tilted away gouges nothing.
TEST(CheckSurface, AShankDrivenIntoAWallOfThePartIsAGouge) {
  const TempDir dir;
  writeFloorAndWall(dir, {-30, 7, -30, 30, -10, 0}, {8, 30, -30, 30, -10, 60});  // wall beside
  const double s = std::sin(20.0 * M_PI / 180.0), c = std::cos(20.0 * M_PI / 180.0);
  for (const double side : {1.0, -1.0}) {
    std::ostringstream path;
    path.precision(17);
    path << "# pass 1\n";
    // the ball resting on the floor: its centre at z = 3 over x = -1, the tip R below it
    for (int k = 0; k <= 40; ++k)
      path << -1 - 3 * side * s << ' ' << -5 + 0.25 * k << ' ' << 3 - 3 * c << ' ' << side * s
           << " 0 " << c << '\n';
    dir.write(side > 0 ? "towards.cl" : "away.cl", path.str());
  }
  std::map<std::string, std::string> said;  // stdout of each
  auto checked = [&](const std::string& name) {
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path " + name + ".cl --spacing 0.1 --out out_" + name);
    EXPECT_EQ(r.exit_code, 0) << r.output();
    said[name] = r.out;
    return nlohmann::json::parse(test::slurp(dir.path() / ("out_" + name) / "check.json"));
  };
  const auto towards = checked("towards"), away = checked("away");
  // The verdict is the last line (it was only in check.json), and a scene with no holder says
  // what is then not proven.
  EXPECT_NE(said["towards"].find(
                "check: NOT OK: " + towards["not_ok_because"][0].get<std::string>() + "; "),
            std::string::npos)
      << said["towards"];
  EXPECT_TRUE(said["away"].ends_with("check: ok\n")) << said["away"];
  EXPECT_NE(away["tool_notes"].dump().find("no `holder` in the scene"), std::string::npos)
      << away["tool_notes"];
  EXPECT_GT(towards["surface"]["max_gouge_um"].get<double>(), 3000.0);
  EXPECT_GT(towards["surface"]["gouged_lines"].get<int>(), 100);
  EXPECT_FALSE(towards["ok"].get<bool>());
  // The gouge said as the reasons: the cutter's exact entry, then the Z-buffer's lines.
  ASSERT_EQ(towards["not_ok_because"].size(), 2u) << towards["not_ok_because"];
  EXPECT_NE(towards["not_ok_because"][0].get<std::string>().find("the cutter enters the part"),
            std::string::npos);
  EXPECT_NE(towards["not_ok_because"][1].get<std::string>().find("below the part"),
            std::string::npos);
  EXPECT_EQ(towards["cutter_part"]["gouging_postures"].get<int>(), 41);
  // A gouge, not a crash: not in `unsafe` (a concave part's chordal error reads as one too).
  EXPECT_TRUE(towards["unsafe"].empty()) << towards["unsafe"];
  EXPECT_EQ(away["cutter_part"]["gouging_postures"].get<int>(), 0);
  EXPECT_EQ(away["surface"]["gouged_lines"].get<int>(), 0);
  EXPECT_TRUE(away["ok"].get<bool>()) << away["not_ok_because"];
}

// The shank above the flutes (L 20) and below a holder that starts at 40 does not cut: driven
// 1 mm into an overhang of the part at z 25..35 it is a crash, found by `check` and `generate`
// (it was neither the cutter's, which ends at L, nor the holder's: ok and safe, a reviewer's
// case). 1 mm clear of the overhang, the same pass is ok.
TEST(CheckClearance, TheShankAboveTheFlutesIntoAnOverhangIsUnsafe) {
  const TempDir dir;
  for (const double edge : {2.0, 4.0}) {
    // The overhang over the pass's middle only: the links at its ends, straight up, clear it.
    writeFloorAndWall(dir, {-30, 30, -30, 30, -10, 0}, {-2, 2, edge, 30, 25, 35});
    dir.write("scene.yaml",
              "obstacles:\n  - mesh: far.stl\npart: part.stl\n"
              "tool: { shape: ball, radius: 3, length: 20 }\nholder: [[40, 6], [90, 6]]\n"
              "clearance: 0.5\npath: { nominal: pass.cl }\n");
    std::ostringstream path;
    path << "# pass 1\n";
    for (int k = 0; k <= 32; ++k) path << -8 + 0.5 * k << " 0 0 0 0 1\n";
    dir.write("pass.cl", path.str());
    const std::string out = edge < 3.0 ? "into" : "clear";
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path pass.cl --spacing 0.1 --out " + out + "_check");
    EXPECT_EQ(r.exit_code, 0) << r.output();
    const auto check =
        nlohmann::json::parse(test::slurp(dir.path() / (out + "_check") / "check.json"));
    const auto g = test::runFieldpath(dir, "generate scene.yaml --nominal --out " + out + "_gen");
    EXPECT_EQ(g.exit_code, 0) << g.output();
    const auto report =
        nlohmann::json::parse(test::slurp(dir.path() / (out + "_gen") / "report.json"));
    if (edge < 3.0) {
      EXPECT_FALSE(check["ok"].get<bool>()) << check["holder_part"];
      EXPECT_FALSE(check["unsafe"].empty()) << check["holder_part"];
      EXPECT_FALSE(report["safe"].get<bool>()) << report["holder_part"];
    } else {
      EXPECT_TRUE(check["ok"].get<bool>()) << check["not_ok_because"];
      EXPECT_TRUE(report["safe"].get<bool>()) << report["unsafe"];
    }
  }
}

// A shank 0.3 mm into a vertical wall of the part gouges 0.3 mm (along the wall's normal), not
// the wall's height: lines on the wall's top cut 10 mm down by the shank read 10 mm (a helper's
// 7.4 mm for 0.03 mm). Read as the distance to the nearest uncut line: up to a spacing (0.05 mm)
// more, never less.
TEST(CheckSurface, AShankIntoAWallGougesItsDepthNotTheWallsHeight) {
  const TempDir dir;
  writeFloorAndWall(dir, {-30, 30, -30, 5, -10, 0}, {-30, 30, 5, 15, -10, 10});  // wall at y = 5
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k <= 40; ++k) path << -5 + 0.25 * k << " 2.3 0 0 0 1\n";  // shank to y = 5.3
  dir.write("wall.cl", path.str());
  const auto r = test::runFieldpath(dir, "check scene.yaml --path wall.cl --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto check = nlohmann::json::parse(test::slurp(dir.path() / "out" / "check.json"));
  const double gouge = check["surface"]["max_gouge_um"].get<double>();
  EXPECT_GT(gouge, 300.0 - 1.0);
  EXPECT_LT(gouge, 300.0 + 50.0 + 1.0);
  EXPECT_FALSE(check["ok"].get<bool>());
  // The exact test of the cutter: 300 um to its 0.1 um, at every posture.
  EXPECT_NEAR(check["cutter_part"]["max_depth_um"].get<double>(), 300.0, 0.2);
  EXPECT_EQ(check["cutter_part"]["gouging_postures"].get<int>(), 41);
}

// A shank 0.02 mm into a wall can fall between the Z-buffer's lines (0.05 mm apart): the exact
// test of the cutter against the part sees it at every posture, 20 um deep, and `check` is not
// ok (a helper's case; it passed as clean). 0.004 mm, inside the 5 um tolerance, stays ok.
TEST(CheckSurface, AShankGrazingAWallBetweenTheLinesIsSeenExactly) {
  const TempDir dir;
  writeFloorAndWall(dir, {-30, 30, -30, 5, -10, 0}, {-30, 30, 5, 15, -10, 10});  // wall at y = 5
  for (const double entry : {0.02, 0.004}) {
    std::ostringstream path;
    path.precision(17);
    path << "# pass 1\n";
    for (int k = 0; k <= 40; ++k) path << -5 + 0.25 * k << ' ' << 2.0 + entry << " 0 0 0 1\n";
    dir.write("graze.cl", path.str());
    const auto r = test::runFieldpath(dir, "check scene.yaml --path graze.cl --out out");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const auto check = nlohmann::json::parse(test::slurp(dir.path() / "out" / "check.json"));
    const auto& cutter = check["cutter_part"];
    if (entry > 0.005) {
      EXPECT_NEAR(cutter["max_depth_um"].get<double>(), 1e3 * entry, 0.2) << cutter;
      EXPECT_EQ(cutter["gouging_postures"].get<int>(), 41);
      EXPECT_EQ(cutter["gouging_motions"].get<int>(), 40);
      EXPECT_FALSE(check["ok"].get<bool>());
      EXPECT_NE(r.out.find("(GOUGES)"), std::string::npos) << r.out;
    } else {
      EXPECT_EQ(cutter["gouging_postures"].get<int>(), 0) << cutter;
      EXPECT_EQ(cutter["max_depth_um"].get<double>(), 0.0);
    }
  }
}

// Passes that do not cross the part leave no surface to check, but their clearance still
// counts: `check` refused the whole job (exit 1) and never said that the shank, tilted 40°
// into a wall, collides.
TEST(CheckSurface, PassesBesideThePartAreStillCheckedForClearance) {
  const TempDir dir;
  geometry::TriangleMesh part, wall;
  pathgen::test::addBox(part, -40, -20, -30, 30, -10, 0);  // a plate well away from the pass
  pathgen::test::addBox(wall, 8, 20, -30, 30, -10, 60);    // an obstacle beside the pass
  geometry::saveMesh(part, dir.path() / "part.stl");
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\nclearance: 0.5\n");
  const double s = std::sin(40.0 * M_PI / 180.0), c = std::cos(40.0 * M_PI / 180.0);
  std::ostringstream path;
  path.precision(17);
  path << "# pass 1\n";
  for (int k = 0; k <= 10; ++k) path << "0 " << -5 + k << " 0 " << s << " 0 " << c << '\n';
  dir.write("lean.cl", path.str());
  const auto r = test::runFieldpath(dir, "check scene.yaml --path lean.cl --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  EXPECT_NE(r.output().find("surface: not checked (the passes do not pass over the part"),
            std::string::npos)
      << r.output();
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out" / "check.json"));
  EXPECT_TRUE(report["surface"].is_null());
  EXPECT_NE(report["surface_skipped"].get<std::string>().find("do not pass over the part"),
            std::string::npos);
  // The shank's axis reaches x = 8 (the wall) 8 / sin 40° = 12.4 mm up: every posture collides.
  EXPECT_EQ(report["clearance"]["colliding_postures"].get<int>(), 11);
  EXPECT_FALSE(report["ok"].get<bool>());
  // The axis holds its 40° all along: no turn, no warning.
  EXPECT_NEAR(report["axis_turn"]["max_deg"].get<double>(), 0.0, 1e-6);
  EXPECT_EQ(report["axis_turn"]["posture"].get<int>(), 0);  // the first pair: none turns more
  EXPECT_EQ(r.err.find("the tool axis turns"), std::string::npos) << r.err;
  // The same pass with the axis snapping upright half-way: the turn said, naming the lines.
  std::ostringstream snap;
  snap.precision(17);
  snap << "# pass 1\n";
  for (int k = 0; k <= 10; ++k)
    snap << "0 " << -5 + k
         << (k < 6 ? " 0 " + std::to_string(s) + " 0 " + std::to_string(c)
                   : std::string(" 0 0 0 1"))
         << '\n';
  dir.write("snap.cl", snap.str());
  const auto t = test::runFieldpath(dir, "check scene.yaml --path snap.cl --out snapped");
  ASSERT_EQ(t.exit_code, 0) << t.output();
  EXPECT_NE(t.err.find("warning: the tool axis turns 40.0 deg between postures 5 (snap.cl:7) and "
                       "6 (snap.cl:8)"),
            std::string::npos)
      << t.err;
  const auto snapped = nlohmann::json::parse(test::slurp(dir.path() / "snapped" / "check.json"));
  EXPECT_NEAR(snapped["axis_turn"]["max_deg"].get<double>(), 40.0, 1e-4);
  EXPECT_EQ(snapped["axis_turn"]["posture"].get<int>(), 5);
}

TEST(CheckSurface, TheSameJobFarFromTheOriginReadsTheSame) {
  // A pass along a plate, and the whole job lifted 1e5 mm in z, or moved 5e5 mm in x and y: the
  // same surface figures (float heights held there read a clean pass as 7.8 um of gouge on 498
  // lines; float plan coordinates, 1/32 mm apart at 5e5 mm, a reviewer's clean slope as 20 um).
  const TempDir dir;
  struct Place {
    std::string tag;
    double shift, lift;  // mm, in x and y; in z
  };
  const std::vector<Place> places = {{"low", 0.0, 0.0}, {"high", 0.0, 1e5}, {"far", 5e5, 0.0}};
  for (const auto& [tag, shift, lift] : places) {
    geometry::TriangleMesh part, wall;
    pathgen::test::addBox(part, shift, shift + 50, shift, shift + 50, lift - 10, lift);
    pathgen::test::addBox(wall, shift, shift + 50, shift + 30, shift + 35, lift - 5, lift + 20);
    geometry::saveMesh(part, dir.path() / ("part_" + tag + ".stl"));
    geometry::saveMesh(wall, dir.path() / ("wall_" + tag + ".stl"));
    dir.write(tag + ".yaml", "obstacles:\n  - mesh: wall_" + tag + ".stl\npart: part_" + tag +
                                 ".stl\ntool: { shape: ball, radius: 3, length: 40 }\n");
    std::ostringstream path;
    path.precision(17);
    for (const double y : {20.3, 24.3}) {  // two passes: a scallop between them, off 1/32 mm
      if (y > 20.0)
        path << "# link\n"
             << shift + 45 << ' ' << shift + y - 4 << ' ' << lift + 8 << " 0 0 1\n"
             << shift + 5 << ' ' << shift + y << ' ' << lift + 8 << " 0 0 1\n";
      path << "# pass\n";
      for (int k = 0; k <= 80; ++k)
        path << shift + 5.0 + 0.5 * k << ' ' << shift + y << ' ' << lift << " 0 0 1\n";
    }
    dir.write(tag + ".cl", path.str());
  }
  auto surface = [&](const std::string& tag) {
    const auto r =
        test::runFieldpath(dir, "check " + tag + ".yaml --path " + tag + ".cl --out out_" + tag);
    EXPECT_EQ(r.exit_code, 0) << r.output();
    return nlohmann::json::parse(
        test::slurp(dir.path() / ("out_" + tag) / "check.json"))["surface"];
  };
  const auto low = surface("low");
  EXPECT_EQ(low["gouged_lines"].get<int>(), 0);
  for (const char* tag : {"high", "far"}) {
    const auto moved = surface(tag);
    EXPECT_EQ(moved["gouged_lines"].get<int>(), 0) << tag;
    EXPECT_NEAR(moved["max_gouge_um"].get<double>(), low["max_gouge_um"].get<double>(), 1.0) << tag;
    EXPECT_NEAR(moved["max_scallop_um"].get<double>(), low["max_scallop_um"].get<double>(), 1.0)
        << tag;
    EXPECT_EQ(moved["band_lines"].get<int>(), low["band_lines"].get<int>()) << tag;
  }
  EXPECT_GT(low["max_scallop_um"].get<double>(), 600.0);  // R - sqrt(R² - 4) = 764 um
}
