#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/geometry/tool_model.h"
#include "temp_files.h"
#include "temporaries.h"

using namespace fieldpath::geometry;
using fieldpath::common::InputError;
using namespace fieldpath::geometry::test_files;
namespace fs = std::filesystem;

namespace {

/// Tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1): volume 1/6, outward.
const char* kAsciiTetra = R"(solid tetra
facet normal 0 0 -1
 outer loop
  vertex 0 0 0
  vertex 0 1 0
  vertex 1 0 0
 endloop
endfacet
facet normal 0 -1 0
 outer loop
  vertex 0 0 0
  vertex 1 0 0
  vertex 0 0 1
 endloop
endfacet
facet normal -1 0 0
 outer loop
  vertex 0 0 0
  vertex 0 0 1
  vertex 0 1 0
 endloop
endfacet
facet normal 1 1 1
 outer loop
  vertex 1 0 0
  vertex 0 1 0
  vertex 0 0 1
 endloop
endfacet
endsolid tetra
)";

void expectInputErrorNamingFile(const fs::path& p) {
  try {
    loadMesh(p);
    ADD_FAILURE() << "no error for " << p;
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
  }
}

}  // namespace

TEST(MeshIo, AsciiStlClosedForm) {
  const TriangleMesh m = loadMesh(writeBytes("tetra.stl", kAsciiTetra));
  EXPECT_EQ(m.vertices.size(), 4u);  // corners joined across facets
  EXPECT_EQ(m.triangles.size(), 4u);
  EXPECT_TRUE(validateMesh(m).closed()) << validateMesh(m).summary();
  EXPECT_NEAR(meshVolume(m), 1.0 / 6.0, 1e-12);
}

// Written in capitals (`SOLID`, `FACET NORMAL`, `VERTEX`, `1.0E+00`), as some CAD systems do: the
// same tetrahedron (it was taken for binary and refused with a triangle count from its text).
TEST(MeshIo, AsciiStlInCapitalsIsTheSame) {
  std::string capitals = kAsciiTetra;
  for (char& c : capitals) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  const std::string::size_type one = capitals.find("VERTEX 1 0 0");
  ASSERT_NE(one, std::string::npos);
  capitals.replace(one, 12, "VERTEX 1.0E+00 0 0");
  const TriangleMesh m = loadMesh(writeBytes("TETRA.STL", capitals));
  const TriangleMesh lower = loadMesh(writeBytes("tetra_lower.stl", kAsciiTetra));
  EXPECT_EQ(m.vertices, lower.vertices);
  EXPECT_EQ(m.triangles, lower.triangles);
  // `solid` in lower case, the rest in capitals or mixed case (it was refused: assimp saw no facet)
  std::string mixed = capitals;
  mixed.replace(mixed.find("SOLID"), 5, "solid");
  mixed.replace(mixed.find("VERTEX"), 6, "Vertex");
  const TriangleMesh m_mixed = loadMesh(writeBytes("tetra_mixed.stl", mixed));
  EXPECT_EQ(m_mixed.vertices, lower.vertices);
  EXPECT_EQ(m_mixed.triangles, lower.triangles);
}

// Normals as MSVC-built exporters print NaN (`-nan(ind)`, `1.#QNAN`), a `facet` line with no
// normal, a blank line before `solid`: the same tetrahedron (assimp refused each, dumping the
// file's text or "Failed to determine STL storage representation"). The normals are not read:
// a triangle's comes from its winding.
TEST(MeshIo, AsciiStlWithUnreadableNormalsOrALeadingBlankLineIsTheSame) {
  const TriangleMesh clean = loadMesh(writeBytes("tetra_clean.stl", kAsciiTetra));
  std::string first_normal = kAsciiTetra;
  const std::size_t facet = first_normal.find("facet normal");
  ASSERT_NE(facet, std::string::npos);
  const std::size_t line_end = first_normal.find('\n', facet);
  for (const std::string replacement :
       {"facet normal -nan(ind) -nan(ind) -nan(ind)", "facet normal 1.#QNAN 0 -1.#IND", "facet"}) {
    std::string text = first_normal;
    text.replace(facet, line_end - facet, replacement);
    const TriangleMesh m = loadMesh(writeBytes("tetra_normals.stl", text));
    EXPECT_EQ(m.vertices, clean.vertices) << replacement;
    EXPECT_EQ(m.triangles, clean.triangles) << replacement;
  }
  const TriangleMesh blank =
      loadMesh(writeBytes("tetra_blank.stl", "\n\n" + std::string(kAsciiTetra)));
  EXPECT_EQ(blank.vertices, clean.vertices);
  EXPECT_EQ(blank.triangles, clean.triangles);
}

TEST(MeshIo, AsciiPlyAndObjWithQuadsClosedForm) {
  // Unit cube as six quads: split into 12 triangles, 8 vertices, volume 1.
  const char* quads = "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  std::string obj,
      ply =
          "ply\nformat ascii 1.0\nelement vertex 8\nproperty float x\nproperty float y\n"
          "property float z\nelement face 6\nproperty list uchar int vertex_indices\nend_header\n";
  for (int i = 0; i < 8; ++i) {
    const std::string v = std::to_string(i & 1) + " " + std::to_string((i >> 1) & 1) + " " +
                          std::to_string((i >> 2) & 1);
    obj += "v " + v + "\n";
    ply += v + "\n";
  }
  obj += quads;
  for (std::string_view line : {"0 2 3 1", "4 5 7 6", "0 1 5 4", "2 6 7 3", "0 4 6 2", "1 3 7 5"})
    ply += "4 " + std::string(line) + "\n";
  for (const auto& [name, text] : {std::pair{"cube.obj", obj}, std::pair{"cube.ply", ply}}) {
    const TriangleMesh m = loadMesh(writeBytes(name, text));
    EXPECT_EQ(m.vertices.size(), 8u) << name;
    EXPECT_EQ(m.triangles.size(), 12u) << name;
    EXPECT_TRUE(validateMesh(m).closed()) << name << ": " << validateMesh(m).summary();
    EXPECT_NEAR(meshVolume(m), 1.0, 1e-12) << name;
    EXPECT_NEAR(meshArea(m), 6.0, 1e-12) << name;
  }
}

// A concave polygon face (an L whose first corner is the notch's: CAD exports write such faces
// as OBJ and PLY n-gons) is split ear by ear: its area, 3, every triangle facing the polygon's
// way (+z), and none over the notch. The fan from the first corner covered the notch (a helper's
// L-shaped prism read 9 colliding postures where 1.98 mm was clear). A convex one stays the fan.
TEST(MeshIo, AConcavePolygonFaceIsSplitWithinItselfItsCornersListedOnceOrTwice) {
  const char* corners = "v 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\nv 0 0 0\nv 2 0 0\n";
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 6\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "2 1 0\n1 1 0\n1 2 0\n0 2 0\n0 0 0\n2 0 0\n6 0 1 2 3 4 5\n";
  // The reflex corner (1, 1) listed twice, by its index or as a second record of its point: a
  // zero-length edge there split its turn into two of none, and the face read convex, fanned
  // over the notch (a reviewer's).
  for (const auto& [name, text] :
       {std::pair{"l.obj", std::string(corners) + "f 1 2 3 4 5 6\n"}, std::pair{"l.ply", ply},
        std::pair{"l_twice.obj", std::string(corners) + "f 1 2 2 3 4 5 6\n"},
        std::pair{"l_two_records.obj", std::string(corners) + "v 1 1 0\nf 1 2 7 3 4 5 6\n"}}) {
    const TriangleMesh m = loadMesh(writeBytes(name, text));
    ASSERT_EQ(m.triangles.size(), 4u) << name;
    EXPECT_NEAR(meshArea(m), 3.0, 1e-12) << name;
    const Eigen::Vector3d notch(1.6, 1.6, 0.0);
    for (const auto& t : m.triangles) {
      const Eigen::Vector3d a = m.vertices[t[0]], b = m.vertices[t[1]], c = m.vertices[t[2]];
      EXPECT_GT((b - a).cross(c - a).z(), 0.0) << name;
      const auto side = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
        return (q - p).cross(notch - p).z();
      };
      EXPECT_FALSE(side(a, b) > 0 && side(b, c) > 0 && side(c, a) > 0) << name << ": the notch";
    }
  }
  // A concave face of more corners than can be split (a star of 1026): refused, named.
  std::string star;
  for (int k = 0; k < 1026; ++k) {
    const double angle = 2.0 * 3.141592653589793 * k / 1026, r = k % 2 ? 1.0 : 2.0;
    star += "v " + std::to_string(r * std::cos(angle)) + " " + std::to_string(r * std::sin(angle)) +
            " 0\n";
  }
  star += "f";
  for (int k = 1; k <= 1026; ++k) star += " " + std::to_string(k);
  try {
    (void)loadMesh(writeBytes("star.obj", star + "\n"));
    ADD_FAILURE() << "a concave face of 1026 corners was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("face 1, a polygon of 1026 corners, is concave and too "
                                         "large to split"),
              std::string::npos)
        << e.what();
  }
}

// Saved by a Windows editor with a UTF-8 byte-order mark: the same meshes (the ASCII STL was read
// as binary, "header says 170926129 triangles"; the OBJ lost its first vertex; the PLY's first
// line was not `ply`). A binary STL whose header starts with those bytes stays binary.
TEST(MeshIo, TextMeshesWithAByteOrderMarkAreTheSame) {
  const std::string bom = "\xEF\xBB\xBF";
  const TriangleMesh stl = loadMesh(writeBytes("bom.stl", bom + kAsciiTetra));
  EXPECT_EQ(stl.triangles.size(), 4u);
  EXPECT_NEAR(meshVolume(stl), 1.0 / 6.0, 1e-12);
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const TriangleMesh plain = loadMesh(writeBytes("plain.obj", obj));
  const TriangleMesh marked = loadMesh(writeBytes("bom.obj", bom + obj));
  EXPECT_EQ(marked.vertices, plain.vertices);
  EXPECT_EQ(marked.triangles, plain.triangles);
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
      "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n";
  EXPECT_NEAR(meshArea(loadMesh(writeBytes("bom.ply", bom + ply))), 0.5, 1e-12);
  // The mark and nothing else: an empty file.
  try {
    loadMesh(writeBytes("bom_only.obj", bom));
    ADD_FAILURE() << "no error for a mark alone";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("empty file"), std::string::npos) << e.what();
  }
  // An error in a marked file names the file itself (not the copy read past the mark).
  const fs::path bad =
      writeBytes("bom_bad.stl", bom + std::string("solid x\nfacet normal 0 0 1\n"));
  expectInputErrorNamingFile(bad);
  // A binary STL of one triangle whose 80-byte header starts with the mark's bytes.
  std::string binary = bom + std::string(77, ' ');
  const std::uint32_t one = 1;
  binary.append(reinterpret_cast<const char*>(&one), 4);
  const float facet[12] = {0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1, 0};
  binary.append(reinterpret_cast<const char*>(facet), sizeof facet);
  binary.append(2, '\0');
  EXPECT_NEAR(meshArea(loadMesh(writeBytes("bom_binary.stl", binary))), 0.5, 1e-12);
}

TEST(MeshIo, TextMeshesWithLinesEndedByCrAloneOrCommentsAfterObjDataAreTheSame) {
  const auto crAlone = [](std::string text) {
    std::replace(text.begin(), text.end(), '\n', '\r');
    return text;
  };
  // The tetrahedron as an ASCII STL, an OBJ and a PLY, every line ended by CR (the STL and the
  // PLY were refused as one line: "without `endsolid`", "the first line must be `ply`").
  const TriangleMesh stl = loadMesh(writeBytes("cr.stl", crAlone(kAsciiTetra)));
  EXPECT_EQ(stl.triangles.size(), 4u);
  EXPECT_NEAR(meshVolume(stl), 1.0 / 6.0, 1e-12);
  const std::string obj =
      "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";
  const TriangleMesh plain = loadMesh(writeBytes("lf.obj", obj));
  const TriangleMesh cr = loadMesh(writeBytes("cr.obj", crAlone(obj)));
  EXPECT_EQ(cr.vertices, plain.vertices);
  EXPECT_EQ(cr.triangles, plain.triangles);
  const std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";
  EXPECT_NEAR(meshVolume(loadMesh(writeBytes("cr.ply", crAlone(ply)))), 1.0 / 6.0, 1e-12);
  // Comments after a line's data (assimp read `#` as a face index: "Invalid face index"), a
  // `#` inside a group's name, a comment line: the same tetrahedron.
  const std::string commented =
      "# made by hand\no tetra#1\nv 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nv 0 0 1\t#apex\n"
      "f 1 3 2 # base\nf 1 2 4\nf 1 4 3 #side\nf 2 3 4\n";
  const TriangleMesh cut = loadMesh(writeBytes("comments.obj", commented));
  EXPECT_EQ(cut.vertices, plain.vertices);
  EXPECT_EQ(cut.triangles, plain.triangles);
  // An error in such a file still names the file itself (not the copy read).
  expectInputErrorNamingFile(
      writeBytes("cr_bad.stl", crAlone("solid x\nfacet normal 0 0 1\n outer loop\n")));
  expectInputErrorNamingFile(writeBytes("comments_bad.obj", "v 0 0 0 # a\nf 1 2 3 # b\n"));
}

TEST(MeshIo, RoundTripsStlObjPly) {
  const TriangleMesh tool =
      toolMesh(parseToolSpec("torus:5:1:20"), parseHolderProfile("20:8,35:8"), 0.01);
  for (const char* ext : {".stl", ".obj", ".ply", ".STL"}) {
    SCOPED_TRACE(ext);
    const fs::path p = tempPath(std::string("tool") + ext);
    saveMesh(tool, p);
    EXPECT_TRUE(fieldpath::test::temporariesOf(p).empty());
    const TriangleMesh back = loadMesh(p);
    EXPECT_EQ(back.vertices.size(), tool.vertices.size());
    ASSERT_EQ(back.triangles.size(), tool.triangles.size());
    EXPECT_TRUE(validateMesh(back).closed()) << validateMesh(back).summary();
    EXPECT_NEAR(meshVolume(back), meshVolume(tool), 1e-5 * meshVolume(tool));
    // Same triangles in the same order, vertices to single precision.
    for (std::size_t t = 0; t < tool.triangles.size(); t += 97)
      for (int c = 0; c < 3; ++c)
        EXPECT_LT(
            (back.vertices[back.triangles[t][c]] - tool.vertices[tool.triangles[t][c]]).norm(),
            1e-5);
  }
  EXPECT_THROW(saveMesh(tool, tempPath("tool.xyz")), InputError);
}

TEST(MeshIo, BinaryStlIsBinary) {
  const TriangleMesh tool = toolMesh(parseToolSpec("ball:3"), {}, 0.05);
  const fs::path p = tempPath("bin.stl");
  saveMesh(tool, p);
  EXPECT_EQ(fs::file_size(p), 84 + 50 * tool.triangles.size());
  // Each facet's stored normal is its own (the exporter wrote its corners' mean: up to 66 deg
  // off on a tool mesh, a helper's finding), against the triangle's cross product.
  std::ifstream in(p, std::ios::binary);
  in.seekg(84);
  for (std::size_t t = 0; t < tool.triangles.size(); ++t) {
    float record[12];
    char attribute[2];
    in.read(reinterpret_cast<char*>(record), sizeof record);
    in.read(attribute, 2);
    const auto& tri = tool.triangles[t];
    const Eigen::Vector3d n = (tool.vertices[tri[1]] - tool.vertices[tri[0]])
                                  .cross(tool.vertices[tri[2]] - tool.vertices[tri[0]])
                                  .normalized();
    EXPECT_GT(n.dot(Eigen::Vector3d(record[0], record[1], record[2])), 1.0 - 1e-6) << "facet " << t;
  }
}

TEST(MeshIo, BrokenFilesAreInputErrors) {
  expectInputErrorNamingFile(tempPath("missing.stl"));
  expectInputErrorNamingFile(writeBytes("empty.stl", ""));
  expectInputErrorNamingFile(writeBytes("garbage.stl", std::string("\x01\x02\xff garbage", 12)));
  expectInputErrorNamingFile(writeBytes("garbage.ply", "ply\nformat nonsense\n"));
  expectInputErrorNamingFile(writeBytes("noface.obj", "v 0 0 0\nv 1 0 0\n"));
  // Binary STL whose header announces more triangles than the file holds.
  std::string truncated(80, ' ');
  const std::uint32_t count = 1000;
  truncated.append(reinterpret_cast<const char*>(&count), 4);
  truncated.append(50 * 3, '\0');
  expectInputErrorNamingFile(writeBytes("truncated.stl", truncated));
  // ... said as such, with the counts (not "cannot tell ASCII from binary").
  try {
    loadMesh(tempPath("truncated.stl"));
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(
        std::string(e.what()).find("header says 1000 triangles (50084 bytes), the file has 234"),
        std::string::npos)
        << e.what();
  }
  // A directory or a device is said to be one, not "no such file".
  for (const auto& [path, what] :
       {std::pair<fs::path, std::string>{fs::temp_directory_path(), "is a directory"},
        {"/dev/null", "not a regular file"}}) {
    try {
      loadMesh(path);
      FAIL();
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  }
  // Truncated ASCII STL.
  expectInputErrorNamingFile(writeBytes("cut.stl", std::string(kAsciiTetra).substr(0, 60)));
  // Files assimp reads without a word, losing faces: an ASCII STL cut after a whole facet (no
  // `endsolid`), a facet of 4 vertices, an ASCII PLY with fewer or more lines than its header's
  // elements.
  const std::string tetra = kAsciiTetra;
  const auto expectMessage = [](const fs::path& p, const std::string& what) {
    try {
      (void)loadMesh(p);
      ADD_FAILURE() << "no error for " << p;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expectMessage(writeBytes("cut_at_facet.stl", tetra.substr(0, tetra.find("endsolid"))),
                "without `endsolid`");
  std::string quad = tetra;
  quad.insert(quad.find("  vertex 1 0 0\n endloop"), "  vertex 1 1 0\n");
  expectMessage(writeBytes("quad_facet.stl", quad),
                "quad_facet.stl:2: ASCII STL facet with 4 vertices");
  const std::string ply_header =
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
      "property float z\nelement face 2\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n";
  expectMessage(writeBytes("short.ply", ply_header), "declares 6 element lines, the file has 5");
  expectMessage(writeBytes("long.ply", ply_header + "3 0 2 3\n3 0 1 3\n"),
                "declares 6 element lines, the file has 7");
  EXPECT_EQ(loadMesh(writeBytes("whole.ply", ply_header + "3 0 2 3\n")).triangles.size(), 2u);
  // The right count of lines with a value missing or one too many: assimp read on into the next
  // line's values, a mesh silently wrong (an adversary's cube: walls 0.08 mm thick). The line
  // and the element named; x y z finite; a `+` sign and exponents read as strtod reads them.
  const std::string body_of_4 = ply_header.substr(0, ply_header.find("0 0 0\n"));
  expectMessage(
      writeBytes("vshort.ply", body_of_4 + "0 0 0\n1 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
      "vshort.ply:11: ASCII PLY: vertex 2 has 2 values where its header's properties "
      "take 3");
  expectMessage(
      writeBytes("flong.ply", ply_header + "3 0 2 3 1\n"),
      "flong.ply:15: ASCII PLY: face 2 has 5 values where its header's properties take 4");
  expectMessage(writeBytes("fshort.ply", ply_header + "4 0 2 3\n"),
                "fshort.ply:15: ASCII PLY: face 2 has 4 values where its header's properties "
                "take 5");
  expectMessage(writeBytes("fnone.ply", ply_header + "\n"), "declares 6 element lines");
  expectMessage(
      writeBytes("vnan.ply", body_of_4 + "0 0 0\n1 0 0\n1 nan 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
      "vnan.ply:12: ASCII PLY: vertex 3: y is not finite");
  expectMessage(
      writeBytes("vword.ply", body_of_4 + "0 0 0\n1 0 0\n1 1,5 0\n0 1 0\n3 0 1 2\n3 0 2 3\n"),
      "vword.ply:12: ASCII PLY: vertex 3: '1,5' is not a number (y)");
  EXPECT_EQ(loadMesh(writeBytes("signs.ply", body_of_4 + "+0 0 0\n1e0 0 0\n1 1 0.\n0 1 .0\n"
                                                         "3 0 1 2\n3 0 2 3\n"))
                .triangles.size(),
            2u);
  // Said in the file's terms, with the line where we can (assimp's own words named neither).
  std::string short_vertex = tetra;
  short_vertex.replace(short_vertex.find("vertex 1 0 0"), 12, "vertex 1 0");
  const std::size_t short_line =
      1 + std::count(tetra.begin(), tetra.begin() + tetra.find("vertex 1 0 0"), '\n');
  expectMessage(
      writeBytes("short_vertex.stl", short_vertex),
      "short_vertex.stl:" + std::to_string(short_line) + ": ASCII STL vertex line needs 3 numbers");
  // A number that is no number, or not finite, named with its line (`2x6`: assimp quoted the
  // file in a 1.6 kB line; `nan`: "needs 3 numbers" of a line that has three).
  for (const char* bad : {"2x6", "nan", "inf"}) {
    std::string text = tetra;
    text.replace(text.find("vertex 1 0 0"), 12, std::string("vertex 1 ") + bad + " 0");
    expectMessage(writeBytes("bad_number.stl", text),
                  "bad_number.stl:" + std::to_string(short_line) + ": ASCII STL vertex: '" + bad +
                      "' is not a finite number");
  }
  // A binary STL whose header starts with `solid` (CAD exports) and whose size is not its
  // count's: said as a binary one (it was "ASCII STL without `endsolid`").
  std::string solid_header = "solid exported by a CAD system";
  solid_header.resize(80, ' ');
  const std::uint32_t two = 2;
  solid_header.append(reinterpret_cast<const char*>(&two), 4);
  std::string facet(50, '\0');
  expectMessage(writeBytes("solid_binary_cut.stl", solid_header + facet + facet.substr(0, 30)),
                "binary STL: its header says 2 triangles (184 bytes), the file has 164");
  expectMessage(writeBytes("solid_binary_long.stl", solid_header + facet + facet + facet),
                "binary STL: its header says 2 triangles (184 bytes), the file has 234");
  // Text of another format named .stl, short or long: said as text, not as a binary header's
  // count ("811479840 triangles" of an OBJ's `v 0 0 0`, an adversary's).
  std::string obj_text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  expectMessage(writeBytes("short_obj.stl", obj_text),
                "short_obj.stl: text that does not start with `solid`, as an ASCII STL does (it "
                "starts \"v 0 0 0\"): not STL");
  for (int k = 0; k < 10; ++k) obj_text += "v 1 1 " + std::to_string(k) + "\n";
  expectMessage(writeBytes("long_obj.stl", obj_text), "(it starts \"v 0 0 0\"): not STL");
  expectMessage(writeBytes("line.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n"),
                "a face with fewer than 3 vertices");
  expectMessage(writeBytes("index.ply", ply_header.substr(0, ply_header.find("element face 2")) +
                                            "element face 1\nproperty list uchar int "
                                            "vertex_indices\nend_header\n0 0 0\n1 0 0\n1 1 0\n"
                                            "0 1 0\n3 0 1 7\n"),
                "index.ply:14: ASCII PLY: face 1 names vertex 7, the file has 4 (numbered from 0)");
  // An OBJ's bad face index is named with its line (assimp's "Invalid face index" has none: a
  // blisk helper's typo in 90 000 lines); vt/vn parts and a negative index as OBJ reads them.
  const std::string tri = "v 0 0 0\nv 1 0 0\nv 0 1 0\n# a comment\nf 1/1/1 2//2 -1\n";
  expectMessage(writeBytes("past.obj", tri + "f 1 2 9\n"),
                "past.obj:6: face index '9': past the last vertex (the file has 3 vertices)");
  expectMessage(writeBytes("zero.obj", tri + "f 1 0 3\n"),
                "zero.obj:6: face index '0': 0 (OBJ counts vertices from 1)");
  expectMessage(writeBytes("back.obj", "v 0 0 0\nf 1 -2 -1\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
                "back.obj:2: face index '-2': counts back past the first vertex (1 read so far)");
  // A statement continued by `\` is one (its first line named), a vertex without three finite
  // coordinates is named by its line (assimp's count read "vertex 6" for the fourth), a file of
  // no vertex is no OBJ mesh; indented keys are read (assimp took indented `v` lines for none).
  expectMessage(writeBytes("cont.obj",
                           "v 0 0 0\nv 1 0 1\nv 1 1 1\nv 0 1 1\nf 1 2 \\\n  3 4\n"
                           "f 1 2 99\n"),
                "cont.obj:7: face index '99': past the last vertex (the file has 4 vertices)");
  expectMessage(writeBytes("v2.obj", "v 0 0 0\nv 1 0\nv 1 1 1\nf 1 2 3\n"),
                "v2.obj:2: vertex 2 has no z (a vertex is `v x y z`)");
  expectMessage(writeBytes("vnan.obj", "v 0 0 0\nv 1 0 1\nv 1 1 1\nv nan 0 0\nf 1 2 3\nf 1 3 4\n"),
                "vnan.obj:4: vertex 4: x 'nan' is not a finite number");
  expectMessage(writeBytes("part.step",
                           "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION(('x'),'2;1');\n"
                           "ENDSEC;\nDATA;\nENDSEC;\nEND-ISO-10303-21;\n"),
                "part.step: a STEP CAD model (ISO-10303-21), not a mesh: export it as STL");
  expectMessage(writeBytes("only_comments.obj", "# nothing\n# here\n"),
                "only_comments.obj: no vertex (`v x y z` lines): not an OBJ mesh");
  EXPECT_EQ(loadMesh(writeBytes("indented.obj", "  v 0 0 0\n\tv 1 0 1\n  v 1 1 1\nf 1 2 3\n"))
                .triangles.size(),
            1u);
  // A key OBJ does not have is named with its line (assimp read `foo 1 2 3` as a face: a
  // triangle more, without a word); free-form geometry is said not read (assimp dropped the
  // faces after `cstype`: "Mesh contains no faces"); the grouping, material and other polygon
  // statements are read past.
  const std::string three = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";
  expectMessage(writeBytes("unknown_key.obj", three + "foo 1 2 3\nf 1 2 3\n"),
                "unknown_key.obj:4: `foo`: not an OBJ statement");
  expectMessage(writeBytes("free_form.obj", three + "cstype bspline\nf 1 2 3\n"),
                "free_form.obj:4: `cstype`: free-form geometry (curves and surfaces) is not read");
  expectMessage(writeBytes("call.obj", three + "f 1 2 3\ncall other.obj\n"),
                "call.obj:5: `call`: another file's statements are not read");
  EXPECT_EQ(loadMesh(writeBytes("statements.obj",
                                "mtllib a.mtl\no part\ng walls\n" + three +
                                    "vt 0 0\nvn 0 0 1\nvp 0.5\nusemtl steel\ns off\nf 1 2 3\n"))
                .triangles.size(),
            1u);
}

TEST(MeshIo, DefectiveMeshesLoadAndAreReported) {
  // Tetrahedron with one facet missing: loads, three open edges.
  std::string open = kAsciiTetra;
  open.erase(open.find("facet normal 1 1 1"),
             open.find("endsolid") - open.find("facet normal 1 1 1"));
  const TriangleMesh m = loadMesh(writeBytes("open.stl", open));
  const MeshReport r = validateMesh(m);
  EXPECT_EQ(r.triangles, 3u);
  EXPECT_EQ(r.open_edges, 3u);
  EXPECT_FALSE(r.closed());
  // OBJ with a face flipped: inconsistent orientation is reported.
  const TriangleMesh flipped = loadMesh(writeBytes(
      "flipped.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 3 2 4\n"));
  EXPECT_GT(validateMesh(flipped).inconsistent_edges, 0u);
}

// Exporters' extras around a whole STL: text after `endsolid` (a `% exported ...` line) and a
// few bytes of padding after a binary STL's last triangle. The same tetrahedron is read; a
// second solid left open, or a padding of a whole triangle or more (a count that lies), is not.
TEST(MeshIo, ExportersTrailingTextAndPaddingAreReadPast) {
  const std::string tetra = kAsciiTetra;
  for (const std::string& tail : {std::string("% exported 2024\n"), std::string("\r\n  \nEND\n"),
                                  std::string("% a line with no end")}) {
    const TriangleMesh m = loadMesh(writeBytes("trailing.stl", tetra + tail));
    EXPECT_EQ(m.triangles.size(), 4u) << tail;
    EXPECT_EQ(m.vertices.size(), 4u) << tail;
  }
  std::string shouting = tetra;  // capitals and a tail: both handled in the one copy
  for (char& c : shouting) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  EXPECT_EQ(loadMesh(writeBytes("TRAILING.STL", shouting + "% EXPORTED\n")).triangles.size(), 4u);
  EXPECT_THROW(
      loadMesh(writeBytes("open_second.stl", tetra + "solid second\nfacet normal 0 0 1\n")),
      InputError);

  const TriangleMesh ascii = loadMesh(writeBytes("tetra.stl", tetra));
  const fs::path binary = tempPath("tetra_bin.stl");
  saveMesh(ascii, binary);
  std::ifstream in(binary, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_EQ(bytes.size(), 84u + 50u * 4u);
  const TriangleMesh padded = loadMesh(writeBytes("padded.stl", bytes + std::string(2, '\0')));
  EXPECT_EQ(padded.triangles.size(), 4u);
  EXPECT_EQ(padded.vertices, ascii.vertices);
  EXPECT_THROW(loadMesh(writeBytes("overlong.stl", bytes + std::string(50, '\0'))), InputError);
}
