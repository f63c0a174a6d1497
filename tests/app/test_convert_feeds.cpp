/// `fieldpath convert` and the feed of an APT output: an APT input's FEDRAT records are read in
/// mm/min (MMPM, IPM, the file's unit) and written back where they were; a path with no feed of
/// its own (.cl, .npy, an APT without FEDRAT) needs `--feed`; a feed per revolution or past a
/// machine's is refused naming its line (convert wrote FEDRAT/MMPM,1000 over a FEDRAT/MMPM,150
/// without a word, and generate's 1e300 as FEDRAT/MMPM,1e+300: a machine-side helper's findings);
/// and FROM/, read past, said.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "files.h"

namespace fieldpath::app::test {
namespace {

namespace fs = std::filesystem;
using geometry::PathFile;

/// The FEDRAT records of an APT text, in order, each with the number of GOTOs before it.
std::vector<std::pair<int, std::string>> fedrats(const std::string& apt) {
  std::vector<std::pair<int, std::string>> out;
  int gotos = 0;
  for (std::size_t at = 0; at < apt.size();) {
    const std::size_t end = std::min(apt.find('\n', at), apt.size());
    const std::string line = apt.substr(at, end - at);
    if (line.rfind("GOTO/", 0) == 0) ++gotos;
    if (line.rfind("FEDRAT/", 0) == 0) out.emplace_back(gotos, line);
    at = end + 1;
  }
  return out;
}

/// A scene of one wall 30 mm below the paths and a ball of radius 3: for what `check` says of a
/// path file's records.
void writeWallScene(const TempDir& dir) {
  dir.write("wall.stl", squareStl(20.0, -30.0));
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 3, length: 40 }\n");
}

TEST(ConvertFeeds, AnAptInputsFeedsAreWrittenBackWhereTheyWere) {
  const TempDir dir;
  // Pass 1 at 150 mm/min, a change within it to 3 in/min; a link; pass 2 in inches at 5 in/min
  // (the file's unit), then 300 mm/min set during the next link, which the next pass takes.
  dir.write("in.apt",
            "PARTNO/X\nUNITS/MM\nFEDRAT/MMPM,150\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0\n"
            "FEDRAT/IPM,3\nGOTO/2,0,0\nRAPID\nGOTO/2,0,10\nUNITS/INCHES\nFEDRAT/5\n"
            "GOTO/0.1,0,0\nGOTO/0.2,0,0\nFEDRAT/ 300 , MMPM\nRAPID\nGOTO/0.2,0,1\n"
            "UNITS/MM\nGOTO/5,0,0\nFINI\n");
  const PathFile read = geometry::readPathFile(dir.path() / "in.apt");
  ASSERT_EQ(read.feeds.size(), 4u);
  const double mm_per_min[] = {150, 76.2, 127, 300};  // 3 in/min: 76.2, not 76.19999999999999
  const std::size_t from[] = {0, 2, 4, 6}, line[] = {3, 6, 11, 14};
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(read.feeds[k].mm_per_min, mm_per_min[k]) << k;
    EXPECT_EQ(read.feeds[k].from, from[k]) << k;
    EXPECT_EQ(read.feeds[k].line, line[k]) << k;
  }
  // The same whatever the chunks the file is read in (a chunk may hold a FEDRAT and no GOTO).
  geometry::PathReadOptions small;
  small.chunk_bytes = 16;
  const PathFile chunked = geometry::readPathFile(dir.path() / "in.apt", small);
  ASSERT_EQ(chunked.feeds.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_EQ(chunked.feeds[k].mm_per_min, read.feeds[k].mm_per_min) << k;
    EXPECT_EQ(chunked.feeds[k].from, read.feeds[k].from) << k;
  }

  // The feed set during the last link is written before the pass after it (a FEDRAT between
  // RAPID and its GOTO would make the link a feed move).
  const Outcome run = runFieldpath(dir, "convert in.apt out.apt --tool ball:3");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const auto written = fedrats(slurp(dir.path() / "out.apt"));
  const std::vector<std::pair<int, std::string>> expected = {{0, "FEDRAT/MMPM,150"},
                                                             {2, "FEDRAT/MMPM,76.2"},
                                                             {4, "FEDRAT/MMPM,127"},
                                                             {7, "FEDRAT/MMPM,300"}};
  EXPECT_EQ(written, expected);
  const PathFile back = geometry::readPathFile(dir.path() / "out.apt");
  ASSERT_EQ(back.feeds.size(), 4u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(back.feeds[k].mm_per_min, mm_per_min[k]);
  EXPECT_EQ(back.blocks, read.blocks);

  // --feed over all of them, said; a .cl keeps no feed, said.
  const Outcome over = runFieldpath(dir, "convert in.apt over.apt --tool ball:3 --feed 2000");
  ASSERT_EQ(over.exit_code, 0) << over.err;
  EXPECT_NE(over.err.find("--feed 2000 mm/min written over the 4 FEDRAT records"),
            std::string::npos)
      << over.err;
  for (const auto& [gotos, record] : fedrats(slurp(dir.path() / "over.apt")))
    EXPECT_EQ(record, "FEDRAT/MMPM,2000") << gotos;
  const Outcome to_cl = runFieldpath(dir, "convert in.apt out.cl");
  ASSERT_EQ(to_cl.exit_code, 0) << to_cl.err;
  EXPECT_NE(to_cl.err.find("the 4 FEDRAT records dropped"), std::string::npos) << to_cl.err;
}

TEST(ConvertFeeds, APathWithoutAFeedPerMinuteNeedsFeed) {
  const TempDir dir;
  dir.write("p.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  dir.write("none.apt", "GOTO/0,0,0,0,0,1\nGOTO/1,0,0\n");
  dir.write("rev.apt", "UNITS/MM\nFEDRAT/0.1,IPR\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0\n");
  dir.write("far.apt", "FEDRAT/MMPM,1e300\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0\n");
  dir.write("typo.apt", "FEDRAT/IMP,10\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0\n");  // 10 mm/min once
  dir.write("two.apt", "FEDRAT/MMPM,10,IPM\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0\n");
  const std::pair<const char*, const char*> refused[] = {
      {"convert p.cl o.apt --tool ball:1", "o.apt: APT output needs --feed (mm/min): p.cl"},
      {"convert none.apt o.apt --tool ball:1", "needs --feed (mm/min): none.apt has no FEDRAT"},
      {"convert rev.apt o.apt --tool ball:1", "rev.apt:2: FEDRAT/0.1,IPR: no feed per minute"},
      {"convert far.apt o.apt --tool ball:1", "far.apt:1: FEDRAT: 1e+300 mm/min is no machine's"},
      {"convert typo.apt o.apt --tool ball:1", "typo.apt:1: FEDRAT/IMP,10: no feed per minute"},
      {"convert two.apt o.apt --tool ball:1", "two.apt:1: FEDRAT/MMPM,10,IPM: no feed per minute"},
      {"convert p.cl o.apt --tool ball:1 --feed 0", "--feed: must be a number from 0.001"},
      {"convert p.cl o.apt --tool ball:1 --feed 2e6", "--feed: must be a number from 0.001"},
      {"convert p.cl o.cl --feed 100", "o.cl: --feed is the FEDRAT of an APT output"},
  };
  for (const auto& [args, said] : refused) {
    const Outcome run = runFieldpath(dir, args);
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_NE(run.err.find(said), std::string::npos) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << args << ": " << run.err;
    EXPECT_FALSE(fs::exists(dir.path() / "o.apt")) << args;
    EXPECT_FALSE(fs::exists(dir.path() / "o.cl")) << args;
  }
  // With --feed, each: the feed before the pass.
  for (const char* in : {"p.cl", "none.apt", "rev.apt", "far.apt", "typo.apt", "two.apt"}) {
    const Outcome run =
        runFieldpath(dir, std::string("convert ") + in + " o.apt --tool ball:1 --feed 450");
    ASSERT_EQ(run.exit_code, 0) << in << ": " << run.err;
    const auto written = fedrats(slurp(dir.path() / "o.apt"));
    ASSERT_EQ(written.size(), 1u) << in;
    EXPECT_EQ(written[0], (std::pair<int, std::string>{0, "FEDRAT/MMPM,450"})) << in;
  }
}

// FROM/ (the start point) is no motion of the path: read past, its line kept whatever the chunks,
// and said by check (the move from it is not checked) and convert (not carried).
TEST(ConvertFeeds, FromIsReadPastAndSaid) {
  const TempDir dir;
  dir.write("from.apt",
            "PARTNO/X\nFROM/0,0,100\nFEDRAT/MMPM,200\nGOTO/0,0,5,0,0,1\n"
            "GOTO/5,0,5\nFROM/1,1,1\nGOTO/10,0,5\n");
  for (const std::size_t chunk : {std::size_t{16}, std::size_t{1} << 20}) {
    geometry::PathReadOptions options;
    options.chunk_bytes = chunk;
    const PathFile read = geometry::readPathFile(dir.path() / "from.apt", options);
    EXPECT_EQ(read.from_line, 2u) << chunk;
    EXPECT_EQ(read.postures.size(), 3u) << chunk;
  }
  const Outcome run = runFieldpath(dir, "convert from.apt to.apt --tool ball:3");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("from.apt:2: FROM/ (the start point) is not carried"), std::string::npos)
      << run.err;
  writeWallScene(dir);
  const Outcome check = runFieldpath(dir, "check scene.yaml --path from.apt --out out");
  EXPECT_NE(check.err.find("note: from.apt:2: FROM/ (the start point) is read past: the machine's "
                           "move from it to the first GOTO is not checked"),
            std::string::npos)
      << check.err;
  const auto report = nlohmann::json::parse(slurp(dir.path() / "out" / "check.json"));
  ASSERT_EQ(report["path_notes"].size(), 1u);
  // A path with no FROM: no note.
  dir.write("plain.apt", "GOTO/0,0,5,0,0,1\nGOTO/5,0,5\n");
  const Outcome plain = runFieldpath(dir, "check scene.yaml --path plain.apt --out out2");
  EXPECT_EQ(plain.err.find("FROM/"), std::string::npos) << plain.err;
  EXPECT_TRUE(
      nlohmann::json::parse(slurp(dir.path() / "out2" / "check.json"))["path_notes"].empty());
}

// The tool of `TLDATA/MILL, d, r, ...` (as NX writes it) is compared with the scene's, as CUTTER's
// is: a 16 mm flat end mill against a 6 mm ball went unsaid (a CAM engineer's); TLDATA of
// another kind is not a cutter.
TEST(ConvertFeeds, TldataMillIsTheFilesCutter) {
  const TempDir dir;
  dir.write("nx.cls",
            "TLDATA/MILL,16.0000,0.0000,50.0000,0.0000,0.0000\nTLDATA/DRILL,5,118\n"
            "GOTO/0,0,5,0,0,1\nGOTO/5,0,5\n");
  const PathFile read = geometry::readPathFile(dir.path() / "nx.cls");
  ASSERT_EQ(read.cutters.size(), 1u);
  EXPECT_EQ(read.cutters[0].record, "TLDATA");
  EXPECT_EQ(read.cutters[0].diameter_mm, 16.0);
  EXPECT_EQ(read.cutters[0].corner_mm, 0.0);
  EXPECT_EQ(read.cutters[0].length_mm, 50.0);  // TLDATA/MILL, d, r, l
  writeWallScene(dir);
  const Outcome check = runFieldpath(dir, "check scene.yaml --path nx.cls --out out");
  EXPECT_NE(check.err.find("nx.cls:1: TLDATA says the path was written for a 16 mm cutter"),
            std::string::npos)
      << check.err;
  // simulate against its --tool (its length not compared: no holder there), view on the
  // terminal as on its page (both were silent: an adversary's)
  const Outcome sim =
      runFieldpath(dir, "simulate --tool ball:3 --path nx.cls --stock 1 --grid 64x64 --out sim");
  EXPECT_EQ(sim.exit_code, 0) << sim.err;
  EXPECT_NE(sim.err.find("note: nx.cls:1: TLDATA says the path was written for a 16 mm cutter "
                         "with a 0 mm corner; --tool is a ball of radius 3 mm (6 mm): what "
                         "follows is for --tool, not the file's"),
            std::string::npos)
      << sim.err;
  const Outcome flat =
      runFieldpath(dir, "simulate --tool flat:8:20 --path nx.cls --stock 1 --grid 64x64 --out sim");
  EXPECT_EQ(flat.err.find("TLDATA says"), std::string::npos) << flat.err;  // 16 mm flat: the same
  const Outcome view = runFieldpath(dir, "view scene.yaml --path nx.cls --out view.html");
  EXPECT_NE(view.out.find("note: nx.cls:1: TLDATA says the path was written for a 16 mm cutter"),
            std::string::npos)
      << view.out;
}

// A file that loads a second tool (`LOAD/TOOL,n`, `LOADTL/n`) is said: every motion is proven
// with the scene's one tool (a CAM engineer's program with a tool change went unsaid); the same
// tool loaded again is no change. Whatever the chunks.
TEST(ConvertFeeds, AToolChangeIsSaid) {
  const TempDir dir;
  dir.write("two.apt",
            "PARTNO/X\nLOAD/TOOL,1\nGOTO/0,0,5,0,0,1\nLOAD / TOOL, 1, ADJUST, 1\nGOTO/5,0,5\n"
            "LOADTL/7\nGOTO/6,0,5\n");
  dir.write("one.apt", "PARTNO/X\nLOAD/TOOL,1\nGOTO/0,0,5,0,0,1\nLOADTL/1\nGOTO/5,0,5\n");
  for (const std::size_t chunk : {std::size_t{16}, std::size_t{1} << 20}) {
    geometry::PathReadOptions options;
    options.chunk_bytes = chunk;
    const PathFile two = geometry::readPathFile(dir.path() / "two.apt", options);
    ASSERT_EQ(two.tool_loads.size(), 3u) << chunk;
    EXPECT_EQ(two.tool_loads[2].number, "7");
    EXPECT_EQ(two.tool_loads[2].line, 6u);
  }
  writeWallScene(dir);
  const Outcome check = runFieldpath(dir, "check scene.yaml --path two.apt --out out");
  EXPECT_NE(check.err.find("note: two.apt:6: the file changes tools (2 loads: 1 (line 2), 7 (line "
                           "6)): every motion is proven with the scene's one tool"),
            std::string::npos)
      << check.err;
  const Outcome same = runFieldpath(dir, "check scene.yaml --path one.apt --out same");
  EXPECT_EQ(same.err.find("changes tools"), std::string::npos) << same.err;
}

// A non-identity MSYS (a frame shifted or turned), and a CUTCOM that is not OFF, are read past,
// and said: the path is taken in the file's coordinates, where it is written (a CAM engineer's
// MSYS/0,-5,0 put the ball 1 mm into a wall the check read 3.98 mm clear, unsaid); the identity is
// no note. Whatever the chunks.
TEST(ConvertFeeds, AShiftedMsysIsSaid) {
  const TempDir dir;
  const std::string motions = "GOTO/0,0,5,0,0,1\nGOTO/5,0,5\n";
  dir.write("shifted.apt", "PARTNO/X\nMSYS/0,0,0,1,0,0,0,1,0\nMSYS/0,-5,0,1,0,0,0,1,0\n" + motions);
  dir.write("identity.apt", "PARTNO/X\nMSYS/0,0,0,1,0,0,0,1,0\n" + motions);
  for (const std::size_t chunk : {std::size_t{16}, std::size_t{1} << 20}) {
    geometry::PathReadOptions options;
    options.chunk_bytes = chunk;
    EXPECT_EQ(geometry::readPathFile(dir.path() / "shifted.apt", options).msys_line, 3u) << chunk;
    EXPECT_EQ(geometry::readPathFile(dir.path() / "identity.apt", options).msys_line, 0u) << chunk;
  }
  writeWallScene(dir);
  const Outcome check = runFieldpath(dir, "check scene.yaml --path shifted.apt --out out");
  EXPECT_NE(check.err.find("note: shifted.apt:3: MSYS/ (a frame shifted or turned) is read past"),
            std::string::npos)
      << check.err;
  const Outcome same = runFieldpath(dir, "check scene.yaml --path identity.apt --out same");
  EXPECT_EQ(same.err.find("MSYS"), std::string::npos) << same.err;
  // CUTCOM/LEFT too (the control's offset), CUTCOM/OFF not.
  dir.write("cutcom.apt", "PARTNO/X\nCUTCOM / OFF\nCUTCOM/LEFT\n" + motions + "CUTCOM/OFF\n");
  EXPECT_EQ(geometry::readPathFile(dir.path() / "cutcom.apt").cutcom_line, 3u);
  const Outcome offset = runFieldpath(dir, "check scene.yaml --path cutcom.apt --out cc");
  EXPECT_NE(offset.err.find("note: cutcom.apt:3: CUTCOM/ (the control's cutter offset) is read"),
            std::string::npos)
      << offset.err;
}

}  // namespace
}  // namespace fieldpath::app::test
