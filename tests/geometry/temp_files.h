#pragma once
/// Scratch files for the geometry tests: one folder per test process under the system temp dir,
/// removed when the process ends (ctest runs each test in a process of its own: the folders of
/// one run of the suite were 3 500 left behind in /tmp).
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <system_error>

namespace fieldpath::geometry::test_files {

/// This process's scratch folder, made on first use and removed at exit.
inline const std::filesystem::path& scratchDir() {
  struct Dir {
    std::filesystem::path path = std::filesystem::temp_directory_path() /
                                 ("fieldpath_test_geometry_" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ignored;  // a folder already gone is no failure of the test
      std::filesystem::remove_all(path, ignored);
    }
    Dir(const Dir&) = delete;
    Dir& operator=(const Dir&) = delete;
  };
  static const Dir dir;
  return dir.path;
}

inline std::filesystem::path tempPath(const std::string& name) { return scratchDir() / name; }

/// Writes `bytes` as they are (binary) to tempPath(name) and returns that path.
inline std::filesystem::path writeBytes(const std::string& name, const std::string& bytes) {
  const auto p = tempPath(name);
  std::ofstream(p, std::ios::binary) << bytes;
  return p;
}

}  // namespace fieldpath::geometry::test_files
