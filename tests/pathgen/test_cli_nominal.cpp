/// Jobs from meshes and a nominal path file through the built `fieldpath`, as a user runs them:
/// the same nominal path as .cl, APT and .npy gives the same path.cl; limits clamped on a stiff
/// scene give a path and a count; bad nominal paths and meshes are one-line errors, no outputs.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/impeller.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using namespace fieldpath;
using geometry::PathBlock;
using geometry::PathFile;
using test::TempDir;

namespace {

const fs::path kImpellerScene = fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// The scene keys shared by these jobs (the impeller example's tool, holder and settings).
std::string sceneText(const std::string& nominal, const std::string& extra = "") {
  return "obstacles:\n  - mesh: blades.stl\npart: hub.stl\n"
         "tool: { shape: ball, radius: 3, length: 40 }\n"
         "holder: [[40, 6], [55, 6], [55, 12], [90, 12]]\nclearance: 0.5\n"
         "path: { nominal: " + nominal + " }\n" + extra;
}

/// The impeller's blades and hub as STL, and its nominal path (from `generate --nominal`) as .cl
/// with its links, APT with RAPID links, and .npy (pass postures only: passes split at the gaps).
class MeshJob : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    const pathgen::Impeller impeller{pathgen::ImpellerParams{}};
    geometry::TriangleMesh blades = impeller.bladeMesh(0);
    const geometry::TriangleMesh right = impeller.bladeMesh(1);
    const int offset = static_cast<int>(blades.vertices.size());
    blades.vertices.insert(blades.vertices.end(), right.vertices.begin(), right.vertices.end());
    for (auto t : right.triangles)
      blades.triangles.push_back(t + Eigen::Vector3i::Constant(offset));
    geometry::saveMesh(blades, dir_->path() / "blades.stl");
    geometry::saveMesh(impeller.hubMesh(), dir_->path() / "hub.stl");
    const auto r = test::runFieldpath(*dir_, "generate '" + kImpellerScene.string() +
                                                 "' --nominal --out nominal_run");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const PathFile run = geometry::readPathFile(dir_->path() / "nominal_run/path.cl");
    geometry::writeClFile(dir_->path() / "nominal.cl", run, "the impeller's nominal path");
    geometry::AptHeader header;
    geometry::writeAptFile(dir_->path() / "nominal.apt", run, header);
    std::vector<geometry::Posture> cutting;
    for (const PathBlock& b : run.blocks)
      if (b.kind == PathBlock::Kind::Pass)
        cutting.insert(cutting.end(), run.postures.begin() + b.begin, run.postures.begin() + b.end);
    geometry::writeNpyFile(dir_->path() / "nominal.npy", cutting);
  }
  static void TearDownTestSuite() { dir_.reset(); }

  /// `generate` of the scene naming `nominal`; path.cl without its first comment line (which
  /// names the scene file).
  static std::string generated(const std::string& nominal, nlohmann::json* report = nullptr) {
    const std::string scene = "scene_" + fs::path(nominal).extension().string().substr(1) + ".yaml";
    dir_->write(scene, sceneText(nominal));
    const std::string out = "out_" + scene;
    const auto r = test::runFieldpath(*dir_, "generate " + scene + " --out " + out);
    EXPECT_EQ(r.exit_code, 0) << r.output();
    if (report) *report = nlohmann::json::parse(test::slurp(dir_->path() / out / "report.json"));
    const std::string text = test::slurp(dir_->path() / out / "path.cl");
    return text.substr(text.find('\n') + 1);
  }
  static inline std::unique_ptr<TempDir> dir_;
};

}  // namespace

TEST_F(MeshJob, ClAptAndNpyNominalPathsGiveTheSamePathBitForBit) {
  nlohmann::json report;
  const std::string from_cl = generated("nominal.cl", &report);
  EXPECT_EQ(generated("nominal.apt"), from_cl);
  EXPECT_EQ(generated("nominal.npy"), from_cl);
  // The job on meshes: 7 passes, the field path clear at every posture and motion, links made.
  EXPECT_EQ(report["passes"].get<int>(), 7);
  EXPECT_EQ(report["clearance"]["colliding_postures"].get<int>(), 0);
  EXPECT_EQ(report["motions"]["colliding_motions"].get<int>(), 0);
  EXPECT_GE(report["motions"]["min_mm"].get<double>(), 0.5);
  EXPECT_EQ(report["links"]["links"].get<int>(), 8);
  EXPECT_NE(from_cl.find("# link"), std::string::npos);
  // Clear everywhere: nothing marks it unsafe.
  EXPECT_TRUE(report["safe"].get<bool>());
  EXPECT_EQ(from_cl.find("UNSAFE"), std::string::npos);
}

// The least links.safe_z accepted (the highest mesh point + clearance) puts the links at exactly
// the clearance, which the checks' own margin (chordal tolerance, motion resolution) may read as
// under it: said, with the least height proven clear; 0.05 mm above that, nothing to say.
TEST_F(MeshJob, ASafeZAtTheLeastAcceptedIsSaid) {
  double top = -HUGE_VAL;
  for (const char* mesh : {"blades.stl", "hub.stl"})
    for (const auto& v : geometry::loadMesh(dir_->path() / mesh).vertices)
      top = std::max(top, v.z());
  const double least = top + 0.5;  // the scene's clearance
  for (const double above : {0.0, 0.05}) {
    std::ostringstream extra;
    extra.precision(17);
    extra << "links: { safe_z: " << least + above << " }\n";
    dir_->write("tight.yaml", sceneText("nominal.cl", extra.str()));
    const auto r = test::runFieldpath(*dir_, "generate tight.yaml --out out_tight");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const std::size_t note = r.err.find("leaves the links within the checks' margin");
    EXPECT_EQ(note != std::string::npos, above == 0.0) << above << ": " << r.err;
  }
}

// The nominal path's `# link` blocks are not cut (links are made anew): said with their size
// and the first one's line, as a `# link` with no `# pass` after its moves takes the cutting
// that follows (a helper's file lost two thirds of its passes without a word).
TEST_F(MeshJob, LinkBlocksOfTheNominalPathAreSaidNotCut) {
  const PathFile nominal = geometry::readPathFile(dir_->path() / "nominal.cl");
  std::size_t blocks = 0, postures = 0, first = 0;
  for (const PathBlock& b : nominal.blocks)
    if (b.kind == PathBlock::Kind::Link) {
      if (blocks++ == 0) first = b.begin;
      postures += b.size();
    }
  ASSERT_GT(blocks, 0u);
  dir_->write("linked.yaml", sceneText("nominal.cl"));
  const auto r = test::runFieldpath(*dir_, "generate linked.yaml --out out_linked");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const std::string said = fs::path(nominal.where(first)).filename().string() + ": " +
                           std::to_string(postures) + " postures in " + std::to_string(blocks) +
                           " `# link` blocks";
  EXPECT_NE(r.err.find(said), std::string::npos) << said << "\n" << r.err;
}

// A setting refused below the app (links.safe_z under the meshes, found once they are read)
// names the scene's file and the key's line, as the scene's own checks do.
TEST_F(MeshJob, ASettingRefusedByTheJobNamesItsLine) {
  const std::string text = sceneText("nominal.cl", "links:\n  retract: 2\n  safe_z: -50\n");
  dir_->write("low.yaml", text);
  const int line =
      1 + static_cast<int>(std::count(text.begin(),
                                      text.begin() + static_cast<long>(text.find("safe_z")), '\n'));
  const auto r = test::runFieldpath(*dir_, "generate low.yaml --out out_low");
  EXPECT_EQ(r.exit_code, 1) << r.output();
  EXPECT_NE(r.err.find("low.yaml:" + std::to_string(line) + ": links.safe_z: "), std::string::npos)
      << r.err;
  EXPECT_FALSE(std::filesystem::exists(dir_->path() / "out_low" / "path.cl"));
}

TEST_F(MeshJob, BladesWoundAwayFromThePassesAreTurnedToFaceThem) {
  // The blades are open sheets: wound the other way their field would pull the tool into them.
  // Turned before sampling, the job is the same, bit for bit.
  const std::string expected = generated("nominal.cl");
  geometry::TriangleMesh flipped = geometry::loadMesh(dir_->path() / "blades.stl");
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  geometry::saveMesh(flipped, dir_->path() / "blades_away.stl");
  std::string scene = sceneText("nominal.cl");
  scene.replace(scene.find("blades.stl"), 10, "blades_away.stl");
  dir_->write("away.yaml", scene);
  const auto r = test::runFieldpath(*dir_, "generate away.yaml --out out_away");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  EXPECT_NE(r.err.find("open obstacle surfaces faced away from the passes"), std::string::npos)
      << r.out;
  const std::string text = test::slurp(dir_->path() / "out_away/path.cl");
  EXPECT_EQ(text.substr(text.find('\n') + 1), expected);
}

TEST_F(MeshJob, ACollidingPathIsMarkedUnsafeWhereTheMachineReadsIt) {
  // The nominal path hits the blades with the shank (README): SetUpTestSuite's `generate
  // --nominal` wrote it. Marked before the first motion in both files, and in report.json.
  const fs::path run = dir_->path() / "nominal_run";
  const auto report = nlohmann::json::parse(test::slurp(run / "report.json"));
  const int colliding = report["clearance"]["colliding_postures"].get<int>();
  ASSERT_GT(colliding, 0);
  EXPECT_FALSE(report["safe"].get<bool>());
  ASSERT_FALSE(report["unsafe"].empty());
  const std::string reason = report["unsafe"][0].get<std::string>();
  EXPECT_NE(reason.find(std::to_string(colliding)), std::string::npos) << reason;

  std::istringstream cl(test::slurp(run / "path.cl"));
  bool marked = false;
  for (std::string line; std::getline(cl, line);) {
    if (line.empty() || line[0] != '#') break;  // the first posture: the mark must come before
    marked = marked || line.rfind("# UNSAFE TO RUN: " + reason, 0) == 0;
  }
  EXPECT_TRUE(marked) << "path.cl has no '# UNSAFE TO RUN: " << reason << "' before its postures";

  std::istringstream apt(test::slurp(run / "path.apt"));
  bool partno = false, pprint = false;
  for (std::string line; std::getline(apt, line);) {
    if (line.rfind("GOTO", 0) == 0 || line.rfind("RAPID", 0) == 0) break;
    partno = partno || line.rfind("PARTNO", 0) == 0;
    pprint = pprint || (partno && line.rfind("PPRINT/UNSAFE TO RUN: ", 0) == 0);
  }
  EXPECT_TRUE(pprint) << "path.apt has no PPRINT/UNSAFE TO RUN after PARTNO, before its motions";
  // The APT reader reads the remark past: the same postures as the .cl.
  EXPECT_EQ(geometry::readPathFile(run / "path.apt").postures.size(),
            geometry::readPathFile(run / "path.cl").postures.size());
}

TEST_F(MeshJob, CheckComparesWithThePartMesh) {
  generated("nominal.cl");
  const auto r = test::runFieldpath(
      *dir_, "check scene_cl.yaml --path out_scene_cl.yaml/path.cl --spacing 0.2 --out checked");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const auto check = nlohmann::json::parse(test::slurp(dir_->path() / "checked/check.json"));
  EXPECT_EQ(check["motions"]["colliding_motions"].get<int>(), 0);
  EXPECT_GT(check["surface"]["band_lines"].get<int>(), 10000);
  EXPECT_EQ(check["surface"]["gouged_lines"].get<int>(), 0);
  EXPECT_GT(check["surface"]["max_scallop_um"].get<double>(), 100.0);
  EXPECT_TRUE(fs::exists(dir_->path() / "checked/deviation.png"));
  EXPECT_TRUE(fs::exists(dir_->path() / "checked/clearance.csv"));
  // A spacing wider than the surface is the option's error (it was a grid "outside any
  // machine"), before any output.
  const auto wide = test::runFieldpath(
      *dir_, "check scene_cl.yaml --path out_scene_cl.yaml/path.cl --spacing 1e6 --out wide");
  EXPECT_EQ(wide.exit_code, 1) << wide.output();
  EXPECT_NE(wide.output().find("--spacing"), std::string::npos) << wide.output();
  EXPECT_FALSE(fs::exists(dir_->path() / "wide"));
}

TEST_F(MeshJob, BadNominalPathsAndMeshesAreOneLineErrorsWithNoOutputs) {
  dir_->write("one.cl", "0 0 0 0 0 1\n");
  dir_->write("twice.cl",
              "0 -8 0 0 0 1\n1 -8 0 0 0 1\n2 -8 0 0 0 1\n# pass\n5 0 1 0 0 1\n5 0 1 0 0 1\n");
  dir_->write("plunge.cl", "0 -8 0 1 0 0\n1 -8 0 1 0 0\n2 -8 0 1 0 0\n");
  dir_->write("empty.stl", "solid empty\nendsolid empty\n");
  struct Case {
    std::string scene, expected;
  };
  const Case cases[] = {
      {sceneText("one.cl"), "one.cl:1"},
      {sceneText("twice.cl"), "twice.cl:5"},
      {sceneText("plunge.cl"), "plunge.cl:1"},
      {sceneText("missing.cl"), "missing.cl"},
      {"obstacles:\n  - mesh: empty.stl\npart: hub.stl\npath: { nominal: nominal.cl }\n",
       "empty.stl"},
      {"obstacles:\n  - mesh: blades.stl\npart: nothere.stl\npath: { nominal: nominal.cl }\n",
       "nothere.stl"},
      // A torus: the passes are a ball's (the line of `shape` named).
      {"obstacles:\n  - mesh: blades.stl\ntool:\n  shape: torus\n  radius: 3\n"
       "  corner_radius: 1\npath: { nominal: nominal.cl }\n",
       "bad.yaml:4: tool.shape: the passes are for a ball-end mill"},
  };
  for (const Case& c : cases) {
    dir_->write("bad.yaml", c.scene);
    fs::remove_all(dir_->path() / "bad_out");
    const auto r = test::runFieldpath(*dir_, "generate bad.yaml --out bad_out");
    const std::string output = r.output();
    EXPECT_EQ(r.exit_code, 1) << c.expected << ": " << output;
    EXPECT_EQ(std::count(output.begin(), output.end(), '\n'), 1) << output;
    EXPECT_NE(output.find(c.expected), std::string::npos) << output;
    EXPECT_FALSE(fs::exists(dir_->path() / "bad_out")) << c.expected;
  }
}

// A stiff scene whose tilt rings (damped for the spring alone) into max_lead_deg: with on_limit
// clamp (the default) a path and a count of the postures held at the limit; with fail, exit 1
// naming the pass and no outputs.
TEST(StiffScene, ClampGivesAPathAndACountFailStops) {
  TempDir dir;
  std::string scene = test::slurp(kImpellerScene);
  auto set = [&](const std::string& key, const std::string& value) {
    const auto at = scene.find(key + ":");
    ASSERT_NE(at, std::string::npos) << key;
    const auto end = scene.find_first_of("#\n", at);
    scene.replace(at, end - at, key + ": " + value + " ");
  };
  set("width_out", "18");
  set("passes_v", "[0.3, 0.75]");  // the ball still fits the narrower outlet
  set("stiffness", "100");
  set("inertia", "1e-4");
  set("gain", "50");
  set("damping", "0.2");  // 2 sqrt(kJ): critical for the spring alone, the field's stiffness rings
  dir.write("stiff.yaml", scene);
  const auto clamp = test::runFieldpath(dir, "generate stiff.yaml --out clamp");
  ASSERT_EQ(clamp.exit_code, 0) << clamp.output();
  const auto report = nlohmann::json::parse(test::slurp(dir.path() / "clamp/report.json"));
  EXPECT_GT(report["limits"]["limited_postures"].get<int>(), 0);
  EXPECT_FALSE(report["limits"]["first_limited"].is_null());
  EXPECT_LE(report["max_lead_deg"].get<double>(), 20.0 + 1e-9);
  EXPECT_LE(report["max_tilt_deg"].get<double>(), 35.0 + 1e-9);
  EXPECT_NE(test::slurp(dir.path() / "clamp/path.cl").find("# limit"), std::string::npos);
  // check reads the marks and says whether those postures collide.
  const auto checked =
      test::runFieldpath(dir, "check stiff.yaml --path clamp/path.cl --spacing 0.3");
  ASSERT_EQ(checked.exit_code, 0) << checked.output();
  EXPECT_NE(checked.out.find("held at an angle limit"), std::string::npos) << checked.out;

  scene += "\n";
  set("max_lead_deg", "20\n  on_limit: fail");
  dir.write("stiff.yaml", scene);
  const auto fail = test::runFieldpath(dir, "generate stiff.yaml --out fail");
  EXPECT_EQ(fail.exit_code, 1) << fail.output();
  EXPECT_NE(fail.output().find("pass "), std::string::npos) << fail.output();
  EXPECT_FALSE(fs::exists(dir.path() / "fail"));
}
