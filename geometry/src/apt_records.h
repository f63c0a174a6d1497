#pragma once
/// One APT CLDATA record's text and values (apt_file.cpp reads the file with them): a line's
/// content without card numbers and comments, whether it goes on in the next line, and the
/// values of the CUTTER / TLDATA, FEDRAT and UNITS records.
#include <cstddef>
#include <optional>
#include <string_view>

#include "fieldpath/geometry/cl_file.h"

namespace fieldpath::geometry::detail {

/// A FEDRAT record's feed (`feed.from`: the chunk's posture after it) as written, in mm per
/// minute times `unit` (0: the file's unit in force; `units_before` counts the chunk's UNITS
/// records before it, set by the chunk's reader).
struct AptFeed {
  PathFile::Feed feed;
  double unit = 1.0;
  std::size_t units_before = 0;
};

/// PPRINT, PARTNO, INSERT and REMARK carry text: a `$` in it is the text's (at its end it
/// swallowed the next GOTO; a Siemens post's `INSERT/R1=$P_TOOLNO` names a variable).
bool isTextRecord(std::string_view content);

/// A line's content without its `$$` comment and surrounding blanks. A single `$` followed by a
/// blank continues the statement on the next line and what follows it is a remark
/// (`GOTO/0,0,-0.5,$ first part` was refused as a bad number); the content then ends at that
/// `$`. Not in text records, whose text may hold a `$`.
std::string_view aptContent(std::string_view line);

/// The leading finite numbers of comma-separated `values` (at most `max`, into v): how many.
std::size_t leadingNumbers(std::string_view values, double* v, std::size_t max);

/// CUTTER/d[, r, ...]: diameter, corner radius and length (the value at `length_at`, 0-based:
/// 6 for CUTTER's h, 2 for TLDATA/MILL's l) in file units, or nothing when the first value is
/// not a number (a CAM's `CUTTER/TOOL1`: read past, as DESIGN.md says of CUTTER). A diameter
/// <= 0 is kept as written (app/cutter_note.h says the record gives no tool).
std::optional<PathFile::Cutter> cutterOf(std::string_view values, std::size_t line,
                                         std::size_t length_at);

/// A FEDRAT record's feed: its number in `feed.mm_per_min` and, in `unit`, mm per unit of it:
/// 1 with MMPM, 25.4 with IPM, 0 (the file's unit) with none or PERMIN. NaN, with the record's
/// text in `feed.text`, where it is per revolution (IPR, MMPR, PERREV, REV), inverse time
/// (INVERS), or not read whole: no number or one <= 0, a second number, a word of no feed
/// (`FEDRAT/IMP,10`, a typo, was read as 10 mm/min) or two units.
AptFeed feedOf(std::string_view values, std::size_t line, std::size_t posture);

/// mm per unit of a UNITS record's value (MM, INCHES), 0 if unknown.
double unitScale(std::string_view value);

/// A length of the file in mm, `mm_per_unit` the unit's (25.4: inches), on a picometre grid
/// where that is not 1: 0.7874 in is 19.99996 mm, not the product's 19.999959999999998 that
/// `convert` wrote (an adversary's). The grid holds an inch value of up to 7 decimals exactly
/// and the readers' range (1e6 mm) in a double's 53 bits. Where the unit is mm, as read.
double inMm(double value, double mm_per_unit);
Vec3 inMm(const Vec3& value, double mm_per_unit);

/// A sum of lengths in mm (a relative move from where the path is) on the same grid: 0.1 + 0.2
/// is 0.3.
Vec3 onPicometres(const Vec3& value);

/// Whether a line's content goes on in the next line (`$` at its end, not a text record's).
/// Decided by the line alone, so that the chunk splitter and the parser agree: a PPRINT line
/// inside a continued record ends it too (the fuzzer found them disagreeing there).
bool continuesRecord(std::string_view content);

}  // namespace fieldpath::geometry::detail
