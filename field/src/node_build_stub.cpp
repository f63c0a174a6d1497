/// The CUDA node build when the program is built without CUDA (node_cuda.h).
#include <stdexcept>

#include "node_cuda.h"

namespace fieldpath::field::kernel {

bool cudaNodeBuildAvailable() { return false; }

struct CudaNodeBuild::State {};
CudaNodeBuild::CudaNodeBuild(const CellTable&, const NodeJob&, const std::vector<LeafTask>&) {
  throw std::runtime_error("field: this program was built without CUDA (FIELDPATH_WITH_CUDA)");
}
CudaNodeBuild::~CudaNodeBuild() = default;
NodeValues CudaNodeBuild::finish() { return {}; }

}  // namespace fieldpath::field::kernel
