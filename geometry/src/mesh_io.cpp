#include "fieldpath/geometry/mesh_io.h"

#include <stdexcept>

#include "fieldpath/common/errors.h"

namespace fieldpath::geometry {

TriangleMesh loadMesh(const std::filesystem::path& file) {
  throw common::InputError(file.string() + ": mesh reading is not implemented yet");
}

void saveMesh(const TriangleMesh&, const std::filesystem::path& file) {
  throw common::InputError(file.string() + ": mesh writing is not implemented yet");
}

}  // namespace fieldpath::geometry
