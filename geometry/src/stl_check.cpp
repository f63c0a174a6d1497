#include "stl_check.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/file_names.h"
#include "fieldpath/common/limits.h"

namespace fieldpath::geometry::detail {

using common::InputError;
using common::lowerExtension;

namespace {

/// assimp reads an ASCII STL cut after a facet (no `endsolid`) and a facet loop of 4 vertices
/// (some exporters' quads: half the face lost) without a word: every facet must have 3
/// `vertex` lines and the last solid must end with `endsolid`. Text after it that is no STL (an
/// exporter's `% exported ...` line) is left out of what assimp reads, where it made assimp
/// look for another solid; a `solid` after it is another solid of the file and must end too.
/// assimp takes keywords in lower case only: a keyword in capitals anywhere (`FACET NORMAL`,
/// `Vertex`, also after a lower-case `solid`) has the text read in lower case.
StlFeed checkAsciiStl(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  std::string line;
  std::size_t number = 0, facet_line = 0, vertices = 0, facets = 0;
  bool in_facet = false, capitals = false, in_solid = false, bad_normals = false;
  std::uintmax_t offset = 0, solid_end = 0;  // bytes read; the end of the last `endsolid` line
  std::size_t trailing_line = 0;             // the first line of text after it, if any
  // The first word of each line, lower case (a scan by hand: a million facets are 7 M lines).
  const auto firstWord = [&capitals](const std::string& text) {
    std::size_t b = 0;
    while (b < text.size() && std::isspace(static_cast<unsigned char>(text[b]))) ++b;
    std::size_t e = b;
    std::string w;
    while (e < text.size() && !std::isspace(static_cast<unsigned char>(text[e])) && e - b < 9) {
      const char c = text[e++];
      w += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      capitals = capitals || w.back() != c;
    }
    return w;
  };
  while (std::getline(in, line)) {
    ++number;
    offset += line.size() + 1;
    const bool was_capital = capitals;
    const std::string word = firstWord(line);
    if (word.empty()) continue;
    if (!in_solid && word != "solid") {  // text after the last `endsolid`: not STL
      capitals = was_capital;            // (its words are not keywords)
      if (trailing_line == 0) trailing_line = number;
      continue;
    }
    if (word == "solid") {
      in_solid = true;
      trailing_line = 0;
    } else if (word == "facet") {
      // `facet normal nx ny nz`, each a number strtod reads (nan and inf too, as assimp does)
      if (!bad_normals) {
        std::istringstream rest(line);
        std::string facet_word, normal_word, token;
        rest >> facet_word >> normal_word;
        int numbers = 0;
        while (rest >> token) {
          char* stop = nullptr;
          (void)std::strtod(token.c_str(), &stop);
          // (strtod reads MSVC's `-nan(ind)` too, assimp does not)
          const bool plain = token.find('(') == std::string::npos;
          numbers += stop == token.c_str() + token.size() && plain ? 1 : 100;
        }
        bad_normals = common::lowerCase(normal_word) != "normal" || numbers != 3;
      }
      ++facets;
      in_facet = true;
      facet_line = number;
      vertices = 0;
    } else if (word == "vertex") {
      ++vertices;
      // x y z: assimp's own word on a short line names no line ("Cannot parse string ...").
      // Each a whole number (`2x6` made assimp quote the file in a 1.6 kB line), and finite.
      std::size_t tokens = 0, at = line.find_first_of("xX") + 1;
      std::string bad;
      while (true) {
        at = line.find_first_not_of(" \t\r", at);
        if (at == std::string::npos) break;
        const std::size_t end = std::min(line.find_first_of(" \t\r", at), line.size());
        const std::string token = line.substr(at, end - at);
        char* stop = nullptr;
        const double value = std::strtod(token.c_str(), &stop);
        if (bad.empty() && (stop != token.c_str() + token.size() || !std::isfinite(value) ||
                            std::abs(value) > common::kMaxCoordinateMm))
          bad = token;
        ++tokens;
        at = end;
      }
      const std::string where = file.string() + ":" + std::to_string(number) + ": ";
      if (tokens != 3)
        throw InputError(where + "ASCII STL vertex line needs 3 numbers (x y z), it has " +
                         std::to_string(tokens));
      if (!bad.empty())
        throw InputError(where + "ASCII STL vertex: '" + bad.substr(0, 40) +
                         "' is not a finite number within +-1e6 mm");
    } else if (word == "endfacet") {
      if (in_facet && vertices != 3)
        throw InputError(file.string() + ":" + std::to_string(facet_line) +
                         ": ASCII STL facet with " + std::to_string(vertices) +
                         " vertices (an STL facet has 3)");
      in_facet = false;
    } else if (word == "endsolid") {
      in_solid = false;
      solid_end = std::min(offset, size);
    }
  }
  if (in_solid || solid_end == 0)
    throw InputError(file.string() + ": ASCII STL without `endsolid` at its end (truncated?)");
  StlFeed feed;
  feed.lower = capitals;
  feed.zero_normals = bad_normals;
  feed.copy = capitals || trailing_line > 0 || bad_normals;
  feed.length = trailing_line > 0 ? solid_end : size;
  feed.ascii = true;
  feed.triangles = facets;
  return feed;
}

/// Whether the first 64 KiB hold a NUL byte: binary (an ASCII STL has none; a binary one's
/// floats and attribute counts have many).
bool hasNulByte(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string head(1 << 16, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  return head.find('\0') != std::string::npos;
}

}  // namespace

std::string zeroFacetNormals(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    const std::size_t word = text.find_first_not_of(" \t\r", at);
    if (word < end && end - word >= 5 && common::lowerCase(text.substr(word, 5)) == "facet")
      out += "facet normal 0 0 0";
    else
      out.append(text, at, end - at);
    if (end < text.size()) out += '\n';
    at = end + 1;
  }
  return out;
}

/// A binary STL's size is fixed by its header: 84 bytes and 50 a triangle. One shorter than its
/// count says (truncated, or a count that lies) is refused saying so, where assimp would only say
/// it cannot tell ASCII from binary; up to 49 bytes more (an exporter's padding, less than a
/// triangle) are read past. A file that starts with `solid` and has no NUL byte is ASCII.
StlFeed checkStl(const std::filesystem::path& file, std::uintmax_t size) {
  if (lowerExtension(file) != ".stl") return {};
  std::ifstream in(file, std::ios::binary);
  unsigned char header[84] = {};
  in.read(reinterpret_cast<char*>(header), sizeof header);
  const std::size_t got = static_cast<std::size_t>(in.gcount());
  std::size_t first = 0;
  while (first < got && std::isspace(header[first])) ++first;
  std::string word = got >= first + 5
                         ? std::string(reinterpret_cast<const char*>(header) + first, 5)
                         : std::string();
  word = common::lowerCase(std::move(word));
  const auto binaryFits = [size](std::uintmax_t needed) {
    return size >= needed && size - needed < 50;
  };
  // assimp takes a binary STL of its exact size only: the padding is left out of its copy.
  const bool marked = got >= 3 && header[0] == 0xEF && header[1] == 0xBB && header[2] == 0xBF;
  const auto binaryFeed = [size, marked](std::uintmax_t needed) {
    StlFeed feed;
    feed.copy = size != needed || marked;
    feed.blank_mark = marked;
    feed.length = needed;
    feed.triangles = (needed - 84) / 50;
    return feed;
  };
  // A binary header's triangle count, and the size it gives (0 and 84 where there is none).
  const std::uint32_t count =
      got < 84 ? 0
               : std::uint32_t(header[80]) | std::uint32_t(header[81]) << 8 |
                     std::uint32_t(header[82]) << 16 | std::uint32_t(header[83]) << 24;
  const std::uintmax_t needed = 84 + 50 * std::uintmax_t(count);
  // A binary STL whose header starts so (CAD exports): its size matches its count.
  if (word == "solid" && got == 84 && binaryFits(needed)) return binaryFeed(needed);
  // Else ASCII, unless it holds a NUL byte: a binary one cut short or padded (it was read as
  // ASCII "without `endsolid`"); its counts are said below.
  if (word == "solid" && !hasNulByte(file)) {
    StlFeed feed = checkAsciiStl(file, size);
    feed.skip = first;
    feed.copy = feed.copy || first > 0;
    return feed;
  }
  // Text, not `solid ...`, that no binary STL's size fits: another format named .stl (an OBJ's
  // `v 0 0 0` read as a binary header said "811479840 triangles", an adversary's).
  if (!binaryFits(needed) && !hasNulByte(file)) {
    std::string start;
    for (std::size_t k = first; k < got && header[k] != '\n' && header[k] != '\r' && k < first + 40;
         ++k)
      start += std::isprint(header[k]) ? static_cast<char>(header[k]) : '?';
    throw InputError(file.string() + ": text that does not start with `solid`, as an ASCII STL " +
                     "does (it starts \"" + start +
                     "\"): not STL; another format named .stl? (OBJ starts `v`, PLY `ply`)");
  }
  if (got < 84)
    throw InputError(file.string() + ": binary STL of " + std::to_string(size) +
                     " bytes, shorter than its 84-byte header (truncated, or not STL)");
  if (!binaryFits(needed))
    throw InputError(file.string() + ": binary STL: its header says " + std::to_string(count) +
                     " triangles (" + std::to_string(needed) + " bytes), the file has " +
                     std::to_string(size) + " bytes (truncated, or not STL)");
  return binaryFeed(needed);
}

}  // namespace fieldpath::geometry::detail
