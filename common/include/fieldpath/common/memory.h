#pragma once
/// The memory a run may take (`--max-memory`, else the machine's available memory) and what its
/// work holds of it: sizes are estimated before allocation and refused with the estimate
/// (DESIGN.md), each against what the run's earlier items left.
#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <mutex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <sys/resource.h>
#include <unistd.h>

#include "fieldpath/common/errors.h"

namespace fieldpath::common {

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
namespace detail {
/// A "KEY: N kB" line of /proc/self/status (`key` with its colon), as bytes; 0 where unread.
inline double processStatusBytes(const char* key) {
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
}
}  // namespace detail

inline std::size_t processHeadroomBytes() {
  double headroom = HUGE_VAL;
  for (const auto& [resource, key] : {std::pair{RLIMIT_AS, "VmSize:"}, {RLIMIT_DATA, "VmData:"}}) {
    rlimit r{};
    if (getrlimit(resource, &r) == 0 && r.rlim_cur != RLIM_INFINITY)
      headroom = std::min(headroom, double(r.rlim_cur) - detail::processStatusBytes(key));
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

/// What a run's accepted estimates leave the next one under `--max-memory`: the estimates are
/// made one item at a time (meshes, samples, voxels, postures), and each under the limit had let
/// a run's items together pass it by 4 times (a memory sweep's). An item kept to the run's end
/// (MemoryUse::kKept) is held against the limit by every later estimate; one made and dropped
/// before the next (kPassing: a file read into a mesh counted again once loaded, a study's grids
/// built one after another) is checked and not held.
enum class MemoryUse { kKept, kPassing };

namespace detail {
struct MemoryLedger {
  std::mutex mutex;  ///< every field below; an estimate is checked and held under it at once
  double held_bytes = 0.0;
  std::uint64_t next_id = 1;
  std::map<std::uint64_t, std::pair<std::string, double>> items;  ///< id: what holds it, bytes
  bool cuda_context = false;  ///< requireCudaContext's hold is made
};
inline MemoryLedger& memoryLedger() {
  static MemoryLedger ledger;
  return ledger;
}

/// Adds an item to the ledger; its id (0: nothing held). Kept only under a limit set
/// (setMemoryLimitBytes): without one the available memory is measured anew at each estimate.
/// (The caller holds ledger.mutex.)
inline std::uint64_t holdLocked(MemoryLedger& ledger, const std::string& what, double bytes) {
  if (!(bytes > 0.0) || memory_limit_bytes == 0) return 0;
  ledger.held_bytes += bytes;
  ledger.items.emplace(ledger.next_id, std::pair{what, bytes});
  return ledger.next_id++;
}
inline std::uint64_t holdInLedger(const std::string& what, double bytes) {
  MemoryLedger& ledger = memoryLedger();
  const std::lock_guard lock(ledger.mutex);
  return holdLocked(ledger, what, bytes);
}
/// What the limit leaves with `held_bytes` held (see memoryLeftBytes).
inline double leftWith(double held_bytes) {
  const std::size_t set = memory_limit_bytes;
  const double left = set != 0 ? double(set) - held_bytes : double(availableMemoryBytes());
  return std::max(0.0, std::min(left, double(processHeadroomBytes())));
}
}  // namespace detail

/// Holds `bytes` to the run's end against `--max-memory`, named `what` in later refusals.
inline void holdMemory(const std::string& what, double bytes) { detail::holdInLedger(what, bytes); }

/// Holds bytes against `--max-memory` while it lives (an object that owns them: a voxel field a
/// study builds and drops); move-only.
class HeldMemory {
 public:
  HeldMemory() = default;
  HeldMemory(const std::string& what, double bytes) : id_(detail::holdInLedger(what, bytes)) {}
  HeldMemory(HeldMemory&& other) noexcept : id_(std::exchange(other.id_, 0)) {}
  HeldMemory& operator=(HeldMemory&& other) noexcept {
    if (this != &other) {
      release();
      id_ = std::exchange(other.id_, 0);
    }
    return *this;
  }
  HeldMemory(const HeldMemory&) = delete;
  HeldMemory& operator=(const HeldMemory&) = delete;
  ~HeldMemory() { release(); }
  /// Gives the bytes back to the ledger (nothing where none is held).
  void release() {
    if (id_ == 0) return;
    detail::MemoryLedger& ledger = detail::memoryLedger();
    const std::lock_guard lock(ledger.mutex);
    const auto item = ledger.items.find(std::exchange(id_, 0));
    if (item == ledger.items.end()) return;  // released with the whole ledger
    ledger.held_bytes -= item->second.second;
    ledger.items.erase(item);
  }

 private:
  std::uint64_t id_ = 0;
};

/// Bytes the run holds (holdMemory), and the three largest holders as "A 12 MiB, B 3 MiB, ...".
inline std::pair<double, std::string> memoryHeld() {
  detail::MemoryLedger& ledger = detail::memoryLedger();
  const std::lock_guard lock(ledger.mutex);
  std::vector<std::pair<std::string, double>> items;
  for (const auto& [id, item] : ledger.items) items.push_back(item);
  std::stable_sort(items.begin(), items.end(),
                   [](const auto& a, const auto& b) { return a.second > b.second; });
  std::string named;
  for (std::size_t i = 0; i < items.size() && i < 3; ++i) {
    // By its key: "SCENE: path.step" as "path.step" (the scene is named by the refusal's own).
    const std::string& what = items[i].first;
    const std::size_t colon = what.rfind(": ");
    named += (i ? ", " : "") + (colon == std::string::npos ? what : what.substr(colon + 2)) + " " +
             formatBytes(items[i].second);
  }
  if (items.size() > 3) {
    double rest = 0.0;
    for (std::size_t i = 3; i < items.size(); ++i) rest += items[i].second;
    named += " and " + std::to_string(items.size() - 3) + " more of " + formatBytes(rest);
  }
  return {ledger.held_bytes, named};
}

/// The resident memory of the program at its start (VmRSS: its code and libraries, ~33 MiB),
/// held for the run, once: `--max-memory` bounds the whole process, as `time -v` and a cgroup
/// count it.
inline void holdProgramMemory() {
  static std::once_flag once;
  std::call_once(once, [] { holdMemory("the program", detail::processStatusBytes("VmRSS:")); });
}

/// What the next item may take, bytes: `--max-memory` less what the run holds; the available
/// memory where no limit is set (measured now: what the run took is out of it already); never
/// past what the process's own limits leave it.
inline double memoryLeftBytes() { return detail::leftWith(memoryHeld().first); }

/// ", limit L (--max-memory)", or with what the run holds: ", limit L (--max-memory), of which the
/// run holds H (the program 33 MiB, ...)"; the ulimit named where that is what binds.
inline std::string memoryLimitText() {
  const double limit = static_cast<double>(memoryLimitBytes());
  if (static_cast<double>(processHeadroomBytes()) <= memoryLeftBytes())
    return ", limit " + formatBytes(double(processHeadroomBytes())) +
           " (what the process's ulimit -v / -d leaves it)";
  const auto [held, named] = memoryHeld();
  if (detail::memory_limit_bytes == 0 || !(held > 0.0))
    return ", limit " + formatBytes(limit) + " (--max-memory)";
  return ", limit " + formatBytes(limit) + " (--max-memory), of which the run holds " +
         formatBytes(held) + " (" + named + ")";
}

/// Throws InputError "`what`: needs about E of memory (DETAIL), limit L (--max-memory)[, of
/// which the run holds H (...)]" when `estimate_bytes` (a double: estimates may overflow any
/// integer) exceeds what the limit leaves; an estimate accepted as kKept is then held.
inline void requireMemory(const std::string& what, double estimate_bytes,
                          const std::string& detail = {}, MemoryUse use = MemoryUse::kKept) {
  {
    detail::MemoryLedger& ledger = detail::memoryLedger();
    const std::lock_guard lock(ledger.mutex);  // checked and held at once (threads)
    if (estimate_bytes <= detail::leftWith(ledger.held_bytes)) {
      if (use == MemoryUse::kKept) detail::holdLocked(ledger, what, estimate_bytes);
      return;
    }
  }
  throw InputError(what + ": needs about " + formatBytes(estimate_bytes) + " of memory" +
                   (detail.empty() ? "" : " (" + detail + ")") + memoryLimitText());
}

/// Resident memory a process gains once it uses CUDA (its context, the driver's and the
/// runtime's host memory): on an H200 (driver 580) generate's peak grew 101 MB and check's 156 MB
/// over the CPU backend's, in no estimate (an accepted --max-memory 130M ran check to 254 MB).
inline constexpr double kCudaContextBytes = 160.0 * 1024 * 1024;

/// Holds kCudaContextBytes once, before a backend first uses the GPU; InputError naming it (and
/// `--backend cpu`, which spares it) where the limit leaves less.
inline void requireCudaContext() {
  static std::mutex once;  // two backends' threads asking at once hold it once
  const std::lock_guard lock(once);
  detail::MemoryLedger& ledger = detail::memoryLedger();
  {
    const std::lock_guard held(ledger.mutex);
    if (ledger.cuda_context) return;
  }
  requireMemory("the CUDA backend", kCudaContextBytes,
                "its context and driver: 100-156 MB measured on an H200; --backend cpu spares it");
  const std::lock_guard held(ledger.mutex);
  ledger.cuda_context = true;
}

/// Forgets what was held: a new run in the same process (a fuzzer's next input).
inline void releaseHeldMemory() {
  detail::MemoryLedger& ledger = detail::memoryLedger();
  const std::lock_guard lock(ledger.mutex);
  ledger.held_bytes = 0.0;
  ledger.items.clear();
  ledger.cuda_context = false;
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
      case 'k':
      case 'K':
        scale = 1024.0;
        break;
      case 'm':
      case 'M':
        scale = 1024.0 * 1024;
        break;
      case 'g':
      case 'G':
        scale = 1024.0 * 1024 * 1024;
        break;
      case 't':
      case 'T':
        scale = 1024.0 * 1024 * 1024 * 1024;
        break;
      default:
        used = 0;
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

/// Sets `--max-memory` from its text (`option` names it in errors) and holds the program's own
/// memory under it; InputError where the limit is under what the program holds at its start.
inline void limitMemory(const std::string& text, const std::string& option) {
  const std::size_t limit = parseMemorySize(text, option);
  setMemoryLimitBytes(limit);
  holdProgramMemory();
  const double program = memoryHeld().first;
  if (program >= double(limit))
    throw InputError(option + " " + text + ": under the " + formatBytes(program) +
                     " the program holds at its start (its code and libraries)");
}

}  // namespace fieldpath::common
