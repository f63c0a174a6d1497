#pragma once
/// Helpers shared by the path readers and writers (.cl, APT, .npy): errors naming the file and
/// line, strict number parsing, the axis check, shortest round-trip numbers.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/input_file.h"
#include "fieldpath/geometry/cl_file.h"

namespace fieldpath::geometry::detail {

/// Axes whose length is off 1 by no more than this are taken as they are: unit vectors rounded to
/// float (a float32 .npy, or .cl text written from 32-bit values: length off by up to ~1e-7) or to
/// double. Normalising them would move the .cl's decimal values and the .npy's floats apart by
/// ~1e-9, enough to round a few axes to another float: the same path as .cl and as .npy would not
/// cut the same heights bit for bit (bench/zbuffer/process.sh checks it).
inline constexpr double kUnitAsIs = 1e-6;
/// Axes off unit length by less than this are normalised; the others are rejected (DESIGN.md).
inline constexpr double kUnitTolerance = 1e-3;

/// "FILE:LINE: why" (`where` already formatted, e.g. by PathFile::where).
[[noreturn]] inline void failAt(const std::string& where, const std::string& why) {
  throw common::InputError(where + ": " + why);
}

[[noreturn]] inline void fail(const std::filesystem::path& file, std::size_t line,
                              const std::string& why) {
  failAt(file.string() + ":" + std::to_string(line), why);
}

/// Printable form of a token for an error message (garbage bytes shown as \xNN, long tokens cut).
inline std::string quoted(std::string_view token) {
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
inline double parseFinite(std::string_view token, const std::filesystem::path& file,
                          std::size_t line) {
  std::string_view digits = token;
  if (!digits.empty() && digits.front() == '+') digits.remove_prefix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
  if (ec == std::errc::result_out_of_range) fail(file, line, quoted(token) + " is out of range");
  if (ec != std::errc() || end != digits.data() + digits.size()) {
    // `PARTNO/...`, `$$ ...`, `GOTO/...` in a file read as `.cl` (by its name): APT renamed.
    const bool apt_like = token.find('/') != std::string_view::npos || token.rfind("$$", 0) == 0;
    fail(file, line,
         quoted(token) + " is not a number" +
             (apt_like && pathFormatOf(file) == PathFormat::Cl
                  ? " (APT CLDATA? the format is told by the name: .apt or .cls)"
                  : ""));
  }
  if (!std::isfinite(value)) fail(file, line, quoted(token) + " is not finite");
  return value;
}

/// Clinger's fast path: a decimal number whose digits fit in 2^53 and whose power of ten is
/// within 1e+-22 is one multiplication or division of two exact doubles, correctly rounded: the
/// same bits std::from_chars gives, several times faster. Reads [p, end) from p (an optional
/// sign, digits, '.', digits, an exponent); returns false, p unchanged, for anything else (the
/// caller then parses the careful way).
inline bool fastNumber(const char*& p, const char* end, double& out) {
  static constexpr double kPow10[] = {1e0,  1e1,  1e2,  1e3,  1e4,  1e5,  1e6,  1e7,
                                      1e8,  1e9,  1e10, 1e11, 1e12, 1e13, 1e14, 1e15,
                                      1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22};
  const char* s = p;
  bool negative = false;
  if (s < end && (*s == '-' || *s == '+')) negative = *s++ == '-';
  std::uint64_t mantissa = 0;
  int digits = 0, fraction = 0;
  for (; s < end && static_cast<unsigned>(*s - '0') < 10; ++s, ++digits)
    mantissa = mantissa * 10 + static_cast<unsigned>(*s - '0');
  if (s < end && *s == '.') {
    for (++s; s < end && static_cast<unsigned>(*s - '0') < 10; ++s, ++digits, ++fraction)
      mantissa = mantissa * 10 + static_cast<unsigned>(*s - '0');
  }
  if (digits == 0 || digits > 19) return false;  // (19 digits cannot overflow 64 bits)
  int exponent = -fraction;
  if (s < end && (*s == 'e' || *s == 'E')) {
    ++s;
    bool negative_exponent = false;
    if (s < end && (*s == '-' || *s == '+')) negative_exponent = *s++ == '-';
    int value = 0, exponent_digits = 0;
    for (; s < end && static_cast<unsigned>(*s - '0') < 10; ++s)
      if (++exponent_digits > 4) return false;
      else value = value * 10 + (*s - '0');
    if (exponent_digits == 0) return false;
    exponent += negative_exponent ? -value : value;
  }
  if (mantissa > (std::uint64_t{1} << 53) || exponent < -22 || exponent > 22) return false;
  const double magnitude = exponent < 0 ? double(mantissa) / kPow10[-exponent]
                                        : double(mantissa) * kPow10[exponent];
  out = negative ? -magnitude : magnitude;
  p = s;
  return true;
}

/// The axis as read: unit (or normalised when off by < 1e-3); otherwise an error at `where()`
/// (a callable giving "FILE:LINE", built only on failure: this runs once per posture).
template <class Where>
Vec3 checkedAxis(const Vec3& axis, const Where& where) {
  const double length = axis.norm();
  if (!(length > 0.0)) failAt(where(), "zero tool axis");
  if (!std::isfinite(length)) failAt(where(), "tool axis is not finite");
  if (std::abs(length - 1.0) >= kUnitTolerance) {
    std::ostringstream why;
    why << "tool axis is not a unit vector (length " << length << ")";
    failAt(where(), why.str());
  }
  return std::abs(length - 1.0) <= kUnitAsIs ? axis : Vec3(axis / length);
}

/// Splits on whitespace (a `\r` of CRLF files included).
inline std::vector<std::string_view> splitWhitespace(std::string_view text) {
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

/// `text` in upper case (APT records are read whatever their case).
inline std::string upperCase(std::string_view text) {
  std::string s(text);
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

inline std::string_view trimmed(std::string_view text) {
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.front())))
    text.remove_prefix(1);
  while (!text.empty() && std::isspace(static_cast<unsigned char>(text.back())))
    text.remove_suffix(1);
  return text;
}

/// Below this magnitude a path number is written 0: far under any machine's resolution (mm, or an
/// axis component), and its fixed form would run past an APT card.
inline constexpr double kPathZero = 1e-12;

/// The shortest decimal form that reads back as the same double, without an exponent: many APT
/// and CL post-processors and controllers refuse "4.8e-05" (an axis component of the impeller's
/// path was written so). Magnitudes under kPathZero are written 0 (or -0); past 1e32, where no
/// path goes (scene coordinates stop at 1e6 mm), with an exponent.
inline void appendNumber(std::string& out, double value) {
  if (std::abs(value) < kPathZero) {
    out.append(std::signbit(value) ? "-0" : "0");
    return;
  }
  char buffer[64];
  const auto fixed = std::to_chars(buffer, buffer + sizeof buffer, value, std::chars_format::fixed);
  if (fixed.ec == std::errc() && fixed.ptr - buffer <= 32) {
    out.append(buffer, fixed.ptr);
  } else {
    const auto general = std::to_chars(buffer, buffer + sizeof buffer, value);
    out.append(buffer, general.ptr);
  }
}

/// A path file's text as the readers take it: without a UTF-8 byte-order mark at its start
/// (editors on Windows write one). UTF-16 (its mark, as some Windows editors save) is refused
/// saying so (it read as "no GOTO records" or a
/// line of garbage); so are lines ended by a CR alone (classic Mac OS: the file read as one line
/// of too many columns).
inline std::string_view readableText(std::string_view text, const std::filesystem::path& file) {
  if (text.substr(0, 2) == "\xFF\xFE" || text.substr(0, 2) == "\xFE\xFF")
    throw common::InputError(file.string() + ": UTF-16 text: save it as UTF-8 or ASCII");
  // The first line tells (not a scan of the whole text: paths run to gigabytes).
  const std::string_view first = text.substr(0, text.find('\n'));
  if (const std::size_t cr = first.find('\r');
      cr != std::string_view::npos && cr + 1 < first.size())
    throw common::InputError(file.string() +
                             ":1: the line ends in a CR alone (classic Mac OS line ends): save "
                             "the file with LF or CRLF line ends");
  return text.substr(0, 3) == "\xEF\xBB\xBF" ? text.substr(3) : text;
}

/// Throws "FILE: reason" unless `file` is a regular file.
inline void requireRegularFile(const std::filesystem::path& file) {
  common::requireRegularFile(file, "path file");
}

/// Appends posture index `i` to the block list: a new block when `kind` differs from the last
/// block's or `split` is set.
inline void addToBlocks(std::vector<PathBlock>& blocks, PathBlock::Kind kind, bool split,
                        std::size_t i) {
  if (blocks.empty() || split || blocks.back().kind != kind)
    blocks.push_back({kind, i, i + 1});
  else
    blocks.back().end = i + 1;
}

/// The header lines that declare a path's posture count (checkDeclaredCount), as written.
inline constexpr std::string_view kClCountPrefix = "# postures: ";
inline constexpr std::string_view kAptCountPrefix = "PPRINT/POSTURES ";
/// The columns of an APT card: a record is continued on the next line with `$` past them (the
/// writer), and a card sequence number stands past them (the reader).
inline constexpr std::size_t kAptColumns = 72;

/// Whether `s` starts with `prefix`, ASCII letters compared without case.
inline bool startsWithNoCase(std::string_view s, std::string_view prefix) {
  if (s.size() < prefix.size()) return false;
  for (std::size_t i = 0; i < prefix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[i])) !=
        std::tolower(static_cast<unsigned char>(prefix[i])))
      return false;
  return true;
}

/// What follows a header line's count keyword, from its number on, or nullopt where the line
/// declares no count: `.cl` `# postures: N` in any case and spacing (`#Postures:N`), APT
/// `PPRINT/POSTURES N` in any case and spacing (`pprint / postures N`). A number declares: `.cl`
/// a comment `# postures: x y z i j k` is a comment, `# postures: 2x` or `-1` a count misread
/// (refused by checkDeclaredCount); an APT PPRINT is free text, so only a number standing alone
/// declares (`PPRINT/POSTURES 3-AXIS FINISH` is a remark).
inline std::optional<std::string_view> declaredCountText(std::string_view l, bool apt) {
  const auto skip = [](std::string_view& t) {
    while (!t.empty() && std::isspace(static_cast<unsigned char>(t.front()))) t.remove_prefix(1);
  };
  const auto digit = [](char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; };
  if (apt) {
    if (!startsWithNoCase(l, "PPRINT")) return std::nullopt;
    l.remove_prefix(6);
    skip(l);
    if (l.empty() || l.front() != '/') return std::nullopt;
    l.remove_prefix(1);
    skip(l);
    if (!startsWithNoCase(l, "POSTURES") || l.size() == 8 ||
        !std::isspace(static_cast<unsigned char>(l[8])))
      return std::nullopt;
    l.remove_prefix(8);
    skip(l);
    std::size_t n = 0;
    while (n < l.size() && digit(l[n])) ++n;
    const bool alone =
        n < l.size() ? std::isspace(static_cast<unsigned char>(l[n])) || l[n] == '(' : true;
    if (n == 0 || !alone) return std::nullopt;
    return l;
  }
  if (l.empty() || l.front() != '#') return std::nullopt;
  l.remove_prefix(1);
  skip(l);
  if (!startsWithNoCase(l, "postures")) return std::nullopt;
  l.remove_prefix(8);
  skip(l);
  if (l.empty() || l.front() != ':') return std::nullopt;
  l.remove_prefix(1);
  skip(l);
  const bool signed_number = l.size() > 1 && (l[0] == '-' || l[0] == '+') && digit(l[1]);
  if (l.empty() || !(digit(l.front()) || signed_number)) return std::nullopt;
  return l;
}

/// Whether a `.cl` text ends whole: its last line ended, or what follows its last line end is
/// blank or a comment (a cut there loses no posture; a whole file saved without its last line
/// end, ending in `# end`, was refused: a reviewer's finding).
inline bool clEndsWhole(std::string_view text) {
  const std::size_t last = text.rfind('\n');
  std::string_view tail = last == std::string_view::npos ? text : text.substr(last + 1);
  while (!tail.empty() && std::isspace(static_cast<unsigned char>(tail.front())))
    tail.remove_prefix(1);
  return tail.empty() || tail.front() == '#';
}

/// The posture count a path's writer declares in its header (`.cl`: `# postures: N ...`, APT:
/// `PPRINT/POSTURES N ...`, anywhere before the first posture), checked against the `read`
/// count: a path file cut short (a DNC or USB transfer) ends at a line boundary and reads as a
/// shorter, valid path that stops in the cut (a helper's 500 lines of a 1089-posture path.cl read
/// `check: ok`). A file that declares its count must also be whole (`complete`: `.cl` ends with a
/// line end, APT with FINI, as their writers end them): one cut inside its last record read the
/// fragment as a posture (`GOTO/0.37,15.03,1`: a 3-number GOTO at z = 1 where 17.8 was written,
/// `check: ok`; a `.cl` cut in its last axis, normalised). A declared number that is not a whole
/// number of postures (`2x`, `-1`, past 2^64) is refused (it switched the check off). Files that
/// declare nothing are taken as they are.
inline void checkDeclaredCount(std::string_view text, std::string_view prefix, std::size_t read,
                               const std::filesystem::path& file, bool complete) {
  const bool apt = prefix == kAptCountPrefix;
  std::size_t line = 1;
  for (std::size_t at = 0; at < text.size(); ++line) {
    const std::size_t end = std::min(text.find('\n', at), text.size());
    std::string_view l = text.substr(at, end - at);
    at = end + 1;
    while (!l.empty() && std::isspace(static_cast<unsigned char>(l.front()))) l.remove_prefix(1);
    if (apt ? startsWithNoCase(l, "GOTO") : !l.empty() && l.front() != '#') return;  // a posture
    const std::optional<std::string_view> rest = declaredCountText(l, apt);
    if (!rest) continue;
    std::size_t declared = 0;
    const char* first = rest->data();
    const char* last = rest->data() + rest->size();
    const auto [next, error] = std::from_chars(first, last, declared);
    if (error != std::errc() || next == first ||
        (next != last && !std::isspace(static_cast<unsigned char>(*next)) && *next != '\r'))
      fail(file, line,
           "'" + std::string(l.substr(0, std::min<std::size_t>(l.size(), 40))) +
               "': a posture count is a whole number (`" + std::string(prefix) +
               "N`, the number of postures the file holds)");
    if (declared != read)
      fail(file, line,
           "declares " + std::to_string(declared) + " postures and the file holds " +
               std::to_string(read) + ": it was cut short (a transfer?) or edited; write it " +
               "again, or delete this line to take the file as it is");
    if (!complete)
      fail(file, line,
           "declares " + std::to_string(declared) + " postures and the file ends " +
               (apt ? std::string("without FINI") : std::string("inside its last line")) +
               ": it was cut short (a transfer?) in its last record; write it again, or delete "
               "this line to take the file as it is");
    return;
  }
}

}  // namespace fieldpath::geometry::detail
