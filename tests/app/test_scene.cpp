/// Scene files: every key of DESIGN.md read into the Scene, defaults, paths relative to the file,
/// and bad files rejected with the file, line and key.
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/units.h"
#include "files.h"
#include "job.h"
#include "path_report.h"
#include "progress.h"
#include "scene.h"

using namespace fieldpath;
using app::test::TempDir;

TEST(Scene, ReadsEveryKey) {
  TempDir dir;
  dir.write("meshes/left.stl", app::test::squareStl(10, 0));
  dir.write("meshes/right.stl", app::test::squareStl(10, 5));
  dir.write("meshes/hub.stl", app::test::squareStl(20, -3));
  const auto file = dir.write("jobs/scene.yaml", R"(
obstacles:
  - mesh: ../meshes/left.stl
  - mesh: ../meshes/right.stl
part: ../meshes/hub.stl
tool: { shape: torus, radius: 4, corner_radius: 1, length: 30 }
holder: [[40, 6], [55, 6], [55.5, 12], [90, 12]]
clearance: 0.7
field:
  r0: 6.0
  r_min: 0.3
  gain: 2.5
  sample_step: 0.8
  weights: unit
  voxel_size: 0.4
  interpolation: quadratic
  stored: force
  refine_tolerance: 0.02
  refine_levels: 3
  refine_region: reach
  backend: cpu
dynamics:
  inertia: 2.0
  damping: 3.0
  stiffness: 4.0
  feed: 1200
  rtol: 1.0e-7
  atol: 1.0e-10
  max_tilt_deg: 30
  max_lead_deg: 15
  integrator: erk
  on_limit: fail
  start: settled
path:
  passes: 5
  step: 0.25
  lead_deg: 3
  pass_gap: 2.5
links: { retract: 7, safe_z: 80 }
)");
  const app::Scene s = app::loadScene(file);
  ASSERT_EQ(s.obstacles.size(), 2u);
  EXPECT_EQ(s.obstacle_files[0], dir.path() / "jobs/../meshes/left.stl");
  EXPECT_EQ(s.obstacles[0].triangles.size(), 2u);
  EXPECT_DOUBLE_EQ(s.obstacles[1].vertices[0].z(), 5.0);
  ASSERT_TRUE(s.part.has_value());
  EXPECT_DOUBLE_EQ(s.part->vertices[0].z(), -3.0);
  EXPECT_FALSE(s.impeller.has_value());
  EXPECT_EQ(s.tool.shape, geometry::ToolShape::Torus);
  EXPECT_EQ(s.tool.radius_mm, 4.0);
  EXPECT_EQ(s.tool.corner_radius_mm, 1.0);
  EXPECT_EQ(s.tool.length_mm, 30.0);
  ASSERT_EQ(s.holder.size(), 4u);
  EXPECT_EQ(s.holder[2].z_mm, 55.5);
  EXPECT_EQ(s.holder[2].radius_mm, 12.0);
  EXPECT_EQ(s.clearance_mm, 0.7);
  EXPECT_EQ(s.field.r0_mm, 6.0);
  EXPECT_EQ(s.field.r_min_mm, 0.3);
  EXPECT_EQ(s.field.gain, 2.5);
  EXPECT_EQ(s.field.sample_step_mm, 0.8);
  EXPECT_EQ(s.field.weights, field::Weights::Unit);
  EXPECT_EQ(s.field.voxel.voxel_size_mm, 0.4);
  EXPECT_EQ(s.field.voxel.interpolation, field::Interpolation::Quadratic);
  EXPECT_EQ(s.dynamics.inertia, 2.0);
  EXPECT_EQ(s.dynamics.damping, 3.0);
  EXPECT_EQ(s.dynamics.stiffness, 4.0);
  EXPECT_EQ(s.dynamics.feed_mm_per_min, 1200.0);
  EXPECT_EQ(s.dynamics.rtol, 1e-7);
  EXPECT_EQ(s.dynamics.atol, 1e-10);
  EXPECT_EQ(s.dynamics.max_tilt_deg, 30.0);
  EXPECT_EQ(s.dynamics.max_lead_deg, 15.0);
  EXPECT_EQ(s.dynamics.integrator, dynamics::Integrator::Erk);
  EXPECT_EQ(s.path.passes, 5);
  EXPECT_EQ(s.path.step_mm, 0.25);
  EXPECT_EQ(s.path.lead_deg, 3.0);
  // (a test audit: these keys were read by no test, a user's setting could fall to its default)
  EXPECT_EQ(s.field.voxel.stored, field::StoredQuantity::Force);
  EXPECT_EQ(s.field.voxel.refine_tolerance, 0.02);
  EXPECT_EQ(s.field.voxel.refine_levels, 3);
  EXPECT_EQ(s.field.voxel.refine_region, field::RefineRegion::Reach);
  EXPECT_EQ(s.field.voxel.backend, field::FieldBackend::Cpu);
  EXPECT_EQ(s.dynamics.on_limit, dynamics::LimitPolicy::Fail);
  EXPECT_EQ(s.dynamics.start, dynamics::StartPolicy::Settled);
  EXPECT_EQ(s.path.pass_gap_mm, 2.5);
  EXPECT_EQ(s.links.retract_mm, 7.0);
  ASSERT_TRUE(s.links.safe_z_mm.has_value());
  EXPECT_EQ(*s.links.safe_z_mm, 80.0);
}

// DESIGN writes unit weights as "w_j = 1": `weights: 1` is `unit` (a third party's scene, written
// from DESIGN alone, was refused).
TEST(Scene, WeightsOfOneAreUnitWeights) {
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  const app::Scene s = app::loadScene(
      dir.write("s.yaml", "obstacles:\n  - mesh: wall.stl\nfield: { weights: 1 }\n"));
  EXPECT_EQ(s.field.weights, field::Weights::Unit);
}

TEST(Scene, DefaultsComeFromTheParamsStructs) {
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  const app::Scene s = app::loadScene(
      dir.write("s.yaml", "obstacles:\n  - mesh: wall.stl\ndynamics: { damping: critical }\n"));
  EXPECT_EQ(s.obstacles.size(), 1u);
  EXPECT_FALSE(s.part.has_value());
  const field::FieldParams f;
  EXPECT_EQ(s.field.r0_mm, f.r0_mm);
  EXPECT_EQ(s.field.r_min_mm, f.r_min_mm);
  EXPECT_EQ(s.field.voxel.voxel_size_mm, f.voxel.voxel_size_mm);
  EXPECT_EQ(s.field.weights, f.weights);
  EXPECT_EQ(s.field.voxel.interpolation, f.voxel.interpolation);
  EXPECT_LT(s.dynamics.damping, 0.0);  // critical
  EXPECT_EQ(s.path.passes, pathgen::PathParams{}.passes);
  EXPECT_EQ(s.tool.radius_mm, geometry::ToolSpec{}.radius_mm);
}

namespace {

/// The InputError message of loading `yaml` (beside a valid wall.stl), or "" if it loads.
std::string errorOf(const std::string& yaml, std::string* file_name = nullptr) {
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  const auto file = dir.write("bad.yaml", yaml);
  if (file_name) *file_name = file.string();
  try {
    app::loadScene(file);
  } catch (const common::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Scene, BadFilesNameTheFileLineAndKey) {
  struct Case {
    const char* yaml;
    const char* key;  // in the message
    int line;         // 1-based, 0: no line expected
  };
  const Case cases[] = {
      {"obstacles:\n  - mesh: missing.stl\n", "obstacles[1].mesh", 2},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0: -1\n", "field.r0", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0: 5\n  r_min: 5\n", "field.r_min", 5},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0: 0.2\n", "field.r_min", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  voxel_size: 0\n", "field.voxel_size", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0: five\n", "field.r0", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  weights: volume\n", "field.weights", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  gain: 1\n  rzero: 5\n", "field.rzero", 5},
      {"obstacles:\n  - mesh: wall.stl\ncolour: red\n", "colour", 3},
      {"obstacles:\n  - mesh: wall.stl\nfield: 5\n", "field", 3},
      {"obstacles:\n  - mesh: wall.stl\n    impeller: {}\n", "obstacles[1]", 2},
      {"field:\n  r0: 5\n", "obstacles", 0},
      {"obstacles: []\n", "obstacles: the list is empty", 1},
      // Tolerances of 1 or more accept any step (rtol 1e6 moved the lead 1.6 deg, unsaid).
      {"obstacles:\n  - mesh: wall.stl\ndynamics:\n  rtol: 2\n", "dynamics.rtol: must be in (0, 1)",
       4},
      {"obstacles:\n  - mesh: wall.stl\ndynamics:\n  atol: 1\n", "dynamics.atol: must be in (0, 1)",
       4},
      // A feed past any machine's was written into path.apt as FEDRAT/MMPM,1e+300.
      {"obstacles:\n  - mesh: wall.stl\ndynamics:\n  feed: 1e300\n",
       "dynamics.feed: must be a feed from 0.001 to 1e6 mm/min", 4},
      // A module's refusal names the line of the key it names, not its map's first line.
      {"obstacles:\n  - mesh: wall.stl\ntool:\n  shape: ball\n  radius: 3\n  length: 1\n",
       "tool length", 6},
      {"obstacles:\n  - impeller:\n      length: 80\n      chord_tol: 0\n",
       "obstacles.impeller.chord_tol", 4},
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: torus, radius: 3 }\n", "tool.corner_radius",
       3},
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: cone }\n", "tool.shape", 3},
      // Only a torus has a corner radius of its own: one given to another tool was read past.
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: flat, radius: 3, corner_radius: 1 }\n",
       "tool.corner_radius", 3},
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 3, corner_radius: 1 }\n",
       "tool.corner_radius", 3},
      {"obstacles:\n  - mesh: wall.stl\nholder: [[40, 6], [30, 6]]\n", "holder", 3},
      // Stations counted from 1, as holder[K] is, with the z that fails.
      {"obstacles:\n  - mesh: wall.stl\nholder: [[40, 6], [50, 6], [45, 6]]\n",
       "station 3 (z 45): z must increase", 3},
      // An empty value is reported at its key's line (YAML marks it where the next key starts).
      {"obstacles:\n  - mesh: wall.stl\ntool:\nclearance: 0.5\n", "tool", 3},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0:\n  r_min: 0.2\n", "field.r0", 4},
      {"obstacles:\n  - mesh: wall.stl\ndynamics: { damping: heavy }\n",
       "dynamics.damping: expected a number >= 0 or `critical`, got 'heavy'", 3},
      {"obstacles:\n  - mesh: wall.stl\nfield: { r0: 2, r_min: 3 }\n", "(r_min 3, r0 2)", 3},
      // The spring-damper's constants within 1e-12..1e12: 1e300 over 1e-300 crashed generate,
      // damping 1e-300 settled a pass's start for ever (a diff review's).
      {"obstacles:\n  - mesh: wall.stl\ndynamics: { inertia: 1.0e300 }\n",
       "dynamics.inertia: must be from 1e-12 to 1e12", 3},
      {"obstacles:\n  - mesh: wall.stl\ndynamics: { stiffness: 1.0e-300 }\n",
       "dynamics.stiffness: must be from 1e-12 to 1e12", 3},
      {"obstacles:\n  - mesh: wall.stl\ndynamics: { damping: 1.0e-300 }\n",
       "dynamics.damping: must be 0, from 1e-12 to 1e12, or `critical`", 3},
      {"obstacles:\n  - mesh: wall.stl\nholder: [[40, 6], [50]]\n", "holder[2]", 3},
      // A holder under the tool's cutting end, at loading with its line (it was said with neither
      // file nor key where the tool's mesh was made, a helper's).
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 3, length: 40 }\nholder: "
       "[[-5, "
       "6], [20, 6]]\n",
       "holder: holder starts at z -5 mm, not above the cutting end of the tool (3 mm)", 4},
      {"obstacles:\n  - mesh: wall.stl\nclearance: -0.1\n", "clearance", 3},
      {"obstacles:\n  - mesh: wall.stl\ndynamics:\n  max_tilt_deg: 95\n", "dynamics.max_tilt_deg",
       4},
      {"obstacles:\n  - mesh: wall.stl\ndynamics:\n  integrator: rk4\n", "dynamics.integrator", 4},
      {"obstacles:\n  - mesh: wall.stl\npath:\n  passes: 2.5\n", "path.passes", 4},
      // Finer than a machine's resolution: 8 M postures on 80 mm, minutes without a word.
      {"obstacles:\n  - mesh: wall.stl\npath:\n  step: 0.00001\n", "path.step: must be >= 0.001 mm",
       4},
      {"obstacles:\n  - mesh: wall.stl\npart: hub.stl\n", "part", 3},
      {"obstacles:\n  - mesh: wall.stl\npath: { nominal: none.cl }\n", "path.nominal", 3},
      {"obstacles:\n  - mesh: wall.stl\ndynamics: { on_limit: stop }\n", "dynamics.on_limit", 3},
      {"obstacles:\n  - mesh: wall.stl\nlinks: { retract: -1 }\n", "links.retract", 3},
      // A lead past the lead limit was held at it from the first posture, unsaid.
      {"obstacles:\n  - mesh: wall.stl\npath: { lead_deg: 50 }\n",
       "path.lead_deg: must be within dynamics.max_lead_deg (lead 50 deg, limit 20 deg)", 3},
      // 0: each link's last rapid move ended on the part, at the pass's first posture.
      {"obstacles:\n  - mesh: wall.stl\nlinks: { retract: 0 }\n",
       "links.retract: must be a distance in (0", 3},
      {"obstacles:\n  - mesh: wall.stl\nlinks: { safe_z: high }\n", "links.safe_z", 3},
      {"obstacles:\n  - mesh: wall.stl\nfield: { r0: [5\n", "YAML syntax", 0},
      // A key given twice (YAML keeps one of them without a word), at the top and inside.
      {"obstacles:\n  - mesh: wall.stl\nclearance: 0.5\nclearance: 0.7\n", "clearance", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  r0: 5\n  r0: 6\n", "field.r0", 5},
      // A tool without its shape or radius is not the default tool.
      {"obstacles:\n  - mesh: wall.stl\ntool: {}\n", "tool.shape", 3},
      {"obstacles:\n  - mesh: wall.stl\ntool: { shape: ball }\n", "tool.radius", 3},
      // The same mesh twice would repel twice.
      {"obstacles:\n  - mesh: wall.stl\n  - mesh: ./wall.stl\n", "obstacles[2].mesh", 3},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  gain: -1\n", "field.gain", 4},
      {"obstacles:\n  - mesh: wall.stl\nfield:\n  gain: 1e38\n", "field.gain", 4},
      // A second scene in the file would be ignored (YAML reads the first document).
      {"obstacles:\n  - mesh: wall.stl\n---\nclearance: 0.5\n", "second YAML document", 4},
      {"obstacles:\n  - mesh: wall.stl\n...\nclearance: 0.5\n", "second YAML document", 4},
  };
  for (const Case& c : cases) {
    std::string file;
    const std::string message = errorOf(c.yaml, &file);
    ASSERT_FALSE(message.empty()) << c.yaml;
    EXPECT_EQ(message.rfind(file, 0), 0u) << message;  // starts with the file name
    EXPECT_NE(message.find(c.key), std::string::npos) << message;
    if (c.line > 0)
      EXPECT_NE(message.find(":" + std::to_string(c.line) + ": "), std::string::npos) << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
  }
  EXPECT_NE(errorOf("obstacles:\n  - mesh: wall.stl\nfield: { r0: five }\n").find("five"),
            std::string::npos);
}

TEST(Scene, MissingSceneFile) {
  EXPECT_THROW(app::loadScene("/nonexistent/scene.yaml"), common::InputError);
}

TEST(Scene, ADirectoryIsNoSceneFile) {
  try {
    const app::test::TempDir dir;
    (void)app::loadScene(dir.path());
    ADD_FAILURE() << "a directory was read as a scene";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
}

TEST(Scene, TheSameSurfacesFromTwoFilesAreRefused) {
  // A copy of an obstacle's file would add its field twice, as the same file twice does; a
  // different surface beside it is another obstacle.
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  dir.write("copy.stl", app::test::squareStl(5));
  dir.write("other.stl", app::test::squareStl(6));
  const auto twice =
      dir.write("twice.yaml", "obstacles:\n  - mesh: wall.stl\n  - mesh: copy.stl\n");
  try {
    (void)app::loadScene(twice);
    ADD_FAILURE() << "a copy of an obstacle was read as a second obstacle";
  } catch (const common::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(":3: obstacles[2].mesh"), std::string::npos) << message;
    EXPECT_NE(message.find("obstacles[1].mesh"), std::string::npos) << message;
  }
  const auto two = dir.write("two.yaml", "obstacles:\n  - mesh: wall.stl\n  - mesh: other.stl\n");
  EXPECT_EQ(app::loadScene(two).obstacles.size(), 2u);
}

// The thin-wall note names walls under half the voxel size the job steers with (`generate
// --voxel` or the scene's; none for --direct): it quoted the scene's 0.5 mm beside --voxel 1 (a
// helper's) and spoke of a sample step the samples no longer mind (law.h's thin-wall rule).
TEST(Scene, TheThinWallNoteIsOnTheVoxelSizeSteeredWith) {
  TempDir dir;
  dir.write("plate.stl", app::test::boxStl(0, 0, 0, 10, 10, 0.3));
  const auto file = dir.write("job.yaml", "obstacles:\n  - mesh: plate.stl\n");
  const app::Scene scene = app::loadScene(file);
  auto thin = [&](std::optional<double> voxel_mm) {
    std::string said;
    for (const std::string& note : app::openObstacleNotes(scene, voxel_mm))
      if (note.find("walls down to 0.3 mm") != std::string::npos) said = note;
    return said;
  };
  EXPECT_EQ(thin(0.5), "");  // 0.3 mm is not under half of 0.5
  const std::string at_one = thin(1.0);
  EXPECT_NE(at_one.find("under half the voxel size steered with (1 mm)"), std::string::npos)
      << at_one;
  EXPECT_NE(at_one.find("at most 0.6 mm"), std::string::npos) << at_one;
  EXPECT_EQ(thin(std::nullopt), "");  // --direct: the samples see the wall
}

// A mesh of degenerate triangles only (points on a line) has no surface to repel from: refused,
// naming the key and the file (its field was zero everywhere without a word).
TEST(Scene, AMeshWithNoAreaIsRefused) {
  TempDir dir;
  dir.write("line.stl",
            "solid line\n facet normal 0 0 1\n  outer loop\n   vertex 0 0 0\n   vertex 1 0 0\n"
            "   vertex 2 0 0\n  endloop\n endfacet\nendsolid line\n");
  dir.write("wall.stl", app::test::squareStl(5));
  const auto file = dir.write("job.yaml", "obstacles:\n  - mesh: wall.stl\n  - mesh: line.stl\n");
  try {
    (void)app::loadScene(file);
    ADD_FAILURE() << "a mesh with no area was read";
  } catch (const common::InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(":3: obstacles[2].mesh"), std::string::npos) << message;
    EXPECT_NE(message.find("line.stl: every triangle has zero area"), std::string::npos) << message;
  }
}

// `path.passes` is the parametric impeller's: with a nominal path it was read past (the same
// path.cl). A ball's corner radius equal to its radius says nothing new and is taken.
TEST(Scene, KeysThatDoNotApplyAreRefused) {
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  dir.write("nominal.cl", "0 0 1 0 0 1\n1 0 1 0 0 1\n");
  const auto file =
      dir.write("job.yaml",
                "obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 3, "
                "corner_radius: 3, length: 40 }\npath: { nominal: nominal.cl, passes: 3 }\n");
  const app::Scene scene = app::loadScene(file);
  EXPECT_EQ(scene.tool.radius_mm, 3.0);
  try {
    app::sceneJob(scene);
    ADD_FAILURE() << "path.passes with a nominal path was read past";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("path.passes"), std::string::npos) << e.what();
  }
}

TEST(AxisTurn, TheWarningNamesBothPosturesWhateverTheFileNamesLength) {
  // A path file 300 characters long: both postures named with their lines, the numbers after
  // them (a fixed buffer cut the text and glued the names together).
  geometry::PathFile path;
  path.file = std::string(290, 'd') + "/p.cl";
  auto at = [](double x, double deg) {
    const double r = deg * M_PI / 180.0;
    return geometry::Posture{geometry::Vec3(x, 0, 0),
                             geometry::Vec3(std::sin(r), 0, std::cos(r)), 0.0, false};
  };
  path.postures = {at(0, 0), at(0.5, 0), at(1, 12)};
  path.lines = {3, 4, 123456};
  path.blocks = {{geometry::PathBlock::Kind::Pass, 0, 3}};
  const pathgen::AxisTurn t = pathgen::largestAxisTurn(path, 3.0);
  EXPECT_EQ(t.at, 1u);
  const std::string w = app::axisTurnWarning(path, t);
  const std::string name = path.file.string();
  EXPECT_EQ(w, "the tool axis turns 12.0 deg between postures 1 (" + name + ":4) and 2 (" + name +
                   ":123456), " + [&] {
                     char step[32];
                     std::snprintf(step, sizeof step, "%.2f", t.step_mm);
                     return std::string(step);
                   }() + " mm apart: more than a machine's rotary axes follow at feed (over 10 "
                         "deg between two postures of a pass)");
  // Under 10 deg: nothing said; a pass whose axis never turns still names its first pair.
  path.postures[2] = at(1, 4);
  EXPECT_TRUE(app::axisTurnWarning(path, pathgen::largestAxisTurn(path, 3.0)).empty());
  path.postures[2] = at(1, 0);
  const pathgen::AxisTurn still = pathgen::largestAxisTurn(path, 3.0);
  EXPECT_EQ(still.at, 0u);
  EXPECT_EQ(still.deg, 0.0);
  EXPECT_DOUBLE_EQ(still.step_mm, 0.5);
}

// A posture repeated (the same ball centre as the one before) is dropped from its pass, and
// said (it went unsaid: DESIGN asks for what is kept out of a path to be reported).
TEST(Scene, RepeatedPosturesDroppedAreSaid) {
  TempDir dir;
  dir.write("wall.stl", app::test::squareStl(5));
  dir.write("nominal.cl",
            "0 0 1 0 0 1\n1 0 1 0 0 1\n1 0 1 0 0 1\n2 0 1 0 0 1\n2 0 1 0 0 1\n3 0 1 0 0 1\n");
  const auto file = dir.write("job.yaml",
                              "obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 3, "
                              "length: 40 }\npath: { nominal: nominal.cl }\n");
  const app::Scene scene = app::loadScene(file);
  testing::internal::CaptureStderr();
  const auto job = app::sceneJob(scene);
  const std::string err = testing::internal::GetCapturedStderr();
  ASSERT_EQ(job.passes.size(), 1u);
  EXPECT_NE(err.find("nominal.cl: 2 postures at the ball centre of the one before dropped"),
            std::string::npos)
      << err;
}

namespace fieldpath::app {
namespace {

// The progress line's time left: the stage's pace so far, said once it says something.
TEST(ProgressLine, TheTimeLeftIsTheStagesPaceSoFar) {
  EXPECT_EQ(timeLeftText(94.4, 0.444), "  ~2 min left");  // 118 s at 44.4 % in 94.4 s
  EXPECT_EQ(timeLeftText(10.0, 0.5), "  ~10 s left");
  EXPECT_EQ(timeLeftText(60.0, 0.01 * 2.5), "  ~39 min left");
  EXPECT_EQ(timeLeftText(300.0, 0.02), "  ~4.1 h left");
  // Not before 5 s and 2 % of the stage, nor at its end.
  EXPECT_EQ(timeLeftText(4.9, 0.5), "");
  EXPECT_EQ(timeLeftText(100.0, 0.019), "");
  EXPECT_EQ(timeLeftText(100.0, 1.0), "");
  EXPECT_EQ(timeLeftText(100.0, std::nan("")), "");
  // A stage that began at 35 % of the work: 1.2 % of it in 11 s is the stage's 1.8 %, not yet
  // said (it read "~20 s left" of a stage that had 200 s to go); at 40 % in 20 s, 7.7 % of it.
  EXPECT_EQ(timeLeftText(11.2, 0.362, 0.35), "");
  EXPECT_EQ(timeLeftText(20.0, 0.40, 0.35), "  ~4 min left");
}

}  // namespace
}  // namespace fieldpath::app

// The passes whose postures touch, named in the reason's summary (the first posture alone was
// named, the passes only in report.json: a CAM engineer's mould, 19 passes): up to 8, then how
// many more; a link's said as links.
TEST(JobText, CollidingPassesAreNamed) {
  using geometry::PathBlock;
  geometry::PathFile path;
  path.postures.resize(24);
  std::vector<double> clearance(24, 1.0);
  // Pass 1 [0, 2), link [2, 3), passes 2..11 of two postures each from 3.
  path.blocks = {{PathBlock::Kind::Pass, 0, 2}, {PathBlock::Kind::Link, 2, 3}};
  for (std::size_t b = 3; b + 1 < 24; b += 2)
    path.blocks.push_back({PathBlock::Kind::Pass, b, b + 2});
  EXPECT_EQ(app::collidingPasses(path, clearance), "");
  EXPECT_EQ(app::collidingPasses(path, {}), "");  // not kept: nothing said
  clearance[1] = 0.0;
  EXPECT_EQ(app::collidingPasses(path, clearance), " in pass 1");
  clearance[2] = 0.0;
  clearance[4] = 0.0;  // pass 2
  EXPECT_EQ(app::collidingPasses(path, clearance), " in passes 1 and 2 and links");
  clearance[2] = 1.0;
  for (std::size_t i = 5; i < 24; i += 2) clearance[i] = 0.0;  // passes 3..11
  EXPECT_EQ(app::collidingPasses(path, clearance), " in passes 1, 2, 3, 4, 5, 6, 7, 8 and 3 more");
}

// A link's plunge into a pass posture that touches itself touches because the pass does: the
// reason says so, not the link's keys (a CAM engineer's mould: the holder met a pin at pass 1's
// start, and the hint named links.retract and links.safe_z); a plunge into a clear posture keeps
// the hint.
TEST(JobText, APlungeIntoATouchingPassBlamesThePass) {
  using geometry::PathBlock;
  geometry::PathFile path;
  path.postures.resize(6);
  path.blocks = {{PathBlock::Kind::Link, 0, 2}, {PathBlock::Kind::Pass, 2, 6}};
  pathgen::ClearanceResult c;
  c.clearance_mm = {5, 5, 1, 1, 1, 1};
  pathgen::MotionResult m;
  m.colliding = 1;
  m.first_colliding = 1;  // from the link's last posture into the pass's first
  const std::string hint = "THE LINK'S KEYS";
  std::vector<std::string> reasons = app::unsafeReasons(path, c, m, {}, {}, hint);
  ASSERT_EQ(reasons.size(), 1u);
  EXPECT_NE(reasons[0].find(hint), std::string::npos) << reasons[0];
  c.clearance_mm[2] = 0.0;
  c.colliding = 1;
  c.first_colliding = 2;
  reasons = app::unsafeReasons(path, c, m, {}, {}, hint);
  ASSERT_EQ(reasons.size(), 2u);
  EXPECT_EQ(reasons[1].find(hint), std::string::npos) << reasons[1];
  EXPECT_NE(reasons[1].find("its end in the pass touches too"), std::string::npos) << reasons[1];
}

// A link posture up a pass's first axis meets the obstacle because that axis does: said so, not
// hinted with the links' keys, which do not move it (an oracle's mould: a link coming down pass
// 12's start axis into a rib). One elsewhere (the travel plane) keeps the hint.
TEST(JobText, ALinkUpAPassAxisBlamesTheAxis) {
  using geometry::PathBlock;
  geometry::PathFile path;
  const geometry::Vec3 axis = geometry::Vec3(1, 0, 1).normalized();
  const geometry::Vec3 start(10, 0, 0);
  path.postures.resize(5);
  path.postures[0].tip_mm = start + geometry::Vec3(-30, 0, 40);  // in the travel plane
  path.postures[0].axis = axis;
  path.postures[1].tip_mm = start + 7.5 * axis;  // retract above the start, on its axis
  path.postures[1].axis = axis;
  for (std::size_t k = 2; k < 5; ++k) {
    path.postures[k].tip_mm = start + geometry::Vec3(double(k - 2), 0, 0);
    path.postures[k].axis = axis;
  }
  path.blocks = {{PathBlock::Kind::Link, 0, 2}, {PathBlock::Kind::Pass, 2, 5}};
  pathgen::ClearanceResult c;
  c.clearance_mm = {5, 0, 1, 1, 1};
  c.colliding = 1;
  c.first_colliding = 1;
  const std::string hint = "THE LINK'S KEYS";
  std::vector<std::string> reasons = app::unsafeReasons(path, c, {}, {}, {}, hint);
  ASSERT_EQ(reasons.size(), 1u);
  EXPECT_EQ(reasons[0].find(hint), std::string::npos) << reasons[0];
  EXPECT_NE(reasons[0].find("7.5 mm up the axis of the first posture of its pass (posture 2"),
            std::string::npos)
      << reasons[0];
  // Its pass's start touching too: the pass is the cause.
  c.clearance_mm[2] = 0.0;
  c.colliding = 2;
  reasons = app::unsafeReasons(path, c, {}, {}, {}, hint);
  EXPECT_NE(reasons[0].find("that posture touches too"), std::string::npos) << reasons[0];
  // Off the axis (turned 1 deg): the links' keys place it.
  c.clearance_mm[2] = 1.0;
  c.colliding = 1;
  path.postures[1].axis = geometry::Vec3(1.02, 0, 1).normalized();
  reasons = app::unsafeReasons(path, c, {}, {}, {}, hint);
  EXPECT_NE(reasons[0].find(hint), std::string::npos) << reasons[0];
}

// Colliding postures with an angle at its limit are counted, by angle, in a note (the UNSAFE line
// named the collisions only, and the summary's "N postures held at a limit" did not say they were
// the same ones: an oracle found the limits binding at the corpus's UNSAFE corners, the lead's in
// three of seven). Postures clear, or colliding within the limits, are not counted.
TEST(JobText, CollisionsAtTheAngleLimitsAreCounted) {
  using geometry::PathBlock;
  pathgen::GenerateResult r;
  r.path.postures.resize(5);
  r.path.blocks = {{PathBlock::Kind::Pass, 0, 5}};
  const double deg = geometry::kDegToRad;
  // (lead, tilt, clearance): clear at both limits; colliding at the lead's; at both; within them.
  const double rows[][3] = {
      {20, 35, 1.0}, {0, 10, 0.3}, {-20, 5, 0.0}, {20, -35, 0.0}, {5, 30, 0.0}};
  for (std::size_t i = 0; i < 5; ++i) {
    pathgen::GeneratedPosture g;
    g.lead_rad = rows[i][0] * deg;
    g.tilt_rad = rows[i][1] * deg;
    g.clearance_mm = rows[i][2];
    g.output = i;
    r.postures.push_back(g);
  }
  EXPECT_EQ(app::limitsAtCollisionsNote(r, 20.0, 35.0),
            "2 of the 3 colliding postures have an angle held at its limit (lead at 20 deg "
            "(dynamics.max_lead_deg): 2; tilt at 35 deg (dynamics.max_tilt_deg): 1; first: "
            "posture 2 (pass 1)): the field pushes the axis past the limits there; wider limits "
            "where the machine and the holder allow, or a nominal path with more room there");
  EXPECT_EQ(app::limitsAtCollisionsNote(r, 25.0, 40.0), "");  // none at these limits
  r.postures[4].limited = true;                               // the clamp's own flag counts too
  EXPECT_NE(app::limitsAtCollisionsNote(r, 25.0, 40.0).find("1 of the 3"), std::string::npos);
  r.postures.resize(4);
  EXPECT_EQ(app::limitsAtCollisionsNote(r, 20.0, 35.0).rfind("both colliding postures have", 0),
            0u);
}
