/// `generate` and the scene's meshes, through the built `fieldpath`: a mesh in metres beside ones
/// in millimetres, a mesh turned on loading kept in the report, obstacles out of the field's
/// reach. (Split from test_cli_generate_edges.cpp, which holds the scene's edges.)
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using namespace fieldpath;
using test::TempDir;

namespace {
/// A plate 4 mm square (the part, plate.stl), a post beside it (x 2.5 to 3, post.stl) and passes
/// along x over the plate (p.cl); returns the scene's keys after its obstacles.
std::string writePlateAndPost(const TempDir& dir) {
  geometry::TriangleMesh plate, post;
  pathgen::test::addBox(plate, -2, 2, -2, 2, -0.5, 0);
  pathgen::test::addBox(post, 2.5, 3, -2, 2, -0.5, 1);
  geometry::saveMesh(plate, dir.path() / "plate.stl");
  geometry::saveMesh(post, dir.path() / "post.stl");
  std::ostringstream cl;
  for (int i = -3; i <= 3; ++i) cl << 0.5 * i << " 1 0 0 0 1\n";
  dir.write("p.cl", cl.str());
  return "part: plate.stl\ntool: { shape: ball, radius: 0.5, length: 10 }\nclearance: 0.05\n"
         "field: { r0: 1.0, r_min: 0.05, sample_step: 0.1, voxel_size: 0.1 }\n"
         "path: { nominal: p.cl }\n";
}
}  // namespace

// A mesh exported in metres among millimetres: a pin 8 um wide 3 mm from the passes steered
// nothing and was never met, and the path read safe where the holder ran into the real pin (a
// CAM engineer's mould). Warned by the scene's loading, kept in report.json; a mesh of the same
// scale as the others is not.
TEST(GenerateEdges, AMeshInMetresBesideOnesInMillimetresIsWarned) {
  const TempDir dir;
  const std::string rest = writePlateAndPost(dir);
  geometry::TriangleMesh post_m;  // the post in metres
  pathgen::test::addBox(post_m, 0.0025, 0.003, -0.002, 0.002, -0.0005, 0.001);
  geometry::saveMesh(post_m, dir.path() / "post_m.stl");
  // (the largest mesh: the part, 5.68 mm across; the post in metres 0.0043 mm)
  const std::string said = "obstacles[2] (post_m.stl) spans 0.0043 mm, ";
  const std::string than = " times less than part (plate.stl) (5.679 mm)";
  for (const bool metres : {false, true}) {
    dir.write("scene.yaml", std::string("obstacles:\n  - mesh: post.stl\n") +
                                (metres ? "  - mesh: post_m.stl\n" : "") + rest);
    const auto r = test::runFieldpath(dir, "generate scene.yaml --out out");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const std::string notes =
        nlohmann::json::parse(test::slurp(dir.path() / "out/report.json"))["mesh_notes"].dump();
    if (!metres) {
      EXPECT_EQ(r.err.find("times less than"), std::string::npos) << r.err;
      continue;
    }
    EXPECT_NE(r.err.find("warning: scene.yaml: " + said), std::string::npos) << r.err;
    EXPECT_NE(r.err.find(than), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("a mesh in metres (scale it by 1000)"), std::string::npos) << r.err;
    EXPECT_NE(notes.find("WARNING: " + said), std::string::npos) << notes;
  }
}

// What loading a mesh mended or turned is kept in report.json, not only said on stderr (a CAM
// engineer's walls wound inward were turned with a note that the report lacked).
TEST(GenerateEdges, AMeshTurnedOnLoadingIsInTheReport) {
  const TempDir dir;
  const std::string rest = writePlateAndPost(dir);
  geometry::TriangleMesh inward;
  pathgen::test::addBox(inward, 2.5, 3, -2, 2, -0.5, 1);
  for (auto& t : inward.triangles) std::swap(t[1], t[2]);
  geometry::saveMesh(inward, dir.path() / "inward.stl");
  dir.write("scene.yaml", "obstacles:\n  - mesh: inward.stl\n" + rest);
  const auto r = test::runFieldpath(dir, "generate scene.yaml --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const std::string said = "inward.stl: 1 closed shell wound the wrong way round";
  EXPECT_NE(r.err.find(said), std::string::npos) << r.err;
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out/report.json"));
  EXPECT_NE(report["mesh_notes"].dump().find(said), std::string::npos) << report["mesh_notes"];
  // Its times: the total holds the stages, reading included (they summed past it: a claims
  // audit's), field_near_path being part of field.
  const auto& t = report["times_s"];
  double stages = 0.0;
  for (const char* stage : {"read", "setup", "field", "steering", "clearance"})
    stages += t[stage].get<double>();
  EXPECT_LE(stages, t["total"].get<double>()) << t;
  EXPECT_LE(t["field_near_path"].get<double>(), t["field"].get<double>()) << t;
}

// An obstacle farther than field.r0 from the tool at every posture steers nothing (eq. 1 ends at
// r0): blades in inches floating in the mesh impeller's bore, the path over the hub in mm, read
// `safe` with the nominal axes, unsaid (a units adversary's). A post beside passes along x
// (x <= 1.5, the ball R 0.5: the tool's box reaches x = 2) steers; a box at x = 50 is at least
// 48 mm away: said, by its entry; alone, the path is said to be the nominal one.
TEST(GenerateEdges, ObstaclesOutOfTheFieldsReachAreSaid) {
  const TempDir dir;
  const std::string rest = writePlateAndPost(dir);
  geometry::TriangleMesh far;
  pathgen::test::addBox(far, 50, 51, -2, 2, -0.5, 1);
  geometry::saveMesh(far, dir.path() / "far.stl");
  // A wall 1.1 mm beside the ball's side (y = 1.5), under a holder of radius 3 (z 10 to 20): one
  // box of the holder's radius from the tip up kept it "near" (the note fired only far beyond
  // r0, a claims audit's finding); the cutter and the holder in boxes of their own tell it.
  geometry::TriangleMesh wall;
  pathgen::test::addBox(wall, -2, 2, 2.6, 3, -0.5, 1);
  geometry::saveMesh(wall, dir.path() / "wall.stl");
  const std::string holder = "holder: [[10, 3], [20, 3]]\n";
  struct Case {
    std::string obstacles, said, more = "";
  };
  for (const Case& c :
       {Case{"  - mesh: post.stl\n", ""},
        Case{"  - mesh: post.stl\n  - mesh: far.stl\n",
             "obstacles[2] (far.stl, at least 48 mm away) stays farther than field.r0 (1 mm) from "
             "the tool and holder at every posture: it steered nothing"},
        Case{"  - mesh: far.stl\n",
             "obstacles[1] (far.stl, at least 48 mm away) stays farther than field.r0 (1 mm) from "
             "the tool and holder at every posture: no obstacle steered the path"},
        Case{"  - mesh: wall.stl\n",
             "obstacles[1] (wall.stl, at least 1.1 mm away) stays farther than field.r0 (1 mm) "
             "from the tool and holder at every posture",
             holder}}) {
    dir.write("scene.yaml", "obstacles:\n" + c.obstacles + rest + c.more);
    const auto r = test::runFieldpath(dir, "generate scene.yaml --out out");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out/report.json"));
    const std::string notes = report["obstacle_notes"].dump();
    if (c.said.empty()) {
      EXPECT_EQ(r.output().find("farther than field.r0"), std::string::npos) << r.output();
    } else {
      EXPECT_NE(r.output().find(c.said), std::string::npos) << r.output();
      EXPECT_NE(notes.find(c.said), std::string::npos) << notes;
    }
  }
  // Named by its entry in the scene's list: after the impeller's, the box is obstacles[2] (the
  // blades' meshes come after the files' in the scene's obstacles: it was called obstacles[1]).
  std::string impeller =
      test::slurp(fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml");
  const std::size_t guide = impeller.find("\nguide:");
  ASSERT_NE(guide, std::string::npos);
  geometry::TriangleMesh beyond;  // the channel runs along x from 0 to 72
  pathgen::test::addBox(beyond, 500, 501, -2, 2, 0, 1);
  geometry::saveMesh(beyond, dir.path() / "beyond.stl");
  impeller.insert(guide + 1, "  - mesh: beyond.stl\n");
  dir.write("impeller.yaml", impeller);
  const auto r = test::runFieldpath(dir, "generate impeller.yaml --out impeller");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  EXPECT_NE(r.err.find("note: obstacles[2] (beyond.stl, at least"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("it steered nothing"), std::string::npos) << r.err;
}

// `check` makes no field: a field.r0 beyond the obstacles' extent plus the tool's reach (refused
// by `generate`, where every sample would act on every node) does not stop it (a reviewer's
// short tool beside a small post was refused for a default r0 check never uses). A part in
// metres under a path in millimetres is checked at that size: one Z-buffer line of it read
// `check: ok` beside the warning that a path read safe beside it is not; now not ok, saying so.
TEST(GenerateEdges, CheckReadsPastTheFieldsReachAndFailsAPartInMetres) {
  const TempDir dir;
  std::string rest = writePlateAndPost(dir);
  rest.replace(rest.find("r0: 1.0"), 7, "r0: 20");  // the post 4.3 mm across, the tool 10 long
  dir.write("scene.yaml", "obstacles:\n  - mesh: post.stl\n" + rest);
  const auto generated = test::runFieldpath(dir, "generate scene.yaml --out g");
  EXPECT_EQ(generated.exit_code, 1);
  EXPECT_NE(generated.err.find("field.r0: 20 mm exceeds"), std::string::npos) << generated.err;
  const auto checked = test::runFieldpath(dir, "check scene.yaml --path p.cl --out c");
  EXPECT_EQ(checked.err.find("field.r0"), std::string::npos) << checked.err;
  EXPECT_NE(checked.out.find("check: ok"), std::string::npos) << checked.output();

  geometry::TriangleMesh plate_m;  // the plate in metres, under the passes (y = 1)
  pathgen::test::addBox(plate_m, -0.002, 0.002, 0.998, 1.002, -0.0005, 0);
  geometry::saveMesh(plate_m, dir.path() / "plate_m.stl");
  std::string in_metres = rest;
  in_metres.replace(in_metres.find("part: plate.stl"), 15, "part: plate_m.stl");
  dir.write("metres.yaml", "obstacles:\n  - mesh: post.stl\n" + in_metres);
  // At the default spacing the speck holds no line: refused, asking whether it is in metres.
  const auto coarse = test::runFieldpath(dir, "check metres.yaml --path p.cl --out n");
  EXPECT_EQ(coarse.exit_code, 1) << coarse.output();
  EXPECT_NE(coarse.err.find("is it in metres?"), std::string::npos) << coarse.err;
  const auto metres =
      test::runFieldpath(dir, "check metres.yaml --path p.cl --spacing 0.001 --out m");
  EXPECT_EQ(metres.exit_code, 0) << metres.output();
  EXPECT_EQ(metres.out.find("the surface is not checked"), std::string::npos) << metres.out;
  EXPECT_NE(metres.out.find("check: NOT OK: the surface is checked against a part of another "
                            "scale: part (plate_m.stl) spans"),
            std::string::npos)
      << metres.output();
}
