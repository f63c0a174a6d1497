#include "fieldpath/geometry/cl_file.h"

#include <fstream>

#include "fieldpath/common/atomic_file.h"

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
  return rows ? file.string() + ": row " + std::to_string(lines[i])
              : file.string() + ":" + std::to_string(lines[i]);
}

std::size_t PathFile::count(PathBlock::Kind kind) const {
  std::size_t n = 0;
  for (const PathBlock& b : blocks) n += b.kind == kind;
  return n;
}

PathFile singlePass(std::vector<Posture> postures) {
  PathFile path;
  if (!postures.empty()) path.blocks.push_back({PathBlock::Kind::Pass, 0, postures.size()});
  path.postures = std::move(postures);
  return path;
}

PathFile readPathFile(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".npy") return readNpyPath(file);
  if (ext == ".apt" || ext == ".cls") return readAptPath(file);
  return readClPath(file);
}

PathFile readClPath(const std::filesystem::path& file) {
  std::ifstream in = openPathFile(file);
  PathFile path;
  path.file = file;
  PathBlock::Kind next_kind = PathBlock::Kind::Pass;
  bool split = true;  // the next posture starts a block
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::string_view content(text), comment;
    if (const auto hash = content.find('#'); hash != std::string_view::npos) {
      comment = content.substr(hash + 1);
      content = content.substr(0, hash);
    }
    const auto tokens = splitWhitespace(content);
    if (tokens.empty()) {
      const Marker marker = comment.data() ? markerOf(comment) : Marker::None;
      if (!comment.data() || marker == Marker::Pass) {  // a blank line or `# pass ...`
        next_kind = PathBlock::Kind::Pass;
        split = true;
      } else if (marker == Marker::Link) {
        next_kind = PathBlock::Kind::Link;
        split = true;
      }
      continue;
    }
    if (tokens.size() < 6)
      fail(file, line,
           "short line: " + std::to_string(tokens.size()) + " numbers, need x y z i j k");
    if (tokens.size() > 7)
      fail(file, line,
           "too many columns: " + std::to_string(tokens.size()) +
               ", expected x y z i j k [spindle]");
    double v[7];
    for (std::size_t c = 0; c < tokens.size(); ++c) v[c] = parseFinite(tokens[c], file, line);
    Posture p;
    p.tip_mm = Vec3(v[0], v[1], v[2]);
    p.axis = checkedAxis(Vec3(v[3], v[4], v[5]), file.string() + ":" + std::to_string(line));
    p.has_spindle = tokens.size() == 7;
    p.spindle_rad = p.has_spindle ? v[6] : 0.0;
    const std::size_t i = path.postures.size();
    addToBlocks(path.blocks, next_kind, split, i);
    split = false;
    if (comment.data() && isLimitNote(comment)) path.limited.push_back(i);
    path.postures.push_back(p);
    path.lines.push_back(line);
  }
  if (in.bad()) throw InputError(file.string() + ": read error");
  if (path.postures.empty()) throw InputError(file.string() + ": no postures (empty path file)");
  return path;
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

void writeClFile(const std::filesystem::path& file, std::span<const Posture> postures,
                 std::string_view comment) {
  writeClFile(file, singlePass({postures.begin(), postures.end()}), comment);
}

}  // namespace fieldpath::geometry
