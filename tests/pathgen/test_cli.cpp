/// The impeller example end to end through the built `fieldpath` binary: golden summary,
/// generate → .cl → check round trip, APT read back, bad scenes → exit 1 naming the pass or key.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using fieldpath::geometry::Posture;

namespace {

const fs::path kScene = fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// stdout and stderr of `fieldpath --quiet ARGS` together (the tests search both).
struct Outcome {
  int exit_code;
  std::string output;
};

Outcome run(const std::string& args) {
  const fieldpath::test::Outcome r = fieldpath::test::runFieldpath(args);
  return {r.exit_code, r.output()};
}

nlohmann::json readJson(const fs::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in);
}

/// The golden answer file: key → (value, tolerance).
std::map<std::string, std::pair<double, double>> readGolden() {
  std::ifstream in(fs::path(FIELDPATH_SOURCE_DIR) / "tests/pathgen/impeller.golden");
  std::map<std::string, std::pair<double, double>> golden;
  std::string line;
  while (std::getline(in, line)) {
    if (line.empty() || line[0] == '#') continue;
    std::istringstream words(line);
    std::string key;
    double value, tolerance;
    words >> key >> value >> tolerance;
    golden[key] = {value, tolerance};
  }
  return golden;
}

/// One generate of the field path and one of the nominal path, shared by the tests.
class ImpellerRun : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / ("fieldpath_test_cli_" + std::to_string(getpid()));
    fs::remove_all(dir_);
    field_ = run("generate '" + kScene.string() + "' --out '" + (dir_ / "field").string() + "'");
    nominal_ = run("generate '" + kScene.string() + "' --nominal --out '" +
                   (dir_ / "nominal").string() + "'");
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }
  static inline fs::path dir_;
  static inline Outcome field_, nominal_;
};

TEST_F(ImpellerRun, MatchesTheGoldenSummary) {
  ASSERT_EQ(field_.exit_code, 0) << field_.output;
  ASSERT_EQ(nominal_.exit_code, 0) << nominal_.output;
  const auto field = readJson(dir_ / "field/report.json");
  const auto nominal = readJson(dir_ / "nominal/report.json");
  const std::map<std::string, double> actual = {
      {"postures", field["pass_postures"].get<double>()},
      {"path_length_mm", field["path_length_mm"].get<double>()},
      {"field.min_clearance_mm", field["clearance"]["min_mm"].get<double>()},
      {"field.max_tilt_deg", field["max_tilt_deg"].get<double>()},
      {"field.max_lead_deg", field["max_lead_deg"].get<double>()},
      {"field.colliding_postures", field["clearance"]["colliding_postures"].get<double>()},
      {"nominal.min_clearance_mm", nominal["clearance"]["min_mm"].get<double>()},
      {"nominal.colliding_postures", nominal["clearance"]["colliding_postures"].get<double>()},
      {"field.colliding_motions", field["motions"]["colliding_motions"].get<double>()},
      {"field.links", field["links"]["links"].get<double>()},
  };
  const auto golden = readGolden();
  ASSERT_EQ(golden.size(), actual.size());
  for (const auto& [key, expected] : golden) {
    ASSERT_TRUE(actual.count(key)) << key;
    EXPECT_NEAR(actual.at(key), expected.first, expected.second) << key;
  }
  // The point of the example: the field path is clear, the nominal one collides.
  EXPECT_TRUE(field["clearance"]["ok"].get<bool>());
  EXPECT_GE(field["clearance"]["min_mm"].get<double>(),
            field["clearance"]["required_mm"].get<double>());
  EXPECT_GT(nominal["clearance"]["colliding_postures"].get<int>(), 0);
  // Critically damped: the steered axis turns smoothly (0.46 deg a 0.5 mm posture at most),
  // far under the turn that generate warns of; the nominal path's axis is the hub normal's.
  EXPECT_LT(field["axis_turn"]["max_deg"].get<double>(), 1.0);
  EXPECT_LT(field["axis_turn"]["max_deg"].get<double>(),
            field["axis_turn"]["note_above_deg"].get<double>());
  EXPECT_EQ(field_.output.find("the tool axis turns"), std::string::npos);
  // Posted as rotary angles (tilt, C) the path strays (2.9 mm at the holder's top where C swings
  // 104 deg for 4.5 deg of axis, high in a link) but nowhere past a motion's clearance.
  EXPECT_GT(field["rotary_angles"]["max_stray_mm"].get<double>(), 0.0);
  EXPECT_EQ(field["rotary_angles"]["motions_stray_past_clearance"].get<int>(), 0);
  EXPECT_EQ(field["rotary_angles"]["motions_stray_under_required"].get<int>(), 0);
  EXPECT_EQ(field_.output.find("may stray past the clearance"), std::string::npos);
  // Run axis by axis, the retracts along tilted axes are not proven clear (41 of 53 rapids on
  // 11-29), and the scene has a part: the note says both.
  const int rapids = field["dog_leg_rapids"]["rapids"].get<int>();
  const int unproven = field["dog_leg_rapids"]["unproven"].get<int>();
  EXPECT_GT(unproven, 0);
  EXPECT_LT(unproven, rapids);
  EXPECT_NE(field_.output.find(std::to_string(unproven) + " of the " + std::to_string(rapids) +
                               " rapid moves are proven clear of the obstacles only when run "
                               "straight"),
            std::string::npos)
      << field_.output;
  EXPECT_NE(field_.output.find("the part is not in that proof"), std::string::npos);
  EXPECT_EQ(field["counts"]["obstacle_points"].get<int>(), 5100);
  // Safe to run: every motion, links included, keeps the clearance; the nominal path's do not.
  EXPECT_TRUE(field["motions"]["ok"].get<bool>());
  EXPECT_GE(field["motions"]["min_mm"].get<double>(),
            field["clearance"]["required_mm"].get<double>());
  EXPECT_GT(nominal["motions"]["colliding_motions"].get<int>(), 0);
  // One link before each pass and one after the last.
  EXPECT_EQ(field["links"]["links"].get<int>(), field["passes"].get<int>() + 1);
}

// generate's reasons name the line of path.cl a posture is written on, as check's name the lines
// of the file it reads: the line the reader gives the first colliding posture of the nominal path.
TEST_F(ImpellerRun, GeneratesReasonsNamePathClLines) {
  ASSERT_EQ(nominal_.exit_code, 0) << nominal_.output;
  const auto report = readJson(dir_ / "nominal/report.json");
  const std::size_t first = report["clearance"]["first_colliding_posture"].get<std::size_t>();
  const fieldpath::geometry::PathFile written =
      fieldpath::geometry::readClPath(dir_ / "nominal/path.cl");
  ASSERT_LT(first, written.lines.size());
  const std::string named =
      "touch an obstacle (first: posture " + std::to_string(first) + " (pass ";
  const std::size_t at = nominal_.output.find(named);
  ASSERT_NE(at, std::string::npos) << nominal_.output;
  // (the posture's own parentheses close there; the passes that touch may follow)
  const std::string line = ", path.cl:" + std::to_string(written.lines[first]) + ")";
  const std::size_t end = nominal_.output.find(')', at + named.size());
  ASSERT_NE(end, std::string::npos) << nominal_.output;
  EXPECT_TRUE(nominal_.output.substr(at, end + 1 - at).ends_with(line)) << nominal_.output;
  EXPECT_NE(nominal_.output.find(line + "; in passes 1 and 7 and links)"), std::string::npos)
      << nominal_.output;
  // The same words at the top of the file.
  std::ifstream in(dir_ / "nominal/path.cl");
  std::string top;
  std::getline(in, top);
  EXPECT_NE(top.find(named), std::string::npos) << top;
  EXPECT_NE(top.find(line), std::string::npos) << top;
}

TEST_F(ImpellerRun, GenerateClCheckRoundTrip) {
  ASSERT_EQ(field_.exit_code, 0) << field_.output;
  const Outcome check =
      run("check '" + kScene.string() + "' --path '" + (dir_ / "field/path.cl").string() +
          "' --spacing 0.1 --backend cpu --out '" + (dir_ / "field").string() + "'");
  ASSERT_EQ(check.exit_code, 0) << check.output;
  const auto generated = readJson(dir_ / "field/report.json");
  const auto checked = readJson(dir_ / "field/check.json");
  // .cl numbers round-trip exactly: the same postures give the same FCL clearance.
  EXPECT_EQ(checked["postures"], generated["postures"]);
  EXPECT_DOUBLE_EQ(checked["clearance"]["min_mm"].get<double>(),
                   generated["clearance"]["min_mm"].get<double>());
  EXPECT_EQ(checked["clearance"]["colliding_postures"].get<int>(), 0);
  // The ball centre follows the offset hub exactly: no gouge beyond the hub mesh's chordal error
  // (the part is its 10 µm mesh; concave facets lie above the true hub by less than that).
  EXPECT_LT(checked["surface"]["max_gouge_um"].get<double>(), 5.0);
  EXPECT_EQ(checked["surface"]["gouged_lines"].get<int>(), 0);
  EXPECT_EQ(checked["motions"]["colliding_motions"].get<int>(), 0);
  EXPECT_EQ(checked["links"], generated["links"]["links"]);
  EXPECT_GT(checked["surface"]["max_scallop_um"].get<double>(), 100.0);
  EXPECT_TRUE(fs::exists(dir_ / "field/deviation.png"));

  const Outcome nominal_check =
      run("check '" + kScene.string() + "' --path '" + (dir_ / "nominal/path.cl").string() +
          "' --spacing 0.2 --backend cpu");
  EXPECT_EQ(nominal_check.exit_code, 0) << nominal_check.output;  // collisions are reported, exit 0
  EXPECT_NE(nominal_check.output.find("COLLISIONS"), std::string::npos) << nominal_check.output;
}

TEST_F(ImpellerRun, AptReadBackEqualsTheClPostures) {
  ASSERT_EQ(field_.exit_code, 0) << field_.output;
  const auto cl = fieldpath::geometry::readClFile(dir_ / "field/path.cl");
  const auto apt = fieldpath::geometry::readAptFile(dir_ / "field/path.apt");
  ASSERT_EQ(apt.size(), cl.size());
  for (std::size_t i = 0; i < cl.size(); ++i) {
    EXPECT_NEAR((apt[i].tip_mm - cl[i].tip_mm).norm(), 0.0, 1e-6) << i;
    EXPECT_NEAR((apt[i].axis - cl[i].axis).norm(), 0.0, 1e-6) << i;
  }
}

/// The example scene with impeller keys replaced (or added when absent), written to a temporary
/// file.
fs::path badScene(const std::string& name, const std::map<std::string, std::string>& keys) {
  std::ifstream in(kScene);
  std::string yaml, line;
  const std::string anchor = "  - impeller:";
  std::map<std::string, std::string> missing = keys;
  while (std::getline(in, line)) {
    for (const auto& [key, value] : keys) {
      if (line.rfind("      " + key + ":", 0) == 0) {
        line = "      " + key + ": " + value;
        missing.erase(key);
      }
    }
    yaml += line + "\n";
  }
  for (const auto& [key, value] : missing) {
    const auto at = yaml.find(anchor + "\n") + anchor.size() + 1;
    yaml.insert(at, "      " + key + ": " + value + "\n");
  }
  const fs::path file = fs::temp_directory_path() /
                        ("fieldpath_bad_" + name + "_" + std::to_string(getpid()) + ".yaml");
  std::ofstream(file) << yaml;
  return file;
}

void expectBadScene(const std::string& name, const std::map<std::string, std::string>& keys,
                    std::initializer_list<std::string> expected) {
  const fs::path scene = badScene(name, keys);
  const fs::path out =
      fs::temp_directory_path() / ("fieldpath_bad_out_" + std::to_string(getpid()));
  const Outcome r = run("generate '" + scene.string() + "' --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;  // one line
  for (const auto& words : expected) EXPECT_NE(r.output.find(words), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "path.cl"));  // no partial outputs
  fs::remove(scene);
  fs::remove_all(out);
}

TEST(BadScenes, ExitOneWithALineNamingThePassOrKey) {
  expectBadScene("cross", {{"lean_left_deg", "[60, 60]"}, {"lean_right_deg", "[60, 60]"}},
                 {"lean_left_deg", "blades cross"});
  expectBadScene("narrow",
                 {{"width_in", "8"},
                  {"width_out", "8"},
                  {"lean_left_deg", "[0, 0]"},
                  {"lean_right_deg", "[0, 0]"}},
                 {"pass 1", "narrower than the ball"});
  expectBadScene("empty", {{"u_range", "[0.5, 0.5]"}}, {"pass 1", "empty"});
  expectBadScene("unknown", {{"spoke", "3"}}, {"obstacles.impeller.spoke", "unknown key"});
}

TEST(BadOptions, VoxelSizeMustBeAPositiveLength) {
  const fs::path out =
      fs::temp_directory_path() / ("fieldpath_bad_opt_" + std::to_string(getpid()));
  for (const char* h : {"0", "-1", "nan", "2mm"}) {
    const Outcome r =
        run("generate '" + kScene.string() + "' --voxel " + h + " --out '" + out.string() + "'");
    EXPECT_EQ(r.exit_code, 1) << h << ": " << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;  // one line
    EXPECT_NE(r.output.find("--voxel"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }
  // The field's options beside --nominal (no field): refused, not ignored.
  for (const char* field : {"--direct", "--voxel 1e9", "--backend cpu"}) {
    const Outcome r = run("generate '" + kScene.string() + "' --nominal " + field + " --out '" +
                          out.string() + "'");
    EXPECT_EQ(r.exit_code, 1) << field << ": " << r.output;
    EXPECT_NE(r.output.find("excludes --nominal"), std::string::npos) << r.output;
    EXPECT_FALSE(fs::exists(out));
  }
}

// --max-memory bounds generate's voxel grid as it bounds `field build`'s (a helper's 10M built a
// 35 MB grid: the grid's request kept a fixed 4 GiB), with what the run holds before it (the
// program ~42 MiB, the path's postures, the meshes: ~55 MiB, the grid estimated at 48).
TEST(BadOptions, TheVoxelGridKeepsToMaxMemory) {
  const fs::path out = fs::temp_directory_path() / ("fieldpath_mem_" + std::to_string(getpid()));
  const Outcome r = run("--max-memory 70M generate '" + kScene.string() + "' --voxel 0.5 --out '" +
                        out.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  EXPECT_NE(r.output.find("voxel field at h = 0.5 mm: candidate leaves hold"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("over what is left ("), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("limit 70 MiB (--max-memory), of which the run holds"), std::string::npos)
      << r.output;
  EXPECT_FALSE(fs::exists(out));
}

}  // namespace

namespace {

// Closed form for the surface check: on a flat straight channel two straight passes 2 d apart
// leave a scallop of height R - sqrt(R² - d²) midway, and nothing below the hub.
TEST(CheckSurface, ScallopBetweenTwoStraightPassesIsClosedForm) {
  const fs::path scene = badScene("flat", {{"width_in", "44"},
                                           {"width_out", "44"},
                                           {"bend", "0"},
                                           {"hub_rise", "0"},
                                           {"hub_dish", "0"},
                                           {"lean_left_deg", "[0, 0]"},
                                           {"lean_right_deg", "[0, 0]"},
                                           {"passes_v", "[0.45, 0.55]"}});
  std::string yaml;
  {
    std::ifstream in(scene);
    std::stringstream text;
    text << in.rdbuf();
    yaml = text.str();
  }
  yaml.replace(yaml.find("  passes: 7"), 11, "  passes: 2");
  std::ofstream(scene) << yaml;
  const fs::path out = fs::temp_directory_path() / ("fieldpath_flat_" + std::to_string(getpid()));
  const Outcome gen =
      run("generate '" + scene.string() + "' --nominal --out '" + out.string() + "'");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  const Outcome check = run("check '" + scene.string() + "' --path '" + (out / "path.cl").string() +
                            "' --spacing 0.02 --backend cpu --out '" + out.string() + "'");
  ASSERT_EQ(check.exit_code, 0) << check.output;
  const auto report = readJson(out / "check.json");
  const double r = 3.0, d = 0.5 * 0.1 * 44.0;  // passes at v = 0.45, 0.55 of 44 mm
  const double scallop_um = 1000.0 * (r - std::sqrt(r * r - d * d));
  // Lines lie within half a spacing of the midline: slope there d / sqrt(R² - d²).
  const double tolerance_um = 1000.0 * 0.01 * d / std::sqrt(r * r - d * d) + 1.0;
  EXPECT_NEAR(report["surface"]["max_scallop_um"].get<double>(), scallop_um, tolerance_um);
  EXPECT_LT(report["surface"]["max_gouge_um"].get<double>(), 0.5);
  EXPECT_EQ(report["clearance"]["colliding_postures"].get<int>(), 0);
  fs::remove(scene);
  fs::remove_all(out);
}

}  // namespace
