/// `fieldpath view` as a user runs it: the page's data agrees with `check` (counts, per-posture
/// flags), bad input is exit 1 with one line or a page that says what is missing (the page in a
/// browser: test_view_browser.cpp).
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "files.h"
#include "view_data.h"
#include "view_pages.h"

using namespace fieldpath::app::test::view;  // fs, json, the files.h helpers

TEST(View, PageAgreesWithCheckJson) {
  const TempDir dir;
  writeBlockScene(dir);
  const Outcome check = runFieldpath(dir, "check scene.yaml --path path.cl --out chk");
  ASSERT_EQ(check.exit_code, 0) << check.output();
  const json report = json::parse(slurp(dir.path() / "chk/check.json"));
  const std::size_t colliding = report["clearance"]["colliding_postures"];
  const std::size_t motions = report["motions"]["colliding_motions"];
  ASSERT_GT(colliding, 0u);  // the block stands in pass 1's way
  ASSERT_LT(colliding, 40u);

  // From the check folder (the path named by its check.json), and computed by view itself.
  for (const std::string args : {"--check chk", "--path path.cl"}) {
    const Outcome r = runFieldpath(dir, "view scene.yaml " + args + " --out v.html");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const std::string html = slurp(dir.path() / "v.html");
    const json meta = pageMeta(html);
    const json& counts = meta["path"]["counts"];
    EXPECT_EQ(counts["postures"], 82) << args;
    EXPECT_EQ(counts["passes"], 2);
    EXPECT_EQ(counts["links"], 1);
    EXPECT_EQ(counts["colliding_postures"], colliding) << args;
    EXPECT_EQ(counts["colliding_motions"], motions) << args;
    EXPECT_EQ(counts["limited"], 1);
    const auto flags = pageFlags(html, meta);
    ASSERT_EQ(flags.size(), 82u);
    EXPECT_EQ(countBit(flags, 4), colliding);
    EXPECT_EQ(countBit(flags, 8), motions);
    EXPECT_EQ(countBit(flags, 2), 1u);
    EXPECT_EQ(countBit(flags, 1), 2u);  // the link's postures
    EXPECT_TRUE(meta["missing"].empty());
    // The collisions in the banner too: the one warning.
    ASSERT_EQ(meta["warnings"].size(), 1u) << meta["warnings"];
    EXPECT_EQ(meta["warnings"][0].get<std::string>(),
              "UNSAFE TO RUN: " + std::to_string(colliding) + " postures and " +
                  std::to_string(motions) + " motions touch an obstacle (red on the path)");
    // The scene's passes give the frames: the axis stays on the nominal one.
    EXPECT_NE(meta["path"]["angles_source"].get<std::string>().find("frames of the scene's passes"),
              std::string::npos);
    // check --out wrote deviation.npy: the surface comes with the check folder.
    EXPECT_EQ(meta["surface"].is_null(), args != "--check chk") << args;
    EXPECT_LT(html.size(), 15u << 20);
  }
}

// A path longer than --max-postures: the slider shows every k-th posture and still every
// colliding one, both ends of each colliding motion and each block's ends (a test audit: every
// other page test showed all its postures; dropping the clause that keeps flagged postures lost
// the red marks on long paths).
TEST(View, ALongPathShownEveryKthKeepsEveryCollisionAndBlockEnd) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k < 400; ++k) path << -9.975 + 0.05 * k << " 0 0 0 0 1\n";
  path << "# link\n9.975 0 15 0 0 1\n-9.975 8 15 0 0 1\n# pass 2\n";
  for (int k = 0; k < 400; ++k) path << -9.975 + 0.05 * k << " 8 0 0 0 1\n";
  dir.write("long.cl", path.str());
  const Outcome r =
      runFieldpath(dir, "view scene.yaml --path long.cl --max-postures 100 --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const std::string html = slurp(dir.path() / "v.html");
  const json meta = pageMeta(html);
  const json& counts = meta["path"]["counts"];
  ASSERT_EQ(counts["postures"], 802);
  const std::size_t colliding = counts["colliding_postures"], motions = counts["colliding_motions"];
  ASSERT_GT(colliding, 10u);  // the block stands in pass 1's way
  const auto flags = pageFlags(html, meta);
  const auto index = pageArray<std::uint32_t>(html, meta, "index");
  ASSERT_EQ(index.size(), flags.size());
  EXPECT_LT(flags.size(), 802u - colliding);  // every k-th: fewer than all
  EXPECT_GT(flags.size(), 100u);              // the flagged ones on top of the 100
  EXPECT_EQ(countBit(flags, 4), colliding);
  EXPECT_EQ(countBit(flags, 8), motions);
  for (std::size_t j = 0; j + 1 < index.size(); ++j) {
    EXPECT_LT(index[j], index[j + 1]);
    if (flags[j] & 8) EXPECT_EQ(index[j + 1], index[j] + 1) << "colliding motion at " << index[j];
  }
  // Each block's first and last posture (pass 1: 0, 399; the link: 400, 401; pass 2: 402, 801).
  for (std::uint32_t end : {0u, 399u, 400u, 401u, 402u, 801u})
    EXPECT_NE(std::find(index.begin(), index.end(), end), index.end()) << end;
}

// A path with a few postures far outside the scene (a home position, a tool change) is shown
// with a warning; most of them outside is refused (another scene's path).
TEST(View, AFewPosturesOutsideTheSceneAreShownWithAWarning) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  // Passes running on 25 mm past the floor's edge (x 20): 60 of 80 pass postures off the part, a
  // path for it all the same.
  dir.write("runoff.cl", pathCl(25));
  EXPECT_EQ(runFieldpath(dir, "view scene.yaml --path runoff.cl --out r.html").exit_code, 0);
  // A cutting posture far out is warned of in the banner; a link posture far out (a home
  // position, or generate's link climbing a steep axis to safe_z) is a note beside the page.
  for (const bool in_link : {false, true}) {
    dir.write("home.cl", pathCl() + (in_link ? "# link\n" : "") + "0 0 10000 0 0 1\n");
    const Outcome r = runFieldpath(dir, "view scene.yaml --path home.cl --out v.html");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const json meta = pageMeta(slurp(dir.path() / "v.html"));
    EXPECT_EQ(meta["path"]["counts"]["postures"], 83);
    const auto says = [&meta](const char* list, const std::string& text) {
      bool said = false;
      for (const auto& w : meta[list])
        said = said || w.get<std::string>().find(text) != std::string::npos;
      return said;
    };
    EXPECT_EQ(says("warnings", "postures lie more than"), !in_link) << meta["warnings"];
    EXPECT_EQ(says("notes", "link postures lie more than"), in_link) << meta["notes"];
    if (!in_link)
      EXPECT_TRUE(says("warnings", "1 of 81 cutting postures lie more than")) << meta["warnings"];
  }
}

// Given --path, view shows it beside a scene whose own path.nominal is gone, as check reads it
// (a helper's: view alone refused); the note says the passes' angles are not known. Without
// --path, the scene's nominal path is the one shown: its absence is still exit 1.
TEST(View, ShowsItsPathBesideASceneWhoseNominalIsGone) {
  const TempDir dir;
  writeBlockScene(dir);  // path: { nominal: path.cl }
  std::filesystem::rename(dir.path() / "path.cl", dir.path() / "other.cl");
  const Outcome r = runFieldpath(dir, "view scene.yaml --path other.cl --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const json meta = pageMeta(slurp(dir.path() / "v.html"));
  EXPECT_EQ(meta["path"]["counts"]["postures"], 82);
  ASSERT_FALSE(meta["notes"].empty());
  EXPECT_NE(meta["notes"][0].get<std::string>().find("path.nominal is not read"), std::string::npos)
      << meta["notes"];
  const Outcome none = runFieldpath(dir, "view scene.yaml --out w.html");
  EXPECT_EQ(none.exit_code, 1) << none.output();
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "w.html"));
}

TEST(View, BadInputIsExitOneWithOneLineOrAPageThatSaysWhatIsMissing) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  dir.write("far.cl", pathCl(1e4));
  // Passes 10 mm off the floor's side (y 30): within the scene's margin (14.2 mm, a quarter of
  // its diagonal), but every pass posture more than 7 mm off the floor (the part) it finishes
  // (5 mm and the ball's diameter): an inch file over a small part (a helper's) was shown.
  // Passes that run on past the part's edge, most of them off it, are shown (a regression
  // hunt's: 86 of 142 off a part they cut).
  {
    std::ostringstream off;
    off << "# pass 1\n";
    for (int k = 0; k < 40; ++k) off << -9.75 + 0.5 * k << " 30 0 0 0 1\n";
    off << "# link\n9.75 30 15 0 0 1\n-9.75 32 15 0 0 1\n# pass 2\n";
    for (int k = 0; k < 40; ++k) off << -9.75 + 0.5 * k << " 32 0 0 0 1\n";
    dir.write("off.cl", off.str());
  }
  dir.write("short.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  ASSERT_EQ(runFieldpath(dir, "check scene.yaml --path short.cl --out chk_short").exit_code, 0);
  // The same file, edited after its check (same name, same posture count): the check is stale.
  dir.write("edited.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  ASSERT_EQ(runFieldpath(dir, "check scene.yaml --path edited.cl --out chk_edited").exit_code, 0);
  dir.write("edited.cl", "0 0 0 0 0 1\n1 0 -5 0 0 1\n");
  fs::create_directories(dir.path() / "empty");
  struct Case {
    std::string args, message;
  };
  const Case cases[] = {
      {"--path far.cl", "a path for another scene?"},
      {"--path off.cl", "all 80 pass postures lie more than 7 mm outside the part's box"},
      {"--path path.cl --surface nowhere", "--surface nowhere: no such folder"},
      {"--path path.cl --surface empty", "neither deviation.npy"},
      {"--path path.cl --check nowhere", "--check nowhere: no such folder"},
      {"--path path.cl --check empty", "no check.json"},
      {"--path path.cl --check chk_short", "a check of 2 postures"},
      {"--path edited.cl --check chk_edited", "has changed since it was checked"},
      {"--path missing.cl", "missing.cl"},
  };
  for (const Case& c : cases) {
    const Outcome r = runFieldpath(dir, "view scene.yaml " + c.args + " --out bad.html");
    EXPECT_EQ(r.exit_code, 1) << c.args << ": " << r.output();
    EXPECT_TRUE(oneLine(r.err)) << c.args << ": " << r.err;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << c.args << ": " << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "bad.html")) << c.args;
  }
  // The page written over its own path or scene: refused, both left as they were.
  const std::string path_before = slurp(dir.path() / "short.cl");
  for (const std::string& out : {"short.cl", "scene.yaml"}) {
    const Outcome o = runFieldpath(dir, "view scene.yaml --path short.cl --out " + out);
    EXPECT_EQ(o.exit_code, 1) << o.output();
    EXPECT_NE(o.err.find("--out"), std::string::npos) << o.err;
  }
  EXPECT_EQ(slurp(dir.path() / "short.cl"), path_before);

  // A truncated deviation.npy.
  ASSERT_EQ(runFieldpath(dir, "check scene.yaml --path path.cl --out chk").exit_code, 0);
  fs::resize_file(dir.path() / "chk/deviation.npy",
                  fs::file_size(dir.path() / "chk/deviation.npy") - 8);
  Outcome r = runFieldpath(dir, "view scene.yaml --check chk --out bad.html");
  EXPECT_EQ(r.exit_code, 1) << r.output();
  EXPECT_NE(r.err.find("truncated or padded"), std::string::npos) << r.err;

  // check's files padded far past their size (NUL bytes: a helper's 10 GB check.json was read
  // whole for 96 s and parsed up to its first NUL): refused by their size, at once.
  ASSERT_EQ(runFieldpath(dir, "check scene.yaml --path path.cl --out padded").exit_code, 0);
  for (const char* name : {"check.json", "clearance.csv"}) {
    fs::remove_all(dir.path() / "sized");
    fs::copy(dir.path() / "padded", dir.path() / "sized");
    fs::resize_file(dir.path() / "sized" / name, std::uintmax_t{1} << 30);
    r = runFieldpath(dir, "view scene.yaml --check sized --out bad.html");
    EXPECT_EQ(r.exit_code, 1) << name << ": " << r.output();
    EXPECT_NE(r.err.find(std::string(name) + ": 1 GiB"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "bad.html"));
  }

  // A simulated surface whose .json was edited to lie beyond any machine (1e300 mm).
  ASSERT_EQ(runFieldpath(dir, "simulate --tool ball:1 --path short.cl --grid 32x32 --out sim")
                .exit_code,
            0);
  dir.write("sim/heights.json", R"({"origin":[1e300,0],"spacing":[0.1,0.1],"shape":[32,32]})");
  r = runFieldpath(dir, "view scene.yaml --path path.cl --surface sim --out bad.html");
  EXPECT_EQ(r.exit_code, 1) << r.output();
  EXPECT_TRUE(oneLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("heights.json: origin, spacing: the grid reaches beyond"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir.path() / "bad.html"));

  // Without three.js there is no page: one line naming the package.
  ::setenv("FIELDPATH_THREE_DIR", (dir.path() / "no-three").c_str(), 1);
  r = runFieldpath(dir, "view scene.yaml --path path.cl --out bad.html");
  ::unsetenv("FIELDPATH_THREE_DIR");
  EXPECT_EQ(r.exit_code, 1) << r.output();
  EXPECT_TRUE(oneLine(r.err)) << r.err;
  EXPECT_NE(r.err.find("libjs-three"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir.path() / "bad.html"));

  // No path at all: the page shows the scene and says what is missing.
  r = runFieldpath(dir, "view scene.yaml --out nopath.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  EXPECT_NE(r.out.find("missing: No path"), std::string::npos) << r.out;
  const json meta = pageMeta(slurp(dir.path() / "nopath.html"));
  EXPECT_TRUE(meta["path"].is_null());
  ASSERT_EQ(meta["missing"].size(), 1u);
  EXPECT_NE(meta["missing"][0].get<std::string>().find("No path"), std::string::npos);
}

TEST(View, TiltLeadAndArcLengthAgreeWithGenerate) {
  // A wall beside one pass: the field tilts the tool away from it.
  const TempDir dir;
  dir.write("wall.stl", boxStl(-12, 2.2, -1, 12, 4, 6));
  dir.write("floor.stl", squareStl(20, 0));
  std::ostringstream nominal;
  for (int k = 0; k < 41; ++k) nominal << -10 + 0.5 * k << " 0 0 0 0 1\n";
  dir.write("nominal.cl", nominal.str());
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\npart: floor.stl\n"
            "tool: { shape: ball, radius: 1, length: 10 }\nclearance: 0.2\n"
            "path: { nominal: nominal.cl }\n");
  Outcome r = runFieldpath(dir, "generate scene.yaml --direct --out gen");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  r = runFieldpath(dir, "view scene.yaml --path gen/path.cl --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const std::string html = slurp(dir.path() / "v.html");
  const json meta = pageMeta(html);
  const std::string blob = base64Decode(
      between(html, "<script type=\"application/octet-stream\" id=\"fp-blob\">", "</script>"));
  auto floats = [&](const char* key) {
    const json ref = meta["path"][key];
    std::vector<float> v(ref["count"].get<std::size_t>());
    std::memcpy(v.data(), blob.data() + ref["offset"].get<std::size_t>(), v.size() * sizeof(float));
    return v;
  };
  const auto tilt = floats("tilt_deg"), lead = floats("lead_deg"), s = floats("s_mm");
  std::istringstream csv(slurp(dir.path() / "gen/angles.csv"));
  std::string line;
  std::getline(csv, line);
  ASSERT_EQ(line, "s_mm,pass,lead_deg,tilt_deg,moment,nearest_mm,posture,limited");
  double max_tilt = 0;
  int rows = 0;
  while (std::getline(csv, line)) {
    std::vector<double> cells;
    std::istringstream in(line);
    for (std::string cell; std::getline(in, cell, ',');)
      cells.push_back(cell.empty() ? NAN : std::stod(cell));
    const std::size_t i = static_cast<std::size_t>(cells[6]);
    ASSERT_LT(i, tilt.size());
    EXPECT_NEAR(tilt[i], cells[3], 1e-4) << "posture " << i;
    EXPECT_NEAR(lead[i], cells[2], 1e-4) << "posture " << i;
    EXPECT_NEAR(s[i], cells[0], 1e-3) << "posture " << i;
    max_tilt = std::max(max_tilt, std::abs(cells[3]));
    ++rows;
  }
  EXPECT_EQ(rows, 41);
  EXPECT_GT(max_tilt, 1.0);  // the wall did tilt the tool
}

// A simulated surface's lines that no pass cut are greyed (the page's uncut marker) from the
// stock simulate.json records, not from the highest height: in a zoom that every pass reaches
// (11 passes 1 mm apart under a ball R 3, every line lowered), the highest lines are the cusps
// between passes and postures, cut (they read as uncut before: a helper's finding); a region
// reaching past the passes keeps its uncut corners grey.
TEST(View, ASimulatedZoomCutEverywhereHasNoUncutLines) {
  const TempDir dir;
  dir.write("floor.stl", squareStl(30, 0));
  dir.write("block.stl", boxStl(60, 60, 0, 70, 70, 10));
  std::ostringstream cl;
  for (int k = 0; k <= 10; ++k) {
    cl << "# pass " << k + 1 << "\n";
    for (int i = 0; i <= 40; ++i) cl << 0.5 * i << ' ' << k << " 0 0 0 1\n";
  }
  dir.write("flat.cl", cl.str());
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: block.stl\npart: floor.stl\n"
            "tool: { shape: ball, radius: 3, length: 20 }\nclearance: 0.5\n");
  auto values = [&](const std::string& region) {
    const std::string sim = "sim" + std::to_string(region.size());
    const Outcome s = runFieldpath(dir,
                                   "--quiet simulate --tool ball:3 --path flat.cl --stock 1 "
                                   "--grid 200x100 --region " +
                                       region + " --out " + sim);
    EXPECT_EQ(s.exit_code, 0) << s.output();
    const Outcome v = runFieldpath(
        dir, "--quiet view scene.yaml --path flat.cl --surface " + sim + " --out " + sim + ".html");
    EXPECT_EQ(v.exit_code, 0) << v.output();
    return surfaceValues(slurp(dir.path() / (sim + ".html")));
  };
  const auto [zoom, marker] = values("0,0,20,10");
  ASSERT_EQ(zoom.size(), 20000u);
  EXPECT_EQ(std::count_if(zoom.begin(), zoom.end(), [&](float v) { return v >= marker; }), 0);
  // The highest point left: midway between passes (0.5 mm off each) and postures (0.25 mm),
  // R - sqrt(R² - 0.5² - 0.25²) = 46.4 um; the lines sit at or beside it.
  const double cusp_um = 1000.0 * (3.0 - std::sqrt(9.0 - 0.25 - 0.0625));
  EXPECT_GT(*std::max_element(zoom.begin(), zoom.end()), 40.0);
  EXPECT_LE(*std::max_element(zoom.begin(), zoom.end()), cusp_um + 0.01);
  const auto [wide, wide_marker] = values("-10,-10,30,20");
  EXPECT_GT(std::count_if(wide.begin(), wide.end(), [&](float v) { return v >= wide_marker; }), 0);
  EXPECT_GE(wide.front(), wide_marker);  // the corner (-10, -10): 7 mm from the nearest tip
}

// The surface stands where simulate cut it: a plunge at (5, -3) on a grid whose origin is not
// on its diagonal (x0 != y0, dx != dy), its deepest line at x0 + (ix + 0.5) dx, y0 + (iy + 0.5) dy
// (DESIGN's height map) on the page (a test audit: x0 and y0 swapped, or the half line dropped,
// passed every test: their grids had x0 == y0).
TEST(View, TheSurfaceStandsWhereSimulateCutIt) {
  const TempDir dir;
  dir.write("floor.stl", squareStl(30, 0));
  dir.write("block.stl", boxStl(60, 60, 0, 70, 70, 10));
  dir.write("plunge.cl", "5 -3 -0.5 0 0 1\n");
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: block.stl\npart: floor.stl\n"
            "tool: { shape: ball, radius: 2, length: 20 }\nclearance: 0.5\n");
  ASSERT_EQ(runFieldpath(dir,
                         "--quiet simulate --tool ball:2 --path plunge.cl --stock 0 "
                         "--grid 120x32 --region -10,-8,20,4 --out sim")
                .exit_code,
            0);
  const Outcome v =
      runFieldpath(dir, "--quiet view scene.yaml --path plunge.cl --surface sim --out v.html");
  ASSERT_EQ(v.exit_code, 0) << v.output();
  const std::string html = slurp(dir.path() / "v.html");
  const json surface = pageMeta(html)["surface"];
  const auto height = pageBlob<float>(html, surface["height"]);
  const int nx = surface["nx"], ny = surface["ny"];
  ASSERT_EQ(height.size(), std::size_t(nx) * ny);
  const auto lowest = std::min_element(height.begin(), height.end(), [](float a, float b) {
    return std::isnan(b) || (!std::isnan(a) && a < b);
  });
  const int at = int(lowest - height.begin()), ix = at % nx, iy = at / nx;
  const double dx = surface["dx"], dy = surface["dy"];
  EXPECT_NEAR(surface["x0"].get<double>() + (ix + 0.5) * dx, 5.0, dx) << ix;
  EXPECT_NEAR(surface["y0"].get<double>() + (iy + 0.5) * dy, -3.0, dy) << iy;
  EXPECT_NEAR(*lowest, -0.5, 0.01);
}

// A check's lines no pass cut keep the stock allowance, told along the part's normal: on a 45°
// sheet 2000 cos 45° = 1414 um, which the page showed as stock beside the band (purple), not as
// not cut (grey: a reviewer's finding). One pass along the slope: the rest of it is not cut.
TEST(View, ACheckedSlopesUncutLinesAreGreyed) {
  const TempDir dir;
  dir.write("slope.stl", facetsStl({{-10, -10, -10, 10, -10, -10, 10, 10, 10},  // z = y
                                    {-10, -10, -10, 10, 10, 10, -10, 10, 10}}));
  dir.write("block.stl", boxStl(60, 60, 0, 70, 70, 10));
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: block.stl\npart: slope.stl\n"
            "tool: { shape: ball, radius: 3, length: 20 }\nclearance: 0.5\n");
  std::ostringstream cl;  // the ball's centre R along the normal from the contact (x, 0, 0)
  cl << "# pass 1\n";
  const double off = 3.0 / std::sqrt(2.0);
  for (int i = 0; i <= 20; ++i) cl << -5 + 0.5 * i << ' ' << -off << ' ' << off - 3 << " 0 0 1\n";
  dir.write("pass.cl", cl.str());
  ASSERT_EQ(runFieldpath(dir, "--quiet check scene.yaml --path pass.cl --out chk").exit_code, 0);
  const Outcome v = runFieldpath(dir, "--quiet view scene.yaml --check chk --out v.html");
  ASSERT_EQ(v.exit_code, 0) << v.output();
  const auto [values, marker] = surfaceValues(slurp(dir.path() / "v.html"));
  EXPECT_GT(std::count_if(values.begin(), values.end(), [&](float x) { return x >= marker; }), 0);
  const double stock_um = 2000.0 / std::sqrt(2.0);
  EXPECT_EQ(std::count_if(values.begin(), values.end(),
                          [&](float x) { return std::abs(x - stock_um) < 1.0; }),
            0);
}

// --max-triangles is the page's whole budget (a floor of 2000 a mesh showed 3444 for 1000 on a
// scene of several meshes): shared out, at most the budget in all.
TEST(View, MaxTrianglesIsThePagesWholeBudget) {
  const TempDir dir;
  const Outcome r =
      runFieldpath(dir, "view '" + kImpellerScene.string() + "' --max-triangles 1000 --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const json meta = pageMeta(slurp(dir.path() / "v.html"));
  ASSERT_GE(meta["meshes"].size(), 2u);
  std::size_t shown = 0, source = 0;
  for (const auto& m : meta["meshes"]) {
    shown += m["triangles"].get<std::size_t>();
    source += m["source_triangles"].get<std::size_t>();
    EXPECT_GT(m["triangles"].get<std::size_t>(), 0u) << m["name"];
  }
  EXPECT_GT(source, 5000u);
  EXPECT_LE(shown, 1000u);
  EXPECT_GT(shown, 500u);
}

TEST(View, MeshesAreDecimatedToTheBudget) {
  // A finely triangulated sphere-like mesh: a subdivided box.
  fieldpath::geometry::TriangleMesh mesh;
  const int n = 60;
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j) mesh.vertices.emplace_back(i * 0.1, j * 0.1, 0.01 * ((i * j) % 7));
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j) {
      const int a = i * (n + 1) + j, b = a + 1, c = a + n + 1, d = c + 1;
      mesh.triangles.emplace_back(a, c, b);
      mesh.triangles.emplace_back(b, c, d);
    }
  for (std::size_t budget : {100u, 1000u, 5000u}) {
    const auto out = fieldpath::app::decimateMesh(mesh, budget);
    EXPECT_LE(out.triangles.size(), budget);
    EXPECT_GT(out.triangles.size(), budget / 8) << budget;
    for (const auto& t : out.triangles)
      for (int c = 0; c < 3; ++c) ASSERT_LT(std::size_t(t[c]), out.vertices.size());
  }
  EXPECT_EQ(fieldpath::app::decimateMesh(mesh, 100000).triangles.size(), mesh.triangles.size());
}

// An output never replaces an input of the run, by any name (a helper's sweep): a scene whose
// nominal path is --out's path.cl lost it to `generate` (the next run then steered generate's own
// output), and `view --out floor.stl` wrote its page over the part's mesh.
TEST(Outputs, NeverReplaceAnInputOfTheRun) {
  const TempDir dir;
  writeBlockScene(dir);
  const std::string path = slurp(dir.path() / "path.cl"), floor = slurp(dir.path() / "floor.stl");
  const Outcome generate = runFieldpath(dir, "generate scene.yaml --out .");
  EXPECT_EQ(generate.exit_code, 1) << generate.output();
  EXPECT_NE(generate.err.find("would replace this run's input"), std::string::npos) << generate.err;
  EXPECT_EQ(slurp(dir.path() / "path.cl"), path);
  const Outcome view = runFieldpath(dir, "view scene.yaml --path path.cl --out floor.stl");
  EXPECT_EQ(view.exit_code, 1) << view.output();
  EXPECT_NE(view.err.find("is an input of this run"), std::string::npos) << view.err;
  EXPECT_EQ(slurp(dir.path() / "floor.stl"), floor);
  fs::create_symlink("floor.stl", dir.path() / "page.html");  // by another name
  EXPECT_EQ(runFieldpath(dir, "view scene.yaml --path path.cl --out page.html").exit_code, 1);
  EXPECT_EQ(slurp(dir.path() / "floor.stl"), floor);
}

// What a command prints is its result: to a full device it is lost, and the run says so, exit 1
// (`field probe > /dev/full` exited 0, its values gone). Its files, all written before its
// summary, stay: a lost summary takes none of them away (`generate ... 2>&1 | grep -q UNSAFE`
// stopped reading at the warning, and the SIGPIPE of the next note took away the path warned
// of, and its folder: an environment sweep's), nor does a pipe closed before the summary.
TEST(Outputs, AStandardOutputThatCannotBeWrittenFailsTheRunAndKeepsItsFiles) {
  const TempDir dir;
  const std::string in_dir = "cd '" + dir.path().string() + "' && ";
  const std::string tool = "'" FIELDPATH_EXE "' --quiet tool --shape ball:3 --out ";
  ASSERT_EQ(std::system((in_dir + tool + "whole.stl > /dev/null").c_str()), 0);
  const std::string whole = slurp(dir.path() / "whole.stl");
  ASSERT_FALSE(whole.empty());

  int status = std::system((in_dir + tool + "t.stl > /dev/full 2> err.txt").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1);
  EXPECT_NE(slurp(dir.path() / "err.txt").find("cannot write the standard output"),
            std::string::npos)
      << slurp(dir.path() / "err.txt");
  EXPECT_EQ(slurp(dir.path() / "t.stl"), whole);

  // A reader gone before the summary (`true` has exited by the time the tool is made): the
  // process dies of SIGPIPE at its summary, as a Unix filter does; its file whole.
  status = std::system(
      ("bash -c \"set -o pipefail; { sleep 0.3; " + in_dir + tool + "p.stl; } | true\"").c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGPIPE);
  EXPECT_EQ(slurp(dir.path() / "p.stl"), whole);

  // generate's outputs, claimed by the run (a signal before they are all written takes them
  // away), written whole before its summary and notes: a pipe closed then keeps them.
  writeBlockScene(dir);
  std::string beside;  // a pass beside the block, clear of it (the scene's own path enters it)
  for (int k = -10; k <= 10; ++k) beside += std::to_string(0.5 * k) + " -5 0 0 0 1\n";
  dir.write("path.cl", beside);
  status = std::system(("bash -c \"set -o pipefail; { sleep 0.3; " + in_dir +
                        "'" FIELDPATH_EXE "' --quiet generate scene.yaml --out g 2>&1; } | true\"")
                           .c_str());
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 128 + SIGPIPE);
  for (const char* name : {"path.cl", "path.apt", "angles.csv", "report.json"})
    EXPECT_TRUE(fs::exists(dir.path() / "g" / name)) << name;
  EXPECT_TRUE(json::accept(slurp(dir.path() / "g/report.json")));
}
