/// Built when CUDA is not: the CUDA backend reports itself absent.
#include <stdexcept>

#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

bool cudaAvailable() { return false; }

namespace detail {
std::unique_ptr<BackendEngine> makeCudaEngine(const EngineSetup&) {
  throw std::runtime_error("fieldpath was built without the CUDA backend");
}
void warmUpCuda(const ToolData&) {}
}  // namespace detail
}  // namespace fieldpath::zbuffer
