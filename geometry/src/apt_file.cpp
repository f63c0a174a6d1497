/// APT CLDATA as CAM systems write it and post-processors read it: `GOTO / x, y, z, i, j, k`
/// (spaces allowed, 3 values keep the last axis), `$` at a line's end continues the record, `$$`
/// starts a comment, `RAPID` makes the next motion a rapid (a link), every other record is read
/// past.
#include <fstream>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/geometry/cl_file.h"
#include "path_text.h"

namespace fieldpath::geometry {
namespace {

using namespace detail;
using common::InputError;

std::string upperCase(std::string_view text) {
  std::string s(text);
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

void appendGoto(std::string& text, const Posture& p) {
  text += "GOTO/";
  const double values[] = {p.tip_mm.x(), p.tip_mm.y(), p.tip_mm.z(),
                           p.axis.x(),   p.axis.y(),   p.axis.z()};
  for (double v : values) {
    appendNumber(text, v);
    text += ',';
  }
  text.back() = '\n';
}

}  // namespace

PathFile readAptPath(const std::filesystem::path& file) {
  std::ifstream in = openPathFile(file);
  PathFile path;
  path.file = file;
  bool rapid = false;  // RAPID seen: the next motion is a link
  std::string text;
  std::string record;  // a statement, with `$` continuation lines joined
  std::size_t record_line = 0;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::string_view content(text);
    if (const auto comment = content.find("$$"); comment != std::string_view::npos)
      content = content.substr(0, comment);
    content = trimmed(content);
    if (record.empty()) record_line = line;
    if (!content.empty() && content.back() == '$') {
      record += content.substr(0, content.size() - 1);
      continue;
    }
    record += content;
    const std::string statement = upperCase(record);
    record.clear();
    const auto slash = statement.find('/');
    const std::string_view major =
        trimmed(std::string_view(statement).substr(0, std::min(slash, statement.size())));
    if (major == "RAPID") {
      rapid = true;
      continue;
    }
    if (major != "GOTO" || slash == std::string::npos) continue;
    std::vector<double> v;
    const std::string_view rest = std::string_view(statement).substr(slash + 1);
    for (std::size_t start = 0; start <= rest.size();) {
      const auto comma = std::min(rest.find(',', start), rest.size());
      const auto tokens = splitWhitespace(rest.substr(start, comma - start));
      if (tokens.size() != 1) fail(file, record_line, "GOTO: expected comma-separated numbers");
      v.push_back(parseFinite(tokens[0], file, record_line));
      start = comma + 1;
    }
    if (v.size() != 6 && v.size() != 3)
      fail(file, record_line, "GOTO: " + std::to_string(v.size()) + " numbers, need x,y,z[,i,j,k]");
    Posture p;
    p.tip_mm = Vec3(v[0], v[1], v[2]);
    // A 3-number GOTO keeps the previous axis (APT modal behaviour).
    p.axis = v.size() == 6 ? checkedAxis(Vec3(v[3], v[4], v[5]),
                                         file.string() + ":" + std::to_string(record_line))
                           : (path.postures.empty() ? Vec3::UnitZ() : path.postures.back().axis);
    addToBlocks(path.blocks, rapid ? PathBlock::Kind::Link : PathBlock::Kind::Pass, false,
                path.postures.size());
    rapid = false;
    path.postures.push_back(p);
    path.lines.push_back(record_line);
  }
  if (path.postures.empty()) throw InputError(file.string() + ": no GOTO records");
  return path;
}

void writeAptFile(const std::filesystem::path& file, const PathFile& path,
                  const AptHeader& header) {
  // CUTTER/d,r,e,f,a,b,h: diameter, corner radius, corner centre offsets (radial e, axial f),
  // taper angles a, b (0 for these tools), height h.
  const ToolSpec& t = header.tool;
  const double corner_mm = cornerRadius(t);
  std::string text = "PARTNO/" + header.part_name + "\nUNITS/MM\nMULTAX/ON\nCUTTER/";
  const double cutter[] = {2 * t.radius_mm, corner_mm, t.radius_mm - corner_mm, corner_mm, 0.0, 0.0,
                           t.length_mm};
  for (double v : cutter) {
    appendNumber(text, v);
    text += ',';
  }
  text.back() = '\n';
  std::string feed = "FEDRAT/MMPM,";
  appendNumber(feed, header.feed_mm_per_min);
  feed += '\n';
  for (const PathBlock& block : path.blocks) {
    if (block.kind == PathBlock::Kind::Pass) text += feed;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      if (block.kind == PathBlock::Kind::Link) text += "RAPID\n";
      appendGoto(text, path.postures[i]);
    }
  }
  text += "FINI\n";
  common::writeTextAtomically(file, text);
}

void writeAptFile(const std::filesystem::path& file, std::span<const Posture> postures,
                  const AptHeader& header) {
  writeAptFile(file, singlePass({postures.begin(), postures.end()}), header);
}

}  // namespace fieldpath::geometry
