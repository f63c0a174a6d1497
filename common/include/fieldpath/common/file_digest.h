#pragma once
/// A fingerprint of a file's bytes (64-bit FNV-1a, hex), so that one output can say which version
/// of an input it was made from (check.json of its path; `view --check` compares). Not a
/// cryptographic hash: it tells an edited file from the one checked, not a forged one.
#include <sys/stat.h>

#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "fieldpath/common/errors.h"

namespace fieldpath::common {

/// "fnv1a64:" and 16 hex digits of the file's bytes; InputError naming the file if it cannot
/// be read.
inline std::string fileDigest(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::uint64_t h = 0xcbf29ce484222325ull;
  std::vector<char> buffer(1 << 16);
  while (in) {
    in.read(buffer.data(), static_cast<std::streamsize>(buffer.size()));
    const std::streamsize n = in.gcount();
    for (std::streamsize i = 0; i < n; ++i) {
      h ^= static_cast<unsigned char>(buffer[static_cast<std::size_t>(i)]);
      h *= 0x100000001b3ull;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return std::string("fnv1a64:") + hex;
}

/// What tells a file rewritten or replaced since it was read: its device, inode, size and
/// modification time (ns). Cheap where fileDigest reads every byte: taken before a long job reads
/// the file and compared after (requireUnchanged).
struct FileStamp {
  std::uint64_t device = 0, inode = 0, size = 0;
  std::int64_t mtime_s = 0, mtime_ns = 0;
  bool operator==(const FileStamp&) const = default;
};

/// The stamp of `file` now (all zero when it cannot be stat'ed: then it differs from any taken).
inline FileStamp fileStamp(const std::filesystem::path& file) {
  struct stat st {};
  if (::stat(file.c_str(), &st) != 0) return {};
  return {static_cast<std::uint64_t>(st.st_dev), static_cast<std::uint64_t>(st.st_ino),
          static_cast<std::uint64_t>(st.st_size), static_cast<std::int64_t>(st.st_mtim.tv_sec),
          static_cast<std::int64_t>(st.st_mtim.tv_nsec)};
}

/// Throws InputError "FILE changed while it was WHAT ..." unless `file`'s stamp is still
/// `before`: a verdict on a file must be on the bytes it now holds (a path replaced during
/// `check` was reported ok, and its digest taken after the change).
inline void requireUnchanged(const std::filesystem::path& file, const FileStamp& before,
                             const std::string& what) {
  if (fileStamp(file) == before) return;
  throw InputError(file.string() + ": changed while it was " + what +
                   " (written or replaced by another program): run again on the file as it is");
}

}  // namespace fieldpath::common
