/// APT CLDATA written: one GOTO a posture on 72-column cards, RAPID before each link move,
/// FEDRAT/ before each pass, the safety marks and how the motions were checked in PPRINTs.
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <string_view>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/geometry/cl_file.h"
#include "path_chunks.h"
#include "path_text.h"

namespace fieldpath::geometry {
namespace {

using namespace detail;

/// The PPRINT of every APT output: how its motions were checked (README, "Path files").
constexpr std::string_view kAptMotionNote =
    "MOTIONS CHECKED WITH THE TIP ON A LINE AND THE TOOL AXIS ON THE GREAT CIRCLE BETWEEN "
    "GOTOS, RAPIDS TOO: POST THE TOOL VECTOR (NOT INTERPOLATED ROTARY ANGLES) AND RAPIDS AS "
    "LINEAR MOVES";
/// ... and what it leaves to the post or the operator (a post reading no SPINDL writes no M03).
constexpr std::string_view kAptSetupNote =
    "NO LOADTL, SPINDL OR COOLNT RECORDS: TOOL, SPINDLE SPEED AND COOLANT ARE SET IN THE POST OR "
    "AT THE MACHINE";

/// The text of a PPRINT or PARTNO card after its `/`.
constexpr std::size_t kAptTextColumns = kAptColumns - 7;

/// `MAJOR/` followed by `values` (numbers as the shortest text that reads back the same double),
/// on cards of kAptColumns: a line that would run past them ends after a comma with `$`, and the
/// record goes on in the next (a fixed-format post-processor cut the 131-column GOTOs).
void appendRecord(std::string& text, std::string_view major, std::span<const double> values) {
  std::string line(major);
  line += '/';
  for (std::size_t k = 0; k < values.size(); ++k) {
    std::string number;
    appendNumber(number, values[k]);
    if (k + 1 < values.size()) number += ',';
    // Room for the number and, unless it ends the record, a `$` after it.
    if (line.size() + number.size() + (k + 1 < values.size() ? 1 : 0) > kAptColumns &&
        line.back() == ',') {
      text += line + "$\n";
      line.clear();
    }
    line += number;
  }
  text += line + '\n';
}

void appendGoto(std::string& text, const Posture& p) {
  const double values[] = {p.tip_mm.x(), p.tip_mm.y(), p.tip_mm.z(),
                           p.axis.x(),   p.axis.y(),   p.axis.z()};
  appendRecord(text, "GOTO", values);
}

/// `major/text` as cards of kAptTextColumns characters of text, split between words where it
/// can (a PPRINT has no continuation: each card is a PPRINT of its own).
void appendTextCards(std::string& text, std::string_view major, std::string_view words) {
  do {
    std::size_t take = std::min(words.size(), kAptTextColumns);
    if (take < words.size())
      if (const auto blank = words.substr(0, take + 1).rfind(' ');
          blank != std::string_view::npos && blank > 0)
        take = blank;
    text += std::string(major) + "/" + std::string(words.substr(0, take)) + "\n";
    words.remove_prefix(take);
    while (!words.empty() && words.front() == ' ') words.remove_prefix(1);
  } while (!words.empty());
}

}  // namespace

void writeAptFile(const std::filesystem::path& file, const PathFile& path,
                  const AptHeader& header) {
  // CUTTER/d,r,e,f,a,b,h: diameter, corner radius, corner centre offsets (radial e, axial f),
  // taper angles a, b (0 for these tools), height h.
  const ToolSpec& t = header.tool;
  const double corner_mm = cornerRadius(t);
  // PARTNO is one card: a longer name is cut, and what would end or continue the record there
  // (a line break, a `$`: a scene file named so put raw lines into the program, an environment
  // sweep's) or no post-processor reads (control bytes) is a blank.
  std::string part_name =
      header.part_name.substr(0, std::min(header.part_name.size(), kAptTextColumns));
  for (char& c : part_name)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '$') c = ' ';
  std::string text = "PARTNO/" + part_name + "\n";
  // The count first: a safety mark's text runs on into the PPRINT cards after it.
  text += std::string(kAptCountPrefix) + std::to_string(path.postures.size()) +
          " (A FILE HOLDING FEWER WAS CUT SHORT)\n";
  for (const std::string& remark : header.remarks) {
    std::string line = upperCase(remark);
    for (char& c : line)  // one record, no continuation, nothing a post-processor cannot read
      if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f || c == '$') c = ' ';
    appendTextCards(text, "PPRINT", line);
  }
  text += "UNITS/MM\nMULTAX/ON\n";
  const double cutter[] = {2 * t.radius_mm, corner_mm, t.radius_mm - corner_mm, corner_mm, 0.0, 0.0,
                           t.length_mm};
  appendRecord(text, "CUTTER", cutter);
  // What check proves of a motion, for whoever writes the post: a controller that runs rotary
  // angles (A/B/C) interpolated, or a rapid axis by axis, sweeps other space (a machine-side
  // helper's finding: a dog-leg rapid crossed a wall that the straight retract cleared). After
  // CUTTER, not beside the safety marks: a mark's text runs on in the PPRINT cards after it.
  appendTextCards(text, "PPRINT", kAptMotionNote);
  appendTextCards(text, "PPRINT", kAptSetupNote);
  // A path marked unsafe halts before its first motion (STOP: M00 on post-processors): a PPRINT
  // is only read, and the program ran on (a machine-safety helper's finding).
  if (std::any_of(header.remarks.begin(), header.remarks.end(), [](const std::string& remark) {
        return upperCase(detail::safetyMark(remark)).rfind("UNSAFE TO RUN", 0) == 0;
      }))
    text += "STOP\n";
  // The feed in force: the path's own from the first of its FEDRATs (none before it, as read),
  // else the header's. Written before a pass and where it changes within one; a change at a link
  // waits for the next pass (a FEDRAT after RAPID would make the link's motion a feed move).
  double in_force =
      path.feeds.empty() ? header.feed_mm_per_min : std::numeric_limits<double>::quiet_NaN();
  std::size_t next_feed = 0;
  bool changed = true;
  for (const PathBlock& block : path.blocks) {
    for (std::size_t i = block.begin; i < block.end; ++i) {
      for (; next_feed < path.feeds.size() && path.feeds[next_feed].from <= i; ++next_feed) {
        changed = changed || !(path.feeds[next_feed].mm_per_min == in_force);
        in_force = path.feeds[next_feed].mm_per_min;
      }
      if (block.kind == PathBlock::Kind::Link) {
        text += "RAPID\n";
      } else if ((i == block.begin || changed) && std::isfinite(in_force)) {
        text += "FEDRAT/MMPM,";
        appendNumber(text, in_force);
        text += '\n';
        changed = false;
      }
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
