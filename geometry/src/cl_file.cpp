#include "fieldpath/geometry/cl_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <vector>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_names.h"
#include "fieldpath/geometry/units.h"

#include "path_chunks.h"
#include "path_text.h"

namespace fieldpath::geometry {
namespace {

using namespace detail;
using common::InputError;

/// What a whole-line `.cl` comment says about blocks.
enum class Marker { None, Pass, Link };

Marker markerOf(std::string_view comment) {
  std::string word;
  for (char c : trimmed(comment)) {
    if (!std::isalpha(static_cast<unsigned char>(c))) break;
    word += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return word == "pass" ? Marker::Pass : word == "link" ? Marker::Link : Marker::None;
}

bool isLimitNote(std::string_view comment) {
  const std::string_view text = trimmed(comment);
  return text.substr(0, 5) == "limit";
}

}  // namespace

std::string PathFile::where(std::size_t i) const {
  if (i >= lines.size()) return file.string();
  // Rows as numpy counts them, from 0, which is said (a user counting from 1 read one off).
  return rows ? file.string() + ": row " + std::to_string(lines[i]) + " (from 0)"
              : file.string() + ":" + std::to_string(lines[i]);
}

std::size_t PathFile::count(PathBlock::Kind kind) const {
  std::size_t n = 0;
  for (const PathBlock& b : blocks) n += b.kind == kind;
  return n;
}

void requireSteadyAxis(const PathFile& path, std::size_t before, std::size_t i) {
  const double turn_deg = axisAngle(path.postures[before].axis, path.postures[i].axis) * kRadToDeg;
  if (turn_deg <= kMaxPassAxisTurnDeg) return;
  char turn[64], limit[64];
  std::snprintf(turn, sizeof turn, "%.4g", turn_deg);
  std::snprintf(limit, sizeof limit, "%g", kMaxPassAxisTurnDeg);
  throw InputError(path.where(i) + ": the tool axis turns " + turn +
                   " deg from the posture before (" + path.where(before) + "): more than " + limit +
                   " deg between two postures of a pass (a flipped axis?)");
}

PathFile singlePass(std::vector<Posture> postures) {
  PathFile path;
  if (!postures.empty()) path.blocks.push_back({PathBlock::Kind::Pass, 0, postures.size()});
  path.postures = std::move(postures);
  return path;
}

PathFile readPathFile(const std::filesystem::path& file, const PathReadOptions& options) {
  switch (pathFormatOf(file)) {
    case PathFormat::Npy:
      return readNpyPath(file, options);
    case PathFormat::Apt:
      return readAptPath(file, options);
    case PathFormat::Cl:
      break;
  }
  return readClPath(file, options);
}

PathFormat pathFormatOf(const std::filesystem::path& file) {
  const std::string ext = common::lowerExtension(file);
  if (ext == ".npy") return PathFormat::Npy;
  if (ext == ".apt" || ext == ".cls") return PathFormat::Apt;
  return PathFormat::Cl;
}

namespace {

inline bool isBlank(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f' || c == '\n';
}

/// The common line, the fast way: 6 or 7 numbers fastNumber reads, blanks between them, maybe a
/// comment. Returns false, having done nothing, for any other line (blank, marker, unusual
/// numbers, errors): the careful parse then gives the same posture or the message.
template <class Out>
bool fastLine(std::string_view content, const std::filesystem::path& file, std::size_t line,
              Out& out) {
  const char* p = content.data();
  const char* const end = p + content.size();
  double v[7];
  std::size_t count = 0;
  for (;;) {
    while (p < end && (*p == ' ' || *p == '\t' || *p == '\r')) ++p;
    if (p == end || *p == '#') break;
    if (count == 7 || !fastNumber(p, end, v[count])) return false;
    if (p < end && *p != ' ' && *p != '\t' && *p != '\r' && *p != '#') return false;
    ++count;
  }
  if (count < 6) return false;
  for (std::size_t c = 0; c < count; ++c)
    if (!std::isfinite(v[c])) return false;
  const auto where = [&] { return file.string() + ":" + std::to_string(line); };
  out.add(checkedPosture(v, count, where), line);
  if (p < end && isLimitNote(std::string_view(p + 1, std::size_t(end - p - 1)))) out.limit();
  return true;
}

/// Parses the `.cl` lines of one chunk. `Out` takes the postures (`add`), the block markers
/// (`mark`, with the kind of the next block) and the `# limit` notes (`limit`, after the posture).
template <class Out>
void parseClChunk(std::string_view text, std::size_t first_line, const std::filesystem::path& file,
                  Out& out) {
  std::size_t line = first_line;
  for (std::size_t pos = 0; pos < text.size(); ++line) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    std::string_view content = text.substr(pos, nl - pos), comment;
    pos = nl + 1;
    if (fastLine(content, file, line, out)) continue;
    bool has_comment = false;
    if (const auto hash = content.find('#'); hash != std::string_view::npos) {
      comment = content.substr(hash + 1);
      content = content.substr(0, hash);
      has_comment = true;
    }
    // Up to 8 tokens kept (7 are allowed), all counted: the count is checked before the numbers.
    std::string_view tokens[8];
    std::size_t count = 0;
    for (std::size_t i = 0; i < content.size();) {
      while (i < content.size() && isBlank(content[i])) ++i;
      const std::size_t start = i;
      while (i < content.size() && !isBlank(content[i])) ++i;
      if (i > start) {
        if (count < 8) tokens[count] = content.substr(start, i - start);
        ++count;
      }
    }
    if (count == 0) {
      if (has_comment)
        if (std::string mark = safetyMark(comment); !mark.empty()) {
          out.warn(std::move(mark));
          continue;
        }
      const Marker marker = has_comment ? markerOf(comment) : Marker::None;
      if (!has_comment || marker == Marker::Pass)  // a blank line or `# pass ...`
        out.mark(PathBlock::Kind::Pass);
      else if (marker == Marker::Link)
        out.mark(PathBlock::Kind::Link);
      continue;
    }
    if (count < 6) {
      if (content.find(',') != std::string_view::npos)
        fail(file, line, "numbers separated by commas: a .cl line is `x y z i j k` separated by "
                         "blanks (an APT file? name it .apt or .cls)");
      for (std::size_t c = 0; c < count; ++c) parseFinite(tokens[c], file, line);  // "not a number"
      fail(file, line, "short line: " + std::to_string(count) + " numbers, need x y z i j k");
    }
    if (count > 7)
      fail(file, line,
           "too many columns: " + std::to_string(count) + ", expected x y z i j k [spindle]");
    double v[7];
    for (std::size_t c = 0; c < count; ++c) v[c] = parseFinite(tokens[c], file, line);
    const auto where = [&] { return file.string() + ":" + std::to_string(line); };
    out.add(checkedPosture(v, count, where), line);
    if (has_comment && isLimitNote(comment)) out.limit();
  }
}

/// A chunk as PathFile keeps it.
struct FullOut {
  PathChunk& chunk;
  void add(const Posture& p, std::size_t line) {
    chunk.postures.push_back(p);
    chunk.lines.push_back(line);
  }
  void mark(PathBlock::Kind kind) { chunk.marks.push_back({chunk.postures.size(), kind}); }
  void limit() { chunk.limited.push_back(chunk.postures.size() - 1); }
  void warn(std::string mark) { chunk.warnings.push_back(std::move(mark)); }
};

/// Only the postures, rounded to float.
struct CompactOut {
  std::vector<CompactPosture>& postures;
  void add(const Posture& p, std::size_t) { postures.push_back(compact(p)); }
  void mark(PathBlock::Kind) {}
  void limit() {}
  void warn(std::string) {}
};

/// The blocks of a `.cl` file from its marks: a block starts at posture 0 and at every posture a
/// mark (a marker or a blank line) comes before; the last mark before a posture gives its kind.
std::vector<PathBlock> clBlocks(const std::vector<PathChunk>& chunks, std::size_t postures) {
  std::vector<PathBlock> blocks;
  if (postures == 0) return blocks;
  blocks.push_back({PathBlock::Kind::Pass, 0, postures});
  std::size_t offset = 0;
  for (const PathChunk& chunk : chunks) {
    for (const BlockMark& m : chunk.marks) {
      const std::size_t i = offset + m.posture;
      if (i >= postures) break;  // marks after the last posture
      if (blocks.back().begin == i) {
        blocks.back().kind = m.kind;
      } else {
        blocks.back().end = i;
        blocks.push_back({m.kind, i, postures});
      }
    }
    offset += chunk.postures.size();
  }
  return blocks;
}

}  // namespace

PathFile readClPath(const std::filesystem::path& file, const PathReadOptions& options) {
  const MappedFile mapped(file);
  const std::string_view text = readableText(mapped.text(), file);
  const std::vector<TextChunk> pieces = splitAtLines(text, options.chunk_bytes, options.threads);
  std::vector<PathChunk> chunks(pieces.size());
  forEachChunk(pieces.size(), options.threads, [&](std::size_t i) {
    const TextChunk& c = pieces[i];
    PathChunk& chunk = chunks[i];
    chunk.postures.reserve((c.end - c.begin) / 40 + 1);
    chunk.lines.reserve((c.end - c.begin) / 40 + 1);
    FullOut out{chunk};
    parseClChunk(text.substr(c.begin, c.end - c.begin), c.first_line, file, out);
  });
  PathFile path;
  path.file = file;
  // Blocks from the marks (few: a pass or link each) before the chunks are emptied.
  std::size_t total = 0;
  for (const PathChunk& c : chunks) total += c.postures.size();
  path.blocks = clBlocks(chunks, total);
  concatenate(chunks, options.threads, path);
  if (path.postures.empty()) throw InputError(file.string() + ": no postures (empty path file)");
  checkDeclaredCount(text, kClCountPrefix, path.postures.size(), file, clEndsWhole(text));
  return path;
}

namespace detail {

/// Hands a PathFile's postures over in chunks (APT: cross-record state makes a compact scan
/// of its own not worth it).
std::size_t handOver(const PathFile& path, const PathReadOptions& options,
                     const PostureChunkSink& sink) {
  const std::size_t per_chunk = std::max<std::size_t>(1, options.chunk_bytes / 24);
  const std::size_t n = (path.postures.size() + per_chunk - 1) / per_chunk;
  if (sink.begin) sink.begin(n);
  forEachChunk(n, options.threads, [&](std::size_t i) {
    const std::size_t begin = i * per_chunk,
                      end = std::min(path.postures.size(), begin + per_chunk);
    std::vector<CompactPosture> out(end - begin);
    for (std::size_t k = begin; k < end; ++k) out[k - begin] = compact(path.postures[k]);
    sink.chunk(i, out);
  });
  return path.postures.size();
}

std::size_t scanNpy(const std::filesystem::path& file, const PathReadOptions& options,
                    const PostureChunkSink& sink);

}  // namespace detail

std::size_t scanPathFile(const std::filesystem::path& file, const PathReadOptions& options,
                         const PostureChunkSink& sink) {
  switch (pathFormatOf(file)) {
    case PathFormat::Npy:
      return scanNpy(file, options, sink);
    case PathFormat::Apt: {
      const PathFile path = readAptPath(file, options);
      if (sink.tool_records) {
        PathFile records;
        records.file = path.file;
        records.cutters = path.cutters;
        records.tool_loads = path.tool_loads;
        sink.tool_records(records);
      }
      return handOver(path, options, sink);
    }
    case PathFormat::Cl:
      break;
  }
  const MappedFile mapped(file);
  const std::string_view text = readableText(mapped.text(), file);
  const std::vector<TextChunk> pieces = splitAtLines(text, options.chunk_bytes, options.threads);
  if (sink.begin) sink.begin(pieces.size());
  std::vector<std::size_t> counts(pieces.size(), 0);
  forEachChunk(pieces.size(), options.threads, [&](std::size_t i) {
    const TextChunk& c = pieces[i];
    // One buffer per worker, reused chunk after chunk: fresh pages cost a fault each (and
    // contend for the kernel's locks on many cores); a line holds 12 bytes at least.
    thread_local std::vector<CompactPosture> postures;
    postures.clear();
    postures.reserve((c.end - c.begin) / 12 + 1);
    CompactOut out{postures};
    parseClChunk(text.substr(c.begin, c.end - c.begin), c.first_line, file, out);
    counts[i] = postures.size();
    sink.chunk(i, postures);
  });
  std::size_t total = 0;
  for (std::size_t n : counts) total += n;
  if (total == 0) throw InputError(file.string() + ": no postures (empty path file)");
  // After the chunks were handed on: the caller's work on them fails with this (`simulate`
  // stamped a path cut short, a reviewer's finding).
  checkDeclaredCount(text, kClCountPrefix, total, file, clEndsWhole(text));
  return total;
}

std::vector<Posture> readClFile(const std::filesystem::path& file) {
  return readClPath(file).postures;
}

std::vector<Posture> readAptFile(const std::filesystem::path& file) {
  return readAptPath(file).postures;
}

void writeClFile(const std::filesystem::path& file, const PathFile& path,
                 std::string_view comment) {
  std::string text;
  if (!comment.empty()) {
    std::istringstream lines{std::string(comment)};
    for (std::string line; std::getline(lines, line);) text += "# " + line + "\n";
  }
  const auto& postures = path.postures;
  text += std::string(kClCountPrefix) + std::to_string(postures.size()) +
          " (a file holding fewer was cut short)\n";
  text += "# x y z i j k" +
          std::string(!postures.empty() && postures[0].has_spindle ? " spindle_rad" : "") +
          "  (tool tip, mm; unit tool axis)\n";
  const bool marked = !(path.blocks.size() == 1 && path.blocks[0].kind == PathBlock::Kind::Pass);
  std::size_t next_limited = 0, pass = 0;
  for (const PathBlock& block : path.blocks) {
    if (marked)
      text += block.kind == PathBlock::Kind::Pass ? "# pass " + std::to_string(++pass) + "\n"
                                                  : std::string("# link\n");
    for (std::size_t i = block.begin; i < block.end; ++i) {
      const Posture& p = postures[i];
      const double values[] = {p.tip_mm.x(), p.tip_mm.y(), p.tip_mm.z(),
                               p.axis.x(),   p.axis.y(),   p.axis.z()};
      for (double v : values) {
        appendNumber(text, v);
        text += ' ';
      }
      if (p.has_spindle)
        appendNumber(text, p.spindle_rad);
      else
        text.pop_back();
      while (next_limited < path.limited.size() && path.limited[next_limited] < i) ++next_limited;
      if (next_limited < path.limited.size() && path.limited[next_limited] == i)
        text += "  # limit";
      text += '\n';
    }
  }
  common::writeTextAtomically(file, text);
}

std::size_t clCommentLines(std::string_view comment) {
  std::size_t n = 0;
  std::istringstream lines{std::string(comment)};
  for (std::string line; std::getline(lines, line);) ++n;
  return n;
}

std::vector<std::size_t> clFileLines(const PathFile& path, std::size_t comment_lines) {
  // As writeClFile: the comment, the count and column lines, a marker before each block where
  // the path is not one pass block, one line a posture.
  const bool marked = !(path.blocks.size() == 1 && path.blocks[0].kind == PathBlock::Kind::Pass);
  std::vector<std::size_t> lines(path.postures.size());
  std::size_t line = comment_lines + 2;
  for (const PathBlock& block : path.blocks) {
    line += marked;
    for (std::size_t i = block.begin; i < block.end; ++i) lines[i] = ++line;
  }
  return lines;
}

void writeClFile(const std::filesystem::path& file, std::span<const Posture> postures,
                 std::string_view comment) {
  writeClFile(file, singlePass({postures.begin(), postures.end()}), comment);
}

}  // namespace fieldpath::geometry
