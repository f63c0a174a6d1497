/// Path files as generate writes them (.cl with `# pass` / `# link` / limit marks, .npy, APT)
/// read back bit for bit, and broken .npy files refused with one line.
#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fixtures.h"
#include "run_fieldpath.h"

using namespace fieldpath;
using fieldpath::test::TempDir;
using geometry::PathBlock;
using geometry::PathFile;
using geometry::Posture;
using pathgen::test::errorOf;

namespace {

bool sameBits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

TEST(PathFiles, MarkedClAndNpyReadBackBitForBit) {
  PathFile path;
  for (int i = 0; i < 9; ++i) {
    Posture p;
    p.tip_mm = {0.1 * i + 1.0 / 3.0, -7.25 + i * 1e-7, 12.0 / 7.0};
    p.axis = Eigen::Vector3d(0.1, -0.2 * i, 1.0).normalized();
    path.postures.push_back(p);
  }
  path.blocks = {{PathBlock::Kind::Link, 0, 2},
                 {PathBlock::Kind::Pass, 2, 5},
                 {PathBlock::Kind::Link, 5, 6},
                 {PathBlock::Kind::Pass, 6, 9}};
  path.limited = {3, 7};
  TempDir dir;
  geometry::writeClFile(dir.path() / "m.cl", path, "a test\nof markers");
  const PathFile back = geometry::readPathFile(dir.path() / "m.cl");
  EXPECT_EQ(back.blocks, path.blocks);
  EXPECT_EQ(back.limited, path.limited);
  geometry::writeNpyFile(dir.path() / "m.npy", path.postures);
  const PathFile npy = geometry::readPathFile(dir.path() / "m.npy");
  geometry::AptHeader header;
  geometry::writeAptFile(dir.path() / "m.apt", path, header);
  const PathFile apt = geometry::readPathFile(dir.path() / "m.apt");
  EXPECT_EQ(apt.blocks, path.blocks);
  for (const PathFile* read : {&back, &npy, &apt}) {
    ASSERT_EQ(read->postures.size(), path.postures.size());
    for (std::size_t i = 0; i < path.postures.size(); ++i)
      for (int c = 0; c < 3; ++c) {
        EXPECT_TRUE(sameBits(read->postures[i].tip_mm[c], path.postures[i].tip_mm[c]));
        EXPECT_TRUE(sameBits(read->postures[i].axis[c], path.postures[i].axis[c]));
      }
  }
  // Written again, the .cl file is the same text.
  geometry::writeClFile(dir.path() / "m2.cl", back, "a test\nof markers");
  EXPECT_EQ(fieldpath::test::slurp(dir.path() / "m.cl"),
            fieldpath::test::slurp(dir.path() / "m2.cl"));
}

// A path file cut short at a line (a DNC or USB transfer) reads as a shorter path that stops in
// the cut: a helper's first 500 lines of a path.cl, and an APT file cut before FINI, read
// `check: ok`. The writers declare the count; a file holding fewer is refused at that line.
TEST(PathFiles, AFileCutShortIsRefusedAtItsDeclaredCount) {
  PathFile path;
  for (int i = 0; i < 40; ++i) {
    Posture p;
    p.tip_mm = {0.5 * i, 1.0, 2.0};
    path.postures.push_back(p);
  }
  path.blocks = {{PathBlock::Kind::Pass, 0, 40}};
  TempDir dir;
  geometry::writeClFile(dir.path() / "p.cl", path, "a path");
  geometry::writeAptFile(dir.path() / "p.apt", path, geometry::AptHeader{});
  for (const char* name : {"p.cl", "p.apt"}) {
    SCOPED_TRACE(name);
    ASSERT_EQ(geometry::readPathFile(dir.path() / name).postures.size(), 40u);
    const std::string text = fieldpath::test::slurp(dir.path() / name);
    std::size_t cut = text.size() - 1;  // 10 lines before the end
    for (int k = 0; k < 10; ++k) cut = text.rfind('\n', cut - 1);
    const std::string short_name = std::string("short_") + name;
    dir.write(short_name, text.substr(0, cut + 1));
    const std::string error = errorOf([&] { geometry::readPathFile(dir.path() / short_name); });
    EXPECT_NE(error.find(short_name + ":2: declares 40 postures and the file holds"),
              std::string::npos)
        << error;
    EXPECT_NE(error.find("cut short"), std::string::npos) << error;
  }
  // simulate streams the file (its chunks stamped as they are read): refused all the same.
  const auto sim =
      fieldpath::test::runFieldpath(dir, "simulate --tool ball:3 --path short_p.cl --out sim");
  EXPECT_EQ(sim.exit_code, 1) << sim.output();
  EXPECT_NE(sim.err.find("short_p.cl:2: declares 40 postures"), std::string::npos) << sim.err;
  // A file that declares nothing (any other writer's) is taken as it is.
  dir.write("plain.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  EXPECT_EQ(geometry::readPathFile(dir.path() / "plain.cl").postures.size(), 2u);
}

// Cut inside its last record, a file still holds its declared count: the fragment reads as a
// posture (an APT GOTO cut before its `$` is a 3-number GOTO at z = 1 where 17.8 was written; a
// `.cl` line cut in its axis is normalised). A file that declares its count must end as its
// writer ends it (APT: FINI; `.cl`: a line end). The declaration is read in any case and
// spacing, and one whose number is unreadable is refused (both switched the check off: a helper).
TEST(PathFiles, AFileCutInsideItsLastRecordIsRefused) {
  PathFile path;
  for (int i = 0; i < 12; ++i) {
    Posture p;
    p.tip_mm = {0.37 + i, 15.03, 17.83};
    p.axis = Eigen::Vector3d(0.1, 0.2, 1.0).normalized();
    path.postures.push_back(p);
  }
  path.blocks = {{PathBlock::Kind::Pass, 0, 12}};
  TempDir dir;
  geometry::writeClFile(dir.path() / "p.cl", path, "a path");
  geometry::writeAptFile(dir.path() / "p.apt", path, geometry::AptHeader{});
  const std::string cl = fieldpath::test::slurp(dir.path() / "p.cl");
  const std::string apt = fieldpath::test::slurp(dir.path() / "p.apt");
  // The last GOTO cut after its second comma and one digit, and the last .cl line after 3 bytes
  // of its last axis component.
  const std::size_t last_goto = apt.rfind("GOTO/");
  const std::size_t second_comma = apt.find(',', apt.find(',', last_goto) + 1);
  dir.write("cut.apt", apt.substr(0, second_comma + 2));
  dir.write("nofini.apt", apt.substr(0, apt.rfind("FINI")));
  dir.write("cut.cl", cl.substr(0, cl.size() - 4));
  for (const char* name : {"cut.apt", "nofini.apt", "cut.cl"}) {
    const std::string error = errorOf([&] { geometry::readPathFile(dir.path() / name); });
    EXPECT_NE(error.find(std::string(name) + ":"), std::string::npos) << error;
    EXPECT_NE(error.find("declares 12 postures and the file ends"), std::string::npos) << error;
  }
  // Deleting the declaration takes the file as it is (as the message says).
  std::string undeclared = cl.substr(0, cl.size() - 4);
  undeclared.erase(
      undeclared.find("# postures: "),
      undeclared.find('\n', undeclared.find("# postures: ")) + 1 - undeclared.find("# postures: "));
  dir.write("undeclared.cl", undeclared);
  EXPECT_EQ(geometry::readPathFile(dir.path() / "undeclared.cl").postures.size(), 12u);
  // The declaration in other spellings is still one; a number that is none is refused.
  const std::string body = "0 0 0 0 0 1\n1 0 0 0 0 1\n";
  for (const std::string header : {"#postures:3\n", "# Postures : 3\n", "#\tPOSTURES: 3 (x)\n"}) {
    dir.write("h.cl", header + body);
    EXPECT_NE(errorOf([&] {
                geometry::readPathFile(dir.path() / "h.cl");
              }).find("declares 3 postures and the file holds 2"),
              std::string::npos)
        << header;
  }
  for (const std::string header :
       {"# postures: -1\n", "# postures: 99999999999999999999999\n", "# postures: 2x\n"}) {
    dir.write("h.cl", header + body);
    EXPECT_NE(
        errorOf([&] { geometry::readPathFile(dir.path() / "h.cl"); }).find("h.cl:1: '# postures: "),
        std::string::npos)
        << header;
  }
  // Words after the colon are a comment (`# Postures: x y z i j k`), not a count.
  for (const std::string header : {"# postures: abc\n", "# Postures: x y z i j k\n"}) {
    dir.write("h.cl", header + body);
    EXPECT_EQ(geometry::readPathFile(dir.path() / "h.cl").postures.size(), 2u) << header;
  }
  // Whole but for its last line end, after a comment or blanks: read.
  dir.write("tail.cl", "# postures: 2\n" + body + "# end");
  EXPECT_EQ(geometry::readPathFile(dir.path() / "tail.cl").postures.size(), 2u);
  dir.write("h.apt", "pprint / postures 3\ngoto/0,0,0,0,0,1\ngoto/1,0,0,0,0,1\nfini\n");
  EXPECT_NE(errorOf([&] {
              geometry::readPathFile(dir.path() / "h.apt");
            }).find("declares 3 postures and the file holds 2"),
            std::string::npos);
  // A PPRINT is free text: POSTURES followed by words declares nothing.
  for (const std::string remark :
       {"PPRINT/POSTURES ARE CHECKED", "PPRINT/POSTURES 3-AXIS FINISH"}) {
    dir.write("words.apt", remark + "\nGOTO/0,0,0,0,0,1\nGOTO/1,0,0,0,0,1\n");
    EXPECT_EQ(geometry::readPathFile(dir.path() / "words.apt").postures.size(), 2u) << remark;
  }
  // Whole, with CR LF line ends: read.
  std::string crlf;
  for (char c : cl) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
  dir.write("crlf.cl", crlf);
  EXPECT_EQ(geometry::readPathFile(dir.path() / "crlf.cl").postures.size(), 12u);
}

TEST(PathFiles, BadNpyFilesAreOneLineErrors) {
  TempDir dir;
  std::vector<Posture> postures(3);
  geometry::writeNpyFile(dir.path() / "good.npy", postures);
  const std::string good = fieldpath::test::slurp(dir.path() / "good.npy");
  auto variant = [&](const std::string& name, std::string bytes) {
    const auto file = dir.path() / name;
    std::ofstream(file, std::ios::binary) << bytes;
    return errorOf([&] { geometry::readPathFile(file); });
  };
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string s = good;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_NE(variant("trunc.npy", good.substr(0, good.size() - 8)).find("truncated"),
            std::string::npos);
  EXPECT_NE(variant("dtype.npy", replaced("<f8", "<i8")).find("dtype"), std::string::npos);
  // (Fortran order is read, as numpy reads it: test_cli_path_formats.cpp.)
  EXPECT_NE(variant("order.npy", replaced("False", "Maybe")).find("fortran_order"),
            std::string::npos);
  EXPECT_NE(variant("shape.npy", replaced("(3, 6)", "(6, 3)")).find("shape"), std::string::npos);
  EXPECT_NE(variant("magic.npy", "hello").find("magic"), std::string::npos);
  std::string nan = good;
  const double q = std::nan("");
  std::memcpy(nan.data() + nan.size() - 8, &q, 8);
  EXPECT_NE(variant("nan.npy", nan).find("row 2"), std::string::npos);
  std::string zero = good;  // row 0 has the axis (0, 0, 1): zero it
  std::memset(zero.data() + (good.size() - 3 * 48) + 40, 0, 8);
  EXPECT_NE(variant("zero.npy", zero).find("row 0 (from 0): zero tool axis"), std::string::npos);
}
