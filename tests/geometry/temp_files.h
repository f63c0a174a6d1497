#pragma once
/// Scratch files for the geometry tests: one folder per test process under the system temp dir.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

namespace fieldpath::geometry::test_files {

inline std::filesystem::path tempPath(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("fieldpath_test_geometry_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return dir / name;
}

/// Writes `bytes` as they are (binary) to tempPath(name) and returns that path.
inline std::filesystem::path writeBytes(const std::string& name, const std::string& bytes) {
  const auto p = tempPath(name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

}  // namespace fieldpath::geometry::test_files
