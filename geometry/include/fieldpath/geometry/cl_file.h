#pragma once
/// Path files (DESIGN.md "Conventions of data", "Passes from a nominal path", "Links and motion"):
/// `.cl` (x y z i j k [spindle_rad] per line, `#` comments, `# pass K` / `# link` block markers),
/// APT CLDATA (`GOTO/`, `RAPID` before link moves, `$` continuations, `$$` comments) and NumPy
/// `.npy` (float32 | float64, shape N×6 or N×7, C order).
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/tool.h"

namespace fieldpath::geometry {

/// A run of consecutive postures [begin, end) of a path: a cutting pass or a link between passes.
struct PathBlock {
  enum class Kind { Pass, Link };
  Kind kind = Kind::Pass;
  std::size_t begin = 0, end = 0;
  std::size_t size() const { return end - begin; }
  bool operator==(const PathBlock&) const = default;
};

/// A path as read from (or written to) a file: its postures and how they are grouped.
struct PathFile {
  std::filesystem::path file;  ///< where it was read from (for messages)
  std::vector<Posture> postures;
  /// In order, covering [0, postures.size()) without gaps; empty blocks are never stored. A file
  /// without markers is one pass block. `.cl`: `# pass ...` and blank lines start a pass block,
  /// `# link` a link block. APT: a GOTO after `RAPID` is a link posture, the others pass ones.
  std::vector<PathBlock> blocks;
  /// Per posture: the 1-based line of its record (`.cl`, APT), or its 0-based row (`.npy`).
  std::vector<std::size_t> lines;
  bool rows = false;  ///< `lines` are `.npy` rows
  /// Postures whose `.cl` line carries the comment `# limit ...` (generate marks the postures where
  /// an angle limit held), sorted.
  std::vector<std::size_t> limited;
  /// APT: the `CUTTER/d[, r, ...]` records (diameter d, corner radius r, length), in mm, in file
  /// order; those whose first values are not numbers are read past. Not compared here: the commands
  /// that take a tool say when the file was written for another one (app/cutter_note.h).
  struct Cutter {
    double diameter_mm = 0.0;
    double corner_mm = -1.0;  ///< -1: not given
    std::size_t line = 0;     ///< 1-based
    /// The record: CUTTER, or TLDATA (`TLDATA/MILL,d,r,...`, as NX writes the tool: a 16 mm flat
    /// end mill there against a 6 mm ball in the scene went unsaid).
    std::string record = "CUTTER";
    /// The tool's length from its tip (-1: not given): CUTTER's seventh value (h, the height of
    /// `CUTTER/d, r, e, f, a, b, h`, as the APT writer writes tool.length_mm) or TLDATA/MILL's
    /// third (`TLDATA/MILL, d, r, l, ...`). The holder sits there: a file's tool shorter than
    /// the scene's puts the holder nearer the part than the scene proves (a blisk helper's).
    double length_mm = -1.0;
  };
  std::vector<Cutter> cutters;
  /// APT tool loads (`LOAD/TOOL,n`, `LOADTL/n`): the tool's number as written and the line. More
  /// than one number: the file changes tools, the commands prove the scene's one.
  struct ToolLoad {
    std::string number;
    std::size_t line = 0;  ///< 1-based
  };
  std::vector<ToolLoad> tool_loads;
  /// The safety marks `generate` and `check` write at the top of a path: `# UNSAFE TO RUN: ...`
  /// and `# UNDER THE REQUIRED CLEARANCE: ...` comment lines (`.cl`), the same after `PPRINT/`
  /// (APT), as their text (from UNSAFE / UNDER on), in file order. `convert` carries them over.
  std::vector<std::string> warnings;
  /// APT: the feed of each `FEDRAT/` record in mm/min (NaN where it is per revolution, inverse
  /// time, or not read whole: apt_file.cpp feedOf), from posture `from` on, in file order (one
  /// after the last GOTO is not kept). `convert` writes them back; the other formats have no feed.
  struct Feed {
    std::size_t from = 0;
    double mm_per_min = 0.0;
    std::size_t line = 0;  ///< 1-based
    std::string text;      ///< where mm_per_min is NaN: the record's values, for messages
  };
  std::vector<Feed> feeds;
  /// APT: the line of the first `FROM/` record (0: none). Read past: the machine's move from
  /// that start point to the first GOTO is no motion of the path, and not checked.
  std::size_t from_line = 0;
  /// APT: the line of the first `MSYS/` record that is not the identity (0: none). Read past:
  /// the path is taken in the file's coordinates, not shifted nor turned into the frame it names.
  std::size_t msys_line = 0;
  /// APT: the line of the first `CUTCOM/` record that is not `CUTCOM/OFF` (0: none). Read past:
  /// the control's cutter offset is not applied, the path is taken where it is written.
  std::size_t cutcom_line = 0;

  /// "FILE:LINE" or "FILE: row R" of posture i, for messages.
  std::string where(std::size_t i) const;
  /// Number of blocks of a kind.
  std::size_t count(PathBlock::Kind kind) const;
};

/// How path files are read: on all cores (`threads` 0), the text cut at line ends into chunks of
/// about `chunk_bytes` (`.npy`: rows of that many bytes) parsed in parallel. The result, and every
/// error message, is the same whatever the two are.
struct PathReadOptions {
  unsigned threads = 0;
  std::size_t chunk_bytes = std::size_t{4} << 20;
};

enum class PathFormat { Cl, Apt, Npy };
/// By extension: `.npy`, `.apt` / `.cls` (APT CLDATA), anything else `.cl`.
PathFormat pathFormatOf(const std::filesystem::path& file);

/// Reads a path by its extension (pathFormatOf).
/// Throws common::InputError naming the file and the line (or row) for every defect: non-finite
/// numbers, short/long lines, zero or non-unit axes (axes off unit length by < 1e-3 are
/// normalised; by <= 1e-6, float rounding, kept as written), a tip coordinate beyond +-1e6 mm,
/// garbage, a missing file, a file without postures; `.npy`: a dtype other than float32/float64, a
/// shape other than N×6 / N×7, Fortran order, a truncated or padded file. Where a file has several
/// defects, the first in file order.
PathFile readPathFile(const std::filesystem::path& file, const PathReadOptions& options = {});

/// The readers behind readPathFile, by format whatever the extension.
PathFile readClPath(const std::filesystem::path& file, const PathReadOptions& options = {});
PathFile readAptPath(const std::filesystem::path& file, const PathReadOptions& options = {});
PathFile readNpyPath(const std::filesystem::path& file, const PathReadOptions& options = {});

/// A posture as the Z-buffer takes it: tip (mm) and unit axis rounded to float, 24 bytes.
struct CompactPosture {
  float tip_mm[3];
  float axis[3];
  /// cos, sin of the spindle angle (1, 0 where the file has no 7th column), from the double.
  float spindle_cos, spindle_sin;
};
inline CompactPosture compact(const Posture& p) {
  const bool turned = p.has_spindle && p.spindle_rad != 0.0;
  return {{float(p.tip_mm.x()), float(p.tip_mm.y()), float(p.tip_mm.z())},
          {float(p.axis.x()), float(p.axis.y()), float(p.axis.z())},
          turned ? float(std::cos(p.spindle_rad)) : 1.f,
          turned ? float(std::sin(p.spindle_rad)) : 0.f};
}

/// Where scanPathFile hands the postures over.
struct PostureChunkSink {
  /// Called once, before any chunk, with the number of chunks.
  std::function<void(std::size_t chunks)> begin;
  /// Called once per chunk from worker threads, in any order (chunk indices follow the file,
  /// from 0), with the chunk's postures in file order.
  std::function<void(std::size_t chunk, std::span<const CompactPosture> postures)> chunk;
  /// Optional: an APT file's tool records (its PathFile without postures: file, cutters,
  /// tool_loads), once, before `begin` (APT is read whole: scanPathFile's chunks are handed on
  /// after). Not called for .cl and .npy, which have none.
  std::function<void(const PathFile& records)> tool_records;
};

/// The postures of a path file, compact, without keeping the whole PathFile: for big files.
/// The same postures as compact(readPathFile(file).postures[i]), bit for bit, and the same
/// errors (thrown after every worker stopped; chunks before the error may have been handed
/// over). Returns the number of postures.
std::size_t scanPathFile(const std::filesystem::path& file, const PathReadOptions& options,
                         const PostureChunkSink& sink);

/// The postures of a `.cl` file (readClPath(file).postures).
std::vector<Posture> readClFile(const std::filesystem::path& file);
/// The GOTO postures of an APT file, links included (readAptPath(file).postures).
std::vector<Posture> readAptFile(const std::filesystem::path& file);

/// Writes a `.cl` file atomically, numbers in shortest round-trip form (reading it back gives the
/// same doubles): `comment` lines prefixed with "# ", then `# pass K` (K from 1) before each pass
/// block and `# link` before each link block (no markers when the path is one pass block), and
/// `  # limit` after the postures listed in `path.limited`. The spindle column is written for
/// postures with has_spindle.
void writeClFile(const std::filesystem::path& file, const PathFile& path,
                 std::string_view comment = {});
/// One pass of `postures`.
void writeClFile(const std::filesystem::path& file, std::span<const Posture> postures,
                 std::string_view comment = {});
/// The 1-based line of each posture in the file writeClFile(file, path, comment) writes, for a
/// comment of `comment_lines` lines (clCommentLines): messages computed before the file is
/// written name its lines, as those of a path read from a file do.
std::vector<std::size_t> clFileLines(const PathFile& path, std::size_t comment_lines);
/// The number of `#` lines writeClFile writes for `comment`.
std::size_t clCommentLines(std::string_view comment);

struct AptHeader {
  std::string part_name = "FIELDPATH";
  ToolSpec tool;
  /// The feed of every pass when the path has no `feeds` of its own (mm/min).
  double feed_mm_per_min = 1000;
  /// Operator messages written as `PPRINT/...` records after PARTNO (upper case, one a line).
  std::vector<std::string> remarks;
};

/// Writes APT CLDATA atomically: PARTNO, PPRINT remarks, UNITS/MM, MULTAX/ON, CUTTER/d,r,e,f,a,b,h,
/// then per block `FEDRAT/MMPM,f` before a pass's GOTOs and `RAPID` before each link GOTO, FINI.
/// The feed is the path's own (`path.feeds`: FEDRAT again where it changes within a pass, none
/// before a pass that no feed reaches) or, where it has none, the header's.
void writeAptFile(const std::filesystem::path& file, const PathFile& path,
                  const AptHeader& header);
/// One pass of `postures`.
void writeAptFile(const std::filesystem::path& file, std::span<const Posture> postures,
                  const AptHeader& header);

/// Writes `.npy` (float64, N×6, or N×7 if any posture has a spindle angle) atomically.
void writeNpyFile(const std::filesystem::path& file, std::span<const Posture> postures);

/// One pass block over `postures` (a path without markers).
PathFile singlePass(std::vector<Posture> postures);

/// Largest turn of the tool axis between two postures of a pass (deg): past it the axis is
/// flipped (its sign, or tip and ball centre confused), not a cutting move.
constexpr double kMaxPassAxisTurnDeg = 90.0;

/// InputError naming both lines if the tool axis turns more than kMaxPassAxisTurnDeg from
/// posture `before` to posture `i` of a pass.
void requireSteadyAxis(const PathFile& path, std::size_t before, std::size_t i);

}  // namespace fieldpath::geometry
