#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <regex>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "temp_files.h"
#include "temporaries.h"

using namespace fieldpath::geometry;
using fieldpath::common::InputError;
using namespace fieldpath::geometry::test_files;
namespace fs = std::filesystem;

namespace {

bool bitwiseEqual(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

void expectSame(const std::vector<Posture>& a, const std::vector<Posture>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_TRUE(bitwiseEqual(a[i].tip_mm[c], b[i].tip_mm[c]))
          << i << " " << a[i].tip_mm[c] << " " << b[i].tip_mm[c];
      EXPECT_TRUE(bitwiseEqual(a[i].axis[c], b[i].axis[c]))
          << i << " " << a[i].axis[c] << " " << b[i].axis[c];
    }
    EXPECT_EQ(a[i].has_spindle, b[i].has_spindle);
    EXPECT_TRUE(bitwiseEqual(a[i].spindle_rad, b[i].spindle_rad));
  }
}

std::vector<Posture> randomPostures(std::size_t n, bool spindle) {
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u(-500, 500);
  std::vector<Posture> out(n);
  for (auto& p : out) {
    p.tip_mm = Vec3(u(rng), u(rng), u(rng));
    p.axis = Vec3(g(rng), g(rng), g(rng)).normalized();
    p.has_spindle = spindle;
    p.spindle_rad = spindle ? u(rng) / 100 : 0.0;
  }
  // Awkward but valid numbers.
  out[0].tip_mm = Vec3(-0.0, 1e-300, -1e6);  // 1e6 mm: the largest coordinate a path may hold
  out[0].axis = Vec3::UnitZ();
  out[1].tip_mm = Vec3(0.1, 1.0 / 3.0, 5e-324);
  out[1].axis = -Vec3::UnitZ();
  return out;
}

/// The postures as a path file holds them: magnitudes under 1e-12 (mm, axis components) are 0.
std::vector<Posture> writtenAs(std::vector<Posture> postures) {
  const auto zeroTiny = [](double& v) {
    if (std::abs(v) < 1e-12) v = std::signbit(v) ? -0.0 : 0.0;
  };
  for (Posture& p : postures)
    for (int c = 0; c < 3; ++c) zeroTiny(p.tip_mm[c]), zeroTiny(p.axis[c]);
  return postures;
}

/// No number of the file in exponent form ("4.8e-05"): post-processors refuse it.
void expectNoExponent(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  const std::regex exponent("[0-9.][eE][-+]?[0-9]");
  while (std::getline(in, line))
    EXPECT_FALSE(std::regex_search(line, exponent)) << file << ": " << line;
}

/// Expects readClFile to throw an InputError naming `file:line:` and containing `what`.
void expectClError(const std::string& text, int line, const std::string& what) {
  const fs::path p = writeBytes("bad.cl", text);
  try {
    readClFile(p);
    ADD_FAILURE() << "no error for: " << text;
  } catch (const InputError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find(p.string() + ":" + std::to_string(line) + ": "), std::string::npos) << msg;
    EXPECT_NE(msg.find(what), std::string::npos) << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

}  // namespace

TEST(ClFile, ClosedFormRead) {
  const auto p = readClFile(
      writeBytes("one.cl", "# header\n\n1 2 3 0 0 1   # trailing\n  4\t5 6 0 1 0 0.5\r\n"));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].tip_mm, Vec3(1, 2, 3));
  EXPECT_EQ(p[0].axis, Vec3::UnitZ());
  EXPECT_FALSE(p[0].has_spindle);
  EXPECT_EQ(p[1].axis, Vec3::UnitY());
  EXPECT_TRUE(p[1].has_spindle);
  EXPECT_EQ(p[1].spindle_rad, 0.5);
}

TEST(ClFile, RoundTripsExactly) {
  for (bool spindle : {false, true}) {
    const auto postures = randomPostures(1000, spindle);
    const fs::path p = tempPath("rt.cl");
    writeClFile(p, postures, "fieldpath test\nsecond line");
    expectSame(readClFile(p), writtenAs(postures));
    expectNoExponent(p);
    EXPECT_TRUE(fieldpath::test::temporariesOf(p).empty());
  }
  // The check sees a temporary where one is left.
  const fs::path p = tempPath("rt.cl");
  const fs::path left = p.parent_path() / ("." + p.filename().string() + ".tmp-1");
  std::ofstream(left) << "1 2 3";
  EXPECT_EQ(fieldpath::test::temporariesOf(p).size(), 1u);
  fs::remove(left);
}

// The lines generate names in its messages before path.cl is written (clFileLines) are those the
// reader gives the written file's postures: blocks marked or not, comments of any length, an
// empty comment line, a limit mark.
TEST(ClFile, LinesNamedBeforeWritingAreTheFilesLines) {
  PathFile path;
  path.postures = randomPostures(9, false);
  const std::vector<std::vector<PathBlock>> layouts = {
      {{PathBlock::Kind::Pass, 0, 9}},
      {{PathBlock::Kind::Link, 0, 2}, {PathBlock::Kind::Pass, 2, 6}, {PathBlock::Kind::Link, 6, 9}},
      {{PathBlock::Kind::Pass, 0, 1}, {PathBlock::Kind::Pass, 1, 9}}};
  path.limited = {3};
  for (const auto& blocks : layouts)
    for (const std::string comment : {"", "one", "UNSAFE TO RUN: x\n\nthird\nfourth"}) {
      path.blocks = blocks;
      const fs::path p = tempPath("lines.cl");
      writeClFile(p, path, comment);
      const std::vector<std::size_t> named = clFileLines(path, clCommentLines(comment));
      EXPECT_EQ(named, readClPath(p).lines) << blocks.size() << " blocks, comment: " << comment;
    }
}

// Numbers as post-processors read them: no exponent ("4.8e-05" was written for an axis component
// of the impeller's path), the shortest fixed form that reads back the same; under 1e-12, 0.
TEST(ClFile, WritesNumbersWithoutAnExponent) {
  std::vector<Posture> postures(2);
  postures[0].tip_mm = Vec3(-4.8037586702237175e-05, 1e-13, -1e-20);
  postures[0].axis = Vec3(4.8037586702237175e-05, 0, 1).normalized();
  postures[1].tip_mm = Vec3(123456.789, -0.1, 1e6);
  postures[1].axis = Vec3(0, -1, 1e-14).normalized();
  const fs::path p = tempPath("numbers.cl");
  writeClFile(p, postures, "");
  expectNoExponent(p);
  const auto back = readClFile(p);
  ASSERT_EQ(back.size(), 2u);
  EXPECT_EQ(back[0].tip_mm.x(), -4.8037586702237175e-05);
  EXPECT_EQ(back[0].tip_mm.y(), 0.0);
  EXPECT_TRUE(std::signbit(back[0].tip_mm.z()));  // -0: the sign kept
  EXPECT_EQ(back[0].axis, postures[0].axis);
  EXPECT_EQ(back[1].tip_mm, postures[1].tip_mm);
  EXPECT_EQ(back[1].axis, Vec3(0, -1, 0));
  std::ifstream in(p);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("-0.000048037586702237175 0 -0 "), std::string::npos) << text;
}

TEST(ClFile, NormalisesNearlyUnitAxes) {
  const auto p = readClFile(
      writeBytes("near.cl", "0 0 0 0 0 1.0009\n0 0 0 0.6 0.8 0.01\n0 0 0 0.6 0.8 0.0001\n"));
  EXPECT_EQ(p[0].axis, Vec3::UnitZ());
  EXPECT_NEAR(p[1].axis.norm(), 1.0, 1e-15);
  // off by 5e-9 (float rounding, as from 32-bit values): kept as written, so that the same
  // floats as text and as a float32 .npy give the same postures
  EXPECT_EQ(p[2].axis, Vec3(0.6, 0.8, 0.0001));
}

TEST(ClFile, MalformedLinesNameTheLine) {
  expectClError("0 0 0 0 0 1\nnan 0 0 0 0 1\n", 2, "not finite");
  expectClError("0 0 0 0 0 1\n0 0 0 0 0 inf\n", 2, "not finite");
  expectClError("# c\n0 0 0 0 0 1\n\n1 2 3 0 0\n", 4, "short line");
  expectClError("1 2 3 0 0 0\n", 1, "zero tool axis");
  expectClError("1 2 3 0 0 1.002\n", 1, "not a unit vector");
  expectClError("1 2 3 0 0 0.998\n", 1, "not a unit vector");
  expectClError("1 2 3 0 0 1\n\xff\xfe\x01garbage 2 3 0 0 1\n", 2, "not a number");
  expectClError("1 2 3 0 0 1\n1 2 3 0 0 1 0 9\n", 2, "too many columns");
  expectClError("1 2 3 0 0 1x\n", 1, "not a number");
  expectClError("1 2 3 0 0 1\n1 2 1e999 0 0 1\n", 2, "out of range");
  expectClError("1,2,3,0,0,1\n", 1, "separated by commas");
  expectClError("GOTO/1,2,3\n", 1, "separated by commas");  // an APT file named .cl
  expectClError("PARTNO X\n", 1, "'PARTNO' is not a number");
}

// UTF-16 (a Windows editor's "Unicode") is said so, in either format (it read as "no GOTO
// records" or a line of garbage).
TEST(ClFile, Utf16IsRefusedSayingSo) {
  for (const char* name : {"w16.cl", "w16.apt"}) {
    std::string text = "\xFF\xFE";
    for (char c : std::string("GOTO/1,2,3,0,0,1\n")) text += std::string{c, '\0'};
    try {
      readPathFile(writeBytes(name, text));
      ADD_FAILURE() << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("UTF-16"), std::string::npos) << e.what();
    }
  }
}

// Lines ended by a CR alone (classic Mac OS) read as one line of 12 columns: said what they are.
// CRLF, and a lone CR at the very end, still read.
TEST(ClFile, CrOnlyLineEndsAreRefusedSayingSo) {
  for (const char* name : {"mac.cl", "mac.apt"}) {
    const std::string text = std::string(name).ends_with(".cl")
                                 ? "1 2 3 0 0 1\r4 5 6 0 0 1\r"
                                 : "GOTO/1,2,3,0,0,1\rGOTO/4,5,6,0,0,1\r";
    try {
      readPathFile(writeBytes(name, text));
      ADD_FAILURE() << name;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(":1: the line ends in a CR alone"), std::string::npos)
          << e.what();
    }
  }
  EXPECT_EQ(readPathFile(writeBytes("crlf.cl", "1 2 3 0 0 1\r\n4 5 6 0 0 1\r\n")).postures.size(),
            2u);
  EXPECT_EQ(readPathFile(writeBytes("one.cl", "1 2 3 0 0 1\r")).postures.size(), 1u);
}

TEST(ClFile, EmptyAndMissingFiles) {
  for (const char* text : {"", "# only a comment\n\n   \n"}) {
    const fs::path p = writeBytes("empty.cl", text);
    try {
      readClFile(p);
      ADD_FAILURE() << "no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("no postures"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(readClFile(tempPath("does_not_exist.cl")), InputError);
  EXPECT_THROW(readClFile(fs::temp_directory_path()), InputError);  // a directory
}

// The part's name (generate's: the scene file's) is one PARTNO card whatever it holds: a scene
// file named with a line break put a raw line of its name into the program (an environment
// sweep's; here a GOTO), a `$` would have continued the record into the next.
TEST(AptFile, APartNameIsOneCardWhateverItHolds) {
  AptHeader header;
  header.part_name = "PART\nGOTO/0,0,-50,0,0,1\r$";
  header.remarks = {"UNSAFE\tTO RUN\n$GOTO/1,1,1"};
  const fs::path p = tempPath("named.apt");
  writeAptFile(p, randomPostures(3, false), header);
  std::ifstream in(p);
  std::string first, line;
  std::getline(in, first);
  EXPECT_EQ(first, "PARTNO/PART GOTO/0,0,-50,0,0,1  ");
  std::size_t gotos = 0;
  while (std::getline(in, line)) {
    gotos += line.rfind("GOTO/", 0) == 0;
    for (char c : line) EXPECT_GE(static_cast<unsigned char>(c), 0x20) << line;
  }
  EXPECT_EQ(gotos, 3u);
  EXPECT_EQ(readAptFile(p).size(), 3u);
}

TEST(AptFile, WritesHeaderAndParsesBackExactly) {
  const auto postures = randomPostures(200, false);
  AptHeader header;
  header.part_name = "IMPELLER";
  header.tool.shape = ToolShape::Torus;
  header.tool.radius_mm = 5;
  header.tool.corner_radius_mm = 1;
  header.tool.length_mm = 30;
  header.feed_mm_per_min = 1500;
  const fs::path p = tempPath("path.apt");
  writeAptFile(p, postures, header);
  std::ifstream in(p);
  std::string l1, count, l2, l3, l4, note, l5, l6;
  std::getline(in, l1), std::getline(in, count), std::getline(in, l2), std::getline(in, l3),
      std::getline(in, l4);
  // How the motions were checked, for the post-processor's author: cards of their own.
  std::string notes;
  while (std::getline(in, note) && note.rfind("PPRINT/", 0) == 0) notes += note.substr(7) + " ";
  l5 = note;
  std::getline(in, l6);
  EXPECT_NE(notes.find("TOOL AXIS ON THE GREAT CIRCLE"), std::string::npos) << notes;
  EXPECT_NE(notes.find("RAPIDS AS LINEAR MOVES"), std::string::npos) << notes;
  EXPECT_NE(notes.find("NO LOADTL, SPINDL OR COOLNT"), std::string::npos) << notes;
  EXPECT_EQ(l1, "PARTNO/IMPELLER");
  EXPECT_EQ(count, "PPRINT/POSTURES " + std::to_string(postures.size()) +
                       " (A FILE HOLDING FEWER WAS CUT SHORT)");
  EXPECT_EQ(l2, "UNITS/MM");
  EXPECT_EQ(l3, "MULTAX/ON");
  EXPECT_EQ(l4, "CUTTER/10,1,4,1,0,0,30");
  EXPECT_EQ(l5, "FEDRAT/MMPM,1500");
  EXPECT_EQ(l6.rfind("GOTO/", 0), 0u);
  // Cards of 72 columns: a GOTO of 17-digit numbers (131 columns) goes on after a `$`.
  std::string last, line;
  std::size_t continued = 0;
  while (std::getline(in, line)) {
    EXPECT_LE(line.size(), 72u) << line;
    continued += !line.empty() && line.back() == '$';
    last = line;
  }
  EXPECT_GT(continued, 0u);
  EXPECT_EQ(last, "FINI");

  auto back = readAptFile(p);
  for (auto& b : back) b.has_spindle = false;
  expectSame(back, writtenAs(postures));
  expectNoExponent(p);
  EXPECT_TRUE(readPathFile(p).warnings.empty());  // the note is no safety mark
}

TEST(AptFile, ReadsContinuationAndRejectsBadGoto) {
  const auto p =
      readAptFile(writeBytes("c.apt", "PARTNO/X\nGOTO/1,2,$\n 3,0,0,1\nGOTO/4,5,6\nFINI\n"));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[0].tip_mm, Vec3(1, 2, 3));
  EXPECT_EQ(p[1].tip_mm, Vec3(4, 5, 6));
  EXPECT_EQ(p[1].axis, Vec3::UnitZ());
  EXPECT_THROW(readAptFile(writeBytes("b.apt", "GOTO/1,2,3,0,0\n")), InputError);
  EXPECT_THROW(readAptFile(writeBytes("b.apt", "GOTO/1,2,x,0,0,1\n")), InputError);
  EXPECT_THROW(readAptFile(writeBytes("b.apt", "PARTNO/X\nFINI\n")), InputError);
  // A record still continued at the end of the file: truncated.
  EXPECT_THROW(readAptFile(writeBytes("b.apt", "GOTO/1,2,3\nGOTO/1,2,$\n")), InputError);
  // What follows a single `$` and a blank on its line is a remark (it was read as a bad number);
  // a `$` in a text record's text is the text's (a Siemens post's INSERT/R1=$P_TOOLNO took the
  // RAPID after it into itself: a rapid move read as a feed move).
  const auto remark = readAptFile(writeBytes("r.apt", "GOTO/0,0,-0.5,$ first part\n0,1,0\n"));
  ASSERT_EQ(remark.size(), 1u);
  EXPECT_EQ(remark[0].tip_mm, Vec3(0, 0, -0.5));
  EXPECT_EQ(remark[0].axis, Vec3::UnitY());
  const PathFile insert = readPathFile(writeBytes(
      "i.apt", "GOTO/0,0,0,0,0,1\nINSERT/R1=$ P_TOOLNO\nRAPID\nGOTO/0,0,9\nGOTO/1,0,9\n"));
  ASSERT_EQ(insert.postures.size(), 3u);
  EXPECT_EQ(insert.count(PathBlock::Kind::Link), 1u);
}

// A UTF-8 byte-order mark at the start (Windows editors) is not a number of line 1.
TEST(ClFile, ByteOrderMarkIsReadPast) {
  const auto cl = readClFile(writeBytes("bom.cl", "\xEF\xBB\xBF" "0 0 1 0 0 1\n1 0 1 0 0 1\n"));
  ASSERT_EQ(cl.size(), 2u);
  EXPECT_EQ(cl[0].tip_mm, Vec3(0, 0, 1));
  EXPECT_EQ(readAptFile(writeBytes("bom.apt", "\xEF\xBB\xBFGOTO/1,2,3\n")).size(), 1u);
}

// Inches in mm are the decimals they are (the nearest double to them), as a CAM engineer reads
// them and `convert` writes them: 0.7874 in was written 19.999959999999998 (an adversary's). A
// relative move's sum too: 0.1 + 0.2 mm is 0.3, and a CUTTER in inches is its mm.
TEST(AptFile, InchesAndRelativeMovesAreTheirDecimalsInMm) {
  const PathFile p = readPathFile(
      writeBytes("inch_decimals.apt",
                 "UNITS/INCHES\nCUTTER/0.23622, 0.11811\nGOTO/0.7874, -1.1811, 0.0001, "
                 "0, 0, 1\nUNITS/MM\nGOTO/0.1, 0, 0\nGODLTA/0.2, 0, 0\n"));
  ASSERT_EQ(p.postures.size(), 3u);
  EXPECT_EQ(p.postures[0].tip_mm, Vec3(19.99996, -29.99994, 0.00254));
  EXPECT_EQ(p.postures[2].tip_mm, Vec3(0.3, 0, 0));
  ASSERT_EQ(p.cutters.size(), 1u);
  EXPECT_EQ(p.cutters[0].diameter_mm, 5.999988);
  EXPECT_EQ(p.cutters[0].corner_mm, 2.999994);
  // What the writers write of them: the decimals (shortest round trip of the double).
  char text[64];
  const auto end = std::to_chars(text, text + sizeof text, p.postures[0].tip_mm.x()).ptr;
  EXPECT_EQ(std::string(text, end), "19.99996");
  // A CUTTER whose diameter is not > 0 is kept as written (the notes say it gives no tool; it was
  // read past without a word), one of words read past.
  const PathFile q = readPathFile(
      writeBytes("cutter_negative.apt", "CUTTER/-6, 3\nCUTTER/TOOL1\nGOTO/0,0,0,0,0,1\n"));
  ASSERT_EQ(q.cutters.size(), 1u);
  EXPECT_EQ(q.cutters[0].diameter_mm, -6.0);
  EXPECT_EQ(q.cutters[0].line, 1u);
}

// UNITS scales what follows to mm (inches: 25.4), an unknown unit is refused with its line, FINI
// ends the program (a post-processor reads nothing after it), PPRINT remarks are read past.
TEST(AptFile, UnitsFiniAndRemarks) {
  const auto p = readAptFile(writeBytes(
      "u.apt",
      "PARTNO/X\nPPRINT/UNSAFE TO RUN: 1 POSTURE\nUNITS/MM\nGOTO/1,2,3,0,0,1\nUNITS/INCHES\n"
      "GOTO/1,2,3\nUNITS/MM\nGOTO/4,5,6\nFINI\nGOTO/7,8,9,0,0,1\n"));
  ASSERT_EQ(p.size(), 3u);
  EXPECT_EQ(p[0].tip_mm, Vec3(1, 2, 3));
  // On the picometre grid: 3 in is 76.2 mm (the product is 76.19999999999999).
  EXPECT_EQ(p[1].tip_mm, Vec3(25.4, 50.8, 76.2));
  EXPECT_EQ(p[1].axis, Vec3::UnitZ());
  EXPECT_EQ(p[2].tip_mm, Vec3(4, 5, 6));
  try {
    readAptFile(writeBytes("f.apt", "GOTO/1,2,3\nUNITS/FEET\nGOTO/1,2,3\n"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("f.apt:2: UNITS/FEET"), std::string::npos) << e.what();
  }
  // Written remarks come back as PPRINT records, one line each, and read past.
  AptHeader header;
  header.remarks = {"unsafe to run: a $ and\na newline"};
  const fs::path w = tempPath("remarks.apt");
  writeAptFile(w, p, header);
  std::ifstream in(w);
  std::string l1, l2;  // PARTNO, the posture count, then the remark
  std::getline(in, l1), std::getline(in, l1), std::getline(in, l2);
  EXPECT_EQ(l2, "PPRINT/UNSAFE TO RUN: A   AND A NEWLINE");
  EXPECT_EQ(readAptFile(w).size(), 3u);
  // A remark past a PPRINT card's 65 characters of text goes on in PPRINT cards of its own,
  // split between words; the safety mark stays on the first.
  header.remarks = {
      "UNSAFE TO RUN: 49 motions touch an obstacle (first: posture 114 to the "
      "next) and 47 postures"};
  writeAptFile(w, p, header);
  std::ifstream cards(w);
  std::string c1, c2, c3, c4;  // PARTNO, the posture count, then the remark
  std::getline(cards, c1), std::getline(cards, c1), std::getline(cards, c2),
      std::getline(cards, c3), std::getline(cards, c4);
  EXPECT_EQ(c2, "PPRINT/UNSAFE TO RUN: 49 MOTIONS TOUCH AN OBSTACLE (FIRST: POSTURE 114");
  EXPECT_EQ(c3, "PPRINT/TO THE NEXT) AND 47 POSTURES");
  EXPECT_EQ(c4, "UNITS/MM");
  // An unsafe path halts before its first motion (STOP: M00), read past; under the clearance
  // only, it runs.
  const std::string halted((std::istreambuf_iterator<char>(cards)),
                           std::istreambuf_iterator<char>());
  ASSERT_NE(halted.find("\nSTOP\n"), std::string::npos) << halted;
  EXPECT_LT(halted.find("\nSTOP\n"), halted.find("GOTO/")) << halted;
  const PathFile marked = readPathFile(w);
  EXPECT_EQ(marked.postures.size(), 3u);
  ASSERT_EQ(marked.warnings.size(), 1u);  // the mark whole, read back from its cards
  EXPECT_EQ(marked.warnings[0],
            "UNSAFE TO RUN: 49 MOTIONS TOUCH AN OBSTACLE (FIRST: POSTURE 114 "
            "TO THE NEXT) AND 47 POSTURES");
  header.remarks = {"UNDER THE REQUIRED CLEARANCE: postures min 0.3 mm"};
  writeAptFile(w, p, header);
  std::ifstream under(w);
  const std::string runs((std::istreambuf_iterator<char>(under)), std::istreambuf_iterator<char>());
  EXPECT_EQ(runs.find("STOP"), std::string::npos) << runs;
}

// A motion the reader does not take is refused with its line (each lost a posture silently),
// and a `$` ending a PPRINT is its text's, not a continuation (it swallowed the next GOTO).
TEST(AptFile, MotionsNotReadAreRefusedAndPprintKeepsItsDollar) {
  for (const std::string& record :
       {"RAPID,GOTO/1,2,3", "N40 GOTO/1,2,3", "GO TO/1,2,3", "GODLTA/0,5",
        // an arc (CIRCLE/ makes the next GOTO one), drive-surface moves, a cycle, home without
        // a FROM/ point, a move by what is not a number
        "CIRCLE/0,0,0,0,0,1,18,0.01,0.5,6,0", "MOVARC/0,0,0,0,0,1,18,ANGLE,90",
        "GOFWD/(CIRCLE/0,0,0,5)", "GOHOME", "CYCLE/DRILL,5,FEDTO,0,MMPM,100", "GODLTA/0,0,5,1",
        "GODLTA/Z,5", "GOHOME/XAXIS"}) {
    try {
      readAptFile(writeBytes("m.apt", "GOTO/0,0,0,0,0,1\n" + record + "\nGOTO/1,0,0\n"));
      ADD_FAILURE() << record << " was read past";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("m.apt:2:"), std::string::npos) << e.what();
    }
  }
  const auto p = readAptFile(
      writeBytes("d.apt", "GOTO/0,0,0,0,0,1\nPPRINT/PRICE 5$\nGOTO/1,0,0\nGOTO/2,0,0\n"));
  EXPECT_EQ(p.size(), 3u);
  // CYCLE/OFF ends a cycle: read past
  EXPECT_EQ(readAptFile(writeBytes("o.apt", "CYCLE/OFF\nGOTO/0,0,0,0,0,1\n")).size(), 1u);
  // A GOTO line joined by a `$` to the record above (it was lost), named at its own line; an
  // operation name holding "GOTO" (NX: TOOL PATH/GOTO_POINTS,...) is no motion.
  try {
    readAptFile(writeBytes("j.apt", "GOTO/0,0,0,0,0,1\nCOOLNT/ON $\nGOTO/2,2,3,0,0,1\n"));
    ADD_FAILURE() << "a GOTO joined to COOLNT was read past";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("j.apt:3:"), std::string::npos) << e.what();
  }
  EXPECT_EQ(readAptFile(writeBytes("nx.apt", "TOOL PATH/GOTO_POINTS,TOOL,BALL_6\n"
                                             "GOTO/0,0,0,0,0,1\n")).size(), 1u);
}

// Classic 80-column cards number themselves in columns 73-80 (after a blank column 72): read
// past (such decks were refused as bad numbers); a free-format record's number past column 72 is
// still the record's.
TEST(AptFile, CardSequenceNumbersAreReadPast) {
  const auto card = [](std::string text, const std::string& sequence) {
    text.resize(72, ' ');
    return text + sequence + "\r\n";
  };
  const auto p = readAptFile(writeBytes(
      "seq.apt",
      card("MULTAX/ON", "00000010") + card("GOTO/0.0000,10.0000,0.0000,0.,0.,1.", "00000020") +
          card("GOTO/0.5000,10.0000,0.0000,0.,0.,1.", "PART0030") + card("FINI", "00000040")));
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(p[1].tip_mm, Vec3(0.5, 10, 0));
  EXPECT_EQ(p[1].axis, Vec3::UnitZ());
  std::string free_format = "GOTO / 10.0000000000, 20.0000000000, 30.0000000000, 0.0000000000, ";
  free_format.resize(72, ' ');  // the last number stands alone past column 72
  const auto q = readAptFile(writeBytes("free.apt", free_format + "0, 1\n"));
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(q[0].tip_mm, Vec3(10, 20, 30));
}

// TLAXIS/i,j,k sets the axis of the 3-value GOTOs after it (APT's modal axis: they kept the old
// one).
TEST(AptFile, TlaxisSetsTheAxisOfThreeValueGotos) {
  const auto p = readAptFile(writeBytes(
      "t.apt", "GOTO/0,0,0,0,0,1\nTLAXIS/0.6,0,0.8\nGOTO/1,0,0\nGOTO/2,0,0,0,0,1\nGOTO/3,0,0\n"));
  ASSERT_EQ(p.size(), 4u);
  EXPECT_EQ(p[1].axis, Vec3(0.6, 0, 0.8));
  EXPECT_EQ(p[3].axis, Vec3::UnitZ());
  // Other forms (TLAXIS/NORMPS) are read past, as are a fourth value's words.
  const auto n = readAptFile(writeBytes(
      "n.apt",
      "GOTO/0,0,0,0.6,0,0.8\nTLAXIS/NORMPS\nGOTO/1,0,0\nTLAXIS/0,0.6,0.8,0\nGOTO/2,0,0\n"));
  ASSERT_EQ(n.size(), 3u);
  EXPECT_EQ(n[1].axis, Vec3(0.6, 0, 0.8));
  EXPECT_EQ(n[2].axis, Vec3(0, 0.6, 0.8));
}

// GODLTA moves by dx, dy, dz (or by d along the tool axis) from where the motion before ends,
// GOHOME to the FROM/ point (a rapid, as posts run it), each keeping the axis, in the unit in
// force, whatever the chunks (the move before may be an earlier chunk's); they were refused, and
// a CAM system's program ending in them with it.
TEST(AptFile, GodltaMovesFromThePostureBeforeAndGohomeGoesToTheFromPoint) {
  const double s = std::sqrt(0.5);
  const auto file =
      writeBytes("rel.apt", "FROM/0,0,4,0,0,1\nUNITS/INCHES\nRAPID\nGOTO/1,0,2,0," +
                                std::to_string(s) + "," + std::to_string(s) +
                                "\nFEDRAT/IPM,20\nGODLTA/0,0,-1\nGOTO/2,0,1\nGODLTA/2\n"
                                "RAPID\nGODLTA/0,0,1\nGOHOME\nFINI\n");
  for (const std::size_t chunk : {std::size_t{8}, std::size_t{16}, std::size_t{1} << 20}) {
    PathReadOptions options;
    options.chunk_bytes = chunk;
    const PathFile p = readPathFile(file, options);
    ASSERT_EQ(p.postures.size(), 6u) << chunk;
    const double in = 25.4;
    const Vec3 axis(0, s, s);
    const Vec3 expected[] = {Vec3(1, 0, 2) * in,
                             Vec3(1, 0, 1) * in,
                             Vec3(2, 0, 1) * in,
                             Vec3(2, 0, 1) * in + 2 * in * axis,
                             Vec3(2, 0, 2) * in + 2 * in * axis,
                             Vec3(0, 0, 4)};  // FROM/ before UNITS: in mm
    for (std::size_t k = 0; k < 6; ++k) {
      EXPECT_NEAR((p.postures[k].tip_mm - expected[k]).norm(), 0.0, 1e-4) << chunk << " " << k;
      // GOHOME too keeps the axis (not FROM/'s).
      EXPECT_NEAR((p.postures[k].axis - axis).norm(), 0.0, 1e-5) << chunk << " " << k;
    }
    // The rapid, the pass of three (the GODLTA along the axis at feed), the rapid and home.
    ASSERT_EQ(p.blocks.size(), 3u) << chunk;
    EXPECT_EQ(p.blocks[0].kind, PathBlock::Kind::Link);
    EXPECT_EQ(p.blocks[1].size(), 3u);
    EXPECT_EQ(p.blocks[2].kind, PathBlock::Kind::Link);
    EXPECT_EQ(p.blocks[2].size(), 2u);
    EXPECT_EQ(p.lines[5], 11u);
  }
  // Its error waits for the file's own errors, whatever the chunks (a fuzzer's: in chunks the
  // GODLTA from nowhere on line 2 was said, whole the bad GOTO on line 3).
  // So does a tip past the readers' range once in mm (50 000 inches).
  for (const std::string text :
       {"GODLTA/0,0,-1\nGOTO/NI\n", "UNITS/INCHES\nGOTO/0,0,50000,0,0,1\nGOTO/NI\n"}) {
    const auto both = writeBytes("both.apt", text);
    const std::string line = text.starts_with("UNITS") ? "both.apt:3:" : "both.apt:2:";
    for (const std::size_t chunk : {std::size_t{4}, std::size_t{1} << 20}) {
      PathReadOptions options;
      options.chunk_bytes = chunk;
      try {
        readPathFile(both, options);
        ADD_FAILURE() << "read";
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(line), std::string::npos) << chunk << e.what();
      }
    }
  }
  // A GODLTA with nothing before it to move from is refused at its line.
  try {
    readAptFile(writeBytes("first.apt", "PARTNO/X\nGODLTA/0,0,5\nGOTO/1,0,0,0,0,1\n"));
    ADD_FAILURE() << "a GODLTA from nowhere was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("first.apt:2: GODLTA/: no position before it"),
              std::string::npos)
        << e.what();
  }
}
