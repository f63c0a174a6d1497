#pragma once
/// FIELDPATH_TRACE_BUILD=1: a job's phases on stderr ("LABEL: phase  12.3 ms  cpu 20.1 ms  faults
/// 812": wall time, the process's CPU time (all threads) and its minor page faults each), for
/// finding where a build's host time goes (issue 15: the voxel build, the refinement near the
/// path; a phase whose cpu is below its wall runs on fewer threads than there are, one with many
/// faults is paying for fresh memory); silent otherwise.
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>

namespace fieldpath::common {

class PhaseTrace {
 public:
  explicit PhaseTrace(const char* label = "build trace")
      : label_(label), on_(std::getenv("FIELDPATH_TRACE_BUILD") != nullptr) {
    if (on_) usage(last_cpu_ms_, last_faults_);
  }
  /// Prints the time since the last lap (or since made) under `what`.
  void lap(const std::string& what) {
    if (!on_) return;
    const auto now = std::chrono::steady_clock::now();
    double cpu_ms = 0.0;
    long faults = 0;
    usage(cpu_ms, faults);
    std::fprintf(stderr, "%s: %-28s %8.1f ms  cpu %8.1f ms  faults %7ld\n", label_, what.c_str(),
                 std::chrono::duration<double, std::milli>(now - last_).count(),
                 cpu_ms - last_cpu_ms_, faults - last_faults_);
    last_ = now;
    last_cpu_ms_ = cpu_ms;
    last_faults_ = faults;
  }

 private:
  static void usage(double& cpu_ms, long& faults) {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    cpu_ms = 1e3 * double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) +
             1e-3 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
    faults = u.ru_minflt;
  }
  const char* label_;
  bool on_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
  double last_cpu_ms_ = 0.0;
  long last_faults_ = 0;
};

}  // namespace fieldpath::common
