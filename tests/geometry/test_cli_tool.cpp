#include <algorithm>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "fieldpath/geometry/mesh_io.h"
#include "run_fieldpath.h"
#include "temp_files.h"

namespace fs = std::filesystem;
using fieldpath::geometry::test_files::tempPath;

namespace {

using fieldpath::test::runFieldpath;

std::size_t lines(const std::string& s) {
  return static_cast<std::size_t>(std::count(s.begin(), s.end(), '\n'));
}

}  // namespace

TEST(CliTool, WritesAClosedMesh) {
  const fs::path out = tempPath("cli_tool.stl");
  const fieldpath::test::Outcome r = runFieldpath(
      "tool --shape ball:3:12 --holder 12:5,30:5 --tol 0.01 --out '" + out.string() + "'");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(lines(r.out), 1u) << r.out;
  EXPECT_NE(r.out.find("closed yes"), std::string::npos) << r.out;
  EXPECT_TRUE(fieldpath::geometry::validateMesh(fieldpath::geometry::loadMesh(out)).closed());
  fs::remove(out);
}

TEST(CliTool, BadInputIsOneLineAndExitOne) {
  const fs::path out = tempPath("cli_bad.stl");
  for (const std::string args :
       {"--shape cone:3", "--shape ball:3 --tol 0", "--shape ball:3 --tol -1",
        "--shape ball:3 --holder 5:1", "--shape torus:3:4"}) {
    const fieldpath::test::Outcome r =
        runFieldpath("tool " + args + " --out '" + out.string() + "'");
    EXPECT_EQ(r.exit_code, 1) << args;
    EXPECT_EQ(lines(r.err), 1u) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
    EXPECT_FALSE(fs::exists(out)) << args;
  }
}
