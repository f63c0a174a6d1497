#pragma once
/// Scratch folders and files for the app tests.
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace fieldpath::app::test {

/// A fresh folder under the system temp folder, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("fieldpath_app_" + std::to_string(rd()) + std::to_string(rd()));
    std::filesystem::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;

  const std::filesystem::path& path() const { return path_; }
  /// Writes `text` to `name` (sub-folders created) and returns the full path.
  std::filesystem::path write(const std::string& name, const std::string& text) const {
    const auto file = path_ / name;
    std::filesystem::create_directories(file.parent_path());
    std::ofstream(file) << text;
    return file;
  }

 private:
  std::filesystem::path path_;
};

inline std::string slurp(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// Exit code, stdout and stderr of a run of the built `fieldpath`.
struct Outcome {
  int exit_code;
  std::string out, err;
};

/// Runs `fieldpath --quiet ARGS` in `dir` (FIELDPATH_EXE: the test target's compile definition).
inline Outcome runFieldpath(const TempDir& dir, const std::string& args) {
  const auto out = dir.path() / "stdout.txt", err = dir.path() / "stderr.txt";
  const std::string command = "cd '" + dir.path().string() + "' && '" FIELDPATH_EXE "' --quiet " +
                              args + " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

/// ASCII STL of the square [-a, a]² at height z, normal +z.
inline std::string squareStl(double a, double z = 0.0) {
  auto v = [z](double x, double y) {
    return "   vertex " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) +
           "\n";
  };
  auto facet = [](const std::string& a, const std::string& b, const std::string& c) {
    return " facet normal 0 0 1\n  outer loop\n" + a + b + c + "  endloop\n endfacet\n";
  };
  return "solid square\n" + facet(v(-a, -a), v(a, -a), v(a, a)) +
         facet(v(-a, -a), v(a, a), v(-a, a)) + "endsolid square\n";
}

}  // namespace fieldpath::app::test
