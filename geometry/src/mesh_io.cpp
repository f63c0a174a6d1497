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
#include "ply_check.h"
#include "polygon_split.h"

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
  if (why.find("mIndices[") != std::string::npos && why.find("out of range") != std::string::npos)
    return "a face names a vertex the file does not have (index out of range) [" + why + "]";
  return why;
}

/// How assimp is to read an STL: the file as it is, or a copy in memory (`length` bytes of it,
/// in lower case where `lower`).
struct StlFeed {
  bool copy = false;
  bool lower = false;
  /// A binary header starting with a UTF-8 byte-order mark's bytes: assimp skips them as text
  /// (and misreads the count, "Failed to determine STL storage"), so the copy has them blank.
  bool blank_mark = false;
  /// ASCII facets whose normal assimp cannot read (MSVC's `-nan(ind)`, `1.#QNAN`, or no
  /// `normal` word: it refused the file with a dump of its text): every facet's normal written
  /// 0 0 0 in the copy (the triangles' normals come from their winding).
  bool zero_normals = false;
  /// Bytes of white space before `solid` (a blank first line: "Failed to determine STL storage
  /// representation"), left out of the copy.
  std::uintmax_t skip = 0;
  std::uintmax_t length = 0;
  bool ascii = false;
  std::uintmax_t triangles = 0;  ///< its header's count (binary) or its facets (ASCII)
};

/// `text` (an ASCII STL) with every `facet ...` line written `facet normal 0 0 0`.
std::string zeroFacetNormals(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::size_t word = text.find_first_not_of(" \t\r", at);
    if (word < end && end - word >= 5 && common::lowerCase(text.substr(word, 5)) == "facet")
      out += "facet normal 0 0 0";
    else
      out.append(text, at, end - at);
    if (end < text.size()) out += '\n';
    at = end + 1;
  }
  return out;
}

/// assimp reads an ASCII STL cut after a facet (no `endsolid`) and a facet loop of 4 vertices
/// (some exporters' quads: half the face lost) without a word: every facet must have 3
/// `vertex` lines and the last solid must end with `endsolid`. Text after it that is no STL (an
/// exporter's `% exported ...` line) is left out of what assimp reads, where it made assimp
/// look for another solid; a `solid` after it is another solid of the file and must end too.
/// assimp takes keywords in lower case only: a keyword in capitals anywhere (`FACET NORMAL`,
/// `Vertex`, also after a lower-case `solid`) has the text read in lower case.
StlFeed checkAsciiStl(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  std::size_t number = 0, facet_line = 0, vertices = 0, facets = 0;
  bool in_facet = false, capitals = false, in_solid = false, bad_normals = false;
  std::uintmax_t offset = 0, solid_end = 0;  // bytes read; the end of the last `endsolid` line
  std::size_t trailing_line = 0;             // the first line of text after it, if any
  // The first word of each line, lower case (a scan by hand: a million facets are 7 M lines).
  const auto firstWord = [&capitals](const std::string& text) {
    std::size_t b = 0;
    while (b < text.size() && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
    std::size_t e = b;
    std::string w;
    while (e < text.size() && !std::isspace(static_cast<unsigned char>(text[e])) && e - b < 9) {
      const char c = text[e++];
      w += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      capitals = capitals || w.back() != c;
    }
    return w;
  };
  while (std::getline(in, line)) {
    ++number;
    offset += line.size() + 1;
    const bool was_capital = capitals;
    const std::string word = firstWord(line);
    if (word.empty()) continue;
    if (!in_solid && word != "solid") {  // text after the last `endsolid`: not STL
      capitals = was_capital;            // (its words are not keywords)
      if (trailing_line == 0) trailing_line = number;
      continue;
    }
    if (word == "solid") {
      in_solid = true;
      trailing_line = 0;
    } else if (word == "facet") {
      // `facet normal nx ny nz`, each a number strtod reads (nan and inf too, as assimp does)
      if (!bad_normals) {
        std::istringstream rest(line);
        std::string facet_word, normal_word, token;
        rest >> facet_word >> normal_word;
        int numbers = 0;
        while (rest >> token) {
          char* stop = nullptr;
          (void)std::strtod(token.c_str(), &stop);
          // (strtod reads MSVC's `-nan(ind)` too, assimp does not)
          const bool plain = token.find('(') == std::string::npos;
          numbers += stop == token.c_str() + token.size() && plain ? 1 : 100;
        }
        bad_normals = common::lowerCase(normal_word) != "normal" || numbers != 3;
      }
      ++facets;
      in_facet = true;
      facet_line = number;
      vertices = 0;
    } else if (word == "vertex") {
      ++vertices;
      // x y z: assimp's own word on a short line names no line ("Cannot parse string ...").
      // Each a whole number (`2x6` made assimp quote the file in a 1.6 kB line), and finite.
      std::size_t tokens = 0, at = line.find_first_of("xX") + 1;
      std::string bad;
      while (true) {
        at = line.find_first_not_of(" \t\r", at);
        if (at == std::string::npos) break;
        const std::size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
        const std::string token = line.substr(at, end - at);
        char* stop = nullptr;
        const double value = std::strtod(token.c_str(), &stop);
        if (bad.empty() && (stop != token.c_str() + token.size() || !std::isfinite(value) ||
                            std::abs(value) > common::kMaxCoordinateMm))
          bad = token;
        ++tokens;
        at = end;
      }
      const std::string where = file.string() + ":" + std::to_string(number) + ": ";
      if (tokens != 3)
        throw InputError(where + "ASCII STL vertex line needs 3 numbers (x y z), it has " +
                         std::to_string(tokens));
      if (!bad.empty())
        throw InputError(where + "ASCII STL vertex: '" + bad.substr(0, 40) +
                         "' is not a finite number within +-1e6 mm");
    } else if (word == "endfacet") {
      if (in_facet && vertices != 3)
        throw InputError(file.string() + ":" + std::to_string(facet_line) +
                         ": ASCII STL facet with " + std::to_string(vertices) +
                         " vertices (an STL facet has 3)");
      in_facet = false;
    } else if (word == "endsolid") {
      in_solid = false;
      solid_end = std::min(offset, size);
    }
  }
  if (in_solid || solid_end == 0)
    throw InputError(file.string() + ": ASCII STL without `endsolid` at its end (truncated?)");
  StlFeed feed;
  feed.lower = capitals;
  feed.zero_normals = bad_normals;
  feed.copy = capitals || trailing_line > 0 || bad_normals;
  feed.length = trailing_line > 0 ? solid_end : size;
  feed.ascii = true;
  feed.triangles = facets;
  return feed;
}

/// Whether the first 64 KiB hold a NUL byte: binary (an ASCII STL has none; a binary one's
/// floats and attribute counts have many).
bool hasNulByte(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find('\0') != std::string::npos;
}

/// A binary STL's size is fixed by its header: 84 bytes and 50 a triangle. One shorter than its
/// count says (truncated, or a count that lies) is refused saying so, where assimp would only say
/// it cannot tell ASCII from binary; up to 49 bytes more (an exporter's padding, less than a
/// triangle) are read past. A file that starts with `solid` and has no NUL byte is ASCII.
StlFeed checkStl(const std::filesystem::path& file, std::uintmax_t size) {
  if (lowerExtension(file) != ".stl") return {};
  std::ifstream in(file, std::ios::binary);
  unsigned char header[84] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  std::size_t first = 0;
  while (first < got && std::isspace(header[first])) ++first;
  std::string word = got >= first + 5
                         ? std::string(reinterpret_cast<const char*>(header) + first, 5)
                         : std::string();
  word = common::lowerCase(std::move(word));
  const auto binaryFits = [size](std::uintmax_t needed) {
    return size >= needed && size - needed < 50;
  };
  // assimp takes a binary STL of its exact size only: the padding is left out of its copy.
  const bool marked = got >= 3 && header[0] == 0xEF && header[1] == 0xBB && header[2] == 0xBF;
  const auto binaryFeed = [size, marked](std::uintmax_t needed) {
    StlFeed feed;
    feed.copy = size != needed || marked;
    feed.blank_mark = marked;
    feed.length = needed;
    feed.triangles = (needed - 84) / 50;
    return feed;
  };
  if (word == "solid" && got == 84) {
    // A binary STL whose header starts so (CAD exports): its size matches its count.
    const std::uint32_t count = std::uint32_t(header[80]) | std::uint32_t(header[81]) << 8 |
                                std::uint32_t(header[82]) << 16 | std::uint32_t(header[83]) << 24;
    if (binaryFits(84 + 50 * std::uintmax_t(count)))
      return binaryFeed(84 + 50 * std::uintmax_t(count));
  }
  // Else ASCII, unless it holds a NUL byte: a binary one cut short or padded (it was read as
  // ASCII "without `endsolid`"); its counts are said below.
  if (word == "solid" && !hasNulByte(file)) {
    StlFeed feed = checkAsciiStl(file, size);
    feed.skip = first;
    feed.copy = feed.copy || first > 0;
    return feed;
  }
  if (got < 84)
    throw InputError(file.string() + ": binary STL of " + std::to_string(size) +
                     " bytes, shorter than its 84-byte header (truncated, or not STL)");
  const std::uint32_t count = std::uint32_t(header[80]) | std::uint32_t(header[81]) << 8 |
                              std::uint32_t(header[82]) << 16 | std::uint32_t(header[83]) << 24;
  const std::uintmax_t needed = 84 + 50 * std::uintmax_t(count);
  if (!binaryFits(needed))
    throw InputError(file.string() + ": binary STL: its header says " + std::to_string(count) +
                     " triangles (" + std::to_string(needed) + " bytes), the file has " +
                     std::to_string(size) + " bytes (truncated, or not STL)");
  return binaryFeed(needed);
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

/// The file read past its byte-order mark: a copy without it (same name, in a folder of its own
/// under the temporary directory, removed after), its messages naming the file itself.
TriangleMesh loadWithoutByteOrderMark(const std::filesystem::path& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (std::filesystem::file_size(file, ec) <= 3 && !ec)
    throw InputError(file.string() + ": empty file (a UTF-8 byte-order mark and nothing else)");
  if (file.parent_path().filename().string().rfind("fieldpath-bom-", 0) == 0)
    throw InputError(file.string() + ": starts with two UTF-8 byte-order marks");
  // A private folder of its own (mkdtemp: created new, mode 0700): a predictable name could be
  // made ahead by another user with a link in it (a reviewer overwrote a file so) or be another
  // run's.
  fs::path base = fs::temp_directory_path(ec);
  if (ec) base = "/tmp";
  std::string pattern = (base / "fieldpath-bom-XXXXXX").string();
  if (::mkdtemp(pattern.data()) == nullptr)
    throw InputError(file.string() +
                     ": starts with a UTF-8 byte-order mark, and no copy "
                     "without it could be made: save it without the mark");
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
    in.seekg(3);
    common::detail::beginCreating(listing.slot);
    std::ofstream out(copy, std::ios::binary);
    common::detail::endCreating(listing.slot);
    out << in.rdbuf();
    if (!out.flush())
      throw InputError(file.string() +
                       ": starts with a UTF-8 byte-order mark, and no copy "
                       "without it could be made: save it without the mark");
  }
  try {
    return loadMesh(copy);
  } catch (const InputError& e) {
    std::string why = e.what();
    for (std::size_t at = why.find(copy.string()); at != std::string::npos;
         at = why.find(copy.string(), at + file.string().size()))
      why.replace(at, copy.string().size(), file.string());
    throw InputError(why);
  }
}

}  // namespace

TriangleMesh loadMesh(const std::filesystem::path& file) {
  std::error_code ec;
  common::requireRegularFile(file, "mesh file");
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (ec || size == 0) throw InputError(file.string() + ": empty file");
  if (startsWithByteOrderMark(file, size)) return loadWithoutByteOrderMark(file);
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
    } else {
      scene = importer.ReadFile(file.string(), aiProcess_ValidateDataStructure);
    }
  } catch (const std::exception& e) {
    throw InputError(file.string() + ": cannot read mesh: " + readableAssimpError(e.what()));
  }
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0 ||
      scene->mRootNode == nullptr) {
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
          std::abs(v.z) > common::kMaxCoordinateMm)
        throw InputError(file.string() + ": vertex " + std::to_string(i + 1) +
                         " is not finite or beyond +-1e6 mm");
      const auto [it, added] =
          index_of.try_emplace({v.x, v.y, v.z}, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.emplace_back(v.x, v.y, v.z);
      remap[i] = it->second;
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices < 3 || face.mIndices == nullptr) continue;  // points and lines
      for (unsigned k = 0; k < face.mNumIndices; ++k)
        if (face.mIndices[k] >= in->mNumVertices)
          throw InputError(file.string() + ": face " + std::to_string(f + 1) +
                           " names a vertex that does not exist");
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
