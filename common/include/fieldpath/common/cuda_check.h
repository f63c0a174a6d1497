#pragma once
/// Every CUDA runtime call checked (for .cu files: includes cuda_runtime.h). A failed call throws
/// std::runtime_error naming the file, the line, the call and CUDA's own words for the error,
/// which the command line turns into one line and exit code 1.
#include <cuda_runtime.h>

#include <atomic>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace fieldpath::common {

inline void checkCuda(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                             cudaGetErrorString(status));
}

/// For destructors and other places that must not throw: a failed call said on stderr, once a
/// process (after a fault CUDA's later calls all fail with the same sticky error: one line, not
/// one a buffer), and never for a runtime already unloading at the process's exit.
inline void warnCuda(cudaError_t status, const char* what, const char* file, int line) noexcept {
  if (status == cudaSuccess || status == cudaErrorCudartUnloading) return;
  static std::atomic<bool> said{false};
  if (said.exchange(true)) return;
  std::fprintf(stderr, "warning: %s:%d: %s: %s\n", file, line, what, cudaGetErrorString(status));
}

}  // namespace fieldpath::common

#define FIELDPATH_CUDA_CHECK(call) ::fieldpath::common::checkCuda((call), #call, __FILE__, __LINE__)
/// The same where a throw may not go (destructors): said once on stderr (warnCuda).
#define FIELDPATH_CUDA_WARN(call) ::fieldpath::common::warnCuda((call), #call, __FILE__, __LINE__)
