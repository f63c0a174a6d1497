/// libFuzzer target: the mesh-loading wrapper (geometry::loadMesh over assimp) with STL (ASCII
/// and binary), OBJ and PLY; the first byte picks the extension. Unreadable meshes must give
/// InputError, and a loaded mesh must be one the rest of the program can take (indices in range,
/// finite vertices).
#include <cmath>
#include <cstdlib>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fieldpath::common::releaseHeldMemory();  // each input a run of its own (--max-memory)
  using namespace fieldpath;
  if (size < 1) return 0;
  const char* names[] = {"mesh.stl", "mesh.obj", "mesh.ply", "mesh.stl"};
  const auto file = fuzz::writeScratch(names[data[0] & 3], fuzz::view(data + 1, size - 1));
  try {
    const geometry::TriangleMesh mesh = geometry::loadMesh(file);
    const auto n = static_cast<int>(mesh.vertices.size());
    for (const auto& v : mesh.vertices)
      if (!v.allFinite()) std::abort();
    for (const auto& t : mesh.triangles)
      for (int k = 0; k < 3; ++k)
        if (t[k] < 0 || t[k] >= n) std::abort();
  } catch (const common::InputError&) {
  }
  return 0;
}
