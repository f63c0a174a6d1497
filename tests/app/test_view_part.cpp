/// `view` and the part's contacts (links, holder): marked on the page as `check` finds them,
/// from its clearance.csv or computed; older or edited check folders said or refused.
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
  EXPECT_NE(meta["warnings"].dump().find("The part's contacts (links, holder) are not shown"),
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
