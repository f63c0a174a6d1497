#pragma once
/// Shared by the fuzz targets: readers take file names, so each input is written to a file in a
/// per-process scratch directory (on /dev/shm when there is one: no disk traffic).
///
/// The contract every target checks: bad input is refused with common::InputError (exit 1 in
/// the CLI), never anything else. Any other exception escapes and libFuzzer reports it as a
/// crash ("deadly signal" after std::terminate): that is an exit 2 a user could trigger.
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include "fieldpath/common/limits.h"

namespace fieldpath::fuzz {

/// The scratch directory of this process (created on first use).
inline const std::filesystem::path& scratchDir() {
  // Never destroyed: the atexit handler below runs after the destructors of statics initialised
  // later, and a static path would be one of them (the directories were left behind).
  static const std::filesystem::path* const dir = [] {
    std::error_code ec;
    const std::filesystem::path base = std::filesystem::is_directory("/dev/shm", ec)
                                           ? "/dev/shm"
                                           : std::filesystem::temp_directory_path();
    auto* d = new std::filesystem::path(base / ("fieldpath-fuzz-" + std::to_string(::getpid())));
    std::filesystem::create_directories(*d);
    std::atexit([] {  // libFuzzer ends by exit(): leave no scratch directory behind
      std::error_code ignored;
      std::filesystem::remove_all(scratchDir(), ignored);
    });
    // Every estimate is checked against this: a fuzzer must not be able to ask for gigabytes.
    common::setMemoryLimitBytes(std::size_t{256} << 20);
    return d;
  }();
  return *dir;
}

/// Writes `bytes` to `name` in the scratch directory; returns its path.
inline std::filesystem::path writeScratch(const std::string& name, std::string_view bytes) {
  const auto path = scratchDir() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  return path;
}

inline std::string_view view(const std::uint8_t* data, std::size_t size) {
  return {reinterpret_cast<const char*>(data), size};
}

}  // namespace fieldpath::fuzz
