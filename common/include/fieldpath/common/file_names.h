#pragma once
/// What a file's name says about its format: the extension in lower case, as every reader and
/// writer compares it (`PART.STL`, `path.CL` and `x.Npy` are the files they look like).
#include <cctype>
#include <filesystem>
#include <string>

namespace fieldpath::common {

/// ASCII lower case (file extensions and keywords; locale-independent).
inline std::string lowerCase(std::string text) {
  for (char& c : text) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return text;
}

/// The extension with its dot, in lower case ("" when there is none).
inline std::string lowerExtension(const std::filesystem::path& file) {
  return lowerCase(file.extension().string());
}

}  // namespace fieldpath::common
