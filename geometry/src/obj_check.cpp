#include "obj_check.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <iterator>
#include <string_view>
#include <system_error>

namespace fieldpath::geometry::detail {
namespace {

/// The first word of `line` from `at` on (blanks skip), `at` moved past it.
std::string_view nextWord(std::string_view line, std::size_t& at) {
  at = line.find_first_not_of(" \t\r\v\f", at);
  if (at == std::string_view::npos) return {};
  const std::size_t end = std::min(line.find_first_of(" \t\r\v\f", at), line.size());
  const std::string_view word = line.substr(at, end - at);
  at = end;
  return word;
}

/// Reads the file's statements: a line and those it continues (a `\` at its end), comments cut.
class Statements {
 public:
  explicit Statements(const std::filesystem::path& file) : in_(file, std::ios::binary) {}
  /// The next statement, false at the end; `line` is its first line's number.
  bool next(std::string& text, std::size_t& line) {
    text.clear();
    std::string part;
    bool any = false;
    while (std::getline(in_, part)) {
      ++number_;
      if (!any) line = number_;
      any = true;
      if (const std::size_t hash = part.find('#'); hash != std::string::npos) part.erase(hash);
      while (!part.empty() && (part.back() == '\r' || part.back() == ' ' || part.back() == '\t'))
        part.pop_back();
      if (part.empty() || part.back() != '\\') {
        text += part;
        return true;
      }
      part.pop_back();
      text += part;
      text += ' ';
    }
    return any;
  }

 private:
  std::ifstream in_;
  std::size_t number_ = 0;
};

}  // namespace

std::string objFault(const std::filesystem::path& file) {
  // Two passes: the vertex count first (a positive index may name a vertex given later, as
  // assimp reads it), then the statements with the count read so far for negative ones.
  std::int64_t total = 0;
  std::string text;
  std::size_t line = 0;
  {
    Statements statements(file);
    while (statements.next(text, line)) {
      std::size_t at = 0;
      total += nextWord(text, at) == "v";
    }
  }
  if (total == 0)  // (comments only, or another format saved as .obj: an STL's text, a binary)
    return file.string() + ": no vertex (`v x y z` lines): not an OBJ mesh";
  Statements statements(file);
  std::int64_t so_far = 0;
  while (statements.next(text, line)) {
    const std::string where = file.string() + ":" + std::to_string(line) + ": ";
    std::size_t at = 0;
    const std::string_view key = nextWord(text, at);
    if (key == "v") {
      ++so_far;
      for (const char* axis : {"x", "y", "z"}) {
        const std::string_view word = nextWord(text, at);
        const std::string_view digits =
            word.size() > 1 && word.front() == '+' ? word.substr(1) : word;  // as strtod reads
        double value = 0.0;
        const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
        if (word.empty())
          return where + "vertex " + std::to_string(so_far) + " has no " + axis +
                 " (a vertex is `v x y z`)";
        if (ec != std::errc() || end != digits.data() + digits.size() || !std::isfinite(value))
          return where + "vertex " + std::to_string(so_far) + ": " + axis + " '" +
                 std::string(word.substr(0, 20)) + "' is not a finite number";
      }
      continue;
    }
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
      return where + "face index '" + std::string(index_text.substr(0, 20)) + "': " + why +
             " (the file has " + std::to_string(total) + " vertices)";
    }
  }
  return {};
}

std::string objStatementFault(const std::filesystem::path& file) {
  // The OBJ specification's statements of polygonal geometry, grouping, display and rendering
  // (`fo`: an old face; `csh`: a shell command, read past as assimp does).
  static constexpr std::string_view kPolygonal[] = {
      "v",   "vt",    "vn",       "vp",       "f",          "fo",        "l",      "p",
      "g",   "o",     "s",        "mg",       "usemtl",     "mtllib",    "usemap", "maplib",
      "lod", "bevel", "c_interp", "d_interp", "shadow_obj", "trace_obj", "csh"};
  static constexpr std::string_view kFreeForm[] = {
      "cstype", "deg",  "bmat", "step", "curv", "curv2", "surf",  "parm",
      "trim",   "hole", "scrv", "sp",   "end",  "con",   "ctech", "stech"};
  Statements statements(file);
  std::string text;
  std::size_t line = 0;
  while (statements.next(text, line)) {
    std::size_t at = 0;
    const std::string_view key = nextWord(text, at);
    if (key.empty() ||
        std::find(std::begin(kPolygonal), std::end(kPolygonal), key) != std::end(kPolygonal))
      continue;
    const std::string where =
        file.string() + ":" + std::to_string(line) + ": `" + std::string(key.substr(0, 20)) + "`";
    if (std::find(std::begin(kFreeForm), std::end(kFreeForm), key) != std::end(kFreeForm))
      return where +
             ": free-form geometry (curves and surfaces) is not read: export the part as a "
             "polygon mesh (triangles)";
    if (key == "call")
      return where + ": another file's statements are not read: export the part as one mesh";
    return where + ": not an OBJ statement (v, vt, vn, f, l, g, o, s, usemtl, ...)";
  }
  return {};
}

}  // namespace fieldpath::geometry::detail
