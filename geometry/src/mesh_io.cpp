#include "fieldpath/geometry/mesh_io.h"

#include <array>
#include <cctype>
#include <exception>
#include <string>
#include <unordered_map>

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"

namespace fieldpath::geometry {
namespace {

using common::InputError;

std::string lowerExtension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

/// Hash of a position's exact bits (joining needs equality, not nearness).
struct PositionHash {
  std::size_t operator()(const std::array<ai_real, 3>& p) const {
    std::size_t h = 0;
    for (ai_real c : p) h = h * 0x9E3779B97F4A7C15ull + std::hash<ai_real>{}(c);
    return h;
  }
};

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

}  // namespace

TriangleMesh loadMesh(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string() + ": no such file");
  if (std::filesystem::file_size(file, ec) == 0) throw InputError(file.string() + ": empty file");

  Assimp::Importer importer;
  // Points and lines are dropped; polygons are split into triangles; node transforms applied.
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  const aiScene* scene = nullptr;
  try {
    scene = importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_SortByPType |
                                                 aiProcess_PreTransformVertices);
  } catch (const std::exception& e) {
    throw InputError(file.string() + ": cannot read mesh: " + e.what());
  }
  if (scene == nullptr || (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE) != 0) {
    const std::string why = importer.GetErrorString();
    throw InputError(file.string() + ": cannot read mesh" +
                     (why.empty() ? std::string() : ": " + why));
  }

  // Identical positions are joined across faces and meshes (STL stores every corner per face).
  TriangleMesh mesh;
  std::unordered_map<std::array<ai_real, 3>, int, PositionHash> index_of;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* in = scene->mMeshes[m];
    if ((in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) == 0) continue;
    std::vector<int> remap(in->mNumVertices);
    for (unsigned i = 0; i < in->mNumVertices; ++i) {
      const aiVector3D& v = in->mVertices[i];
      const auto [it, added] =
          index_of.try_emplace({v.x, v.y, v.z}, static_cast<int>(mesh.vertices.size()));
      if (added) mesh.vertices.emplace_back(v.x, v.y, v.z);
      remap[i] = it->second;
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices != 3) continue;
      mesh.triangles.emplace_back(remap[face.mIndices[0]], remap[face.mIndices[1]],
                                  remap[face.mIndices[2]]);
    }
  }
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
  Assimp::Exporter exporter;
  const aiExportDataBlob* blob = exporter.ExportToBlob(&scene, format);
  if (blob == nullptr)
    throw std::runtime_error(file.string() + ": mesh export failed: " + exporter.GetErrorString());
  common::writeFileAtomically(
      file,
      [blob](std::ofstream& out) {
        out.write(static_cast<const char*>(blob->data), static_cast<std::streamsize>(blob->size));
      },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::geometry
