/// `check`'s verdict on what is not a collision, through the built `fieldpath`: postures and
/// motions under the scene's clearance, the gouge tolerance of `--gouge-tol`, a spacing coarsened
/// to the largest grid, a part named as an obstacle too; and `generate`'s travel plane over a
/// part taller than the obstacles. (A test audit: none of these had a test; deleting the
/// under-the-clearance lines of `check` left it saying `ok` of a path 0.3 mm from a blade with the
/// scene asking 0.5.)
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "cli_scenes.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using namespace fieldpath;
using test::TempDir;

namespace {

nlohmann::json checkJson(const TempDir& dir, const std::string& out) {
  return nlohmann::json::parse(test::slurp(dir.path() / out / "check.json"));
}

bool says(const nlohmann::json& reasons, const std::string& text) {
  for (const auto& r : reasons)
    if (r.get<std::string>().find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

// A ridge 0.2 mm thick standing to z = 10. Postures 0.3 mm beside its face, and a move 0.3 mm over
// its top between postures 2.9 mm clear: with `clearance: 0.5` both are not ok (not unsafe: nothing
// is touched); with 0.2 both are ok.
TEST(CheckVerdict, PosturesAndMotionsUnderTheClearanceAreNotOk) {
  const TempDir dir;
  geometry::saveMesh(pathgen::test::boxMesh(4.9, 5.1, -20, 20, -10, 10), dir.path() / "ridge.stl");
  dir.write("beside.cl", "# pass 1\n1.6 0 0 0 0 1\n1.6 1 0 0 0 1\n1.6 2 0 0 0 1\n");
  dir.write("over.cl", "# pass 1\n0 0 10.3 0 0 1\n10 0 10.3 0 0 1\n");
  for (const double clearance : {0.5, 0.2}) {
    dir.write("scene.yaml",
              "obstacles:\n  - mesh: ridge.stl\n"
              "tool: { shape: ball, radius: 3, length: 20 }\nclearance: " +
                  std::to_string(clearance) + "\n");
    for (const std::string path : {"beside", "over"}) {
      const std::string out = path + "_" + std::to_string(clearance);
      const auto r =
          test::runFieldpath(dir, "check scene.yaml --path " + path + ".cl --out " + out);
      ASSERT_EQ(r.exit_code, 0) << r.output();
      const nlohmann::json check = checkJson(dir, out);
      EXPECT_TRUE(check["unsafe"].empty()) << check["unsafe"];
      const std::string reason = path == "beside" ? "postures come within 0.2"
                                                  : "1 motions come under the required clearance";
      EXPECT_EQ(says(check["not_ok_because"], reason), clearance == 0.5)
          << path << " " << clearance << ": " << check["not_ok_because"];
      EXPECT_EQ(check["ok"].get<bool>(), clearance != 0.5) << path << " " << clearance;
      // Named where, as a collision is: the ball's 1.6 mm off the ridge at every posture (the
      // first lowest), the move over its top from the first posture.
      if (clearance == 0.5)
        EXPECT_TRUE(says(check["not_ok_because"],
                         path == "beside" ? "(lowest: posture 0 (pass 1, beside.cl:2))"
                                          : "(first: posture 0 to the next (pass 1, over.cl:2))"))
            << check["not_ok_because"];
      EXPECT_NE(r.out.find(clearance == 0.5 ? "check: NOT OK" : "check: ok"), std::string::npos)
          << r.out;
      // --fail-unsafe: exit 3 on NOT OK, its outputs written (`check && post` posted a path
      // check had marked: a CAM engineer's); 0 on ok.
      const auto strict = test::runFieldpath(
          dir, "check scene.yaml --path " + path + ".cl --fail-unsafe --out strict_" + out);
      EXPECT_EQ(strict.exit_code, clearance == 0.5 ? 3 : 0) << strict.output();
      EXPECT_EQ(checkJson(dir, "strict_" + out)["ok"], check["ok"]);
    }
  }
}

// A pass dipped 8 um into a flat part: a gouge under the default 5 um tolerance, none under
// `--gouge-tol 10`, in the cutter's exact check and in the Z-buffer's; a tolerance of half the
// ball's radius or more is refused before any output.
TEST(CheckVerdict, TheGougeToleranceIsTheOptions) {
  const TempDir dir;
  pathgen::test::writeBoxPartScene(dir, {{-20, 20, -20, 20, -10, 0}});
  std::string cl = "# pass 1\n";
  for (int i = -10; i <= 10; ++i) cl += std::to_string(i) + " 0 -0.008 0 0 1\n";
  dir.write("dip.cl", cl);
  const auto strict = test::runFieldpath(dir, "check scene.yaml --path dip.cl --out strict");
  ASSERT_EQ(strict.exit_code, 0) << strict.output();
  const nlohmann::json s = checkJson(dir, "strict");
  EXPECT_TRUE(says(s["not_ok_because"], "deeper than the gouge tolerance (5 um)"))
      << s["not_ok_because"];
  // The first gouge named as the obstacles' are: its block and its line in the file.
  EXPECT_TRUE(says(s["not_ok_because"], "first: posture 0 (pass 1, ")) << s["not_ok_because"];
  EXPECT_TRUE(says(s["not_ok_because"], "dip.cl:2))")) << s["not_ok_because"];
  EXPECT_NEAR(s["cutter_part"]["max_depth_um"].get<double>(), 8.0, 0.5) << s["cutter_part"];
  EXPECT_NEAR(s["surface"]["max_gouge_um"].get<double>(), 8.0, 0.5) << s["surface"];
  EXPECT_GT(s["surface"]["gouged_lines"].get<int>(), 0) << s["surface"];

  const auto loose =
      test::runFieldpath(dir, "check scene.yaml --path dip.cl --gouge-tol 10 --out loose");
  ASSERT_EQ(loose.exit_code, 0) << loose.output();
  const nlohmann::json l = checkJson(dir, "loose");
  EXPECT_FALSE(says(l["not_ok_because"], "gouge")) << l["not_ok_because"];
  EXPECT_EQ(l["cutter_part"]["gouging_postures"].get<int>(), 0) << l["cutter_part"];
  EXPECT_EQ(l["surface"]["gouged_lines"].get<int>(), 0) << l["surface"];
  EXPECT_DOUBLE_EQ(l["surface"]["gouge_tolerance_um"].get<double>(), 10.0);

  dir.write("small.yaml",
            "obstacles:\n  - mesh: far.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 1, length: 40 }\n");
  const auto wide =
      test::runFieldpath(dir, "check small.yaml --path dip.cl --gouge-tol 600 --out wide");
  EXPECT_EQ(wide.exit_code, 1) << wide.output();
  EXPECT_NE(wide.err.find("--gouge-tol 600 um: must be under half the tool radius (500 um)"),
            std::string::npos)
      << wide.err;
  EXPECT_FALSE(fs::exists(dir.path() / "wide"));
  // Not a number: said so (nan passed the range check and was told it was over half the radius).
  const auto nan = test::runFieldpath(dir, "check small.yaml --path dip.cl --gouge-tol nan");
  EXPECT_EQ(nan.exit_code, 1) << nan.output();
  EXPECT_NE(nan.err.find("--gouge-tol: must be a number from 0.1 to 1000 um, got 'nan'"),
            std::string::npos)
      << nan.err;
}

// `--max-scallop`: the finish the check holds a path to. Two passes 4 mm apart over a flat
// part with a 3 mm ball leave a cusp of 3 - sqrt(9 - 2^2) = 764 um between them (closed form):
// ok at 800 um, not at 700; passes 10 mm apart leave lines no pass cut (the stock stands), not
// ok whatever the bound. Without the option the scallop is measured, not judged (a helper's
// check `ok` of a path leaving the whole 2 mm allowance between passes).
TEST(CheckVerdict, MaxScallopHoldsThePathToAFinish) {
  const TempDir dir;
  pathgen::test::writeBoxPartScene(dir, {{-20, 20, -20, 20, -10, 0}});
  const auto passes = [](double gap_mm) {
    std::string cl;
    for (int p = 0; p < 2; ++p) {
      cl += "# pass " + std::to_string(p + 1) + "\n";
      for (int i = -10; i <= 10; ++i)
        cl += std::to_string(i) + " " + std::to_string((p - 0.5) * gap_mm) + " 0 0 0 1\n";
    }
    return cl;
  };
  dir.write("near.cl", passes(4.0));
  dir.write("far.cl", passes(10.0));
  dir.write("one.cl", "# pass 1\n-10 0 0 0 0 1\n10 0 0 0 0 1\n");
  const double cusp_um = 1e3 * (3.0 - std::sqrt(9.0 - 4.0));
  struct Case {
    std::string path, option;
    bool ok;
    std::string reason;
  };
  for (const Case& c : {Case{"near", "", true, ""}, Case{"near", "--max-scallop 800", true, ""},
                        Case{"near", "--max-scallop 700", false, "over --max-scallop 700 um"},
                        Case{"far", "", true, ""},
                        Case{"far", "--max-scallop 5000", false, "lines between passes not cut"},
                        Case{"one", "", true, ""},
                        Case{"one", "--max-scallop 5000", false,
                             "--max-scallop 5000 um not proven: no scallop measured"}}) {
    const std::string out = c.path + (c.option.empty() ? "" : "_" + c.option.substr(14));
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path " + c.path + ".cl " + c.option + " --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const nlohmann::json check = checkJson(dir, out);
    EXPECT_EQ(check["ok"].get<bool>(), c.ok)
        << c.path << ' ' << c.option << ": " << check["not_ok_because"];
    if (!c.reason.empty()) EXPECT_TRUE(says(check["not_ok_because"], c.reason)) << check;
    if (c.path == "near") {  // the lines may miss the cusp by up to the grid error they state
      const double measured = check["surface"]["max_scallop_um"].get<double>();
      EXPECT_LE(measured, cusp_um + 1.0) << check["surface"];
      EXPECT_GE(measured + check["surface"]["scallop_grid_error_um"].get<double>(), cusp_um - 1.0)
          << check["surface"];
      EXPECT_GT(measured, 700.0) << check["surface"];
    }
    EXPECT_EQ(check["max_scallop_um"].is_null(), c.option.empty());
  }
  // A bound between the measured scallop and the measured plus the grid's error is not proven:
  // the cusp between the lines may stand over it.
  const nlohmann::json surface = checkJson(dir, "near")["surface"];
  const double measured = surface["max_scallop_um"].get<double>();
  const double grid_error = surface["scallop_grid_error_um"].get<double>();
  ASSERT_GT(grid_error, 2.0) << surface;
  for (const auto& [bound, ok] : {std::pair{measured + grid_error / 2, false},
                                  std::pair{measured + grid_error + 1.0, true}}) {
    const std::string option = "--max-scallop " + std::to_string(bound);
    const auto r = test::runFieldpath(
        dir, "check scene.yaml --path near.cl " + option + " --out between_" + (ok ? "1" : "0"));
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const nlohmann::json check = checkJson(dir, std::string("between_") + (ok ? "1" : "0"));
    EXPECT_EQ(check["ok"].get<bool>(), ok) << option << ": " << check["not_ok_because"];
    if (!ok) EXPECT_TRUE(says(check["not_ok_because"], "a cusp between them up to")) << check;
  }
}

// A part with a bore: passes 25.4 times too small (a path in inches read as mm) fall inside it,
// where the Z-buffer lowers lines over no part. The check read them as cut ("0 lines in the
// band", `ok`: a fault injection's); only lines over the part count as the part cut. The same
// passes at their size run over the ring's top: cut, and ok.
TEST(CheckVerdict, PassesThatCutOnlyInsideABoreDoNotFinishThePart) {
  const TempDir dir;
  // A bore 7 mm square; the passes 1 mm over the part's top: in the bore the ball lowers the
  // stock's lines (2 mm over the top), over the ring's edge (the ball's reach) it stays above them.
  pathgen::test::writeBoxPartScene(dir, {{-40, 40, -40, -3.5, -10, 0},
                                         {-40, 40, 3.5, 40, -10, 0},
                                         {-40, -3.5, -3.5, 3.5, -10, 0},
                                         {3.5, 40, -3.5, 3.5, -10, 0}});
  const auto pass = [](double scale) {
    std::string cl = "# pass 1\n";
    for (int i = -10; i <= 10; ++i)
      cl += std::to_string(2.5 * i * scale) + " " + std::to_string(25.0 * scale) + " 1 0 0 1\n";
    return cl;
  };
  dir.write("mm.cl", pass(1.0));
  dir.write("inch.cl", pass(1.0 / 25.4));
  for (const auto& [path, ok] : {std::pair{"mm", true}, {"inch", false}}) {
    const auto r = test::runFieldpath(
        dir, std::string("check scene.yaml --path ") + path + ".cl --out " + path);
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const nlohmann::json check = checkJson(dir, path);
    EXPECT_EQ(check["ok"].get<bool>(), ok) << path << ": " << check["not_ok_because"];
    if (!ok) {
      EXPECT_TRUE(says(check["not_ok_because"], "is the part in the path's frame and units?"))
          << check["not_ok_because"];
      EXPECT_TRUE(check["surface"].is_null()) << check["surface"];
    } else {
      EXPECT_GT(check["surface"]["part_cut_lines"].get<int>(), 0) << check["surface"];
    }
  }
}

// A 400 mm square part at a 0.02 mm spacing is 4 · 10^8 lines: the grid is coarsened to the
// largest the check makes, and says so (check.json and stdout).
TEST(CheckVerdict, AFineSpacingOverALargePartIsCoarsenedAndSaid) {
  const TempDir dir;
  pathgen::test::writeBoxPartScene(dir, {{-200, 200, -200, 200, -10, 0}},
                                   {-300, -290, -300, -290, -50, -40});
  dir.write("diag.cl", "# pass 1\n-190 -190 0 0 0 1\n190 190 0 0 0 1\n");
  const auto r = test::runFieldpath(dir, "check scene.yaml --path diag.cl --spacing 0.02 --out c");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const nlohmann::json surface = checkJson(dir, "c")["surface"];
  EXPECT_TRUE(surface["spacing_coarsened"].get<bool>()) << surface;
  // The passes' reach, 386 mm square, in 6e6 lines: sqrt(386² / 6e6) ≈ 0.158 mm.
  EXPECT_NEAR(surface["grid"]["spacing"][0].get<double>(), 386 / std::sqrt(6e6), 0.002)
      << surface["grid"];
  EXPECT_NE(r.err.find("note: --spacing 0.02 mm would make more Z-buffer lines than a check "
                       "takes"),
            std::string::npos)
      << r.err;
}

// The links' travel plane clears the highest mesh, the part's too: a part 30 mm high beside
// obstacles 10 mm high puts it at 30 + clearance + 2 mm, and the links touch nothing.
TEST(GenerateLinks, TheTravelPlaneClearsAPartTallerThanTheObstacles) {
  const TempDir dir;
  geometry::TriangleMesh part, low;
  pathgen::test::addBox(part, -20, 20, -20, 20, 0, 30);
  pathgen::test::addBox(low, 40, 50, -5, 5, 0, 10);
  geometry::saveMesh(part, dir.path() / "part.stl");
  geometry::saveMesh(low, dir.path() / "low.stl");
  std::string cl = "# pass 1\n";
  for (int i = -10; i <= 10; ++i) cl += std::to_string(i) + " -5 30 0 0 1\n";
  cl += "# pass 2\n";
  for (int i = 10; i >= -10; --i) cl += std::to_string(i) + " 5 30 0 0 1\n";
  dir.write("top.cl", cl);
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: low.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\nclearance: 0.5\n"
            "path: { nominal: top.cl }\nlinks: { retract: 5 }\n");
  const auto r = test::runFieldpath(dir, "generate scene.yaml --nominal --out out");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out" / "report.json"));
  EXPECT_DOUBLE_EQ(report["links"]["safe_z_mm"].get<double>(), 30 + 0.5 + 2) << report["links"];
  EXPECT_TRUE(report["safe"].get<bool>()) << report["unsafe"];
}

// The part named as an obstacle too (DESIGN: obstacles are never the machined surface): the ball
// on it reads as colliding at every posture; said, naming the file, on stderr and in check.json.
TEST(CheckVerdict, APartThatIsAlsoAnObstacleIsSaid) {
  const TempDir dir;
  geometry::saveMesh(pathgen::test::boxMesh(-20, 20, -20, 20, -10, 0), dir.path() / "part.stl");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: part.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\n");
  dir.write("top.cl", "# pass 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n");
  const auto r = test::runFieldpath(dir, "check scene.yaml --path top.cl --out c");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  EXPECT_NE(r.err.find("part.stl: the part is also an obstacle"), std::string::npos) << r.err;
  const nlohmann::json check = checkJson(dir, "c");
  EXPECT_TRUE(says(check["obstacle_notes"], "the part is also an obstacle")) << check;
  EXPECT_GT(check["clearance"]["colliding_postures"].get<int>(), 0);
  // Apart, no such note.
  geometry::saveMesh(pathgen::test::boxMesh(40, 50, -5, 5, 0, 10), dir.path() / "far.stl");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: far.stl\npart: part.stl\n"
            "tool: { shape: ball, radius: 3, length: 40 }\n");
  const auto apart = test::runFieldpath(dir, "check scene.yaml --path top.cl --out d");
  ASSERT_EQ(apart.exit_code, 0) << apart.output();
  EXPECT_EQ(apart.err.find("also an obstacle"), std::string::npos) << apart.err;
}

// A move from one pass straight into the next (no link between) is named with the pass it leaves,
// at the line it leaves from (a helper read "pass 5" beside the last line of pass 4).
TEST(CheckClearance, AMoveBetweenTwoPassesIsNamedWithThePassItLeaves) {
  const TempDir dir;
  geometry::TriangleMesh post;
  pathgen::test::addBox(post, 8, 12, 9, 11, -5, 5);
  geometry::saveMesh(post, dir.path() / "post.stl");
  std::string cl = "# pass 1\n";
  for (int i = 0; i <= 10; ++i) cl += "0 " + std::to_string(i) + " 0 0 0 1\n";
  cl += "# pass 2\n";
  for (int i = 10; i >= 0; --i) cl += "20 " + std::to_string(i) + " 0 0 0 1\n";
  dir.write("two.cl", cl);
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: post.stl\ntool: { shape: ball, radius: 3, length: 40 }\n"
            "clearance: 0.5\n");
  const auto c = test::runFieldpath(dir, "check scene.yaml --path two.cl --out chk");
  ASSERT_EQ(c.exit_code, 0) << c.output();
  const auto checked = nlohmann::json::parse(test::slurp(dir.path() / "chk" / "check.json"));
  EXPECT_EQ(checked["clearance"]["colliding_postures"].get<int>(), 0) << checked["clearance"];
  // The nearest obstacle named as the scene gives it, not only numbered (a user counted files).
  EXPECT_EQ(checked["clearance"]["min_obstacle_name"], "obstacles[1] (post.stl)");
  ASSERT_EQ(checked["unsafe"].size(), 1u) << checked["unsafe"];
  // Posture 10, the last of pass 1, on line 12 of the file.
  EXPECT_NE(checked["unsafe"][0].get<std::string>().find(
                "1 motion touches an obstacle (first: posture 10 to the next (pass 1, two.cl:12))"),
            std::string::npos)
      << checked["unsafe"];
  EXPECT_EQ(checked["passes"].get<int>(), 2);
  EXPECT_EQ(checked["passes_split_at_gaps"].get<int>(), 2);
  // Without markers the file is one pass block, as clearance.csv and the reasons number it; the
  // gap of 20 mm makes it two as generate would read it.
  std::string plain = cl;
  for (const char* marker : {"# pass 1\n", "# pass 2\n"}) plain.erase(plain.find(marker), 9);
  dir.write("plain.cl", plain);
  ASSERT_EQ(test::runFieldpath(dir, "check scene.yaml --path plain.cl --out plain").exit_code, 0);
  const auto unmarked = nlohmann::json::parse(test::slurp(dir.path() / "plain" / "check.json"));
  EXPECT_EQ(unmarked["passes"].get<int>(), 1);
  EXPECT_EQ(unmarked["passes_split_at_gaps"].get<int>(), 2);
  EXPECT_NE(unmarked["unsafe"][0].get<std::string>().find("(pass 1, plain.cl:11))"),
            std::string::npos)
      << unmarked["unsafe"];
}

// A missing --path is said first, before the scene's meshes are read (a user's large meshes were
// loaded, and their notes printed, before the missing path was named): here the scene's own
// mesh is missing too, and the one line names the path.
TEST(CheckClearance, AMissingPathIsNamedBeforeTheScenesMeshesAreRead) {
  const TempDir dir;
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: gone.stl\ntool: { shape: ball, radius: 3, length: 40 }\n");
  const auto c = test::runFieldpath(dir, "check scene.yaml --path nothere.cl");
  EXPECT_EQ(c.exit_code, 1) << c.output();
  EXPECT_NE(c.err.find("nothere.cl: no such path file"), std::string::npos) << c.err;
  EXPECT_EQ(c.err.find("gone.stl"), std::string::npos) << c.err;
}
