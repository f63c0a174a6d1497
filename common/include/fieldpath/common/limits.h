#pragma once
/// The memory limit that size estimates are checked against before anything is allocated
/// (DESIGN.md: "sizes are estimated before allocation and refused with the estimate"), and the
/// coordinate range beyond which a number cannot come from any machine.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <utility>

#include <sys/resource.h>
#include <unistd.h>

#include "fieldpath/common/errors.h"

namespace fieldpath::common {

/// |x| above this (mm) is outside any machine tool: refused as a typo or a corrupt file.
inline constexpr double kMaxCoordinateMm = 1e6;

/// A machine's feed (mm/min): the scene's `dynamics.feed`, and the FEDRAT an APT output is given.
/// The fastest linear-motor machines reach ~1.2e5; 1e300 was written as `FEDRAT/MMPM,1e+300`.
inline constexpr double kMinFeedMmPerMin = 1e-3;
inline constexpr double kMaxFeedMmPerMin = 1e6;

/// The spring-damper's constants (`dynamics.inertia`, `stiffness`, `damping`) within these: their
/// ratios set the steering's time scale, and 1e300 over 1e-300 made it infinite (a crash, then
/// a settling that never ended: a diff review's). The tests' stiffest case is inertia 1e-12.
inline constexpr double kMinSpringConstant = 1e-12;
inline constexpr double kMaxSpringConstant = 1e12;

/// Beyond this distance from the origin (mm) a float's step passes 1 um (2^13 mm: 0.98 um): where
/// single-precision files (meshes read, STL written) stop carrying micron figures.
inline constexpr double kFloatExactMm = 8192.0;

/// The step of a float at x (its distance to the next float up), mm.
inline double floatStepMm(double x) {
  const float f = static_cast<float>(std::abs(x));
  return double(std::nextafter(f, HUGE_VALF) - f);
}

namespace detail {
inline std::atomic<std::size_t> memory_limit_bytes{0};  ///< 0: the machine's available memory
}  // namespace detail

/// The machine's available memory (MemAvailable of /proc/meminfo; half the physical memory where
/// that cannot be read), bytes.
inline std::size_t availableMemoryBytes() {
  if (std::FILE* f = std::fopen("/proc/meminfo", "r")) {
    char line[256];
    unsigned long long kib = 0;
    bool found = false;
    while (!found && std::fgets(line, sizeof line, f))
      found = std::sscanf(line, "MemAvailable: %llu kB", &kib) == 1;
    std::fclose(f);
    if (found && kib > 0) return static_cast<std::size_t>(kib) * 1024;
  }
  const long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGE_SIZE);
  return pages > 0 && page > 0 ? std::size_t(pages) * std::size_t(page) / 2 : std::size_t{4} << 30;
}

/// Sets the limit (`--max-memory`); 0 restores the default (the available memory).
inline void setMemoryLimitBytes(std::size_t bytes) { detail::memory_limit_bytes = bytes; }

/// What the process may still take under its own limits, bytes: `ulimit -v` (RLIMIT_AS) less the
/// address space it holds (VmSize), `ulimit -d` (RLIMIT_DATA) less its data (VmData: the kernel
/// counts that one against it, not the reservations of libraries); SIZE_MAX when neither is set.
/// Under a `ulimit -v` of 200 MB the machine's free memory let FCL's tree allocation fail (and
/// crash).
inline std::size_t processHeadroomBytes() {
  double headroom = HUGE_VAL;
  const auto held = [](const char* key) {  // kB of /proc/self/status, as bytes
    double bytes = 0.0;
    if (std::FILE* f = std::fopen("/proc/self/status", "r")) {
      char line[256];
      unsigned long long kib = 0;
      const std::size_t n = std::strlen(key);
      while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, key, n) == 0 && std::sscanf(line + n, " %llu", &kib) == 1) {
          bytes = 1024.0 * double(kib);
          break;
        }
      std::fclose(f);
    }
    return bytes;
  };
  for (const auto& [resource, key] : {std::pair{RLIMIT_AS, "VmSize:"}, {RLIMIT_DATA, "VmData:"}}) {
    rlimit r{};
    if (getrlimit(resource, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
      headroom = std::min(headroom, double(r.rlim_cur) - held(key));
  }
  if (headroom == HUGE_VAL) return SIZE_MAX;
  return headroom > 0.0 ? static_cast<std::size_t>(headroom) : 0;
}

/// The limit in force, bytes: `--max-memory`, or the available memory; never past what the
/// process's own limits leave it.
inline std::size_t memoryLimitBytes() {
  const std::size_t set = detail::memory_limit_bytes;
  return std::min(set != 0 ? set : availableMemoryBytes(), processHeadroomBytes());
}

/// "1.5 GiB", "320 MiB", "12 KiB" (for messages); huge and non-finite values stay readable.
inline std::string formatBytes(double bytes) {
  std::ostringstream os;
  os.precision(3);
  if (!std::isfinite(bytes)) return "unbounded";
  if (bytes >= 1024.0 * 1024 * 1024 * 1024 * 1024) {
    os << bytes / (1024.0 * 1024 * 1024 * 1024) << " TiB";
  } else if (bytes >= 1024.0 * 1024 * 1024) {
    os << bytes / (1024.0 * 1024 * 1024) << " GiB";
  } else if (bytes >= 1024.0 * 1024) {
    os << bytes / (1024.0 * 1024) << " MiB";
  } else {
    os << bytes / 1024.0 << " KiB";
  }
  return os.str();
}

/// Throws InputError "`what`: needs about E of memory (DETAIL), limit L (--max-memory)" when
/// `estimate_bytes` (a double: estimates may overflow any integer) exceeds the limit.
inline void requireMemory(const std::string& what, double estimate_bytes,
                          const std::string& detail = {}) {
  const double limit = static_cast<double>(memoryLimitBytes());
  if (estimate_bytes <= limit) return;
  const bool ulimit = static_cast<double>(processHeadroomBytes()) <= limit;
  throw InputError(what + ": needs about " + formatBytes(estimate_bytes) + " of memory" +
                   (detail.empty() ? "" : " (" + detail + ")") + ", limit " + formatBytes(limit) +
                   (ulimit ? " (what the process's ulimit -v / -d leaves it)" : " (--max-memory)"));
}

/// Parses a `--max-memory` value: a number of MiB, or a number with a K, M, G or T suffix (binary
/// units), e.g. "512", "512M", "2G". Throws InputError naming the option otherwise.
inline std::size_t parseMemorySize(const std::string& text, const std::string& option) {
  std::size_t used = 0;
  double value = -1.0;
  try {
    value = std::stod(text, &used);
  } catch (...) {
    used = 0;
  }
  double scale = 1024.0 * 1024;  // a bare number: MiB
  if (used + 1 == text.size()) {
    switch (text.back()) {
      case 'k': case 'K': scale = 1024.0; break;
      case 'm': case 'M': scale = 1024.0 * 1024; break;
      case 'g': case 'G': scale = 1024.0 * 1024 * 1024; break;
      case 't': case 'T': scale = 1024.0 * 1024 * 1024 * 1024; break;
      default: used = 0;
    }
    if (used != 0) ++used;
  }
  const double bytes = value * scale;
  if (text.empty() || used != text.size() || !std::isfinite(bytes) || bytes < 1024.0 * 1024 ||
      bytes > 1e18)
    throw InputError(option + " '" + text +
                     "': expected a size from 1 MiB to 1 EB (a number of MiB, or e.g. 512M, "
                     "2G)");
  return static_cast<std::size_t>(bytes);
}

}  // namespace fieldpath::common
