#pragma once
/// What an atomic write leaves beside its file when it fails to rename: `.NAME.tmp-PID`
/// (common/atomic_file.h). Tests assert none is left (`NAME.tmp`, which an earlier form of these
/// tests looked for, is a name the writer never makes: those assertions could not fail).
#include <filesystem>
#include <string>
#include <vector>

namespace fieldpath::test {

/// The names in `file`'s folder that are temporaries of `file` (any process's).
inline std::vector<std::string> temporariesOf(const std::filesystem::path& file) {
  const std::filesystem::path dir =
      file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  const std::string prefix = "." + file.filename().string() + ".tmp-";
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(dir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

}  // namespace fieldpath::test
