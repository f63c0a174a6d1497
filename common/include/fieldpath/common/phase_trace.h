#pragma once
/// FIELDPATH_TRACE_BUILD=1: a job's phases on stderr (ms each, "LABEL: phase  12.3 ms"), for
/// finding where a build's host time goes (issue 15: the voxel build, the refinement near the
/// path); silent otherwise.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace fieldpath::common {

class PhaseTrace {
 public:
  explicit PhaseTrace(const char* label = "build trace")
      : label_(label), on_(std::getenv("FIELDPATH_TRACE_BUILD") != nullptr) {}
  /// Prints the time since the last lap (or since made) under `what`.
  void lap(const std::string& what) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    std::fprintf(stderr, "%s: %-28s %8.1f ms\n", label_, what.c_str(),
                 std::chrono::duration<double, std::milli>(now - last_).count());
    last_ = now;
  }

 private:
  const char* label_;
  bool on_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

}  // namespace fieldpath::common
