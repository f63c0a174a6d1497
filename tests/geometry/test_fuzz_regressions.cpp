/// Inputs found by the fuzz targets (tests/fuzz) that crashed, hung or aborted the program, kept
/// as tests with the input itself: each must now be refused with InputError, quickly.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/geometry/tool_model.h"
#include "temp_files.h"

namespace fieldpath::geometry {
namespace {

using namespace std::string_literals;

/// loadMesh(bytes as NAME) throws InputError within a second (the hang ran forever).
void expectRefusedQuickly(const std::string& name, const std::string& bytes) {
  const auto file = test_files::writeBytes(name, bytes);
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(loadMesh(file), common::InputError) << name;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

// fuzz_mesh timeout-cbc6300b: a PLY header without `end_header`: assimp 5.2 looped forever.
TEST(FuzzRegressions, PlyWithoutEndHeaderDoesNotHang) {
  expectRefusedQuickly("hang.ply",
                       "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float "
                       "y\nproperty float z\nelement face 4\nproperty list uchar int "
                       "vertex_indices\ne0\n0 10 0\n10 0 0\n0 0 10\n3 0 1 2\n3 0 2 3\n3 0 3 1\n3 "
                       "2 1 3\n");
}

// fuzz_mesh crash (SEGV in assimp's Triangulate): a binary PLY whose face names vertices past
// the end of a short vertex block.
TEST(FuzzRegressions, PlyFaceBeyondTheVerticesDoesNotCrash) {
  expectRefusedQuickly(
      "segv.ply",
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80 0 0 0\nv 1 0 0\nv 11 2 3"
      "\x00\x00\x00\x01\x00\x00\x00\x02\x00\x00\x00"s);
}

// fuzz_mesh crash-6d0a047e (abort: ai_assert numOut != pMesh->mNumFaces in Triangulate): a
// misspelt `progerty` line leaves the vertices without y. Refused or read, never an abort.
TEST(FuzzRegressions, PlyWithMisspeltPropertyDoesNotAbort) {
  const std::string bytes =
      "ply\nformat binary_little_endian 0.0\nelement vertex 3\nproperty float x\nprogerty float "
      "y\nproperty float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80?\x00\x00\x00\x00\x00\x00\x00"
      "\x00\x00\x00\x00\x00\x00\x00\x80?\x00\x00\x00\x00\x03\x00\x00\x00\x00\x01\x00\x00\x00\x02"
      "\x00\x00\x00"s;
  const auto file = test_files::writeBytes("abort.ply", bytes);
  try {
    const TriangleMesh mesh = loadMesh(file);
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k) EXPECT_LT(t[k], static_cast<int>(mesh.vertices.size()));
  } catch (const common::InputError&) {
  }
}

// fuzz_mesh timeout-a86c8e3a: `plyply` as the first line (assimp still takes it for PLY) and a
// broken binary body: assimp seeked forever.
TEST(FuzzRegressions, PlyWithAStrangeFirstLineDoesNotHang) {
  expectRefusedQuickly("plyply.mesh",
                       "plyply\nformat binary_little_endian 2.e0eml\ne\xff\xff\x02ply\nformat "
                       "binary_little_endian 1.0\nelement vertex 3\nproperty float "
                       "x\xff\xff\xff\xffoperty float y\nprope\nproperty float rt["s);
}

// Found while building the hostile-input table: a PLY whose element count the file cannot hold
// would size assimp's allocations from the header.
TEST(FuzzRegressions, PlyElementCountBeyondTheFileIsRefused) {
  expectRefusedQuickly("huge.ply",
                       "ply\nformat ascii 1.0\nelement vertex 4000000000\nproperty float "
                       "x\nproperty float y\nproperty float z\nend_header\n0 0 0\n");
}

// CI's smoke fuzz, fuzz_mesh crash-2b0d2aaa: a binary PLY whose `end_header` is followed by a
// vertical tab, not a line end: read as the header's end here, assimp took the body elsewhere and
// read past the file (SEGV). `end_header` must be alone on its line.
TEST(FuzzRegressions, PlyEndHeaderNotAloneOnItsLineIsRefused) {
  const std::string header =
      "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float "
      "y\nproperty float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header";
  const std::string body(
      "\x0b\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x00\x80\x3f\x01\x00\x00\x00\x00\x00"
      "\x00\x07\x00\x00\x00\x00\x00\x00\x80\x3f\x00\x00\x00\x00\x00\x02\x00\x00\x00",
      42);
  expectRefusedQuickly("vt.ply", header + body);
}

// fuzz_tool timeout-93cb5020: a 613 mm holder on a 1 mm ball. Nodes 0.5 mm apart (the target
// tied the spacing to the ball) are ~10 M: work the user never asks for (generate and study pick
// the spacing from the area). At a spacing from the area, the count is what the area says, fast.
TEST(FuzzRegressions, WideHolderOnASmallBallGivesNodesByArea) {
  const ToolSpec tool = parseToolSpec("ball:1:40");
  const HolderProfile holder = parseHolderProfile("45:613,95:13,98:122");
  // The surface, by hand: hemisphere, shank running on to the holder at z = 45, the holder's
  // bottom annulus, its two frusta and its top disc (mm²).
  const double pi = std::numbers::pi;
  const double area = 2 * pi + 2 * pi * 44 + pi * (613.0 * 613 - 1) +
                      pi * (613 + 13) * std::hypot(50, 600) + pi * (13 + 122) * std::hypot(3, 109) +
                      pi * 122 * 122;
  const double spacing = std::sqrt(area / 2000);
  const auto start = std::chrono::steady_clock::now();
  const auto nodes = surfaceNodes(tool, holder, spacing);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  EXPECT_GT(nodes.size(), 1000u);
  EXPECT_LT(nodes.size(), 4000u);
}

}  // namespace
}  // namespace fieldpath::geometry
