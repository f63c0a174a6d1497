/// `fieldpath view` as a user runs it: the page's data agrees with `check` (counts, per-posture
/// flags), bad input is exit 1 with one line or a page that says what is missing; and the
/// impeller's page looked at in a real browser (Debian's chromium, headless, SwiftShader WebGL):
/// it renders the part where the camera puts it, the slider moves the tool, the console is clean.
#include <unistd.h>

#include <algorithm>
#include <cmath>
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
#include "png_read.h"
#include "view_data.h"

namespace fs = std::filesystem;
using fieldpath::app::test::Outcome;
using fieldpath::app::test::runFieldpath;
using fieldpath::app::test::slurp;
using fieldpath::app::test::squareStl;
using fieldpath::app::test::TempDir;
using nlohmann::json;

namespace {

const fs::path kImpellerScene = fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// ASCII STL of the closed box [x0, x1] × [y0, y1] × [z0, z1], outward normals.
std::string boxStl(double x0, double y0, double z0, double x1, double y1, double z1) {
  const double x[2] = {x0, x1}, y[2] = {y0, y1}, z[2] = {z0, z1};
  auto v = [&](int i, int j, int k) {
    std::ostringstream s;
    s << "   vertex " << x[i] << ' ' << y[j] << ' ' << z[k] << '\n';
    return s.str();
  };
  // Each face as four corners, counter-clockwise seen from outside.
  const int faces[6][4][3] = {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},   // z0
                              {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},   // z1
                              {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},   // y0
                              {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},   // y1
                              {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},   // x0
                              {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}};  // x1
  std::string text = "solid box\n";
  for (const auto& f : faces)
    for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      text += " facet normal 0 0 0\n  outer loop\n";
      for (int c : t) text += v(f[c][0], f[c][1], f[c][2]);
      text += "  endloop\n endfacet\n";
    }
  return text + "endsolid box\n";
}

/// Two passes along x (y = 0 through the block, y = 8 beside it) joined by a link; one `# limit`.
std::string pathCl(double shift_mm = 0) {
  std::ostringstream s;
  auto line = [&](double x, double y, double z, const char* mark = "") {
    s << x + shift_mm << ' ' << y << ' ' << z << " 0 0 1" << mark << '\n';
  };
  s << "# pass 1\n";
  for (int k = 0; k < 40; ++k) line(-9.75 + 0.5 * k, 0, 0);
  s << "# link\n";
  line(9.75, 0, 15);
  line(-9.75, 8, 15);
  s << "# pass 2\n";
  for (int k = 0; k < 40; ++k) line(-9.75 + 0.5 * k, 8, 0, k == 20 ? "  # limit" : "");
  return s.str();
}

/// A scene with a block in the way of pass 1 on a floor (the part), the path as its nominal.
void writeBlockScene(const TempDir& dir, bool nominal = true) {
  dir.write("block.stl", boxStl(3, -3, -1, 5, 3, 4));
  dir.write("floor.stl", squareStl(20, 0));
  dir.write("path.cl", pathCl());
  dir.write("scene.yaml", std::string("obstacles:\n  - mesh: block.stl\npart: floor.stl\n"
                                      "tool: { shape: ball, radius: 1, length: 10 }\n"
                                      "clearance: 0.5\n") +
                              (nominal ? "path: { nominal: path.cl }\n" : ""));
}

std::string between(const std::string& text, const std::string& open, const std::string& close) {
  const auto a = text.find(open);
  if (a == std::string::npos) return {};
  const auto b = text.find(close, a + open.size());
  return b == std::string::npos ? std::string() : text.substr(a + open.size(), b - a - open.size());
}

json pageMeta(const std::string& html) {
  return json::parse(
      between(html, "<script type=\"application/json\" id=\"fp-meta\">", "</script>"));
}

std::string base64Decode(const std::string& text) {
  std::string out;
  int bits = 0, buffer = 0;
  for (char c : text) {
    int v = c >= 'A' && c <= 'Z'   ? c - 'A'
            : c >= 'a' && c <= 'z' ? c - 'a' + 26
            : c >= '0' && c <= '9' ? c - '0' + 52
            : c == '+'             ? 62
            : c == '/'             ? 63
                                   : -1;
    if (v < 0) continue;
    buffer = (buffer << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((buffer >> bits) & 0xff);
    }
  }
  return out;
}

/// The page's per-posture flags (1 link, 2 limit held, 4 colliding, 8 colliding motion).
std::vector<std::uint8_t> pageFlags(const std::string& html, const json& meta) {
  const std::string blob = base64Decode(
      between(html, "<script type=\"application/octet-stream\" id=\"fp-blob\">", "</script>"));
  const json ref = meta["path"]["flags"];
  const std::size_t offset = ref["offset"], count = ref["count"];
  return {blob.begin() + offset, blob.begin() + offset + count};
}

std::size_t countBit(const std::vector<std::uint8_t>& flags, int bit) {
  return std::count_if(flags.begin(), flags.end(), [bit](std::uint8_t f) { return f & bit; });
}

bool oneLine(const std::string& text) {
  return !text.empty() && text.find('\n') == text.size() - 1;
}

}  // namespace

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
    EXPECT_TRUE(meta["warnings"].empty()) << meta["warnings"];
    // The scene's passes give the frames: the axis stays on the nominal one.
    EXPECT_NE(meta["path"]["angles_source"].get<std::string>().find("frames of the scene's passes"),
              std::string::npos);
    // check --out wrote deviation.npy: the surface comes with the check folder.
    EXPECT_EQ(meta["surface"].is_null(), args != "--check chk") << args;
    EXPECT_LT(html.size(), 15u << 20);
  }
}

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
  EXPECT_EQ(pageMeta(slurp(dir.path() / "crlf.html"))["path"]["counts"]["part_contact_postures"], 1);
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

TEST(View, BadInputIsExitOneWithOneLineOrAPageThatSaysWhatIsMissing) {
  const TempDir dir;
  writeBlockScene(dir, /*nominal=*/false);
  dir.write("far.cl", pathCl(1e4));
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

// ---------------------------------------------------------------------------- in a browser

namespace {

/// Debian's chromium ($FIELDPATH_CHROMIUM first), or "" when it is not installed.
std::string findChromium() {
  if (const char* given = std::getenv("FIELDPATH_CHROMIUM"); given && *given) return given;
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "");
  for (std::string dir; std::getline(dirs, dir, ':');)
    for (const char* name : {"chromium", "chromium-browser"}) {
      const fs::path file = fs::path(dir) / name;
      if (::access(file.c_str(), X_OK) == 0) return file.string();
    }
  return {};
}

struct Browser {
  std::string exe;
  const TempDir* dir;
  int runs = 0;
  std::vector<std::string> console;  ///< console messages of every run (page errors included)

  /// Runs headless chromium with software WebGL (SwiftShader) on `url`: `mode` is
  /// "--dump-dom" (returns the DOM) or "--screenshot=FILE".
  std::string run(const std::string& mode, const std::string& url) {
    const fs::path out = dir->path() / ("chromium" + std::to_string(runs) + ".out");
    const fs::path err = dir->path() / ("chromium" + std::to_string(runs) + ".err");
    const fs::path profile = dir->path() / ("profile" + std::to_string(runs++));
    const std::string command =
        "timeout 120 '" + exe +
        "' --headless --no-sandbox --use-angle=swiftshader "
        "--enable-unsafe-swiftshader --disable-dev-shm-usage --window-size=800,650 "
        "--virtual-time-budget=5000 "
        "--enable-logging=stderr --v=0 --user-data-dir='" +
        profile.string() + "' " + mode + " '" + url + "' > '" + out.string() + "' 2> '" +
        err.string() + "'";
    const int status = std::system(command.c_str());
    EXPECT_EQ(status, 0) << command << "\n" << slurp(err);
    std::istringstream lines(slurp(err));
    for (std::string line; std::getline(lines, line);)
      if (line.find(":CONSOLE") != std::string::npos) console.push_back(line);
    return slurp(out);
  }
};

/// The page's state (#fp-state) from a DOM dump.
json pageState(const std::string& dom) {
  std::string text = between(dom, "<pre id=\"fp-state\" hidden=\"\">", "</pre>");
  for (const auto& [from, to] : {std::pair<std::string, std::string>{"&quot;", "\""},
                                 {"&lt;", "<"},
                                 {"&gt;", ">"},
                                 {"&amp;", "&"}}) {
    for (std::size_t at; (at = text.find(from)) != std::string::npos;)
      text.replace(at, from.size(), to);
  }
  return json::parse(text.empty() ? "{}" : text);
}

struct Rect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  bool contains(int x, int y) const { return x >= x0 && x < x1 && y >= y0 && y < y1; }
  long area() const { return long(std::max(0, x1 - x0)) * std::max(0, y1 - y0); }
};
Rect rectOf(const json& box) {
  if (!box.is_array() || box.size() != 4) return {};
  return {box[0].get<int>(), box[1].get<int>(), box[2].get<int>(), box[3].get<int>()};
}

bool isBackground(const std::array<int, 3>& c) {
  const int bg[3] = {0x1d, 0x21, 0x27};  // the renderer's clear colour
  return std::abs(c[0] - bg[0]) + std::abs(c[1] - bg[1]) + std::abs(c[2] - bg[2]) < 16;
}
/// The part's colour (0xc9a26b, lit): warm, red over green over blue.
bool isPartColour(const std::array<int, 3>& c) {
  return c[0] > 70 && c[0] >= c[1] && c[1] > c[2] && c[0] - c[2] > 30 && c[1] - c[2] > 15;
}

}  // namespace

TEST(ViewBrowser, ImpellerPageRendersAndTheSliderMovesTheTool) {
  const std::string chromium = findChromium();
  if (chromium.empty())
    GTEST_SKIP() << "chromium not found (scripts/setup.sh installs Debian's chromium; or set "
                    "FIELDPATH_CHROMIUM): the page is not looked at";
  if (!fs::exists("/usr/share/javascript/three/three.min.js") &&
      !std::getenv("FIELDPATH_THREE_DIR"))
    GTEST_SKIP() << "three.js not found (scripts/setup.sh installs Debian's libjs-three)";
  const TempDir dir;
  Outcome r =
      runFieldpath(dir, "generate '" + kImpellerScene.string() + "' --nominal --out nominal");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const json report = json::parse(slurp(dir.path() / "nominal/report.json"));
  r = runFieldpath(dir,
                   "view '" + kImpellerScene.string() + "' --path nominal/path.cl --out view.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  const fs::path page = dir.path() / "view.html";
  EXPECT_LT(fs::file_size(page), 15u << 20);

  // Posture A: the first colliding one (pass 1); B: on the last pass, across the channel.
  const std::size_t a = report["clearance"]["first_colliding_posture"];
  const std::size_t postures = report["postures"];
  const std::size_t b = postures - 60;
  const std::string url = "file://" + page.string() + "#size=580x520&posture=";
  Browser browser{chromium, &dir};

  // What the page says of itself: counts, the posture shown, where things are on the screen.
  // Played for the virtual time of the run (5 s) from A; the tool's screen boxes at A and B.
  const json state = pageState(
      browser.run("--dump-dom", url + std::to_string(a) + "&probe=" + std::to_string(b) + "&play"));
  ASSERT_TRUE(state.value("ready", false)) << state;
  EXPECT_TRUE(state.value("webgl", false));
  EXPECT_TRUE(state["errors"].empty()) << state["errors"];
  EXPECT_EQ(state["postures"], postures);
  EXPECT_EQ(state["shown_postures"], postures);
  EXPECT_EQ(state["colliding_postures"], report["clearance"]["colliding_postures"]);
  EXPECT_EQ(state["colliding_motions"], report["motions"]["colliding_motions"]);
  EXPECT_EQ(state["limited_postures"], 0);
  EXPECT_EQ(state["start"]["index"], a);
  EXPECT_EQ(state["probe"]["index"], b);
  EXPECT_GT(state["posture"]["index"].get<std::size_t>(), a + 10) << "play did not move on";
  EXPECT_GT(state["triangles"].get<int>(), 10000);
  const double first_frame_ms = state["first_frame_ms"];
  RecordProperty("first_frame_ms", std::to_string(first_frame_ms));
  EXPECT_LT(first_frame_ms, 10000) << "first frame (bench/results/view.md: about 1 s)";
  const Rect canvas = rectOf(state["canvas"]), part = rectOf(state["part_box"]);
  const Rect tool_a = rectOf(state["start"]["tool_box"]),
             tool_b = rectOf(state["probe"]["tool_box"]);
  std::vector<Rect> overlays;
  for (const json& o : state["overlays"]) overlays.push_back(rectOf(o));
  ASSERT_EQ(canvas.area(), 580L * 520);
  ASSERT_GT(part.area(), canvas.area() / 8) << state["part_box"];
  ASSERT_GT(tool_a.area(), 0);
  ASSERT_GT(tool_b.area(), 0);
  auto overlaid = [&](int x, int y) {
    return std::any_of(overlays.begin(), overlays.end(),
                       [&](const Rect& o) { return o.contains(x, y); });
  };

  // As a person looks at it: the screenshots at postures A and B.
  const fs::path shot_a = dir.path() / "a.png", shot_b = dir.path() / "b.png";
  browser.run("--screenshot=" + shot_a.string(), url + std::to_string(a));
  browser.run("--screenshot=" + shot_b.string(), url + std::to_string(b));
  const fieldpath::test::Image image_a = fieldpath::test::readPng(shot_a);
  const fieldpath::test::Image image_b = fieldpath::test::readPng(shot_b);
  ASSERT_EQ(image_a.width, 800);
  ASSERT_EQ(image_a.height, 650);
  ASSERT_EQ(image_b.width, 800);
  ASSERT_EQ(image_b.height, 650);

  // The part's pixels are where the camera puts them: inside its screen box (less the tool and
  // the overlays) mostly drawn, much of it in the part's colour; not a blank or flat canvas.
  long in_part = 0, drawn = 0, part_coloured = 0;
  for (int y = part.y0; y < part.y1; ++y)
    for (int x = part.x0; x < part.x1; ++x) {
      if (tool_a.contains(x, y) || overlaid(x, y)) continue;
      const auto c = image_a.at(x, y);
      ++in_part;
      drawn += !isBackground(c);
      part_coloured += isPartColour(c);
    }
  ASSERT_GT(in_part, 1000);
  // The hub is a curved strip across its box: about half of the box (0.51 measured).
  EXPECT_GT(double(drawn) / in_part, 0.35) << "drawn " << drawn << " of " << in_part;
  EXPECT_GT(double(part_coloured) / in_part, 0.1)  // 0.23 measured (path lines and blades over it)
      << "part-coloured " << part_coloured << " of " << in_part;
  long outside_part_coloured = 0, outside = 0;
  std::vector<std::uint32_t> colours;
  for (int y = canvas.y0; y < canvas.y1; ++y)
    for (int x = canvas.x0; x < canvas.x1; ++x) {
      const auto c = image_a.at(x, y);
      colours.push_back(std::uint32_t(c[0]) << 16 | c[1] << 8 | c[2]);
      if (part.contains(x, y) || overlaid(x, y)) continue;
      ++outside;
      outside_part_coloured += isPartColour(c);
    }
  EXPECT_LT(double(outside_part_coloured) / std::max(1L, outside), 0.01)  // 0.0003 measured
      << "the part's colour outside its screen box";
  std::sort(colours.begin(), colours.end());
  EXPECT_GT(std::unique(colours.begin(), colours.end()) - colours.begin(), 500) << "a flat canvas";

  // The slider moved the tool: the two shots differ where the tool was and where it went, and
  // nowhere else on the canvas (the overlays print the posture's numbers).
  long at_tool = 0, changed_at_tool = 0, elsewhere = 0, changed_elsewhere = 0;
  for (int y = canvas.y0; y < canvas.y1; ++y)
    for (int x = canvas.x0; x < canvas.x1; ++x) {
      if (overlaid(x, y)) continue;
      const auto p = image_a.at(x, y), q = image_b.at(x, y);
      const bool changed =
          std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 24;
      if (tool_a.contains(x, y)) {
        ++at_tool;
        changed_at_tool += changed;
      } else if (!tool_b.contains(x, y)) {
        ++elsewhere;
        changed_elsewhere += changed;
      }
    }
  ASSERT_GT(at_tool, 500);
  EXPECT_GT(double(changed_at_tool) / at_tool, 0.2) << changed_at_tool << " of " << at_tool;
  EXPECT_LT(double(changed_elsewhere) / std::max(1L, elsewhere), 0.005)
      << changed_elsewhere << " of " << elsewhere;

  std::printf(
      "first frame %.0f ms; part box: %.2f drawn, %.2f part-coloured; outside it %.4f "
      "part-coloured; tool box: %.2f changed, elsewhere %.5f\n",
      first_frame_ms, double(drawn) / in_part, double(part_coloured) / in_part,
      double(outside_part_coloured) / std::max(1L, outside), double(changed_at_tool) / at_tool,
      double(changed_elsewhere) / std::max(1L, elsewhere));
  // No console message in any run (errors, warnings, logs).
  EXPECT_TRUE(browser.console.empty()) << browser.console.front();
}
