#include "apt_records.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <limits>
#include <string>

#include "path_text.h"

namespace fieldpath::geometry::detail {
namespace {

/// A line without the sequence field of an 80-column card: up to 8 letters or digits in columns
/// 73-80 after a blank column 72 (classic CLDATA decks number their cards so; such a deck's GOTOs
/// were refused as bad numbers). Not where the text before ends in a separator (`,` `/` `=`): a
/// free-format record's last number may stand past column 72.
std::string_view withoutCardSequence(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  if (line.size() <= kAptColumns || line.size() > 80 || line[kAptColumns - 1] != ' ') return line;
  const std::string_view field = trimmed(line.substr(kAptColumns));
  const bool sequence = !field.empty() && std::all_of(field.begin(), field.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) != 0;
  });
  const std::string_view card = trimmed(line.substr(0, kAptColumns));
  if (!sequence || card.empty() || card.back() == ',' || card.back() == '/' || card.back() == '=')
    return line;
  return line.substr(0, kAptColumns);
}

}  // namespace

bool isTextRecord(std::string_view content) {
  const std::string head = upperCase(std::string(trimmed(content).substr(0, 6)));
  return head == "PPRINT" || head == "PARTNO" || head == "INSERT" || head == "REMARK";
}

std::string_view aptContent(std::string_view line) {
  line = withoutCardSequence(line);
  if (const auto comment = line.find("$$"); comment != std::string_view::npos)
    line = line.substr(0, comment);
  line = trimmed(line);
  if (!isTextRecord(line))
    if (const auto dollar = line.find("$ "); dollar != std::string_view::npos)
      line = line.substr(0, dollar + 1);
  if (!isTextRecord(line))
    if (const auto dollar = line.find("$\t"); dollar != std::string_view::npos)
      line = line.substr(0, dollar + 1);
  return line;
}

std::size_t leadingNumbers(std::string_view values, double* v, std::size_t max) {
  std::size_t count = 0;
  for (std::size_t start = 0; start <= values.size() && count < max;) {
    const auto comma = std::min(values.find(',', start), values.size());
    const std::string_view token = trimmed(values.substr(start, comma - start));
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v[count]);
    if (ec != std::errc() || end != token.data() + token.size() || !std::isfinite(v[count])) break;
    ++count;
    start = comma + 1;
  }
  return count;
}

std::optional<PathFile::Cutter> cutterOf(std::string_view values, std::size_t line,
                                         std::size_t length_at) {
  double v[7] = {0.0, -1.0};
  const std::size_t count = leadingNumbers(values, v, length_at + 1);
  if (count == 0) return std::nullopt;
  // A diameter <= 0 is kept as read: no tool, which the notes say (`CUTTER/-6` was read past
  // without a word, an adversary's).
  PathFile::Cutter cutter{v[0], count >= 2 && v[1] >= 0.0 ? v[1] : -1.0, line};
  if (count > length_at && v[length_at] > 0.0) cutter.length_mm = v[length_at];
  return cutter;
}

AptFeed feedOf(std::string_view values, std::size_t line, std::size_t posture) {
  AptFeed out;
  out.feed = {posture, std::numeric_limits<double>::quiet_NaN(), line, {}};
  out.unit = 0.0;
  int numbers = 0, units = 0;
  bool understood = true;
  double value = 0.0;
  for (std::size_t start = 0; start <= values.size();) {
    const auto comma = std::min(values.find(',', start), values.size());
    std::string_view token = trimmed(values.substr(start, comma - start));
    start = comma + 1;
    if (!token.empty() && token.front() == '+') token.remove_prefix(1);  // as GOTO reads `+1`
    double v = 0.0;
    const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), v);
    if (!token.empty() && ec == std::errc() && end == token.data() + token.size()) {
      value = v;
      understood = understood && ++numbers == 1 && std::isfinite(v) && v > 0.0;
    } else if (token == "MMPM" || token == "IPM" || token == "PERMIN") {
      out.unit = token == "MMPM" ? 1.0 : token == "IPM" ? 25.4 : 0.0;
      understood = understood && ++units == 1;
    } else {  // per revolution, inverse time, or a word of no feed
      understood = false;
    }
  }
  if (understood && numbers == 1) {
    out.feed.mm_per_min = value;
  } else {
    out.feed.text =
        std::string(trimmed(values.substr(0, std::min<std::size_t>(values.size(), 60))));
  }
  return out;
}

double unitScale(std::string_view value) {
  if (value == "MM" || value == "MILLIMETERS" || value == "MILLIMETRES") return 1.0;
  if (value == "INCHES" || value == "INCH" || value == "IN") return 25.4;
  return 0.0;
}

double inMm(double value, double mm_per_unit) {
  if (mm_per_unit == 1.0) return value;
  return std::round(value * mm_per_unit * 1e9) / 1e9;
}

Vec3 inMm(const Vec3& value, double mm_per_unit) {
  return {inMm(value.x(), mm_per_unit), inMm(value.y(), mm_per_unit), inMm(value.z(), mm_per_unit)};
}

Vec3 onPicometres(const Vec3& value) {
  return {std::round(value.x() * 1e9) / 1e9, std::round(value.y() * 1e9) / 1e9,
          std::round(value.z() * 1e9) / 1e9};
}

bool continuesRecord(std::string_view content) {
  return !content.empty() && content.back() == '$' && !isTextRecord(content);
}

}  // namespace fieldpath::geometry::detail
