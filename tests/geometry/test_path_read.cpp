/// Path files read on all cores, in chunks cut at line ends: whatever the chunk size and the
/// thread count, the same postures (bit for bit), blocks, lines, `# limit` notes and errors as a
/// one-chunk, one-thread read, and the same as the postures that were written.
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "temp_files.h"

using namespace fieldpath::geometry;
using fieldpath::common::InputError;
using namespace fieldpath::geometry::test_files;
namespace fs = std::filesystem;

namespace {

/// Chunk sizes from one byte (every line its own chunk, cuts inside records tried) to one chunk.
const std::size_t kChunkBytes[] = {1, 7, 64, 1000, std::size_t{1} << 30};

bool sameBits(const Posture& a, const Posture& b) {
  return std::memcmp(a.tip_mm.data(), b.tip_mm.data(), 3 * sizeof(double)) == 0 &&
         std::memcmp(a.axis.data(), b.axis.data(), 3 * sizeof(double)) == 0 &&
         a.has_spindle == b.has_spindle && a.spindle_rad == b.spindle_rad;
}

void expectSamePath(const PathFile& a, const PathFile& b, const std::string& what) {
  ASSERT_EQ(a.postures.size(), b.postures.size()) << what;
  for (std::size_t i = 0; i < a.postures.size(); ++i)
    ASSERT_TRUE(sameBits(a.postures[i], b.postures[i])) << what << ", posture " << i;
  EXPECT_EQ(a.blocks, b.blocks) << what;
  EXPECT_EQ(a.lines, b.lines) << what;
  EXPECT_EQ(a.limited, b.limited) << what;
}

/// A path of passes and links, with every posture's numbers awkward enough to need all digits.
PathFile makePath(std::size_t passes, std::size_t per_pass) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-300, 300);
  std::normal_distribution<double> g;
  PathFile path;
  for (std::size_t k = 0; k < passes; ++k) {
    if (k > 0) {
      path.blocks.push_back({PathBlock::Kind::Link, path.postures.size(),
                             path.postures.size() + 2});
      for (int l = 0; l < 2; ++l)
        path.postures.push_back({Vec3(u(rng), u(rng), 50 + l), Vec3::UnitZ(), 0.0, false});
    }
    path.blocks.push_back({PathBlock::Kind::Pass, path.postures.size(),
                           path.postures.size() + per_pass});
    for (std::size_t i = 0; i < per_pass; ++i) {
      Posture p;
      p.tip_mm = Vec3(u(rng), u(rng), u(rng));
      p.axis = Vec3(g(rng), g(rng), std::abs(g(rng)) + 0.5).normalized();
      path.postures.push_back(p);
    }
  }
  for (std::size_t i = 3; i < path.postures.size(); i += 17) path.limited.push_back(i);
  return path;
}

PathFile read(const fs::path& file, std::size_t chunk_bytes, unsigned threads) {
  PathReadOptions options;
  options.chunk_bytes = chunk_bytes;
  options.threads = threads;
  return readPathFile(file, options);
}

std::string errorOf(const fs::path& file, std::size_t chunk_bytes, unsigned threads) {
  try {
    read(file, chunk_bytes, threads);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

/// Every posture of scanPathFile, in order.
std::vector<CompactPosture> scan(const fs::path& file, std::size_t chunk_bytes) {
  std::vector<std::vector<CompactPosture>> chunks;
  PostureChunkSink sink;
  sink.begin = [&](std::size_t n) { chunks.resize(n); };
  sink.chunk = [&](std::size_t i, std::span<const CompactPosture> p) {
    chunks.at(i).assign(p.begin(), p.end());
  };
  PathReadOptions options;
  options.chunk_bytes = chunk_bytes;
  const std::size_t n = scanPathFile(file, options, sink);
  std::vector<CompactPosture> all;
  for (const auto& c : chunks) all.insert(all.end(), c.begin(), c.end());
  EXPECT_EQ(all.size(), n);
  return all;
}

}  // namespace

TEST(PathRead, ClSameWhateverTheChunksAndThreads) {
  const PathFile written = makePath(6, 40);
  const fs::path file = tempPath("chunks.cl");
  writeClFile(file, written, "written by the test");
  const PathFile reference = read(file, std::size_t{1} << 30, 1);
  // against what was written: the postures bit for bit, the blocks, the limits
  ASSERT_EQ(reference.postures.size(), written.postures.size());
  for (std::size_t i = 0; i < written.postures.size(); ++i)
    ASSERT_TRUE(sameBits(reference.postures[i], written.postures[i])) << i;
  EXPECT_EQ(reference.blocks, written.blocks);
  EXPECT_EQ(reference.limited, written.limited);
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u})
      expectSamePath(read(file, bytes, threads), reference,
                     "chunk " + std::to_string(bytes) + " threads " + std::to_string(threads));
}

TEST(PathRead, AptAndNpySameWhateverTheChunks) {
  const PathFile written = makePath(5, 30);
  const fs::path apt = tempPath("chunks.apt"), npy = tempPath("chunks.npy");
  writeAptFile(apt, written, AptHeader{});
  writeNpyFile(npy, written.postures);
  const PathFile apt_ref = read(apt, std::size_t{1} << 30, 1);
  EXPECT_EQ(apt_ref.blocks, written.blocks);  // RAPID before each link GOTO
  const PathFile npy_ref = read(npy, std::size_t{1} << 30, 1);
  for (std::size_t i = 0; i < written.postures.size(); ++i) {
    ASSERT_TRUE(sameBits(apt_ref.postures[i], written.postures[i])) << i;
    ASSERT_TRUE(sameBits(npy_ref.postures[i], written.postures[i])) << i;
  }
  for (std::size_t bytes : kChunkBytes) {
    expectSamePath(read(apt, bytes, 0), apt_ref, "apt chunk " + std::to_string(bytes));
    expectSamePath(read(npy, bytes, 0), npy_ref, "npy chunk " + std::to_string(bytes));
  }
}

TEST(PathRead, AptStateCrossesChunks) {
  // `$` continuations are never cut; a RAPID at a chunk's end makes the next chunk's first GOTO a
  // link; 3-number GOTOs keep the axis of an earlier chunk.
  const std::string text =
      "PARTNO/X\nGOTO/1,2,3,$\n 0.6,0,$\n0.8\nRAPID\nGOTO/4,5,6\nGOTO/7,8,9\nGOTO/1,1,1,0,0,1\n"
      "RAPID\n$$ a comment\nGOTO/2,2,2\nFINI\n";
  const fs::path file = writeBytes("state.apt", text);
  for (std::size_t bytes : kChunkBytes) {
    const PathFile p = read(file, bytes, 0);
    ASSERT_EQ(p.postures.size(), 5u) << bytes;
    for (std::size_t i : {0, 1, 2}) EXPECT_EQ(p.postures[i].axis, Vec3(0.6, 0, 0.8)) << bytes;
    EXPECT_EQ(p.postures[4].axis, Vec3::UnitZ()) << bytes;
    EXPECT_EQ(p.postures[1].tip_mm, Vec3(4, 5, 6));
    const std::vector<PathBlock> blocks = {{PathBlock::Kind::Pass, 0, 1},
                                           {PathBlock::Kind::Link, 1, 2},
                                           {PathBlock::Kind::Pass, 2, 4},
                                           {PathBlock::Kind::Link, 4, 5}};
    EXPECT_EQ(p.blocks, blocks) << bytes;
    EXPECT_EQ(p.lines, (std::vector<std::size_t>{2, 6, 7, 8, 11})) << bytes;
  }
}

TEST(PathRead, AptPprintLineEndsARecordWhateverTheChunks) {
  // A PPRINT line's `$` is its text's even inside a continued GOTO (the parser took it as a
  // continuation there and the chunk splitter did not: the fuzzer read two different results).
  const fs::path file =
      writeBytes("pprint_inside.apt", "GOTO/1.5,2.5,$\n PPRINT/3.5,1 $\n 3,0,0,1\nGOTO/4,5,6\n");
  const std::string whole = errorOf(file, std::size_t{1} << 30, 1);
  EXPECT_NE(whole.find("pprint_inside.apt:1: 'PPRINT/3.5' is not a number"), std::string::npos)
      << whole;
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u}) EXPECT_EQ(errorOf(file, bytes, threads), whole) << bytes;
}

TEST(PathRead, AptTlaxisCrossesChunks) {
  // A TLAXIS in one chunk gives its axis to the 3-value GOTOs of the next, whatever the chunks.
  const std::string text =
      "GOTO/0,0,0,0,0,1\nTLAXIS/0,0.6,0.8\n$$ a comment\n$$ another\nGOTO/1,0,0\nGOTO/2,0,0\n"
      "TLAXIS/0.6,0,0.8\nCOOLNT/ON\nGOTO/3,0,0\n";
  const fs::path file = writeBytes("tlaxis.apt", text);
  // Read whole, the axes the records give; read in chunks, the same path bit for bit.
  const PathFile whole = read(file, std::size_t{1} << 30, 1);
  ASSERT_EQ(whole.postures.size(), 4u);
  EXPECT_EQ(whole.postures[0].axis, Vec3::UnitZ());
  EXPECT_EQ(whole.postures[1].axis, Vec3(0, 0.6, 0.8));
  EXPECT_EQ(whole.postures[2].axis, Vec3(0, 0.6, 0.8));
  EXPECT_EQ(whole.postures[3].axis, Vec3(0.6, 0, 0.8));
  for (std::size_t bytes : kChunkBytes)
    expectSamePath(read(file, bytes, 0), whole, "chunk " + std::to_string(bytes));
}

TEST(PathRead, AptFedratBetweenRapidAndGotoMakesAFeedMoveWhateverTheChunks) {
  // RAPID, then FEDRAT, then GOTO: the GOTO is a feed move (posts read FEDRAT so), with comments
  // between them to put chunk boundaries anywhere; a RAPID right before a GOTO stays a link.
  const std::string text =
      "GOTO/0,0,0,0,0,1\nRAPID\n$$ one\n$$ two\nFEDRAT/MMPM,500\n$$ three\nGOTO/1,0,0\n"
      "GOTO/2,0,0\nFEDRAT/MMPM,500\nRAPID\n$$ four\nGOTO/3,0,0\nGOTO/4,0,0\n";
  const fs::path file = writeBytes("fedrat.apt", text);
  const std::vector<PathBlock> blocks = {{PathBlock::Kind::Pass, 0, 3},
                                         {PathBlock::Kind::Link, 3, 4},
                                         {PathBlock::Kind::Pass, 4, 5}};
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u}) EXPECT_EQ(read(file, bytes, threads).blocks, blocks) << bytes;
}

TEST(PathRead, FirstErrorInFileOrderWhateverTheChunks) {
  // Two bad lines: every chunking names the first (line 40), with the same message.
  std::string text;
  for (int line = 1; line <= 100; ++line)
    text += line == 40   ? "1 2 3 0 0 0\n"          // zero axis
            : line == 70 ? "1 2 x 0 0 1\n"          // garbage
                         : "1 2 3 0 0.6 0.8\n";
  const fs::path file = writeBytes("two_errors.cl", text);
  const std::string expected = file.string() + ":40: zero tool axis";
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u}) EXPECT_EQ(errorOf(file, bytes, threads), expected) << bytes;
}

TEST(PathRead, RefusesTipsBeyondAnyMachine) {
  const fs::path cl = writeBytes("far.cl", "0 0 0 0 0 1\n1e30 0 0 0 0 1\n");
  EXPECT_NE(errorOf(cl, 4096, 0).find(cl.string() + ":2: tool tip x = 1e+30 mm is beyond"),
            std::string::npos)
      << errorOf(cl, 4096, 0);
  const fs::path apt = writeBytes("far.apt", "GOTO/0,0,0,0,0,1\nGOTO/0,-2e6,0\n");
  EXPECT_NE(errorOf(apt, 4096, 0).find(apt.string() + ":2: tool tip y"), std::string::npos)
      << errorOf(apt, 4096, 0);
  std::vector<Posture> postures(3);
  postures[2].tip_mm.z() = 1e308;
  const fs::path npy = tempPath("far.npy");
  writeNpyFile(npy, postures);
  EXPECT_NE(errorOf(npy, 4096, 0).find(npy.string() + ": row 2 (from 0): tool tip z"),
            std::string::npos)
      << errorOf(npy, 4096, 0);
  // In mm after UNITS/INCHES: 50000 in is 1.27e6 mm (it passed as read, a helper's finding).
  const fs::path inches =
      writeBytes("inches.apt", "UNITS/INCHES\nGOTO/0,0,0,0,0,1\nGOTO/50000,0,0\n");
  for (std::size_t bytes : kChunkBytes)
    EXPECT_NE(errorOf(inches, bytes, 0).find(inches.string() + ":3: tool tip x = 1.27e+06 mm"),
              std::string::npos)
        << errorOf(inches, bytes, 0);
  // 1e6 mm itself is still a coordinate
  EXPECT_EQ(read(writeBytes("edge.cl", "1e6 -1e6 0 0 0 1\n"), 4096, 0).postures.size(), 1u);
}

TEST(PathRead, ScanGivesTheCompactPosturesOfReadPathFile) {
  const PathFile written = makePath(4, 50);
  for (const char* name : {"scan.cl", "scan.apt", "scan.npy"}) {
    const fs::path file = tempPath(name);
    if (pathFormatOf(file) == PathFormat::Cl) writeClFile(file, written);
    if (pathFormatOf(file) == PathFormat::Apt) writeAptFile(file, written, AptHeader{});
    if (pathFormatOf(file) == PathFormat::Npy) writeNpyFile(file, written.postures);
    const PathFile full = readPathFile(file);
    for (std::size_t bytes : kChunkBytes) {
      const std::vector<CompactPosture> compact_postures = scan(file, bytes);
      ASSERT_EQ(compact_postures.size(), full.postures.size()) << name;
      for (std::size_t i = 0; i < full.postures.size(); ++i) {
        const CompactPosture want = compact(full.postures[i]);
        ASSERT_EQ(std::memcmp(&want, &compact_postures[i], sizeof want), 0) << name << " " << i;
      }
    }
  }
  // errors as readPathFile gives them
  const fs::path bad = writeBytes("scan_bad.cl", "0 0 0 0 0 1\n0 0 0 0 0 1\nnan 0 0 0 0 1\n");
  try {
    scan(bad, 8);
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()), errorOf(bad, 8, 1));
  }
}

// fuzz_apt crash-4361ce6d: a record a later chunk cannot read, after FINI, failed the chunked
// read and not the whole one. Nothing after FINI is read, whatever the chunks.
TEST(PathRead, AptAfterFiniIsNotReadWhateverTheChunks) {
  const fs::path file = fs::temp_directory_path() / "fieldpath_fini_chunks.apt";
  std::ofstream(file) << "GOTO/1,2,3,0,0,1\nFINI\nGOTO/1,2,x\nUNITS/FEET\nGOTO/4,5,$\n";
  for (const std::size_t chunk_bytes : {std::size_t{1} << 20, std::size_t{8}, std::size_t{1}})
    for (const unsigned threads : {1u, 2u}) {
      EXPECT_EQ(errorOf(file, chunk_bytes, threads), "no error") << chunk_bytes << " " << threads;
      EXPECT_EQ(read(file, chunk_bytes, threads).postures.size(), 1u);
    }
  fs::remove(file);
}

TEST(PathRead, AptCommentLinesInsideAContinuedRecordAreReadPast) {
  // `$$` lines (and blank ones) between the cards of a `$`-continued record, as CATIA writes
  // them: read past, the record goes on (refused as "GOTO: expected comma-separated numbers", an
  // adversary's); every chunking the same postures, the next record's line kept.
  const std::string text =
      "PARTNO/X\nMULTAX/ON\nGOTO/1,2,0,$\n$$ the axis\n\n   $$ more\n0,0,1\nGOTO/4,5,6\n";
  const fs::path file = writeBytes("comment_cont.apt", text);
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u}) {
      const PathFile p = read(file, bytes, threads);
      ASSERT_EQ(p.postures.size(), 2u) << bytes;
      EXPECT_EQ(p.postures[0].tip_mm, Vec3(1, 2, 0)) << bytes;
      EXPECT_EQ(p.postures[1].tip_mm, Vec3(4, 5, 6)) << bytes;
      EXPECT_EQ(p.postures[1].axis, Vec3(0, 0, 1)) << bytes;
      EXPECT_EQ(p.where(1), file.string() + ":8") << bytes;
    }
}

TEST(PathRead, AptCutterRecordsInMmWhateverTheChunks) {
  // CUTTER/d, r, ... in the unit of the UNITS record before it (inches x 25.4), a continued one
  // joined, one with words read past; every chunking the same records.
  const std::string text =
      "PARTNO/X\nCUTTER/TOOL1\nCUTTER/6.0, 3.0, 0, 3, 0, 0, 40\nGOTO/1,2,3,0,0,1\n"
      "UNITS/INCHES\nCUTTER / 0.25,$\n 0.125\nGOTO/0.1,0.2,0.3\nFINI\nCUTTER/99\n";
  const fs::path file = writeBytes("cutters.apt", text);
  for (std::size_t bytes : kChunkBytes)
    for (unsigned threads : {1u, 0u}) {
      const PathFile p = read(file, bytes, threads);
      ASSERT_EQ(p.cutters.size(), 2u) << bytes;
      EXPECT_EQ(p.cutters[0].diameter_mm, 6.0);
      EXPECT_EQ(p.cutters[0].corner_mm, 3.0);
      EXPECT_EQ(p.cutters[0].line, 3u);
      EXPECT_EQ(p.cutters[0].length_mm, 40.0);  // h, the seventh value
      EXPECT_EQ(p.cutters[1].length_mm, -1.0);  // not given
      EXPECT_DOUBLE_EQ(p.cutters[1].diameter_mm, 6.35) << bytes;
      EXPECT_DOUBLE_EQ(p.cutters[1].corner_mm, 3.175) << bytes;
      EXPECT_EQ(p.cutters[1].line, 6u) << bytes;
    }
  // What the APT writer writes reads back as the tool it was given.
  PathFile written = makePath(1, 5);
  AptHeader header;
  header.tool.radius_mm = 2.5;
  const fs::path apt = tempPath("written.apt");
  writeAptFile(apt, written, header);
  const PathFile back = read(apt, std::size_t{1} << 30, 1);
  ASSERT_EQ(back.cutters.size(), 1u);
  EXPECT_EQ(back.cutters[0].diameter_mm, 5.0);
  EXPECT_EQ(back.cutters[0].corner_mm, 2.5);
  EXPECT_EQ(back.cutters[0].length_mm, header.tool.length_mm);
}
