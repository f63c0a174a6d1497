/// A binary PLY's body walked against its header before assimp reads it (split from
/// test_mesh_io.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh_io.h"
#include "temp_files.h"

using namespace fieldpath::geometry;
using fieldpath::common::InputError;
using namespace fieldpath::geometry::test_files;

namespace {

/// Bytes of `value` in little- or big-endian order.
template <typename T>
std::string bytesOf(T value, bool big_endian) {
  std::string out(sizeof(T), '\0');
  std::memcpy(out.data(), &value, sizeof(T));
  if (big_endian) std::reverse(out.begin(), out.end());
  return out;
}

/// The unit square (0,0,0), (1,0,0), (1,1,0), (0,1,0) in two triangles as a binary PLY: vertices
/// of float x y z and a colour byte, faces as a `count_type` list of ints (`counts` written as
/// that type's bytes), header lines ended by `eol`.
std::string binaryPlySquare(bool big_endian, const std::string& eol = "\n",
                            const std::string& count_type = "uchar") {
  std::string text = "ply" + eol + "format " +
                     (big_endian ? "binary_big_endian" : "binary_little_endian") + " 1.0" + eol +
                     "comment two triangles" + eol + "element vertex 4" + eol + "property float x" +
                     eol + "property float y" + eol + "property float z" + eol +
                     "property uchar red" + eol + "element face 2" + eol + "property list " +
                     count_type + " int vertex_indices" + eol + "end_header" + eol;
  for (const auto& v : {std::array<float, 3>{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}}) {
    for (const float c : v) text += bytesOf(c, big_endian);
    text += '\x07';
  }
  for (const auto& f : {std::array<int, 3>{0, 1, 2}, {0, 2, 3}}) {
    text += count_type == "uchar" ? std::string(1, '\x03')
                                  : bytesOf(static_cast<std::int16_t>(3), big_endian);
    for (const int i : f) text += bytesOf(static_cast<std::int32_t>(i), big_endian);
  }
  return text;
}

}  // namespace

// A binary PLY's body is walked element by element against its header before assimp reads it
// (assimp read past the file's end on a body that did not fit: CI's smoke fuzz, a SEGV).
TEST(MeshIo, BinaryPlyBodyIsWalkedAgainstItsHeader) {
  const auto area = [](const TriangleMesh& mesh) {
    double sum = 0.0;
    for (const auto& t : mesh.triangles)
      sum += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                       .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                       .norm();
    return sum;
  };
  for (const bool big : {false, true})
    for (const std::string eol : {"\n", "\r\n"})
      for (const std::string count : {"uchar", "short"}) {
        const TriangleMesh mesh =
            loadMesh(writeBytes("square.ply", binaryPlySquare(big, eol, count)));
        EXPECT_EQ(mesh.triangles.size(), 2u) << big << count;
        EXPECT_NEAR(area(mesh), 1.0, 1e-12) << big << count;
      }
  const auto expectMessage = [](const std::string& bytes, const std::string& what) {
    try {
      (void)loadMesh(writeBytes("body.ply", bytes));
      ADD_FAILURE() << "no error, expected " << what;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  const std::string square = binaryPlySquare(false);
  expectMessage(square.substr(0, square.size() - 1),
                "the body ends inside face 2 of the 2 its header declares");
  // A count that says more items than the file holds; a negative count of a signed type.
  std::string many = square;
  many[many.size() - 13] = '\x40';
  expectMessage(many, "the body ends inside face 2 of the 2");
  std::string negative = binaryPlySquare(false, "\n", "short");
  negative[negative.size() - 13] = '\xff';
  negative[negative.size() - 14] = '\xff';
  expectMessage(negative, "face 2 has a negative list count");
  // A body whose first byte is a line feed (the first float's lowest byte): assimp 5.2 skips it
  // after `end_header\n` and misreads the file ("no triangles"); the loader is given the header
  // with CRLF line ends, after which it reads it right (it was refused: a valid file, for its
  // first float). The same square either way, whatever the header's line ends.
  for (const std::string eol : {"\n", "\r\n"}) {
    std::string lf = binaryPlySquare(false, eol);
    lf[lf.find("end_header" + eol) + 10 + eol.size()] = '\n';
    const TriangleMesh mesh = loadMesh(writeBytes("lf.ply", lf));
    EXPECT_EQ(mesh.triangles.size(), 2u) << (eol == "\n" ? "LF" : "CRLF");
    EXPECT_NEAR(area(mesh), 1.0, 1e-6) << (eol == "\n" ? "LF" : "CRLF");
  }
  // Data after the body (the header's face count short of the faces: assimp dropped the rest,
  // a sphere with 400 faces left out read clear where it collides): refused; a line end after
  // the body is read past.
  expectMessage(square + std::string(13, '\x01'), "13 byte(s) after the body its header declares");
  for (const std::string padding : {std::string("\r\n"), std::string(90, '\0'), std::string("\x1a"),
                                    std::string("comment end\n")})
    EXPECT_EQ(loadMesh(writeBytes("padded.ply", square + padding)).triangles.size(), 2u);
  std::string short_count = square;
  short_count.replace(short_count.find("element face 2"), 14, "element face 1");
  expectMessage(short_count, "13 byte(s) after the body");
  // The same where the dropped face's bytes read as padding (a count of 33 and indices 32-63
  // and 0: spaces, printable bytes and NULs; a helper's cylinder lost a cap so, a tool inside it
  // read clear): refused as a face after the body.
  std::string circle =
      "ply\nformat binary_little_endian 1.0\nelement vertex 64\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar int vertex_indices\nend_header\n";
  for (int k = 0; k < 64; ++k)
    for (const float c : {float(std::cos(k * 3.141592653589793 / 32)),
                          float(std::sin(k * 3.141592653589793 / 32)), 0.0f})
      circle += bytesOf(c, false);
  for (const int first : {0, 32}) {
    circle += '\x21';
    for (int k = first; k <= first + 32; ++k) circle += bytesOf(std::int32_t(k % 64), false);
  }
  expectMessage(circle,
                "133 byte(s) after the body its header declares read as another face (33 "
                "corners");
  // With 1-byte indices and 132 vertices a line of text after the body reads as a face (`\n`: a
  // count of 10, then printable bytes, each under 132) and the rest as none: padding, as with
  // wider indices (it was refused, a reviewer's). The header one face short: refused still.
  std::string small =
      "ply\nformat binary_little_endian 1.0\nelement vertex 132\nproperty float x\n"
      "property float y\nproperty float z\nelement face 1\n"
      "property list uchar uchar vertex_indices\nend_header\n";
  for (int k = 0; k < 132; ++k)
    for (const float c : {float(k % 2), float(k / 2), 0.0f}) small += bytesOf(c, false);
  small += std::string("\x03\x00\x01\x02", 4);
  EXPECT_EQ(
      loadMesh(writeBytes("trailer.ply", small + "\n# end of mesh data #\n")).triangles.size(), 1u);
  expectMessage(small + std::string("\x03\x01\x03\x02", 4),
                "4 byte(s) after the body its header declares read as another face (3 corners");
  // Vertices without z (read as flat), triangle strips (dropped): refused.
  std::string flat = square;
  flat.replace(flat.find("property float z\n"), 17, "");
  expectMessage(flat, "element vertex has no property z");
  std::string strips = square;
  strips.insert(strips.find("end_header"),
                "element tristrips 1\nproperty list int int vertex_indices\n");
  expectMessage(strips + std::string("\x00\x00\x00\x00", 4),
                "triangle strips (element tristrips) are not read");
  // Vertices cut short: the fixed-size element's step.
  const std::size_t body = square.find("end_header\n") + 11;
  expectMessage(square.substr(0, body + 30), "the body ends inside vertex 3 of the 4");
  // Types outside the standard's names, a float count, a property before any element.
  std::string typo = square;
  typo.replace(typo.find("property float y"), 16, "property flaot y");
  expectMessage(typo, "body.ply:6: PLY header: expected `property TYPE NAME`");
  std::string float_count = square;
  float_count.replace(float_count.find("list uchar"), 10, "list float");
  expectMessage(float_count, "body.ply:10: PLY header: expected `property TYPE NAME`");
  std::string early = square;
  early.insert(early.find("element vertex"), "property float w\n");
  expectMessage(early, "body.ply:4: PLY header: a property before any element");
}
