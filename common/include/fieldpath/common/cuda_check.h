#pragma once
/// Every CUDA runtime call checked (for .cu files: includes cuda_runtime.h). A failed call throws
/// std::runtime_error naming the file, the line, the call and CUDA's own words for the error,
/// which the command line turns into one line and exit code 1.
#include <cuda_runtime.h>

#include <atomic>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <string>

namespace fieldpath::common {

inline void checkCuda(cudaError_t status, const char* what, const char* file, int line) {
  if (status != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                             cudaGetErrorString(status));
}

/// For destructors and other places that must not throw: a failed call said on stderr, each
/// error once a process (after a fault CUDA's later calls all fail with the same sticky error:
/// one line, not one a buffer), never for a runtime already unloading at the process's exit. The
/// error is taken off CUDA's last error, so that the next check does not blame a later call.
inline void warnCuda(cudaError_t status, const char* what, const char* file, int line) noexcept {
  if (status == cudaSuccess) return;
  (void)cudaGetLastError();  // (a sticky error stays: every later call says it anyway)
  if (status == cudaErrorCudartUnloading) return;
  static std::atomic<std::uint64_t> said[16] = {};  // a bit an error code (codes under 1024)
  const auto code = static_cast<unsigned>(status) & 1023u;
  const std::uint64_t bit = std::uint64_t{1} << (code & 63u);
  if (said[code >> 6].fetch_or(bit) & bit) return;
  std::fprintf(stderr, "warning: %s:%d: %s: %s\n", file, line, what, cudaGetErrorString(status));
}

}  // namespace fieldpath::common

#define FIELDPATH_CUDA_CHECK(call) ::fieldpath::common::checkCuda((call), #call, __FILE__, __LINE__)
/// The same where a throw may not go (destructors): each error said once on stderr (warnCuda).
#define FIELDPATH_CUDA_WARN(call) ::fieldpath::common::warnCuda((call), #call, __FILE__, __LINE__)
