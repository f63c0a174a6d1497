#pragma once
/// Every CUDA runtime call checked (for .cu files: includes cuda_runtime.h). A failed call throws
/// std::runtime_error naming the file, the line, the call and CUDA's own words for the error,
/// which the command line turns into one line and exit code 1.
#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace fieldpath::common {

inline void checkCuda(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                             cudaGetErrorString(status));
}

}  // namespace fieldpath::common

#define FIELDPATH_CUDA_CHECK(call) ::fieldpath::common::checkCuda((call), #call, __FILE__, __LINE__)
