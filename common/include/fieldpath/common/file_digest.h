#pragma once
/// A fingerprint of a file's bytes (64-bit FNV-1a, hex), so that one output can say which version
/// of an input it was made from (check.json of its path; `view --check` compares). Not a
/// cryptographic hash: it tells an edited file from the one checked, not a forged one.
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

}  // namespace fieldpath::common
