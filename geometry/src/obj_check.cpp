#include "obj_check.h"

#include <charconv>
#include <cstdint>
#include <fstream>
#include <string_view>
#include <system_error>

namespace fieldpath::geometry::detail {
namespace {

/// The first word of `line` from `at` on (blanks skip), `at` moved past it.
std::string_view nextWord(std::string_view line, std::size_t& at) {
  at = line.find_first_not_of(" \t\r", at);
  if (at == std::string_view::npos) return {};
  const std::size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
  const std::string_view word = line.substr(at, end - at);
  at = end;
  return word;
}

}  // namespace

std::string objFaceFault(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  // Two passes: the vertex count first (a positive index may name a vertex given later, as
  // assimp reads it), then the faces with the count of vertices read so far for negative ones.
  std::int64_t total = 0;
  std::string line;
  while (std::getline(in, line))
    if (line.size() > 1 && line[0] == 'v' && (line[1] == ' ' || line[1] == '\t')) ++total;
  in.clear();
  in.seekg(0);
  std::int64_t so_far = 0;
  for (std::size_t number = 1; std::getline(in, line); ++number) {
    std::string_view text(line);
    if (const std::size_t hash = text.find('#'); hash != std::string_view::npos)
      text = text.substr(0, hash);
    std::size_t at = 0;
    const std::string_view key = nextWord(text, at);
    if (key == "v") ++so_far;
    if (key != "f") continue;
    for (std::string_view word = nextWord(text, at); !word.empty(); word = nextWord(text, at)) {
      const std::string_view index_text = word.substr(0, word.find('/'));  // v[/vt[/vn]]
      std::int64_t index = 0;
      const auto [end, ec] =
          std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
      std::string why;
      if (ec != std::errc() || end != index_text.data() + index_text.size())
        why = "not an integer";
      else if (index == 0)
        why = "0 (OBJ counts vertices from 1)";
      else if (index > total)
        why = "past the last vertex";
      else if (index < 0 && -index > so_far)
        why = "counts back past the first vertex (" + std::to_string(so_far) + " read so far)";
      if (why.empty()) continue;
      return file.string() + ":" + std::to_string(number) + ": face index '" +
             std::string(index_text) + "': " + why + " (the file has " + std::to_string(total) +
             " vertices)";
    }
  }
  return {};
}

}  // namespace fieldpath::geometry::detail
