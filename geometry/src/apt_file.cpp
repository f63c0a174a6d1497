/// APT CLDATA as CAM systems write it and post-processors read it: `GOTO / x, y, z, i, j, k`
/// (spaces allowed, 3 values keep the last axis), `$` at a line's end continues the record, `$$`
/// starts a comment, `RAPID` makes the next motion a rapid (a link) unless a `FEDRAT` comes
/// between them, `UNITS/INCHES` scales the coordinates that follow to mm, `TLAXIS/i,j,k` sets the
/// axis of the 3-value GOTOs that follow, `FEDRAT/` records give the feeds (kept for `convert`),
/// `FROM/` is read past (its line kept: the move from the start point is not the path's; it is
/// GOHOME's point), `GODLTA` moves by dx, dy, dz or by d along the axis, `GOHOME` goes home,
/// `FINI` ends the program (nothing after it is read); motions it does not take (arcs, cycles,
/// drive-surface moves) are refused; every other record is read past.
#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <exception>
#include <fstream>
#include <iterator>
#include <limits>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "apt_records.h"
#include "fieldpath/geometry/cl_file.h"
#include "path_chunks.h"
#include "path_text.h"

namespace fieldpath::geometry {
namespace {

using namespace detail;
using common::InputError;

/// What one chunk of an APT file leaves to the chunks around it.
struct AptChunk {
  PathChunk postures;
  bool first_without_rapid = false;  ///< its first GOTO had no RAPID before it in this chunk
  bool trailing_rapid = false;       ///< a RAPID after its last GOTO (or anywhere, if none)
  /// A FEDRAT before its first GOTO (or anywhere, if none) with no RAPID after it: it cancels a
  /// RAPID pending from an earlier chunk (the next motion is a feed move, as posts read it).
  bool cancels_rapid = false;
  std::size_t inherit_axis = 0;      ///< leading 3-number GOTOs: they keep an earlier chunk's axis
  std::optional<Vec3> end_axis;      ///< the axis in force at its end (a GOTO's or TLAXIS'), if set
  /// UNITS records: (first posture after it, mm per file unit), in order.
  std::vector<std::pair<std::size_t, double>> units;
  bool fini = false;  ///< FINI seen: the program ends there; later records are not read
  /// CUTTER records in file units, each with the count of this chunk's UNITS records before it.
  std::vector<std::pair<std::size_t, PathFile::Cutter>> cutters;
  std::vector<PathFile::ToolLoad> tool_loads;  ///< in the file's order
  std::vector<AptFeed> feeds;                  ///< FEDRAT records, in the file's order
  std::size_t from_line = 0;  ///< its first FROM record's line (0: none)
  /// FROM/x, y, z[, ...] records (the start and home point), in file units: `posture` is the
  /// chunk's posture after it, `units_before` the count of its UNITS records before it.
  struct From {
    Vec3 tip;
    std::size_t posture = 0, units_before = 0, line = 0;
  };
  std::vector<From> froms;
  /// GODLTA postures (their tip holds the move, in file units: dx, dy, dz, or d along the tool
  /// axis in x) and GOHOME ones, by index: resolved where the chunks are joined, from where the
  /// motion before ends (an earlier chunk's, or FROM/'s).
  struct Relative {
    std::size_t posture = 0;
    bool along_axis = false;
  };
  std::vector<Relative> relative;
  std::vector<std::size_t> home;
  std::size_t msys_line = 0;  ///< its first MSYS record that is not the identity (0: none)
  std::size_t cutcom_line = 0;  ///< its first CUTCOM record that is not CUTCOM/OFF (0: none)
};

void parseAptChunk(std::string_view text, std::size_t first_line,
                   const std::filesystem::path& file, AptChunk& out) {
  bool rapid = false;  // RAPID seen: the next motion is a link
  bool own_axis = false;  // a 6-number GOTO or a TLAXIS seen in this chunk
  Vec3 axis_now = Vec3::UnitZ();  // the axis of a 3-number GOTO here (once own_axis)
  std::string record;  // a statement, with `$` continuation lines joined
  bool in_mark = false;  // the record before was a PPRINT safety mark's card
  std::size_t record_line = 0, line = first_line;
  PathChunk& chunk = out.postures;
  for (std::size_t pos = 0; pos < text.size(); ++line) {
    std::size_t nl = text.find('\n', pos);
    if (nl == std::string_view::npos) nl = text.size();
    const std::string_view content = aptContent(text.substr(pos, nl - pos));
    pos = nl + 1;
    if (record.empty()) record_line = line;
    // A GOTO line that a `$` joined to the record above (`COOLNT/ON $`): its motion would be lost.
    if (!record.empty() && upperCase(content.substr(0, 4)) == "GOTO")
      fail(file, line, "a GOTO joined by the `$` ending the line above to its record (the "
                       "motion would be lost): end that line without `$`");
    if (continuesRecord(content)) {
      record += content.substr(0, content.size() - 1);
      continue;
    }
    // A comment line (or a blank one) inside a continued record: read past, the record goes on
    // (`GOTO/1,2,0,$` then `$$ note` then `0,0,1`, as CATIA writes: refused as a GOTO of 3 values
    // and a comma, an adversary's).
    if (!record.empty() && content.empty()) continue;
    record += content;
    const std::string statement = upperCase(record);
    const auto slash = statement.find('/');
    const std::string_view major =
        trimmed(std::string_view(statement).substr(0, std::min(slash, statement.size())));
    // A safety mark goes on in the PPRINT cards right after it (the writer splits a long one).
    const bool pprint = major == "PPRINT" && slash != std::string::npos;
    std::string mark = pprint ? safetyMark(std::string_view(record).substr(slash + 1)) : "";
    if (!mark.empty()) {
      chunk.warnings.push_back(std::move(mark));
      in_mark = true;
    } else if (pprint && in_mark) {
      chunk.warnings.back() +=
          " " + std::string(trimmed(std::string_view(record).substr(slash + 1)));
    } else {
      in_mark = false;
    }
    record.clear();
    if (major == "RAPID") {
      rapid = true;
      if (chunk.postures.empty()) out.cancels_rapid = false;
      continue;
    }
    if (major == "FEDRAT") {  // a feed rate set after RAPID: the next motion is a feed move
      rapid = false;
      if (chunk.postures.empty()) out.cancels_rapid = true;
      if (slash != std::string::npos) {
        out.feeds.push_back(feedOf(std::string_view(statement).substr(slash + 1), record_line,
                                   chunk.postures.size()));
        out.feeds.back().units_before = out.units.size();
      }
      continue;
    }
    if (major == "FINI") {
      out.fini = true;
      break;
    }
    if (major == "FROM") {
      if (out.from_line == 0) out.from_line = record_line;
      double v[3];
      const std::size_t n =
          slash == std::string::npos
              ? 0
              : leadingNumbers(std::string_view(statement).substr(slash + 1), v, 3);
      if (n == 3)  // the home point of a GOHOME (another form: no home, GOHOME refused)
        out.froms.push_back(
            {Vec3(v[0], v[1], v[2]), chunk.postures.size(), out.units.size(), record_line});
      continue;
    }
    if (major == "CUTCOM") {  // the control's offset of the cutter: read past, said unless OFF
      const bool off = slash != std::string::npos &&
                       trimmed(std::string_view(statement).substr(slash + 1)).starts_with("OFF");
      if (!off && out.cutcom_line == 0) out.cutcom_line = record_line;
      continue;
    }
    if (major == "MSYS") {  // origin, x axis, y axis: read past, a shifted or turned frame said
      double v[9] = {};
      const bool identity =
          slash != std::string::npos &&
          leadingNumbers(std::string_view(statement).substr(slash + 1), v, 9) == 9 && v[0] == 0 &&
          v[1] == 0 && v[2] == 0 && v[3] == 1 && v[4] == 0 && v[5] == 0 && v[6] == 0 && v[7] == 1 &&
          v[8] == 0;
      if (!identity && out.msys_line == 0) out.msys_line = record_line;
      continue;
    }
    if (major == "CUTTER") {
      if (slash != std::string::npos)
        if (auto cutter = cutterOf(std::string_view(statement).substr(slash + 1), record_line, 6))
          out.cutters.emplace_back(out.units.size(), *cutter);
      continue;
    }
    if ((major == "LOAD" || major == "LOADTL") && slash != std::string::npos) {
      // LOAD/TOOL, n[, ...] or LOADTL/n[, ...]: the number (or name) of the tool loaded.
      std::string_view values = trimmed(std::string_view(statement).substr(slash + 1));
      if (major == "LOAD") {
        const auto comma = values.find(',');
        if (trimmed(values.substr(0, comma)) != "TOOL" || comma == std::string_view::npos) continue;
        values = values.substr(comma + 1);
      }
      const std::string_view number = trimmed(values.substr(0, values.find(',')));
      if (!number.empty()) out.tool_loads.push_back({std::string(number), record_line});
      continue;
    }
    if (major == "TLDATA" && slash != std::string::npos) {  // TLDATA/MILL, d, r, ...: a cutter
      const std::string_view values = trimmed(std::string_view(statement).substr(slash + 1));
      const auto comma = values.find(',');
      if (trimmed(values.substr(0, comma)) == "MILL" && comma != std::string_view::npos)
        if (auto cutter = cutterOf(values.substr(comma + 1), record_line, 2)) {
          cutter->record = "TLDATA";
          out.cutters.emplace_back(out.units.size(), *cutter);
        }
      continue;
    }
    if (major == "UNITS") {
      const std::string_view value = slash == std::string::npos
                                         ? std::string_view()
                                         : trimmed(std::string_view(statement).substr(slash + 1));
      const double scale = unitScale(value);
      if (scale == 0.0)
        fail(file, record_line, "UNITS/" + std::string(value) + ": unknown unit (MM or INCHES)");
      out.units.emplace_back(chunk.postures.size(), scale);
      continue;
    }
    const std::string_view values = slash == std::string::npos
                                        ? std::string_view()
                                        : std::string_view(statement).substr(slash + 1);
    if (major == "TLAXIS") {
      // TLAXIS/i, j, k[, ...]: the axis of the 3-number GOTOs that follow (APT's modal axis).
      // Other forms (TLAXIS/NORMPS, ...) leave them the last axis, as before: read past.
      double v[3];
      if (leadingNumbers(values, v, 3) == 3) {
        axis_now = checkedAxis(Vec3(v[0], v[1], v[2]),
                               [&] { return file.string() + ":" + std::to_string(record_line); });
        own_axis = true;
      }
      continue;
    }
    // The motions the reader takes: GOTO, GODLTA (a move by dx, dy, dz, or by d along the tool
    // axis) and GOHOME (to the FROM/ point: a rapid, as posts run it); they keep the axis.
    if (major == "GODLTA" || major == "GOHOME") {
      Posture p;
      bool along_axis = false;
      if (major == "GODLTA") {
        double v[3] = {};
        const std::size_t n = leadingNumbers(values, v, 3);
        const auto fields =
            static_cast<std::size_t>(std::count(values.begin(), values.end(), ',')) + 1;
        if (slash == std::string::npos || (n != 1 && n != 3) || fields != n)
          fail(file, record_line,
               "GODLTA/: need d (a move along the tool axis) or dx, dy, dz (a move by them)");
        along_axis = n == 1;
        p.tip_mm = Vec3(v[0], v[1], v[2]);
        out.relative.push_back({chunk.postures.size(), along_axis});
      } else {
        if (slash != std::string::npos && !trimmed(values).empty())
          fail(file, record_line, "GOHOME/: this reader takes GOHOME alone (to the FROM/ point)");
        out.home.push_back(chunk.postures.size());
      }
      p.axis = axis_now;
      if (!own_axis) ++out.inherit_axis;
      const bool link = rapid || major == "GOHOME";
      if (chunk.postures.empty()) out.first_without_rapid = !link;
      if (link) chunk.links.push_back(chunk.postures.size());
      rapid = false;
      chunk.postures.push_back(p);
      chunk.lines.push_back(record_line);
      continue;
    }
    // A motion the reader does not take would be a posture lost without a word: GOTO not at
    // the record's start (`RAPID,GOTO/`, `N40 GOTO/`, `GO TO/`), arcs (CIRCLE/ before a GOTO
    // makes it an arc; MOVARC), drive-surface motions (GOFWD, GOLFT, ...), a canned cycle (its
    // GOTOs become plunges).
    static constexpr std::string_view kMotions[] = {"CIRCLE", "MOVARC", "GOFWD", "GOLFT",
                                                    "GORGT",  "GOBACK", "GOUP",  "GODOWN"};
    const bool motion_word =
        std::find(std::begin(kMotions), std::end(kMotions), major) != std::end(kMotions);
    const bool cycle = major == "CYCLE" && trimmed(values) != "OFF";
    if (major != "GOTO" && (major.find("GOTO") != std::string_view::npos ||
                            major.find("GO TO") != std::string_view::npos || motion_word || cycle))
      fail(file, record_line,
           std::string(major) + "/: a motion record this reader does not take (a GOTO/ record "
           "of its own, absolute x, y, z[, i, j, k]; no arcs, cycles or relative moves)");
    if (major != "GOTO" || slash == std::string::npos) continue;
    double v[6];
    std::size_t count = 0;
    const std::string_view rest = std::string_view(statement).substr(slash + 1);
    for (std::size_t start = 0; start <= rest.size();) {
      const auto comma = std::min(rest.find(',', start), rest.size());
      const auto tokens = splitWhitespace(rest.substr(start, comma - start));
      if (tokens.size() != 1) fail(file, record_line, "GOTO: expected comma-separated numbers");
      const double value = parseFinite(tokens[0], file, record_line);
      if (count < 6) v[count] = value;
      ++count;
      start = comma + 1;
    }
    if (count != 6 && count != 3)
      fail(file, record_line, "GOTO: " + std::to_string(count) + " numbers, need x,y,z[,i,j,k]");
    const auto where = [&] { return file.string() + ":" + std::to_string(record_line); };
    Posture p;
    p.tip_mm = Vec3(v[0], v[1], v[2]);
    checkTip(p.tip_mm, where);
    // A 3-number GOTO keeps the previous axis (APT modal behaviour); before this chunk's first
    // 6-number GOTO, that axis is an earlier chunk's (filled in when the chunks are joined).
    if (count == 6) {
      p.axis = checkedAxis(Vec3(v[3], v[4], v[5]), where);
      axis_now = p.axis;
      own_axis = true;
    } else {
      p.axis = axis_now;
      if (!own_axis) ++out.inherit_axis;
    }
    if (chunk.postures.empty()) out.first_without_rapid = !rapid;
    if (rapid) chunk.links.push_back(chunk.postures.size());
    rapid = false;
    chunk.postures.push_back(p);
    chunk.lines.push_back(record_line);
  }
  if (!record.empty())
    fail(file, record_line, "the record goes on with `$` past the end of the file (truncated?)");
  out.trailing_rapid = rapid;
  if (own_axis) out.end_axis = axis_now;
}

/// The GODLTA and GOHOME postures of chunk `c` (its tips in mm, its axes set), from where the
/// motion before each ends: `last_tip` (the chunks before), or the FROM/ point `home` for a
/// GODLTA before any motion; both carried on to the next chunk. `chunk_scale`: mm per file
/// unit at the chunk's start (a FROM/ before its first UNITS record is in it).
void resolveRelativeMoves(AptChunk& c, double chunk_scale, const std::filesystem::path& file,
                          std::optional<AptChunk::From>& home, std::optional<Vec3>& last_tip) {
  std::vector<Posture>& postures = c.postures.postures;
  std::size_t next_from = 0, next_relative = 0, next_home = 0;
  const auto takeFromsUpTo = [&](std::size_t k) {
    for (; next_from < c.froms.size() && c.froms[next_from].posture <= k; ++next_from) {
      AptChunk::From from = c.froms[next_from];
      from.tip =
          inMm(from.tip, from.units_before ? c.units[from.units_before - 1].second : chunk_scale);
      home = from;
    }
  };
  for (std::size_t k = 0; k < postures.size(); ++k) {
    takeFromsUpTo(k);
    const std::size_t line = c.postures.lines[k];
    if (next_relative < c.relative.size() && c.relative[next_relative].posture == k) {
      const bool along_axis = c.relative[next_relative++].along_axis;
      const std::optional<Vec3> before = k > 0      ? std::optional<Vec3>(postures[k - 1].tip_mm)
                                         : last_tip ? last_tip
                                         : home     ? std::optional<Vec3>(home->tip)
                                                    : std::nullopt;
      if (!before)
        fail(file, line, "GODLTA/: no position before it to move from (a GOTO or a FROM/)");
      const Vec3 move = along_axis ? postures[k].tip_mm.x() * postures[k].axis : postures[k].tip_mm;
      postures[k].tip_mm = onPicometres(*before + move);
    } else if (next_home < c.home.size() && c.home[next_home] == k) {
      ++next_home;
      if (!home) fail(file, line, "GOHOME: no FROM/x, y, z before it (the home point it goes to)");
      // The axis kept, as every motion here keeps it: FROM/'s axis taken here swung 37 deg out
      // and back, the next 3-value GOTO keeping the old one (a regression hunt's).
      postures[k].tip_mm = home->tip;
    } else {
      continue;
    }
    checkTip(postures[k].tip_mm, [&] { return file.string() + ":" + std::to_string(line); });
  }
  takeFromsUpTo(std::numeric_limits<std::size_t>::max());
  if (!postures.empty()) last_tip = postures.back().tip_mm;
}

}  // namespace

PathFile readAptPath(const std::filesystem::path& file, const PathReadOptions& options) {
  const MappedFile mapped(file);
  const std::string_view text = readableText(mapped.text(), file);
  const std::vector<TextChunk> pieces =
      splitAtLines(text, options.chunk_bytes, options.threads,
                   // (never after a comment line either: it may lie inside a continued record)
                   [](std::string_view line) {
                     const std::string_view content = aptContent(line);
                     return content.empty() || continuesRecord(content);
                   });
  std::vector<AptChunk> chunks(pieces.size());
  // A chunk's error counts only if no FINI comes before it: kept, and thrown in file order below.
  std::vector<std::exception_ptr> errors(pieces.size());
  forEachChunk(pieces.size(), options.threads, [&](std::size_t i) {
    const TextChunk& c = pieces[i];
    try {
      parseAptChunk(text.substr(c.begin, c.end - c.begin), c.first_line, file, chunks[i]);
    } catch (const InputError&) {
      errors[i] = std::current_exception();
    }
  });
  // What crosses chunk boundaries: a RAPID pending, and the axis of 3-number GOTOs.
  // And the unit: a UNITS record holds until the next; inches are read as mm x 25.4.
  std::vector<std::size_t> link_postures;
  std::vector<PathFile::Cutter> cutters;
  std::vector<PathFile::ToolLoad> tool_loads;
  std::vector<PathFile::Feed> feeds;
  std::size_t from_line = 0, msys_line = 0, cutcom_line = 0;
  bool pending = false, ended = false;
  double scale = 1.0;
  std::size_t offset = 0;
  Vec3 carried_axis = Vec3::UnitZ();  // the axis in force at the end of the chunks so far
  std::optional<AptChunk::From> home;  // the FROM/ point in force, in mm
  std::optional<Vec3> last_tip;        // where the chunks so far end, mm
  // The errors found here wait for the chunks' own (a reader of the whole file meets those first;
  // fuzzers: a tip too far in inches, or a GODLTA from nowhere, said before a bad GOTO further on
  // in chunks), the tips too far first, as the whole file's scaling meets them before its moves.
  std::exception_ptr too_far;          // the first tip past the readers' range once in mm
  std::exception_ptr unresolved;       // the first GODLTA or GOHOME with nowhere to go
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    AptChunk& c = chunks[i];
    auto& postures = c.postures.postures;
    if (!ended && errors[i]) std::rethrow_exception(errors[i]);
    if (ended) {  // after FINI
      postures.clear();
      c.postures.lines.clear();
      c.postures.links.clear();
      continue;
    }
    ended = c.fini;
    if (from_line == 0) from_line = c.from_line;
    if (msys_line == 0) msys_line = c.msys_line;
    if (cutcom_line == 0) cutcom_line = c.cutcom_line;
    tool_loads.insert(tool_loads.end(), c.tool_loads.begin(), c.tool_loads.end());
    for (auto& [units_before, cutter] : c.cutters) {  // in the unit of the record before it
      const double unit = units_before ? c.units[units_before - 1].second : scale;
      cutter.diameter_mm = inMm(cutter.diameter_mm, unit);
      if (cutter.corner_mm > 0.0) cutter.corner_mm = inMm(cutter.corner_mm, unit);
      if (cutter.length_mm > 0.0) cutter.length_mm = inMm(cutter.length_mm, unit);
      cutters.push_back(cutter);
    }
    for (const AptFeed& f : c.feeds) {  // in the unit in force at the record
      PathFile::Feed feed = f.feed;
      const double unit = f.unit > 0.0     ? f.unit
                          : f.units_before ? c.units[f.units_before - 1].second
                                           : scale;
      // To the micrometre a minute: 3 in/min is 76.2, not 76.19999999999999.
      feed.mm_per_min = std::round(feed.mm_per_min * unit * 1e6) / 1e6;
      feed.from += offset;
      feeds.push_back(feed);
    }
    const double chunk_scale = scale;  // the unit in force at the chunk's start
    std::size_t next_unit = 0;
    for (std::size_t k = 0; k < postures.size(); ++k) {
      while (next_unit < c.units.size() && c.units[next_unit].first <= k)
        scale = c.units[next_unit++].second;
      postures[k].tip_mm = inMm(postures[k].tip_mm, scale);
      // Checked in mm: 50000 inches passed the readers' +-1e6 as read, then `convert` refused
      // its own 1.27e6 mm output (a helper's finding).
      if (scale != 1.0 && !too_far) {
        try {
          checkTip(postures[k].tip_mm,
                   [&] { return file.string() + ":" + std::to_string(c.postures.lines[k]); });
        } catch (const InputError&) {
          too_far = std::current_exception();
        }
      }
    }
    if (next_unit < c.units.size()) scale = c.units.back().second;
    for (std::size_t k = 0; k < c.inherit_axis; ++k) postures[k].axis = carried_axis;
    if (c.end_axis) carried_axis = *c.end_axis;
    try {
      resolveRelativeMoves(c, chunk_scale, file, home, last_tip);
    } catch (const InputError&) {
      if (!unresolved) unresolved = std::current_exception();
    }
    if (postures.empty()) {
      pending = c.trailing_rapid || (pending && !c.cancels_rapid);
      continue;
    }
    if (c.first_without_rapid && pending && !c.cancels_rapid) link_postures.push_back(offset);
    for (std::size_t k : c.postures.links) link_postures.push_back(offset + k);
    pending = c.trailing_rapid;
    offset += postures.size();
  }
  if (too_far) std::rethrow_exception(too_far);
  if (unresolved) std::rethrow_exception(unresolved);
  PathFile path;
  path.file = file;
  path.cutters = std::move(cutters);
  path.tool_loads = std::move(tool_loads);
  path.from_line = from_line;
  path.msys_line = msys_line;
  path.cutcom_line = cutcom_line;
  for (const PathFile::Feed& f : feeds)
    if (f.from < offset) path.feeds.push_back(f);  // a FEDRAT after the last GOTO feeds nothing
  if (offset == 0) throw InputError(file.string() + ": no GOTO records");
  // Blocks: runs of link postures between pass runs.
  std::size_t next = 0;
  for (std::size_t i : link_postures) {
    if (i > next) path.blocks.push_back({PathBlock::Kind::Pass, next, i});
    addToBlocks(path.blocks, PathBlock::Kind::Link, false, i);
    next = i + 1;
  }
  if (next < offset) path.blocks.push_back({PathBlock::Kind::Pass, next, offset});
  std::vector<PathChunk> parts;
  parts.reserve(chunks.size());
  for (AptChunk& c : chunks) parts.push_back(std::move(c.postures));
  concatenate(parts, options.threads, path);
  checkDeclaredCount(text, kAptCountPrefix, path.postures.size(), file, ended);
  return path;
}

}  // namespace fieldpath::geometry
