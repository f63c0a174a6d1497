#pragma once
/// Internal to field/: the CUDA node build (node_build_cuda.cu; node_build_stub.cpp without
/// CUDA). Plain types only (node_kernel.h), so that nvcc sees no Eigen and no OpenVDB.
#include <cstddef>
#include <memory>
#include <vector>

#include "huge_pages.h"
#include "node_kernel.h"

namespace fieldpath::field::kernel {

/// Whether the CUDA build is compiled in and a device is present (any CUDA error: no).
bool cudaNodeBuildAvailable();

/// A build's node values, left uninitialised until the device's are copied in (zeroing the
/// 100 MB of a refined level first cost 30 ms on the GPU machine), in huge pages.
using NodeValues = HugeArray<NodeValue>;

/// The values of the masked nodes of every leaf, computed on the GPU from the cell list
/// (`table`'s pointers are host memory; copied over), compacted in leaf order then node offset
/// order (a leaf's values start at the sum of the popcounts of the masks before it). In two
/// halves, so that the host works while the device computes: the constructor copies the samples
/// and tasks over and starts the kernel (returning at once), finish() waits for it and brings
/// the values back. Throws std::runtime_error (with file and line) on a CUDA error, or without
/// CUDA (the constructor).
class CudaNodeBuild {
 public:
  CudaNodeBuild(const CellTable& table, const NodeJob& job, const std::vector<LeafTask>& leaves);
  ~CudaNodeBuild();
  CudaNodeBuild(const CudaNodeBuild&) = delete;
  CudaNodeBuild& operator=(const CudaNodeBuild&) = delete;
  NodeValues finish();

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace fieldpath::field::kernel
