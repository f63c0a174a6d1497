#pragma once
/// The one check every reader of a user's file makes first: it is a regular file. A directory,
/// a FIFO (which would block the reader) or a device (/dev/zero: endless) is refused with what it
/// is, a missing file as missing, an unreadable one as unreadable. The files that pass are this
/// run's inputs: the writers refuse to write over them (writeFileAtomically).
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "fieldpath/common/errors.h"

namespace fieldpath::common {

namespace detail {
inline std::mutex inputs_mutex;
inline std::vector<std::filesystem::path> input_files;
inline bool guard_inputs = false;
/// The inputs' (device, inode), lock-free, for a signal handler (isInputNow).
struct InputId {
  std::atomic<unsigned long long> device{0}, inode{0};
};
inline constexpr int kInputIds = 64;
inline InputId input_ids[kInputIds];
inline std::atomic<int> input_id_count{0};
}  // namespace detail

/// Whether `path` is one of this run's inputs (stat and lock-free atomics: async-signal-safe, for
/// the handler that removes a run's claimed outputs; an input is never one of them).
inline bool isInputNow(const char* path) noexcept {
  struct stat info {};
  if (::stat(path, &info) != 0) return false;
  const int n = std::min(detail::input_id_count.load(), detail::kInputIds);
  for (int i = 0; i < n; ++i)
    if (detail::input_ids[i].device.load() == static_cast<unsigned long long>(info.st_dev) &&
        detail::input_ids[i].inode.load() == static_cast<unsigned long long>(info.st_ino))
      return true;
  return false;
}

/// The CLI's main() turns it on: one process is one run, and what it reads it must not write
/// over. A library caller (the tests: write, read back, write again) is a run of many.
inline void guardInputs() {
  const std::lock_guard<std::mutex> lock(detail::inputs_mutex);
  detail::guard_inputs = true;
}

/// The input of this run that `file` is (the same file by any name), or an empty path.
inline std::filesystem::path inputAt(const std::filesystem::path& file) {
  const std::lock_guard<std::mutex> lock(detail::inputs_mutex);
  for (const std::filesystem::path& input : detail::input_files) {
    std::error_code ec;
    if (std::filesystem::equivalent(file, input, ec)) return input;
  }
  return {};
}

/// Throws InputError "FILE: no such WHAT" / "FILE: is a directory, expected a WHAT" / "FILE: not
/// a regular file (a FIFO, socket or device), expected a WHAT" unless `file` is a regular file.
inline void requireRegularFile(const std::filesystem::path& file,
                               const std::string& what = "file") {
  std::error_code ec;
  const std::filesystem::file_status status = std::filesystem::status(file, ec);
  if (std::filesystem::is_regular_file(status)) {
    // Unreadable (permissions): said so, not as the empty or cut-short file a reader then sees
    // ("binary STL ... shorter than its 84-byte header").
    if (::access(file.c_str(), R_OK) != 0)
      throw InputError(file.string() + ": cannot read the " + what + ": " + std::strerror(errno));
    const std::lock_guard<std::mutex> lock(detail::inputs_mutex);
    if (!detail::guard_inputs) return;
    detail::input_files.push_back(file);
    struct stat info {};
    if (::stat(file.c_str(), &info) == 0) {
      const int i = detail::input_id_count.load();
      if (i < detail::kInputIds) {
        detail::input_ids[i].device.store(static_cast<unsigned long long>(info.st_dev));
        detail::input_ids[i].inode.store(static_cast<unsigned long long>(info.st_ino));
        detail::input_id_count.store(i + 1);
      }
    }
    return;
  }
  if (std::filesystem::is_directory(status))
    throw InputError(file.string() + ": is a directory, expected a " + what);
  if (std::filesystem::exists(status))
    throw InputError(file.string() +
                     ": not a regular file (a FIFO, socket or device), expected a " + what);
  throw InputError(file.string() + ": no such " + what);
}

namespace detail {
/// An input mapped into memory (listMappedInput): its bytes' addresses, and its name for the
/// SIGBUS a read of a page lost to a cut (another program rewrote the file) raises.
struct MappedInput {
  std::atomic<int> state{0};  ///< 0 free, 1 being claimed, 2 live
  std::atomic<std::uintptr_t> base{0};
  std::atomic<std::size_t> bytes{0};
  char path[4096];
};
inline constexpr int kMappedInputs = 8;
inline MappedInput mapped_inputs[kMappedInputs];
}  // namespace detail

/// Lists the mapping [base, base + bytes) of input `path`; returns its slot, -1 when none is
/// free or the name is too long (a SIGBUS there is then not told from another).
inline int listMappedInput(const std::string& path, const void* base, std::size_t bytes) {
  if (path.size() >= sizeof(detail::MappedInput::path)) return -1;
  for (int i = 0; i < detail::kMappedInputs; ++i) {
    int expected = 0;
    auto& slot = detail::mapped_inputs[i];
    if (slot.state.compare_exchange_strong(expected, 1)) {
      std::memcpy(slot.path, path.c_str(), path.size() + 1);
      slot.base.store(reinterpret_cast<std::uintptr_t>(base));
      slot.bytes.store(bytes);
      slot.state.store(2);
      return i;
    }
  }
  return -1;
}
inline void unlistMappedInput(int slot) {
  if (slot >= 0) detail::mapped_inputs[slot].state.store(0);
}

/// The name of the listed input whose mapping holds `address`, or nullptr (lock-free atomics:
/// async-signal-safe).
inline const char* mappedInputAt(const void* address) noexcept {
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  for (auto& slot : detail::mapped_inputs)
    if (slot.state.load() == 2 && at >= slot.base.load() &&
        at - slot.base.load() < slot.bytes.load())
      return slot.path;
  return nullptr;
}

}  // namespace fieldpath::common
