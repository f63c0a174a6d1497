#include "ply_check.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/file_names.h"

namespace fieldpath::geometry::detail {
namespace {

using common::InputError;

/// One property of an element as its bytes lie in a binary body: a scalar of `item_bytes`, or a
/// list: a count of `count_bytes` (signed or not), then that many items.
struct PlyProperty {
  int count_bytes = 0;  // 0: a scalar
  bool count_signed = false;
  int item_bytes = 0;
  std::string name;
};

struct PlyElement {
  std::string name;
  std::uintmax_t count = 0;
  std::vector<PlyProperty> properties;
};

/// Bytes of a PLY scalar type by the names the standard and assimp know; nothing for others
/// (assimp reads an unknown type as no bytes and the body goes out of step).
std::optional<int> typeBytes(const std::string& type) {
  if (type == "char" || type == "uchar" || type == "int8" || type == "uint8") return 1;
  if (type == "short" || type == "ushort" || type == "int16" || type == "uint16") return 2;
  if (type == "int" || type == "uint" || type == "int32" || type == "uint32" || type == "float" ||
      type == "float32")
    return 4;
  if (type == "double" || type == "float64") return 8;
  return std::nullopt;
}

bool isSignedType(const std::string& type) {
  return type == "char" || type == "int8" || type == "short" || type == "int16" || type == "int" ||
         type == "int32";
}

/// The words of a header line (spaces or tabs between them).
std::vector<std::string> wordsOf(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> words;
  for (std::string word; in >> word;) words.push_back(word);
  return words;
}

/// Reads a binary file forward from any byte, a MiB at a time: the list counts of a body.
class ByteReader {
 public:
  explicit ByteReader(const std::filesystem::path& file)
      : file_(file), in_(file, std::ios::binary), buffer_(std::size_t{1} << 20) {}

  /// The `bytes` bytes at `at` (the caller has checked that they lie in the file).
  const unsigned char* at(std::uintmax_t at, int bytes) {
    if (at < start_ || at + static_cast<std::uintmax_t>(bytes) > start_ + length_) {
      in_.clear();
      in_.seekg(static_cast<std::streamoff>(at));
      in_.read(reinterpret_cast<char*>(buffer_.data()),
               static_cast<std::streamsize>(buffer_.size()));
      start_ = at;
      length_ = static_cast<std::uintmax_t>(std::max<std::streamsize>(in_.gcount(), 0));
      if (length_ < static_cast<std::uintmax_t>(bytes))
        throw InputError(file_.string() + ": the file changed while it was read");
    }
    return buffer_.data() + (at - start_);
  }

 private:
  std::filesystem::path file_;
  std::ifstream in_;
  std::vector<unsigned char> buffer_;
  std::uintmax_t start_ = 0, length_ = 0;
};

/// A list's count as its bytes say, in the body's byte order; negative counts as -1.
long long listCount(const unsigned char* bytes, const PlyProperty& property, bool big_endian) {
  unsigned long long value = 0;
  for (int k = 0; k < property.count_bytes; ++k) {
    const int from = big_endian ? k : property.count_bytes - 1 - k;
    value = value << 8 | bytes[from];
  }
  if (property.count_signed && (bytes[big_endian ? 0 : property.count_bytes - 1] & 0x80)) return -1;
  return static_cast<long long>(value);
}

/// The corners of a whole face that the bytes from `at` hold where the body's last element is
/// `face` (a list of 3 to 64 items that are each an index of the file's vertices), and where it
/// ends. Nothing else.
std::optional<std::pair<long long, std::uintmax_t>> faceAt(ByteReader& reader, std::uintmax_t size,
                                                           std::uintmax_t at,
                                                           const std::vector<PlyElement>& elements,
                                                           bool big_endian) {
  if (elements.empty() || elements.back().name != "face") return std::nullopt;
  std::uintmax_t vertices = 0;
  for (const PlyElement& element : elements)
    if (element.name == "vertex") vertices = element.count;
  std::optional<long long> corners;
  for (const PlyProperty& p : elements.back().properties) {
    if (p.count_bytes == 0) {
      if (static_cast<std::uintmax_t>(p.item_bytes) > size - at) return std::nullopt;
      at += static_cast<std::uintmax_t>(p.item_bytes);
      continue;
    }
    if (static_cast<std::uintmax_t>(p.count_bytes) > size - at) return std::nullopt;
    const long long n = listCount(reader.at(at, p.count_bytes), p, big_endian);
    at += static_cast<std::uintmax_t>(p.count_bytes);
    if (n < 3 || n > 64 || p.item_bytes > 4 ||
        static_cast<std::uintmax_t>(n * p.item_bytes) > size - at)
      return std::nullopt;
    const PlyProperty index{p.item_bytes, false, 0, p.name};  // an item read as a count is
    for (long long k = 0; k < n; ++k, at += static_cast<std::uintmax_t>(p.item_bytes))
      if (static_cast<std::uintmax_t>(listCount(reader.at(at, p.item_bytes), index, big_endian)) >=
          vertices)
        return std::nullopt;
    if (p.name == "vertex_indices" || p.name == "vertex_index") corners = n;
  }
  if (!corners) return std::nullopt;
  return std::pair{*corners, at};
}

/// The corners of the first of the whole faces that the bytes after the body hold, up to the
/// file's end or to NUL padding (a file whose header declared one face short: its last face's
/// bytes, indices under 127, passed for padding and the face was dropped, a tool inside a closed
/// cylinder reading clear). Nothing where they are not faces to the end: a line of text after
/// the body (`\n# end of mesh data #\n` read as a face of 10 corners with 1-byte indices, the
/// rest as none: a reviewer's) is padding.
std::optional<long long> faceAfterBody(ByteReader& reader, std::uintmax_t size, std::uintmax_t at,
                                       const std::vector<PlyElement>& elements, bool big_endian) {
  std::optional<long long> first;
  while (at < size) {
    const auto face = faceAt(reader, size, at, elements, big_endian);
    if (!face) break;
    if (!first) first = face->first;
    at = face->second;
  }
  for (; first && at < size; ++at)
    if (*reader.at(at, 1) != 0) return std::nullopt;
  return first;
}

/// Walks a binary body from `at` element by element as the header declares it: every list count
/// read (none negative), every byte within the file. Where it does not fit, assimp read past the
/// file's end (a SEGV found by CI's smoke fuzz) or took counts from float bytes.
/// Returns the header's bytes where assimp must read it with CRLF line ends (checkPly), else 0.
std::uintmax_t walkBinaryBody(const std::filesystem::path& file, std::uintmax_t size,
                              std::uintmax_t at, const std::vector<PlyElement>& elements,
                              bool big_endian, bool crlf_header) {
  ByteReader reader(file);
  // assimp 5.2 skips a line end after `end_header\n`: a body whose first byte is 0x0A (1 in 256
  // of binary files: the first float's lowest byte) is read one byte late ("no triangles", or
  // counts from the wrong bytes: a reviewer's file). After `end_header\r\n` it is read right:
  // the loader is given the header so (a valid file was refused for its first float: a CAM
  // engineer's shroud).
  const std::uintmax_t crlf_bytes = at < size && !crlf_header && *reader.at(at, 1) == '\n' ? at : 0;
  // `instance` counted from 0, said from 1.
  const auto cutShort = [&](const PlyElement& element, std::uintmax_t instance) {
    throw InputError(file.string() + ": binary PLY: the body ends inside " + element.name + " " +
                     std::to_string(instance + 1) + " of the " + std::to_string(element.count) +
                     " its header declares (" + std::to_string(size) +
                     " bytes: truncated, or the header's counts or types are wrong)");
  };
  for (const PlyElement& element : elements) {
    const bool lists = std::any_of(element.properties.begin(), element.properties.end(),
                                   [](const PlyProperty& p) { return p.count_bytes > 0; });
    if (!lists) {
      // Fixed-size instances: one step (no overflow: count <= size, stride <= 8 * properties).
      std::uintmax_t stride = 0;
      for (const PlyProperty& p : element.properties)
        stride += static_cast<std::uintmax_t>(p.item_bytes);
      if (stride > 0 && element.count > (size - at) / stride)
        cutShort(element, (size - at) / stride);
      at += stride * element.count;
      continue;
    }
    for (std::uintmax_t instance = 0; instance < element.count; ++instance)
      for (const PlyProperty& p : element.properties) {
        if (p.count_bytes == 0) {
          if (static_cast<std::uintmax_t>(p.item_bytes) > size - at) cutShort(element, instance);
          at += static_cast<std::uintmax_t>(p.item_bytes);
          continue;
        }
        if (static_cast<std::uintmax_t>(p.count_bytes) > size - at) cutShort(element, instance);
        const long long n = listCount(reader.at(at, p.count_bytes), p, big_endian);
        at += static_cast<std::uintmax_t>(p.count_bytes);
        if (n < 0)
          throw InputError(file.string() + ": binary PLY: " + element.name + " " +
                           std::to_string(instance + 1) + " has a negative list count");
        if (static_cast<std::uintmax_t>(n) >
            (size - at) / static_cast<std::uintmax_t>(p.item_bytes))
          cutShort(element, instance);
        at += static_cast<std::uintmax_t>(n) * static_cast<std::uintmax_t>(p.item_bytes);
      }
  }
  // More than a line end after the body: the header's counts are short of it (assimp read the
  // declared faces and dropped the rest: a sphere with 400 faces left out read clear where it
  // collides, a helper's file), or the file was joined with something else.
  // Padding is read past (NUL bytes to a block, white space, a DOS end-of-file 0x1A, a line of
  // text: exporters write them, a reviewer's files); bytes of data are not.
  const std::uintmax_t body_end = at;
  if (const auto extra = faceAfterBody(reader, size, body_end, elements, big_endian))
    throw InputError(file.string() + ": binary PLY: " + std::to_string(size - body_end) +
                     " byte(s) after the body its header declares read as another face (" +
                     std::to_string(*extra) +
                     " corners, each a vertex of the file): the header's face count is short of "
                     "the data");
  for (; at < size; ++at) {
    const unsigned char c = *reader.at(at, 1);
    if (!(c == 0 || c == 0x1A || c == '\n' || c == '\r' || c == '\t' || (c >= 0x20 && c < 0x7F)))
      throw InputError(file.string() + ": binary PLY: " + std::to_string(size - body_end) +
                       " byte(s) after the body its header declares, not padding (the header's "
                       "counts are short of the data, or the file was joined with another)");
  }
  return crlf_bytes;
}

/// What a mesh needs of the elements, and what assimp would drop without a word (a helper's
/// files): vertices with x, y and z (without z, read as flat), no triangle strips (left out:
/// 140 open edges and a clearance of 9.21 mm where the same sphere as STL reads 1.85).
template <typename Refuse>
void checkMeshElements(const std::vector<PlyElement>& elements, const Refuse& refuse) {
  for (const PlyElement& element : elements) {
    if (element.name == "tristrips" && element.count > 0)
      refuse("triangle strips (element tristrips) are not read: save the mesh with faces");
    if (element.name != "vertex") continue;
    for (const char* axis : {"x", "y", "z"})
      if (std::none_of(
              element.properties.begin(), element.properties.end(),
              [axis](const PlyProperty& p) { return p.name == axis && p.count_bytes == 0; }))
        refuse(std::string("element vertex has no property ") + axis);
  }
}

/// An ASCII body holds one line per element instance: assimp reads a file with fewer (or more)
/// lines silently, faces dropped or made up at the end.
void countAsciiLines(const std::filesystem::path& file, std::ifstream& in, double declared) {
  double lines = 0.0;
  for (std::string line; std::getline(in, line);)
    for (const char c : line)
      if (!std::isspace(static_cast<unsigned char>(c))) {
        ++lines;
        break;
      }
  if (lines != declared)
    throw InputError(file.string() + ": ASCII PLY: its header declares " +
                     std::to_string(static_cast<long long>(declared)) +
                     " element lines, the file has " +
                     std::to_string(static_cast<long long>(lines)) +
                     " (truncated, or the header's counts are wrong)");
}

/// The whitespace-separated words of `line`.
std::vector<std::string_view> valuesOf(std::string_view line) {
  std::vector<std::string_view> out;
  for (std::size_t at = 0;;) {
    at = line.find_first_not_of(" \t\r\v\f", at);
    if (at == std::string_view::npos) return out;
    const std::size_t end = std::min(line.find_first_of(" \t\r\v\f", at), line.size());
    out.push_back(line.substr(at, end - at));
    at = end;
  }
}

/// An ASCII body's lines against the header's properties, once their count is right: each line
/// holds one value a scalar and, a list, its count then that many values. assimp read a vertex
/// line short of a value or a face line short of a corner without a word, taking the next line's
/// values (a mesh silently wrong: walls 0.08 mm thick, a shell opened; an adversary's files).
/// The vertices' x, y and z must be finite numbers, a face's corners vertices of the file.
void walkAsciiValues(const std::filesystem::path& file, std::ifstream& in,
                     const std::vector<PlyElement>& elements, std::size_t header_lines) {
  std::uintmax_t vertices = 0;
  for (const PlyElement& element : elements)
    if (element.name == "vertex") vertices = element.count;
  std::size_t number = header_lines;
  std::string line;
  for (const PlyElement& element : elements) {
    const bool is_vertex = element.name == "vertex", is_face = element.name == "face";
    for (std::uintmax_t instance = 0; instance < element.count; ++instance) {
      std::vector<std::string_view> values;
      while (values.empty() && std::getline(in, line)) {
        ++number;
        values = valuesOf(line);
      }
      const std::string where = file.string() + ":" + std::to_string(number) +
                                ": ASCII PLY: " + element.name + " " + std::to_string(instance + 1);
      std::size_t at = 0;
      const auto number_at = [&](std::size_t k, double& value) {
        std::string_view text = values[k];
        if (text.size() > 1 && text.front() == '+') text.remove_prefix(1);  // (as strtod reads)
        const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
        return ec == std::errc() && end == text.data() + text.size();
      };
      // The values the properties take here (a list's by its count), counted as they are read:
      // unknown (`counted` false) where a list's count lies past the line's end.
      std::size_t taken = 0;
      bool counted = true;
      for (const PlyProperty& p : element.properties) {
        double value = 0.0;
        ++taken;
        if (at >= values.size()) {  // short: said below with the count
          counted = p.count_bytes == 0 && counted;
          if (!counted) break;
          continue;
        }
        if (!number_at(at, value))
          throw InputError(where + ": '" + std::string(values[at].substr(0, 20)) +
                           "' is not a number (" + p.name + ")");
        ++at;
        if (p.count_bytes == 0) {
          if (is_vertex && (p.name == "x" || p.name == "y" || p.name == "z") &&
              !std::isfinite(value))
            throw InputError(where + ": " + p.name + " is not finite");
          continue;
        }
        if (!(value >= 0.0) || value != std::floor(value) || value > double(values.size()))
          throw InputError(where + ": list " + p.name + " has a count of " +
                           std::string(values[at - 1].substr(0, 20)) + " (the line holds " +
                           std::to_string(values.size()) + " values)");
        const auto n = static_cast<std::size_t>(value);
        taken += n;
        const bool corners = is_face && (p.name == "vertex_indices" || p.name == "vertex_index");
        for (std::size_t k = 0; k < n && at < values.size(); ++k, ++at) {
          if (!number_at(at, value))
            throw InputError(where + ": '" + std::string(values[at].substr(0, 20)) +
                             "' is not a number (" + p.name + ")");
          if (corners && !(value >= 0.0 && value < double(vertices) && value == std::floor(value)))
            throw InputError(where + " names vertex " + std::string(values[at].substr(0, 20)) +
                             ", the file has " + std::to_string(vertices) + " (numbered from 0)");
        }
      }
      if (!counted || taken != values.size())
        throw InputError(where + " has " + std::to_string(values.size()) + " values" +
                         (counted ? " where its header's properties take " + std::to_string(taken)
                                  : std::string(", fewer than its header's properties take")) +
                         " (a value missing or one too many: the mesh would be read wrong from "
                         "there on)");
    }
  }
}

}  // namespace

/// The header must be of the standard's grammar within 64 KiB: `ply`, one `format` line of the
/// three, `element NAME COUNT` with counts that fit in the file (every instance of an element
/// with properties takes at least one byte), `property TYPE NAME` or `property list TYPE TYPE
/// NAME` of known types after an element, `comment ...`, `obj_info ...`, and `end_header` alone
/// on its line. Then the body is checked against it.
std::uintmax_t checkPly(const std::filesystem::path& file, std::uintmax_t size) {
  std::ifstream in(file, std::ios::binary);
  char magic[3] = {};
  in.read(magic, 3);
  const bool looks_ply = in.gcount() == 3 && std::string(magic, 3) == "ply";
  if (!looks_ply && common::lowerExtension(file) != ".ply") return 0;  // assimp decides
  in.seekg(0);
  const auto refuse = [&](std::size_t number, const std::string& why) {
    throw InputError(file.string() + ":" + std::to_string(number) + ": PLY header: " + why);
  };
  std::string line;
  std::uintmax_t read = 0;
  std::size_t number = 0;
  bool format = false, ascii = false, big_endian = false;
  double lines_declared = 0.0;  // an ASCII PLY holds one line per element instance
  std::vector<PlyElement> elements;
  while (std::getline(in, line)) {
    ++number;
    read += line.size() + 1;
    if (read > (std::uintmax_t{64} << 10)) break;
    const bool crlf = !line.empty() && line.back() == '\r';
    if (crlf) line.pop_back();
    const std::vector<std::string> words = wordsOf(line);
    const std::string word = words.empty() ? std::string() : words[0];
    if (number == 1) {
      if (line != "ply") refuse(number, "the first line must be `ply`");
    } else if (word == "format") {
      const std::string kind = words.size() > 1 ? words[1] : "";
      if (format || words.size() != 3 || words[2] != "1.0" ||
          (kind != "ascii" && kind != "binary_little_endian" && kind != "binary_big_endian"))
        refuse(number, "expected one `format ascii|binary_little_endian|binary_big_endian 1.0`");
      format = true;
      ascii = kind == "ascii";
      big_endian = kind == "binary_big_endian";
    } else if (word == "element") {
      double count = -1;
      if (words.size() == 3) {
        std::istringstream(words[2]) >> count;
        if (words[2].find_first_not_of("0123456789") != std::string::npos) count = -1;
      }
      if (count < 0 || count > static_cast<double>(size))
        refuse(number, "element count does not fit in the file: " + line.substr(0, 60));
      lines_declared += count;
      elements.push_back({words[1], static_cast<std::uintmax_t>(count), {}});
    } else if (word == "property") {
      if (elements.empty()) refuse(number, "a property before any element");
      PlyProperty property;
      const bool list = words.size() == 5 && words[1] == "list";
      const std::string item = list ? words[3] : words.size() == 3 ? words[1] : "";
      const auto item_bytes = typeBytes(item);
      const auto count_bytes = list ? typeBytes(words[2]) : std::optional<int>(0);
      if (!item_bytes || !count_bytes ||
          (list && (words[2] == "float" || words[2] == "float32" || words[2] == "double" ||
                    words[2] == "float64")))
        refuse(number,
               "expected `property TYPE NAME` or `property list COUNT-TYPE TYPE NAME` "
               "(types char uchar short ushort int uint float double, or int8 ... float64; a "
               "list's count an integer type): " +
                   line.substr(0, 60));
      property.item_bytes = *item_bytes;
      property.count_bytes = *count_bytes;
      property.count_signed = list && isSignedType(words[2]);
      property.name = words.back();
      elements.back().properties.push_back(property);
    } else if (word == "end_header") {
      // The data starts on the byte after its line end: `end_header` and a vertical tab read as
      // the header's end here while assimp took the body elsewhere and read past the file
      // (SEGV, found by CI's smoke fuzz of fuzz_mesh).
      if (line != "end_header") refuse(number, "`end_header` must be alone on its line");
      if (!format) refuse(number, "no `format` line");
      checkMeshElements(elements, [&](const std::string& why) { refuse(number, why); });
      if (ascii) {
        const std::streampos body = in.tellg();
        countAsciiLines(file, in, lines_declared);
        in.clear();
        in.seekg(body);
        walkAsciiValues(file, in, elements, number);
        return 0;
      }
      // (No line end after `end_header`: the body starts past the file's end.)
      return walkBinaryBody(file, size, std::min(read, size), elements, big_endian, crlf);
    } else if (word != "comment" && word != "obj_info") {
      refuse(number, "unexpected line '" + line.substr(0, 40) + "'");
    }
  }
  throw InputError(file.string() + ": PLY header without `end_header` in its first 64 KiB");
}

}  // namespace fieldpath::geometry::detail
