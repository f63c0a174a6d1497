/// libFuzzer target: scene files (every key, the parametric impeller's block included), read as
/// `generate` reads them: loadScene (keys, meshes, the nominal path, the impeller, the size
/// estimates) then sceneJob (the passes). Beside the scene lie files its keys may name:
/// m.stl (a closed tetrahedron), p.cl, p.apt, p.npy (short paths).
#include "fieldpath/common/errors.h"
#include "fuzz_support.h"
#include "job.h"
#include "scene.h"

namespace {

const char* kTetraStl =
    "solid t\n"
    "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 10 0\nvertex 10 0 "
    "0\nendloop\nendfacet\n"
    "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 10 0 0\nvertex 0 0 "
    "10\nendloop\nendfacet\n"
    "facet normal -1 0 0\nouter loop\nvertex 0 0 0\nvertex 0 0 10\nvertex 0 10 "
    "0\nendloop\nendfacet\n"
    "facet normal 1 1 1\nouter loop\nvertex 10 0 0\nvertex 0 10 0\nvertex 0 0 "
    "10\nendloop\nendfacet\n"
    "endsolid t\n";

const char* kPathCl =
    "# pass 1\n-5 20 12 0 0 1\n0 20 12 0 0 1\n5 20 12 0 0 1\n10 20 12 0 0 1\n"
    "# pass 2\n-5 25 12 0 0 1\n0 25 12 0 0 1\n5 25 12 0 0 1\n";

const char* kPathApt =
    "PARTNO/T\nUNITS/MM\nMULTAX/ON\nGOTO/-5,20,12,0,0,1\nGOTO/0,20,12,0,0,1\nGOTO/5,20,12\n"
    "RAPID\nGOTO/5,25,20,0,0,1\nGOTO/5,25,12,0,0,1\nGOTO/0,25,12,0,0,1\nFINI\n";

std::string npyPath() {
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (3, 6), }";
  header.append((64 - (10 + header.size() + 1) % 64) % 64, ' ');  // data aligned to 64 bytes
  header += '\n';
  std::string out("\x93NUMPY\x01\x00", 8);
  out += static_cast<char>(header.size());
  out += '\0';
  out += header;
  const double rows[3][6] = {{-5, 20, 12, 0, 0, 1}, {0, 20, 12, 0, 0, 1}, {5, 20, 12, 0, 0, 1}};
  out.append(reinterpret_cast<const char*>(rows), sizeof rows);
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fieldpath::common::releaseHeldMemory();  // each input a run of its own (--max-memory)
  using namespace fieldpath;
  static const bool files_ready = [] {
    fuzz::writeScratch("m.stl", kTetraStl);
    fuzz::writeScratch("p.cl", kPathCl);
    fuzz::writeScratch("p.apt", kPathApt);
    fuzz::writeScratch("p.npy", npyPath());
    return true;
  }();
  (void)files_ready;
  const auto file = fuzz::writeScratch("scene.yaml", fuzz::view(data, size));
  try {
    const app::Scene scene = app::loadScene(file);
    (void)app::sceneJob(scene);
  } catch (const common::InputError&) {
  }
  return 0;
}
