#include "fieldpath/geometry/cl_file.h"

#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <limits>
#include <sstream>
#include <system_error>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"

namespace fieldpath::geometry {
namespace {

using common::InputError;

/// Axes whose length is off 1 by no more than this are taken as they are (a few ulps: rounding of
/// an already normalised vector), so a written file reads back bit for bit.
constexpr double kUnitAsIs = 8 * std::numeric_limits<double>::epsilon();
/// Axes off unit length by less than this are normalised; the others are rejected (DESIGN.md).
constexpr double kUnitTolerance = 1e-3;

[[noreturn]] void fail(const std::filesystem::path& file, std::size_t line,
                       const std::string& why) {
  throw InputError(file.string() + ":" + std::to_string(line) + ": " + why);
}

/// Printable form of a token for an error message (garbage bytes shown as \xNN, long tokens cut).
std::string quoted(std::string_view token) {
  std::string s = "'";
  for (std::size_t i = 0; i < token.size() && i < 32; ++i) {
    const auto c = static_cast<unsigned char>(token[i]);
    if (std::isprint(c)) {
      s += static_cast<char>(c);
    } else {
      char hex[8];
      std::snprintf(hex, sizeof hex, "\\x%02X", c);
      s += hex;
    }
  }
  return s + (token.size() > 32 ? "...'" : "'");
}

/// Parses a whole token (an optional leading '+' allowed) as a finite double.
double parseFinite(std::string_view token, const std::filesystem::path& file, std::size_t line) {
  std::string_view digits = token;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range) fail(file, line, quoted(token) + " is out of range");
  if (ec != std::errc() || end != digits.data() + digits.size())
    fail(file, line, quoted(token) + " is not a number");
  if (!std::isfinite(value)) fail(file, line, quoted(token) + " is not finite");
  return value;
}

/// Axis check shared by the `.cl` and APT readers.
Vec3 checkedAxis(const Vec3& axis, const std::filesystem::path& file, std::size_t line) {
  const double length = axis.norm();
  if (!(length > 0.0)) fail(file, line, "zero tool axis");
  if (std::abs(length - 1.0) >= kUnitTolerance) {
    std::ostringstream why;
    why << "tool axis is not a unit vector (length " << length << ")";
    fail(file, line, why.str());
  }
  return std::abs(length - 1.0) <= kUnitAsIs ? axis : Vec3(axis / length);
}

std::ifstream openForReading(const std::filesystem::path& file) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec))
    throw InputError(file.string() + ": no such file");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot open for reading");
  return in;
}

/// Splits on whitespace (a `\r` of CRLF files included).
std::vector<std::string_view> splitWhitespace(std::string_view text) {
  std::vector<std::string_view> tokens;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    const std::size_t start = i;
    while (i < text.size() && !std::isspace(static_cast<unsigned char>(text[i]))) ++i;
    if (i > start) tokens.push_back(text.substr(start, i - start));
  }
  return tokens;
}

/// Shortest decimal form that reads back as the same double.
void appendNumber(std::string& out, double value) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  out.append(buffer, result.ptr);
}

std::string upperCase(std::string_view text) {
  std::string s(text);
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::vector<Posture> readClFile(const std::filesystem::path& file) {
  std::ifstream in = openForReading(file);
  std::vector<Posture> postures;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::string_view content(text);
    if (const auto hash = content.find('#'); hash != std::string_view::npos)
      content = content.substr(0, hash);
    const auto tokens = splitWhitespace(content);
    if (tokens.empty()) continue;
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
    p.axis = checkedAxis(Vec3(v[3], v[4], v[5]), file, line);
    p.has_spindle = tokens.size() == 7;
    p.spindle_rad = p.has_spindle ? v[6] : 0.0;
    postures.push_back(p);
  }
  if (in.bad()) throw InputError(file.string() + ": read error");
  if (postures.empty()) throw InputError(file.string() + ": no postures (empty path file)");
  return postures;
}

void writeClFile(const std::filesystem::path& file, std::span<const Posture> postures,
                 std::string_view comment) {
  std::string text;
  if (!comment.empty()) {
    std::istringstream lines{std::string(comment)};
    for (std::string line; std::getline(lines, line);) text += "# " + line + "\n";
  }
  text += "# x y z i j k" +
          std::string(!postures.empty() && postures[0].has_spindle ? " spindle_rad" : "") +
          "  (tool tip, mm; unit tool axis)\n";
  for (const Posture& p : postures) {
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
    text += '\n';
  }
  common::writeTextAtomically(file, text);
}

void writeAptFile(const std::filesystem::path& file, std::span<const Posture> postures,
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
  text += "FEDRAT/MMPM,";
  appendNumber(text, header.feed_mm_per_min);
  text += '\n';
  for (const Posture& p : postures) {
    text += "GOTO/";
    const double values[] = {p.tip_mm.x(), p.tip_mm.y(), p.tip_mm.z(),
                             p.axis.x(),   p.axis.y(),   p.axis.z()};
    for (double v : values) {
      appendNumber(text, v);
      text += ',';
    }
    text.back() = '\n';
  }
  text += "FINI\n";
  common::writeTextAtomically(file, text);
}

std::vector<Posture> readAptFile(const std::filesystem::path& file) {
  std::ifstream in = openForReading(file);
  std::vector<Posture> postures;
  std::string text;
  std::string record;  // a statement, with `$` continuation lines joined
  std::size_t record_line = 0;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::string_view content(text);
    while (!content.empty() && std::isspace(static_cast<unsigned char>(content.back())))
      content.remove_suffix(1);
    if (record.empty()) record_line = line;
    if (!content.empty() && content.back() == '$') {
      record += content.substr(0, content.size() - 1);
      continue;
    }
    record += content;
    std::string statement = upperCase(record);
    record.clear();
    const auto slash = statement.find('/');
    if (slash == std::string::npos) continue;
    std::string_view major = std::string_view(statement).substr(0, slash);
    while (!major.empty() && std::isspace(static_cast<unsigned char>(major.back())))
      major.remove_suffix(1);
    while (!major.empty() && std::isspace(static_cast<unsigned char>(major.front())))
      major.remove_prefix(1);
    if (major != "GOTO") continue;
    std::vector<double> v;
    std::string_view rest = std::string_view(statement).substr(slash + 1);
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
    p.axis = v.size() == 6 ? checkedAxis(Vec3(v[3], v[4], v[5]), file, record_line)
                           : (postures.empty() ? Vec3::UnitZ() : postures.back().axis);
    postures.push_back(p);
  }
  if (postures.empty()) throw InputError(file.string() + ": no GOTO records");
  return postures;
}

}  // namespace fieldpath::geometry
