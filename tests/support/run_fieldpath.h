#pragma once
/// Running the built `fieldpath` as a user runs it, from the tests of any module (FIELDPATH_EXE is
/// the test target's compile definition), and scratch folders for what it reads and writes.
#include <sys/wait.h>

#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fieldpath::test {

/// A fresh folder under the system temp folder, removed at the end of the test.
class TempDir {
 public:
  TempDir() {
    std::random_device rd;
    path_ = std::filesystem::temp_directory_path() /
            ("fieldpath_test_" + std::to_string(rd()) + std::to_string(rd()));
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
  std::string output() const { return out + err; }
};

/// Runs `fieldpath ARGS` (shell words) in `dir`, exactly as typed (progress lines included).
inline Outcome runFieldpathAsTyped(const TempDir& dir, const std::string& args) {
  const auto out = dir.path() / "stdout.txt", err = dir.path() / "stderr.txt";
  const std::string command = "cd '" + dir.path().string() + "' && '" FIELDPATH_EXE "' " + args +
                              " > '" + out.string() + "' 2> '" + err.string() + "'";
  const int status = std::system(command.c_str());
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(out), slurp(err)};
}

/// Runs `fieldpath --quiet ARGS` (shell words) in `dir`.
inline Outcome runFieldpath(const TempDir& dir, const std::string& args) {
  return runFieldpathAsTyped(dir, "--quiet " + args);
}

/// The same in a scratch folder of its own (for arguments that are absolute paths).
inline Outcome runFieldpath(const std::string& args) {
  const TempDir scratch;
  return runFieldpath(scratch, args);
}

/// The float32 data of a version-1 .npy file's bytes, past its header (the header itself is
/// checked by the zbuffer tests): heights.npy, deviation.npy.
inline std::vector<float> npyFloats(const std::string& bytes) {
  if (bytes.size() < 10) return {};
  const std::size_t header =
      static_cast<unsigned char>(bytes[8]) | (static_cast<unsigned char>(bytes[9]) << 8);
  const std::size_t start = 10 + header;
  if (bytes.size() < start) return {};
  std::vector<float> data((bytes.size() - start) / sizeof(float));
  std::memcpy(data.data(), bytes.data() + start, data.size() * sizeof(float));
  return data;
}

}  // namespace fieldpath::test
