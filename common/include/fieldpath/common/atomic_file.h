#pragma once
/// Outputs are written to a temporary name beside the target and renamed into place, so an
/// interrupted run never leaves a truncated file under the final name (DESIGN.md).
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>

namespace fieldpath::common {

/// Calls `write(stream)` on a temporary file beside `path`, then renames it to `path`.
/// Throws std::runtime_error (naming the path) if the file cannot be written; the temporary is
/// removed on any failure, including an exception thrown by `write`.
inline void writeFileAtomically(const std::filesystem::path& path,
                                const std::function<void(std::ofstream&)>& write,
                                std::ios::openmode mode = std::ios::out) {
  namespace fs = std::filesystem;
  if (path.has_parent_path()) fs::create_directories(path.parent_path());
  const fs::path tmp = path.string() + ".tmp";
  try {
    {
      std::ofstream out(tmp, mode | std::ios::trunc);
      if (!out) throw std::runtime_error("cannot open " + tmp.string() + " for writing");
      write(out);
      out.flush();
      if (!out) throw std::runtime_error("cannot write " + tmp.string());
    }
    fs::rename(tmp, path);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

/// Writes `text` atomically (see writeFileAtomically).
inline void writeTextAtomically(const std::filesystem::path& path, const std::string& text) {
  writeFileAtomically(path, [&](std::ofstream& out) { out << text; });
}

}  // namespace fieldpath::common
