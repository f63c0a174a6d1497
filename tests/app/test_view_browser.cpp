/// The impeller's page of `fieldpath view` looked at in a real browser (Debian's chromium,
/// headless, SwiftShader WebGL): it renders the part where the camera puts it, the slider moves
/// the tool, which stands on the path file's postures, and the console is clean.
#include <unistd.h>

#include <algorithm>
#include <array>
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

#include "fieldpath/geometry/cl_file.h"
#include "files.h"
#include "png_read.h"
#include "view_pages.h"

using namespace fieldpath::app::test::view;  // fs, json, the files.h helpers

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
  /// "--dump-dom" (returns the DOM) or "--screenshot=FILE"; `flags`: chromium's, added.
  std::string run(const std::string& mode, const std::string& url, const std::string& flags = "") {
    const fs::path out = dir->path() / ("chromium" + std::to_string(runs) + ".out");
    const fs::path err = dir->path() / ("chromium" + std::to_string(runs) + ".err");
    const fs::path profile = dir->path() / ("profile" + std::to_string(runs++));
    const std::string command =
        "timeout 120 '" + exe +
        "' --headless --no-sandbox --use-angle=swiftshader "
        "--enable-unsafe-swiftshader --disable-dev-shm-usage --window-size=800,650 "
        "--virtual-time-budget=5000 "
        "--enable-logging=stderr --v=0 " +
        flags + " --user-data-dir='" + profile.string() + "' " + mode + " '" + url + "' > '" +
        out.string() + "' 2> '" + err.string() + "'";
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

/// Why the page cannot be looked at here ("" where it can): no chromium, or no three.js.
std::string whyNoBrowserTest(const std::string& chromium) {
  if (chromium.empty())
    return "chromium not found (scripts/setup.sh installs Debian's chromium; or set "
           "FIELDPATH_CHROMIUM): the page is not looked at";
  if (!fs::exists("/usr/share/javascript/three/three.min.js") &&
      !std::getenv("FIELDPATH_THREE_DIR"))
    return "three.js not found (scripts/setup.sh installs Debian's libjs-three)";
  return {};
}

}  // namespace

TEST(ViewBrowser, ImpellerPageRendersAndTheSliderMovesTheTool) {
  const std::string chromium = findChromium();
  if (const std::string missing = whyNoBrowserTest(chromium); !missing.empty())
    GTEST_SKIP() << missing;
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
  // The tool stands on the path file's tip with its axis up the file's axis (a test audit: a
  // tool turned the other way, or placed at the ball's centre, kept a screen box that moves).
  const auto path = fieldpath::geometry::readPathFile(dir.path() / "nominal/path.cl");
  for (const char* which : {"start", "probe"}) {
    const std::size_t i = state[which]["index"];
    ASSERT_LT(i, path.postures.size());
    const json tip = state[which]["tip_mm"], top = state[which]["top_mm"];
    ASSERT_TRUE(tip.is_array() && top.is_array()) << state[which];
    const Eigen::Vector3d tip_mm(tip[0], tip[1], tip[2]), top_mm(top[0], top[1], top[2]);
    EXPECT_LT((tip_mm - path.postures[i].tip_mm).norm(), 1e-3) << which;
    EXPECT_GT((top_mm - tip_mm).norm(), 10.0) << which;
    EXPECT_LT(((top_mm - tip_mm).normalized() - path.postures[i].axis).norm(), 1e-4) << which;
  }
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

// A browser without WebGL gets the page's banner and its state (`webgl: false`): writing the
// state read the renderer that was never made (a TypeError, no state: the view.js split's
// reader's).
TEST(ViewBrowser, WithoutWebGlThePageSaysSo) {
  const std::string chromium = findChromium();
  if (const std::string missing = whyNoBrowserTest(chromium); !missing.empty())
    GTEST_SKIP() << missing;
  const TempDir dir;
  const Outcome r = runFieldpath(dir, "view '" + kImpellerScene.string() + "' --out view.html");
  ASSERT_EQ(r.exit_code, 0) << r.output();
  Browser browser{chromium, &dir};
  const std::string dom = browser.run("--dump-dom", "file://" + (dir.path() / "view.html").string(),
                                      "--disable-3d-apis");
  const json state = pageState(dom);
  EXPECT_EQ(state.value("webgl", true), false) << dom.substr(0, 2000);
  EXPECT_EQ(state.value("ready", false), true);
  EXPECT_NE(dom.find("WebGL is not available in this browser"), std::string::npos);
}
