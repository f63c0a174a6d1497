/// `view` and the part: its contacts (links, holder, cutter) marked on the page as `check` finds
/// them, from its clearance.csv or computed; older or edited check folders said or refused; a
/// simulated surface measured from the part line by line; a path under the clearance said.
#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "files.h"
#include "view_pages.h"

using namespace fieldpath::app::test::view;  // fs, json, the files.h helpers

TEST(View, PartContactsAreMarkedAsCheckFindsThem) {
  // A link that dips 2 mm through the floor (the part) beside the block: check finds the dip's
  // posture and the motions into and out of it touching the part, marks them in clearance.csv,
  // and the page carries them (bits 32, 64) from the check folder and computed alike. A check
  // folder written before clearance.csv had those columns gives a page without them.
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k < 20; ++k) path << -9.75 + 0.5 * k << " 8 0 0 0 1\n";
  path << "# link\n-0.25 8 5 0 0 1\n4 8 -2 0 0 1\n9.75 8 5 0 0 1\n# pass 2\n";
  for (int k = 0; k < 20; ++k) path << 9.75 - 0.5 * k << " 8 0 0 0 1\n";
  dir.write("dip.cl", path.str());
  const Outcome check = runFieldpath(dir, "check scene.yaml --path dip.cl --out chk");
  ASSERT_EQ(check.exit_code, 0) << check.output();
  const json report = json::parse(slurp(dir.path() / "chk/check.json"));
  ASSERT_EQ(report["link_part"]["colliding_postures"], 1) << report["link_part"];
  ASSERT_EQ(report["link_part"]["colliding_motions"], 2) << report["link_part"];
  const std::string csv = slurp(dir.path() / "chk/clearance.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "posture,block,pass,clearance_mm,motion_to_next_mm,limited,part_contact,"
            "part_contact_to_next");
  // Posture 21 (the dip, 0-based), motions 20 -> 21 and 21 -> 22.
  std::vector<std::uint8_t> at(43, 0), to_next(43, 0);
  {
    std::istringstream rows(csv);
    std::string row;
    std::getline(rows, row);
    for (std::size_t i = 0; std::getline(rows, row); ++i) {
      ASSERT_LT(i, 43u);
      const auto c2 = row.rfind(','), c1 = row.rfind(',', c2 - 1);
      at[i] = row.substr(c1 + 1, c2 - c1 - 1) == "1";
      to_next[i] = row.substr(c2 + 1) == "1";
    }
  }
  for (std::size_t i = 0; i < 43; ++i) {
    EXPECT_EQ(at[i], i == 21) << i;
    EXPECT_EQ(to_next[i], i == 20 || i == 21) << i;
  }
  for (const std::string args : {"--check chk", "--path dip.cl"}) {
    const Outcome r = runFieldpath(dir, "view scene.yaml " + args + " --out v.html");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const std::string html = slurp(dir.path() / "v.html");
    const json meta = pageMeta(html);
    EXPECT_EQ(meta["path"]["counts"]["part_contact_postures"], 1) << args;
    // The dip gouges the floor (check's surface): the banner says so where the page shows the
    // check's surface (it lies under the part, drawn over it).
    if (args == "--check chk") {
      ASSERT_GT(report["surface"]["gouged_lines"].get<int>(), 0) << report["surface"];
      EXPECT_NE(meta["warnings"].dump().find("GOUGE: "), std::string::npos) << meta["warnings"];
    }
    EXPECT_EQ(meta["path"]["counts"]["part_contact_motions"], 2) << args;
    const auto flags = pageFlags(html, meta);
    ASSERT_EQ(flags.size(), 43u);
    for (std::size_t i = 0; i < 43; ++i) {
      EXPECT_EQ(bool(flags[i] & 32), i == 21) << args << " " << i;
      EXPECT_EQ(bool(flags[i] & 64), i == 20 || i == 21) << args << " " << i;
    }
  }
  // Without the two columns (an older check folder): read, the contacts not known.
  std::string old_csv;
  {
    std::istringstream rows(csv);
    for (std::string row; std::getline(rows, row);) {
      const auto c2 = row.rfind(','), c1 = row.rfind(',', c2 - 1);
      old_csv += row.substr(0, c1) + "\n";
    }
  }
  dir.write("chk/clearance.csv", old_csv);
  const Outcome r = runFieldpath(dir, "view scene.yaml --check chk --out old.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const std::string html = slurp(dir.path() / "old.html");
  const json meta = pageMeta(html);
  EXPECT_TRUE(meta["path"]["counts"]["part_contact_postures"].is_null());
  EXPECT_EQ(countBit(pageFlags(html, meta), 32), 0u);
  // ... and the page says so: the scene has a part, the check marks nothing of it.
  EXPECT_NE(
      meta["warnings"].dump().find("The part's contacts (links, holder, cutter) are not shown"),
      std::string::npos)
      << meta["warnings"];
  // Saved again with CR LF line ends: the same page.
  std::string crlf;
  for (char ch : csv) crlf += ch == '\n' ? std::string("\r\n") : std::string(1, ch);
  dir.write("chk/clearance.csv", crlf);
  const Outcome windows = runFieldpath(dir, "view scene.yaml --check chk --out crlf.html");
  ASSERT_EQ(windows.exit_code, 0) << windows.output();
  EXPECT_EQ(pageMeta(slurp(dir.path() / "crlf.html"))["path"]["counts"]["part_contact_postures"],
            1);
  // One cell blanked (the others filled): refused, not every contact dropped.
  std::string blank = csv;
  blank.replace(blank.find(",1,1\n"), 5, ",,1\n");
  dir.write("chk/clearance.csv", blank);
  const Outcome blanked = runFieldpath(dir, "view scene.yaml --check chk --out bad.html");
  EXPECT_EQ(blanked.exit_code, 1) << blanked.output();
  EXPECT_NE(blanked.err.find("clearance.csv:23: part contact cells empty in some rows"),
            std::string::npos)
      << blanked.err;
  // A part-contact cell that is neither 0 nor 1: refused naming the line.
  std::string bad = csv;
  bad.replace(bad.find(",1,1\n"), 5, ",x,1\n");
  dir.write("chk/clearance.csv", bad);
  const Outcome b = runFieldpath(dir, "view scene.yaml --check chk --out bad.html");
  EXPECT_EQ(b.exit_code, 1) << b.output();
  EXPECT_NE(b.err.find("clearance.csv:23: a part contact of 'x'"), std::string::npos) << b.err;
  // The scene edited after the check (here its part file named anew): the check's contacts are
  // not this scene's.
  dir.write("chk/clearance.csv", csv);
  dir.write("floor2.stl", slurp(dir.path() / "floor.stl"));
  std::string scene = slurp(dir.path() / "scene.yaml");
  scene.replace(scene.find("floor.stl"), 9, "floor2.stl");
  dir.write("scene.yaml", scene);
  const Outcome stale = runFieldpath(dir, "view scene.yaml --check chk --out bad.html");
  EXPECT_EQ(stale.exit_code, 1) << stale.output();
  EXPECT_NE(stale.err.find("or its meshes have changed since the check"), std::string::npos)
      << stale.err;
  EXPECT_FALSE(fs::exists(dir.path() / "bad.html"));
}

// simulate's heights over a sloped part, shown in blocks of 3 x 3 lines: each line is measured
// from the part under it, along the facet's normal, as check measures. A block's lowest line less
// the part at the block's centre read the downhill line of every block as a gouge (12 um on a 0.6
// slope, a line 0.02 mm downhill: a helper's clean ramp showed 29 000 gouged blocks of 73 000);
// the vertical gap read 1/n_z too much (a 4.5 um dip on a slope of 2 read 10 um, a gouge, where
// check reads 4.5: a reviewer's). A pass dipped 20 um along the normal reads as the gouge it is.
TEST(View, ASimulatedSlopeReadsItsGougesAlongTheNormal) {
  const TempDir dir;
  dir.write("far.stl", boxStl(60, 60, 0, 70, 70, 10));
  // The blocks' values of the page of simulate's heights: a 33-pass raster on z = slope x with a
  // ball R 1, the middle pass dipped `dip_um` along the normal.
  const auto page = [&](double slope, double dip_um) {
    const double z = 12 * slope;
    dir.write("ramp.stl", facetsStl({{-12, -12, -z, 12, -12, z, 12, 12, z},
                                     {-12, -12, -z, 12, 12, z, -12, 12, -z}}));
    dir.write("scene.yaml",
              "obstacles:\n  - mesh: far.stl\npart: ramp.stl\n"
              "tool: { shape: ball, radius: 1, length: 10 }\n");
    std::ostringstream cl;  // the ball on the slope: centre R along the normal from the contact
    const double n = std::sqrt(1 + slope * slope), R = 1.0;
    for (int j = 0; j <= 32; ++j) {
      cl << "# pass " << j + 1 << '\n';
      const double off = R - (j == 16 ? 1e-3 * dip_um : 0.0);  // centre off the surface
      for (int i = 0; i <= 80; ++i) {
        const double x = (-8 + 0.2 * i) / std::max(1.0, slope), y = -8 + 0.5 * j;
        cl << x - slope * off / n << ' ' << y << ' ' << slope * x + off / n - R << " 0 0 1\n";
      }
    }
    dir.write("ramp.cl", cl.str());
    EXPECT_EQ(runFieldpath(dir, "--quiet simulate --tool ball:1 --path ramp.cl --stock " +
                                    std::to_string(10 * slope + 2) + " --out sim")
                  .exit_code,
              0);
    const Outcome v =
        runFieldpath(dir, "--quiet view scene.yaml --path ramp.cl --surface sim --out v.html");
    EXPECT_EQ(v.exit_code, 0) << v.output();
    const std::string html = slurp(dir.path() / "v.html");
    EXPECT_GT(pageMeta(html)["surface"]["stride"].get<int>(), 1);
    const auto [values, marker] = surfaceValues(html);
    std::size_t cut = 0, gouged = 0;
    float lowest = 0.0f;
    for (float x : values)
      if (std::isfinite(x) && x < marker) ++cut, gouged += x < -5.0f, lowest = std::min(lowest, x);
    EXPECT_GT(cut, 5000u) << slope;
    return std::make_pair(gouged, lowest);
  };
  EXPECT_EQ(page(0.6, 0.0).first, 0u);
  EXPECT_EQ(page(2.0, 4.5).first, 0u);  // under the 5 um tolerance along the normal
  const auto [gouged, lowest] = page(0.6, 20.0);
  EXPECT_GT(gouged, 0u);
  EXPECT_NEAR(lowest, -20.0f, 2.0f);
}

// the holder's), and its banner states the tolerance check counted them against (it said 0 um).
TEST(View, ACuttersGougeIsTheCuttersAtCheckTolerance) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k < 20; ++k) path << -9.75 + 0.5 * k << " 8 -0.05 0 0 1\n";
  dir.write("dip.cl", path.str());
  ASSERT_EQ(runFieldpath(dir, "--quiet check scene.yaml --path dip.cl --out chk").exit_code, 0);
  const Outcome r = runFieldpath(dir, "--quiet view scene.yaml --check chk --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const json meta = pageMeta(slurp(dir.path() / "v.html"));
  EXPECT_GT(meta["path"]["counts"]["part_contact_cutter"].get<int>(), 0) << meta["path"]["counts"];
  EXPECT_EQ(meta["path"]["counts"]["part_contact_holder"].get<int>(), 0);
  EXPECT_NE(meta["warnings"].dump().find("the gouge tolerance (5 um)"), std::string::npos)
      << meta["warnings"];
}

// One pass over the floor: check measures no scallop over its band (null), and the page's scale
// tops at 10 um, the stock left beside the pass above it in its own colour (the scale ran to the
// 1861 um left beside a helper's pass under "gouge < 0 < scallop").
TEST(View, WithNoScallopMeasuredTheScaleIsNotTheStockLeft) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k < 20; ++k) path << -9.75 + 0.5 * k << " 8 0 0 0 1\n";
  dir.write("one.cl", path.str());
  ASSERT_EQ(runFieldpath(dir, "--quiet check scene.yaml --path one.cl --out c").exit_code, 0);
  const json check = json::parse(slurp(dir.path() / "c" / "check.json"));
  ASSERT_TRUE(check["surface"]["max_scallop_um"].is_null()) << check["surface"];
  ASSERT_EQ(runFieldpath(dir, "--quiet view scene.yaml --check c --out v.html").exit_code, 0);
  const json surface = pageMeta(slurp(dir.path() / "v.html"))["surface"];
  EXPECT_EQ(surface["range"][1].get<double>(), 10.0) << surface["range"];
}

// A pass 0.3 mm beside the block, the scene asking 0.5: nothing collides, and the page says the
// path is under the required clearance, with the closest posture (it said nothing; its panel
// read "colliding postures: 0").
TEST(View, APathUnderTheRequiredClearanceIsSaid) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  std::ostringstream path;
  path << "# pass 1\n";
  for (int k = 0; k <= 8; ++k) path << "1.7 " << -2 + 0.5 * k << " 0 0 0 1\n";
  dir.write("under.cl", path.str());
  const Outcome r = runFieldpath(dir, "--quiet view scene.yaml --path under.cl --out v.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const json meta = pageMeta(slurp(dir.path() / "v.html"));
  EXPECT_EQ(meta["path"]["counts"]["colliding_postures"].get<int>(), 0);
  EXPECT_EQ(meta["path"]["counts"]["postures_under_required"].get<int>(), 9);
  const std::string warnings = meta["warnings"].dump();
  EXPECT_NE(warnings.find("UNDER THE REQUIRED CLEARANCE (0.500 mm): 9 postures (closest 0.2"),
            std::string::npos)
      << warnings;
  EXPECT_NE(warnings.find("(pass 1, under.cl:"), std::string::npos) << warnings;
  // The closest posture is check's, with --check too: postures whose clearances tie in
  // clearance.csv's rounding (here all nine) are told apart by check's exact ones, and the page
  // named the first of them, not check's (a helper's: 856 against 889). check.json names posture
  // 5 here (as if its exact distance were the least): the page names it.
  ASSERT_EQ(runFieldpath(dir, "--quiet check scene.yaml --path under.cl --out c").exit_code, 0);
  json check = json::parse(slurp(dir.path() / "c" / "check.json"));
  check["clearance"]["min_posture"] = 5;
  dir.write("c/check.json", check.dump());
  ASSERT_EQ(
      runFieldpath(dir, "--quiet view scene.yaml --path under.cl --check c --out w.html").exit_code,
      0);
  const std::string checked = pageMeta(slurp(dir.path() / "w.html"))["warnings"].dump();
  EXPECT_NE(checked.find("mm, posture 5 (pass 1, under.cl:7)"), std::string::npos) << checked;
}
