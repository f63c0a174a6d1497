/// Postures as NumPy `.npy` (DESIGN.md command line): float32 or float64, either byte order,
/// shape N×6 (x y z i j k) or N×7 (+ spindle angle, rad), C or Fortran order (written: <f8, C
/// order). Anything else is refused with one line naming the file; a bad row names the row.
#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <optional>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/geometry/cl_file.h"
#include "path_chunks.h"
#include "path_text.h"

namespace fieldpath::geometry {
namespace {

using namespace detail;
using common::InputError;

constexpr char kMagic[] = "\x93NUMPY";
constexpr std::size_t kMagicSize = 6;

[[noreturn]] void bad(const std::filesystem::path& file, const std::string& why) {
  throw InputError(file.string() + ": " + why);
}

/// The text after `'key':` in a NumPy header dict, up to the end of the value (a quoted string,
/// a parenthesised tuple, or a bare word).
std::optional<std::string> headerValue(std::string_view header, std::string_view key) {
  for (const char quote : {'\'', '"'}) {
    const std::string quoted_key = std::string(1, quote) + std::string(key) + quote;
    auto at = header.find(quoted_key);
    if (at == std::string_view::npos) continue;
    at = header.find(':', at + quoted_key.size());
    if (at == std::string_view::npos) return std::nullopt;
    std::string_view rest = trimmed(header.substr(at + 1));
    if (rest.empty()) return std::nullopt;
    if (rest.front() == '\'' || rest.front() == '"') {
      const auto end = rest.find(rest.front(), 1);
      if (end == std::string_view::npos) return std::nullopt;
      return std::string(rest.substr(1, end - 1));
    }
    if (rest.front() == '(') {
      const auto end = rest.find(')');
      if (end == std::string_view::npos) return std::nullopt;
      return std::string(rest.substr(1, end - 1));
    }
    const auto end = rest.find_first_of(",}");
    return std::string(trimmed(rest.substr(0, end)));
  }
  return std::nullopt;
}

/// "(N, 6)" → {N, 6}; throws for anything but two non-negative integers.
std::vector<std::uint64_t> parseShape(const std::filesystem::path& file, const std::string& text) {
  std::vector<std::uint64_t> shape;
  std::string_view rest(text);
  while (!trimmed(rest).empty()) {
    const auto comma = rest.find(',');
    std::string_view item = trimmed(rest.substr(0, comma));
    if (!item.empty() && (item.back() == 'L' || item.back() == 'l'))  // Python 2's long: (243L, 6L)
      item.remove_suffix(1);
    if (!item.empty()) {
      std::uint64_t value = 0;
      const auto [end, ec] = std::from_chars(item.data(), item.data() + item.size(), value);
      if (ec != std::errc() || end != item.data() + item.size())
        bad(file, "npy shape (" + text + ") is not a list of sizes");
      shape.push_back(value);
    }
    if (comma == std::string_view::npos) break;
    rest = rest.substr(comma + 1);
  }
  return shape;
}

/// A checked `.npy` posture array: where its rows start in the mapped file and their layout.
struct NpyRows {
  const char* data = nullptr;
  std::uint64_t rows = 0, columns = 0;
  std::size_t item = 0;  ///< 4 (float32) or 8 (float64)
  bool big_endian = false;  ///< `>f4`, `>f8` (numpy reads both byte orders)
  bool fortran =
      false;  ///< column after column (`fortran_order: True`, e.g. a transposed array saved)

  /// Element (r, c) as a double.
  double at(std::uint64_t r, std::uint64_t c) const {
    const char* p = data + (fortran ? c * rows + r : r * columns + c) * item;
    char b[8];
    std::memcpy(b, p, item);
    if (big_endian) std::reverse(b, b + item);
    if (item == 8) {
      double v;
      std::memcpy(&v, b, 8);
      return v;
    }
    float f;
    std::memcpy(&f, b, 4);
    return f;
  }
};

NpyRows checkedRows(const std::filesystem::path& file, std::string_view bytes) {
  const std::uint64_t file_size = bytes.size();
  if (file_size < 10 || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0)
    bad(file, "not a NumPy .npy file (no \\x93NUMPY magic)");
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(bytes[i]); };
  const int major = byte(6);
  std::uint64_t header_size = 0, offset = 10;
  if (major == 1) {
    header_size = byte(8) | (static_cast<std::uint64_t>(byte(9)) << 8);
  } else if (major == 2 || major == 3) {
    if (file_size < 12) bad(file, "truncated npy header");
    for (int b = 0; b < 4; ++b) header_size |= static_cast<std::uint64_t>(byte(8 + b)) << (8 * b);
    offset = 12;
  } else {
    bad(file, "npy format version " + std::to_string(major) + " is not supported (1, 2 or 3)");
  }
  if (header_size > 65536 || offset + header_size > file_size) bad(file, "truncated npy header");
  const std::string_view header = bytes.substr(offset, header_size);

  const auto descr = headerValue(header, "descr");
  const auto fortran = headerValue(header, "fortran_order");
  const auto shape_text = headerValue(header, "shape");
  if (!descr || !fortran || !shape_text)
    bad(file, "npy header lacks descr, fortran_order or shape");
  // As numpy.load takes them: a byte order (< = > |, none: this machine's, little) and a float
  // type by code (f4 f8 f d) or name (float32 float64 single double).
  std::size_t item = 0;
  const std::string& type = *descr;
  const bool ordered =
      !type.empty() && std::string_view("<=>|").find(type[0]) != std::string_view::npos;
  const std::string_view code = std::string_view(type).substr(ordered ? 1 : 0);
  if (code == "f4" || code == "f" || code == "float32" || code == "single")
    item = 4;
  else if (code == "f8" || code == "d" || code == "float64" || code == "double")
    item = 8;
  else
    bad(file, "npy dtype '" + *descr + "': expected float32 or float64 (<f4, <f8, >f4, >f8)");
  if (*fortran != "False" && *fortran != "True")
    bad(file, "npy fortran_order '" + *fortran + "': expected False or True");
  const std::vector<std::uint64_t> shape = parseShape(file, *shape_text);
  if (shape.size() != 2 || (shape[1] != 6 && shape[1] != 7))
    bad(file, "npy shape (" + *shape_text + "): expected N×6 (x y z i j k) or N×7 (+ spindle)");
  const std::uint64_t rows = shape[0], columns = shape[1];
  if (rows == 0) bad(file, "no postures (shape (0, " + std::to_string(columns) + "))");
  const std::uint64_t data_size = file_size - offset - header_size;
  if (rows > data_size / (columns * item))  // also where rows × columns × item overflows
    bad(file, "npy data is " + std::to_string(data_size) + " bytes, shape (" +
                  std::to_string(rows) + ", " + std::to_string(columns) +
                  ") needs more (truncated file, or a shape that lies)");
  if (rows * columns * item != data_size)
    bad(file, "npy data is " + std::to_string(data_size) + " bytes, shape (" +
                  std::to_string(rows) + ", " + std::to_string(columns) + ") needs " +
                  std::to_string(rows * columns * item) + " (trailing bytes)");
  return {bytes.data() + offset + header_size,
          rows,
          columns,
          item,
          ordered && type[0] == '>',
          *fortran == "True"};
}

/// Row r as a posture, checked like a `.cl` line ("FILE: row R: ...").
Posture rowPosture(const std::filesystem::path& file, const NpyRows& a, std::uint64_t r) {
  double v[7];
  for (std::size_t c = 0; c < a.columns; ++c) {
    v[c] = a.at(r, c);
    if (!std::isfinite(v[c]))
      bad(file, "row " + std::to_string(r) + ", column " + std::to_string(c) +
                    " (both counted from 0, as numpy does): not finite");
  }
  const auto where = [&] { return file.string() + ": row " + std::to_string(r) + " (from 0)"; };
  return checkedPosture(v, a.columns, where);
}

/// Rows per parallel piece: about `chunk_bytes` of the file.
std::uint64_t rowsPerChunk(const NpyRows& a, const PathReadOptions& options) {
  return std::max<std::uint64_t>(1, options.chunk_bytes / (a.columns * a.item));
}

}  // namespace

PathFile readNpyPath(const std::filesystem::path& file, const PathReadOptions& options) {
  const MappedFile mapped(file);
  const NpyRows a = checkedRows(file, mapped.text());
  PathFile path;
  path.file = file;
  path.rows = true;
  path.postures.resize(a.rows);
  path.lines.resize(a.rows);
  const std::uint64_t per = rowsPerChunk(a, options);
  forEachChunk((a.rows + per - 1) / per, options.threads, [&](std::size_t i) {
    for (std::uint64_t r = i * per; r < std::min(a.rows, (i + 1) * per); ++r) {
      path.postures[r] = rowPosture(file, a, r);
      path.lines[r] = r;
    }
  });
  path.blocks.push_back({PathBlock::Kind::Pass, 0, path.postures.size()});
  return path;
}

namespace detail {

std::size_t scanNpy(const std::filesystem::path& file, const PathReadOptions& options,
                    const PostureChunkSink& sink) {
  const MappedFile mapped(file);
  const NpyRows a = checkedRows(file, mapped.text());
  const std::uint64_t per = rowsPerChunk(a, options);
  const std::size_t chunks = (a.rows + per - 1) / per;
  if (sink.begin) sink.begin(chunks);
  forEachChunk(chunks, options.threads, [&](std::size_t i) {
    const std::uint64_t begin = i * per, end = std::min(a.rows, begin + per);
    std::vector<CompactPosture> out(end - begin);
    for (std::uint64_t r = begin; r < end; ++r) out[r - begin] = compact(rowPosture(file, a, r));
    sink.chunk(i, out);
  });
  return a.rows;
}

}  // namespace detail

void writeNpyFile(const std::filesystem::path& file, std::span<const Posture> postures) {
  bool spindle = false;
  for (const Posture& p : postures) spindle = spindle || p.has_spindle;
  const std::size_t columns = spindle ? 7 : 6;
  std::string header = "{'descr': '<f8', 'fortran_order': False, 'shape': (" +
                       std::to_string(postures.size()) + ", " + std::to_string(columns) + "), }";
  // Pad with spaces so that the data starts on a 64-byte boundary; the header ends with '\n'.
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes(kMagic, kMagicSize);
  bytes += '\x01';
  bytes += '\x00';
  bytes += static_cast<char>(header.size() & 0xff);
  bytes += static_cast<char>((header.size() >> 8) & 0xff);
  bytes += header;
  for (const Posture& p : postures) {
    const double values[] = {p.tip_mm.x(), p.tip_mm.y(), p.tip_mm.z(), p.axis.x(),
                             p.axis.y(),   p.axis.z(),   p.spindle_rad};
    bytes.append(reinterpret_cast<const char*>(values), columns * sizeof(double));
  }
  common::writeFileAtomically(
      file,
      [&](std::ostream& out) {
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
      },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::geometry
