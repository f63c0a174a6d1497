#include "fieldpath/geometry/mesh_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <exception>
#include <fstream>
#include <functional>
#include <iterator>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_map>
#include <utility>

#include <unistd.h>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <Eigen/Geometry>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/file_names.h"
#include "fieldpath/common/input_file.h"
#include "fieldpath/common/limits.h"
#include "obj_check.h"
#include "ply_check.h"
#include "polygon_split.h"
#include "stl_check.h"

namespace fieldpath::geometry {
namespace {

/// The first `bytes` of `file` (fewer where it is shorter), for assimp to read from memory.
std::string firstBytes(const std::filesystem::path& file, std::uintmax_t bytes) {
  std::ifstream in(file, std::ios::binary);
  std::string text(static_cast<std::size_t>(bytes), '\0');
  in.read(text.data(), static_cast<std::streamsize>(text.size()));
  text.resize(static_cast<std::size_t>(in.gcount()));
  return text;
}

/// What reading an STL takes beyond its text: bytes a triangle, and once (the importer's own),
/// over the worst measured, a soup of separate triangles whose every corner is a vertex (peaks
/// over the program: 30 MiB for 50 k triangles, 113 MiB for 200 k, 445 MiB for 1 M; a welded
/// mesh of 1 M, 188 MiB).
constexpr double kMeshLoadBytesPerTriangle = 600.0;
constexpr double kMeshLoadBytes = 8.0 * 1024 * 1024;

using common::InputError;
using common::lowerExtension;
using detail::checkStl;
using detail::StlFeed;
using detail::zeroFacetNormals;

/// Hash of a position's exact bits (joining needs equality, not nearness).
struct PositionHash {
  std::size_t operator()(const std::array<ai_real, 3>& p) const {
    std::size_t h = 0;
    for (ai_real c : p) h = h * 0x9E3779B97F4A7C15ull + std::hash<ai_real>{}(c);
    return h;
  }
};

/// `out` (fillScene's mesh of `mesh`) with its faces' own normals on their own corners: the
/// STL exporter writes a
/// facet's normal as the mean of its corners' (assimp's GenNormals gives a shared corner the
/// mean of its faces'), and a tool mesh's facets came out up to 66 deg off (a helper's finding).
void setFaceNormals(aiMesh& out, const TriangleMesh& mesh) {
  const std::size_t corners = 3 * mesh.triangles.size();
  delete[] out.mVertices;
  out.mNumVertices = static_cast<unsigned>(corners);
  out.mVertices = new aiVector3D[corners];
  out.mNormals = new aiVector3D[corners];
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    const auto& t = mesh.triangles[f];
    const Eigen::Vector3d n = (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                                  .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                                  .normalized();
    for (int c = 0; c < 3; ++c) {
      const Eigen::Vector3d& v = mesh.vertices[t[c]];
      out.mVertices[3 * f + c] = aiVector3D(
          static_cast<ai_real>(v.x()), static_cast<ai_real>(v.y()), static_cast<ai_real>(v.z()));
      out.mNormals[3 * f + c] = std::isfinite(n.x()) ? aiVector3D(static_cast<ai_real>(n.x()),
                                                                  static_cast<ai_real>(n.y()),
                                                                  static_cast<ai_real>(n.z()))
                                                     : aiVector3D(0, 0, 0);
      out.mFaces[f].mIndices[c] = static_cast<unsigned>(3 * f + c);
    }
  }
}

/// A one-mesh assimp scene holding `mesh` (assimp stores single precision).
void fillScene(aiScene& scene, const TriangleMesh& mesh) {
  scene.mMaterials = new aiMaterial* [1] { new aiMaterial() };
  scene.mNumMaterials = 1;
  scene.mRootNode = new aiNode();
  scene.mRootNode->mMeshes = new unsigned[1]{0};
  scene.mRootNode->mNumMeshes = 1;
  auto* out = new aiMesh();
  scene.mMeshes = new aiMesh* [1] { out };
  scene.mNumMeshes = 1;
  out->mMaterialIndex = 0;
  out->mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
  out->mNumVertices = static_cast<unsigned>(mesh.vertices.size());
  out->mVertices = new aiVector3D[mesh.vertices.size()];
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const auto& v = mesh.vertices[i];
    out->mVertices[i] = aiVector3D(static_cast<ai_real>(v.x()), static_cast<ai_real>(v.y()),
                                   static_cast<ai_real>(v.z()));
  }
  out->mNumFaces = static_cast<unsigned>(mesh.triangles.size());
  out->mFaces = new aiFace[mesh.triangles.size()];
  for (std::size_t f = 0; f < mesh.triangles.size(); ++f) {
    aiFace& face = out->mFaces[f];
    face.mNumIndices = 3;
    face.mIndices = new unsigned[3];
    for (int c = 0; c < 3; ++c) face.mIndices[c] = static_cast<unsigned>(mesh.triangles[f][c]);
  }
}

/// assimp's validation speaks of its own structures (`aiMesh::mFaces[0] is a LINE but
/// aiMesh::mPrimitiveTypes ...`): the two a user's file causes said in the file's terms, the
/// rest as assimp says it.
std::string readableAssimpError(const std::string& why) {
  if (why.find("is a LINE") != std::string::npos || why.find("is a POINT") != std::string::npos)
    return "a face with fewer than 3 vertices (a line or a point; a mesh needs triangles or "
           "polygons) [" +
           why + "]";
  if (why.find("mIndices[") != std::string::npos && why.find("out of range") != std::string::npos) {
    // "aiMesh::mFaces[3]::mIndices[2] is out of range": face 4 as read, its third corner.
    const std::size_t at = why.find("mFaces[");
    const long face = at == std::string::npos ? -1 : std::atol(why.c_str() + at + 7);
    return (face >= 0 ? "face " + std::to_string(face + 1) + " (as read)" : std::string("a face")) +
           " names a vertex the file does not have (index out of range) [" + why + "]";
  }
  return why;
}

/// A text mesh saved with a UTF-8 byte-order mark (Windows editors write one): assimp and the
/// checks above read it as binary or as a bad first line ("header says 170926129 triangles",
/// "vertex index out of range"). Not a binary STL whose 80-byte header happens to start so (its
/// size fits its count).
bool startsWithByteOrderMark(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  unsigned char head[84] = {};
  in.read(reinterpret_cast<char*>(head), sizeof head);
  const std::streamsize got = in.gcount();
  if (got < 3 || head[0] != 0xEF || head[1] != 0xBB || head[2] != 0xBF) return false;
  if (lowerExtension(file) == ".stl" && got == 84) {
    const std::uint32_t count = std::uint32_t(head[80]) | std::uint32_t(head[81]) << 8 |
                                std::uint32_t(head[82]) << 16 | std::uint32_t(head[83]) << 24;
    const std::uintmax_t needed = 84 + 50 * std::uintmax_t(count);
    if (size >= needed && size - needed < 50) return false;
  }
  return true;
}

/// A text mesh whose lines end in CR alone (classic Mac OS, some CAM exports): the checks
/// above and assimp's STL and PLY readers take the whole file for one line ("without
/// `endsolid`", "the first line must be `ply`"). Seen in its first 64 KiB: a CR, no LF and no
/// NUL byte (a binary body has NUL bytes).
bool endsLinesInCrAlone(const std::filesystem::path& file) {
  const std::string head = firstBytes(file, 1 << 16);
  return head.find('\r') != std::string::npos && head.find('\n') == std::string::npos &&
         head.find('\0') == std::string::npos;
}

/// The file read from a copy that `rewrite` writes from it (same name, in a folder of its own
/// under the temporary directory, removed after), its messages naming the file itself. `why`
/// says in a refusal what the copy was for ("starts with a UTF-8 byte-order mark"), `fix` what
/// the user can do instead.
TriangleMesh loadRewrittenCopy(const std::filesystem::path& file, const std::string& why,
                               const std::string& fix,
                               const std::function<void(std::istream&, std::ostream&)>& rewrite) {
  namespace fs = std::filesystem;
  std::error_code ec;
  // A private folder of its own (mkdtemp: created new, mode 0700): a predictable name could be
  // made ahead by another user with a link in it (a reviewer overwrote a file so) or be another
  // run's.
  fs::path base = fs::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::string pattern = (base / "fieldpath-copy-XXXXXX").string();
  const std::string refusal =
      file.string() + ": " + why + ", and no copy of it could be made to read: " + fix;
  if (::mkdtemp(pattern.data()) == nullptr) throw InputError(refusal);
  const fs::path folder = pattern;
  const fs::path copy = folder / file.filename();
  struct Cleanup {
    fs::path folder;
    ~Cleanup() {
      std::error_code ignored;
      fs::remove_all(folder, ignored);
    }
  } cleanup{folder};
  // Removed on Ctrl-C too, as the outputs' temporaries are (common::removeTemporariesNow).
  const common::detail::TemporaryListing listing{common::detail::listTemporary(copy.string())};
  {
    std::ifstream in(file, std::ios::binary);
    common::detail::beginCreating(listing.slot);
    std::ofstream out(copy, std::ios::binary);
    common::detail::endCreating(listing.slot);
    rewrite(in, out);
    if (!out.flush()) throw InputError(refusal);
  }
  try {
    return loadMesh(copy);
  } catch (const InputError& e) {
    std::string what = e.what();
    for (std::size_t at = what.find(copy.string()); at != std::string::npos;
         at = what.find(copy.string(), at + file.string().size()))
      what.replace(at, copy.string().size(), file.string());
    throw InputError(what);
  }
}

/// Whether a copy is being read (a byte-order mark after the one left out is refused).
bool isRewrittenCopy(const std::filesystem::path& file) {
  return file.parent_path().filename().string().rfind("fieldpath-copy-", 0) == 0;
}

/// An OBJ's text with comments after a line's data cut off (`f 1 2 3  # cap`: assimp read
/// `#` as a face index, "OBJ: Invalid face index") and the blanks before a line's key taken away
/// (assimp 5.2 reads keys at a line's start only: indented `v` lines were no vertices, "vertex
/// index out of range", an adversary's file); none where no line needs either. A line that is a
/// comment from its start is assimp's to skip.
std::optional<std::string> objTidied(const std::filesystem::path& file) {
  if (lowerExtension(file) != ".obj") return std::nullopt;
  // A line's data start, and where a comment after it starts (npos: none).
  const auto cuts = [](const std::string& line) {
    const std::size_t data = line.find_first_not_of(" \t");
    const std::size_t hash = line.find('#');
    return std::pair{data, hash != std::string::npos && data < hash ? hash : std::string::npos};
  };
  std::ifstream in(file, std::ios::binary);
  std::string line;
  bool found = false;
  while (!found && std::getline(in, line)) {
    const auto [data, comment] = cuts(line);
    found = comment != std::string::npos ||
            (data != 0 && data != std::string::npos && line[data] != '#' && line[data] != '\r');
  }
  if (!found) return std::nullopt;
  in.clear();
  in.seekg(0);
  std::string text;
  while (std::getline(in, line)) {
    const auto [data, comment] = cuts(line);
    if (comment != std::string::npos) line.erase(comment);
    if (data != std::string::npos) line.erase(0, data);
    text += line;
    text += '\n';
  }
  return text;
}

/// An OBJ that assimp refused, or whose vertex or face came out wrong: the line of its first bad
/// vertex or face index where one is found (assimp's message has none), thrown; nothing else.
void throwObjFault(const std::filesystem::path& file) {
  if (lowerExtension(file) != ".obj") return;
  if (std::string fault = detail::objFault(file); !fault.empty()) throw InputError(fault);
}

}  // namespace

TriangleMesh loadMesh(const std::filesystem::path& file) {
  std::error_code ec;
  common::requireRegularFile(file, "mesh file");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || size == 0) throw InputError(file.string() + ": empty file");
  // A CAD model where a mesh was meant (a common slip: the part's STEP beside its STL): assimp
  // said "IFC: Unrecognized file schema" (an adversary's).
  if (firstBytes(file, 64).find("ISO-10303-21") <= 4)  // (after a byte-order mark, blanks)
    throw InputError(file.string() +
                     ": a STEP CAD model (ISO-10303-21), not a mesh: export it as STL, OBJ or PLY "
                     "(a chordal tolerance of a few micrometres)");
  if (startsWithByteOrderMark(file, size)) {
    if (isRewrittenCopy(file))
      throw InputError(file.string() + ": starts with two UTF-8 byte-order marks");
    if (size <= 3)
      throw InputError(file.string() + ": empty file (a UTF-8 byte-order mark and nothing else)");
    return loadRewrittenCopy(file, "starts with a UTF-8 byte-order mark",
                             "save it without the mark", [](std::istream& in, std::ostream& out) {
                               in.seekg(3);
                               out << in.rdbuf();
                             });
  }
  if (endsLinesInCrAlone(file))  // (its copy's lines end in LF: read once)
    return loadRewrittenCopy(
        file, "ends its lines in CR alone", "save it with LF or CRLF line ends",
        [](std::istream& in, std::ostream& out) {
          std::string chunk(1 << 16, '\0');
          while (in.read(chunk.data(), std::streamsize(chunk.size())) || in.gcount() > 0) {
            chunk.resize(static_cast<std::size_t>(in.gcount()));
            std::replace(chunk.begin(), chunk.end(), '\r', '\n');
            out << chunk;
            chunk.resize(1 << 16);
          }
        });
  const std::uintmax_t ply_crlf_header = detail::checkPly(file, size);
  const StlFeed stl = checkStl(file, size);
  // assimp's scene, our joined copy and the hash that joins them. An STL's triangles are known
  // before it is read: its text (an ASCII one's twice: assimp's buffer; once more where a copy
  // is made) and kMeshLoadBytesPerTriangle (16 B a file byte, as for the others, refused an
  // ASCII STL at 4.7 times its need, a welded binary one at 3.5). Others: 16 B per file byte (a
  // 50-byte facet becomes 3 aiVector3D, a face, 3 map entries, 1.5 vertices; OBJ and PLY pack a
  // triangle into 20-40 bytes: 6.5-10 times their size measured).
  // Passing: the mesh loaded is held as a scene's (app/estimates.h: its triangles).
  const double bytes = double(size);
  const double estimate = stl.triangles > 0
                              ? kMeshLoadBytes + bytes * (1.0 + stl.ascii + stl.copy) +
                                    kMeshLoadBytesPerTriangle * double(stl.triangles)
                              : 16.0 * bytes;
  common::requireMemory(file.string(), estimate,
                        stl.triangles > 0 ? std::to_string(stl.triangles) + " triangles in " +
                                                common::formatBytes(bytes) + " of STL"
                                          : "mesh file of " + common::formatBytes(bytes),
                        common::MemoryUse::kPassing);

  if (lowerExtension(file) == ".obj")
    if (std::string fault = detail::objStatementFault(file); !fault.empty())
      throw InputError(fault);
  Assimp::Importer importer;
  const aiScene* scene = nullptr;
  try {
    // No post-processing but validation: assimp's steps trust the loaders' output and abort
    // (ai_assert in Triangulate) or crash on malformed files (found by tests/fuzz fuzz_mesh), so
    // polygons are split and node transforms applied below, with every index checked.
    if (stl.copy) {  // its solids or triangles only; lower case where asked (keywords, exponents)
      std::string text = firstBytes(file, stl.length);
      text.erase(0, static_cast<std::size_t>(stl.skip));
      if (stl.zero_normals) text = zeroFacetNormals(text);
      if (stl.lower)
        text = common::lowerCase(std::move(text));
      if (stl.blank_mark) text.replace(0, 3, 3, ' ');
      scene = importer.ReadFileFromMemory(text.data(), text.size(), aiProcess_ValidateDataStructure,
                                          "stl");
    } else if (ply_crlf_header > 0) {  // the header's line ends as CRLF (checkPly says why)
      std::string text = firstBytes(file, size);
      for (std::size_t i = static_cast<std::size_t>(ply_crlf_header); i-- > 0;)
        if (text[i] == '\n' && (i == 0 || text[i - 1] != '\r')) text.insert(i, 1, '\r');
      scene = importer.ReadFileFromMemory(text.data(), text.size(), aiProcess_ValidateDataStructure,
                                          "ply");
    } else if (const auto obj = objTidied(file)) {
      scene = importer.ReadFileFromMemory(obj->data(), obj->size(), aiProcess_ValidateDataStructure,
                                          "obj");
    } else {
      scene = importer.ReadFile(file.string(), aiProcess_ValidateDataStructure);
    }
  } catch (const std::exception& e) {
    throwObjFault(file);
    throw InputError(file.string() + ": cannot read mesh: " + readableAssimpError(e.what()));
  }
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 ||
      scene->mRootNode == nullptr) {
    throwObjFault(file);
    const std::string why = importer.GetErrorString();
    throw InputError(file.string() + ": cannot read mesh" +
                     (why.empty() ? std::string() : ": " + readableAssimpError(why)));
  }

  // Identical positions are joined across faces and meshes (STL stores every corner per face).
  TriangleMesh mesh;
  std::unordered_map<std::array<ai_real, 3>, int, PositionHash> index_of;
  std::vector<Eigen::Vector3d> corners;  // a polygon face's, mm
  const auto addMesh = [&](const aiMesh* in, const aiMatrix4x4& transform) {
    std::vector<int> remap(in->mNumVertices);
    for (unsigned i = 0; i < in->mNumVertices; ++i) {
      const aiVector3D v = transform * in->mVertices[i];
      if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z) ||
          std::abs(v.x) > common::kMaxCoordinateMm || std::abs(v.y) > common::kMaxCoordinateMm ||
          std::abs(v.z) > common::kMaxCoordinateMm) {
        throwObjFault(file);
        // (assimp's count of vertices, not the file's: an OBJ's fourth read "vertex 6")
        throw InputError(file.string() + ": a vertex is not finite or lies beyond +-1e6 mm");
      }
      const auto [it, added] =
          index_of.try_emplace({v.x, v.y, v.z}, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.emplace_back(v.x, v.y, v.z);
      remap[i] = it->second;
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices < 3 || face.mIndices == nullptr) continue;  // points and lines
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= in->mNumVertices) {
          throwObjFault(file);
          throw InputError(file.string() + ": face " + std::to_string(f + 1) +
                           " names a vertex that does not exist");
        }
      if (face.mNumIndices == 3) {
        mesh.triangles.emplace_back(remap[face.mIndices[0]], remap[face.mIndices[1]],
                                    remap[face.mIndices[2]]);
        continue;
      }
      // A polygon: a convex one as the fan from its first corner, a concave one ear by ear (an
      // L-shaped OBJ face fanned covered its notch: 9 colliding postures read where 1.98 mm was).
      corners.clear();
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        corners.push_back(mesh.vertices[std::size_t(remap[face.mIndices[k]])]);
      const auto split = splitPolygon(corners);
      if (!split)
        throw InputError(
            file.string() + ": face " + std::to_string(f + 1) + ", a polygon of " +
            std::to_string(face.mNumIndices) + " corners, is concave and " +
            (face.mNumIndices > kMaxClippedCorners ? "too large to split" : "crosses itself") +
            ": export the mesh as triangles");
      for (const Eigen::Vector3i& t : *split)
        mesh.triangles.emplace_back(remap[face.mIndices[t[0]]], remap[face.mIndices[t[1]]],
                                    remap[face.mIndices[t[2]]]);
    }
  };
  // Every mesh where the node tree places it (what aiProcess_PreTransformVertices did).
  const std::function<void(const aiNode*, const aiMatrix4x4&, int)> walk =
      [&](const aiNode* node, const aiMatrix4x4& parent, int depth) {
        if (node == nullptr) return;
        if (depth > 256) throw InputError(file.string() + ": node tree deeper than 256");
        const aiMatrix4x4 transform = parent * node->mTransformation;
        for (unsigned i = 0; i < node->mNumMeshes; ++i)
          if (node->mMeshes[i] < scene->mNumMeshes && scene->mMeshes[node->mMeshes[i]] != nullptr)
            addMesh(scene->mMeshes[node->mMeshes[i]], transform);
        for (unsigned c = 0; c < node->mNumChildren; ++c)
          walk(node->mChildren[c], transform, depth + 1);
      };
  walk(scene->mRootNode, aiMatrix4x4(), 0);
  if (mesh.triangles.empty()) throw InputError(file.string() + ": no triangles in the mesh file");
  return mesh;
}

void saveMesh(const TriangleMesh& mesh, const std::filesystem::path& file) {
  const std::string ext = lowerExtension(file);
  const char* format = ext == ".stl"   ? "stlb"
                       : ext == ".obj" ? "objnomtl"
                       : ext == ".ply" ? "plyb"
                                       : nullptr;
  if (format == nullptr)
    throw InputError(file.string() + ": unknown mesh extension '" + ext +
                     "' (use .stl, .obj or .ply)");
  aiScene scene;
  fillScene(scene, mesh);
  if (ext == ".stl") setFaceNormals(*scene.mMeshes[0], mesh);
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, format);
  if (blob == nullptr)
    throw std::runtime_error(file.string() + ": mesh export failed: " + exporter.GetErrorString());
  common::writeFileAtomically(
      file,
      [blob](std::ostream& out) {
        out.write(static_cast<const char*>(blob->data), static_cast<std::streamsize>(blob->size));
      },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::geometry
