/// fieldpath convert IN OUT: a path file from one format to another (`.cl`, APT CLDATA, `.npy`),
/// each by its extension. The postures travel as doubles in every direction (`.cl` numbers in
/// shortest round-trip form, `.npy` float64), so a path converted and read back gives the same
/// postures bit for bit and `simulate` the same heights. `.npy` has no place for pass and link
/// blocks or `# limit` marks: converting to it says what was dropped. An APT output keeps the
/// feeds of an APT input (`FEDRAT/`) or takes `--feed`: never a feed of its own (1000 mm/min
/// was written over a FEDRAT/MMPM,150, a machine-side helper's finding).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_names.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool_model.h"

namespace fieldpath::app {
namespace {

namespace fs = std::filesystem;
using geometry::PathFormat;

/// The output format by extension; unlike reading (anything else is `.cl`), a typo in the name
/// of a file about to be written is refused. Any case, as the readers take it (`X.CL`).
PathFormat outputFormat(const fs::path& file) {
  const std::string ext = common::lowerExtension(file);
  if (ext == ".cl") return PathFormat::Cl;
  if (ext == ".apt" || ext == ".cls") return PathFormat::Apt;
  if (ext == ".npy") return PathFormat::Npy;
  throw InputError(file.string() + ": unknown output format '" + ext +
                   "' (expected .cl, .apt, .cls or .npy)");
}

const char* formatName(PathFormat format) {
  return format == PathFormat::Npy ? ".npy" : format == PathFormat::Apt ? "APT" : ".cl";
}

/// The feeds of an APT output: `--feed` over all (`feed_mm_per_min` > 0), else the input's own
/// FEDRATs, each a feed per minute within a machine's (the input's line named otherwise).
void takeFeeds(geometry::PathFile& path, double feed_mm_per_min, const fs::path& in,
               const fs::path& out, geometry::AptHeader& header) {
  if (feed_mm_per_min > 0.0) {
    path.feeds.clear();
    header.feed_mm_per_min = feed_mm_per_min;
    return;
  }
  if (path.feeds.empty())
    throw InputError(out.string() + ": APT output needs --feed (mm/min): " + in.string() +
                     " has no FEDRAT of its own");
  for (const geometry::PathFile::Feed& f : path.feeds) {
    const std::string where = in.string() + ":" + std::to_string(f.line) + ": FEDRAT";
    if (!std::isfinite(f.mm_per_min))
      throw InputError(where + "/" + f.text +
                       ": no feed per minute to write (one number > 0 with MMPM, IPM or the "
                       "file's unit; not per revolution or inverse time): give --feed");
    if (f.mm_per_min < common::kMinFeedMmPerMin || f.mm_per_min > common::kMaxFeedMmPerMin)
      throw InputError(where + ": " + common::shortNumber(f.mm_per_min) +
                       " mm/min is no machine's feed (0.001 to 1e6): give --feed");
  }
  // Passes before the first FEDRAT run at whatever feed the machine holds: written so, as read.
  const std::size_t first = path.feeds.front().from;
  for (const geometry::PathBlock& b : path.blocks)
    if (b.kind == geometry::PathBlock::Kind::Pass && b.begin < first) {
      std::fprintf(stderr,
                   "note: %s sets no feed before its line %zu: the GOTOs before it are written "
                   "with no FEDRAT, as read (--feed gives them one)\n",
                   in.string().c_str(), path.feeds.front().line);
      break;
    }
}

}  // namespace

void addConvertCommand(CLI::App& app, const GlobalOptions& /*global*/) {
  auto* cmd = app.add_subcommand(
      "convert", "A path file from one format to another (.cl, APT .apt/.cls, .npy) by extension");
  struct Options {
    std::string in, out, tool;
    double feed_mm_per_min = 0.0;  ///< 0: not given
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("IN", o->in, "Path file to read: .cl, APT (.apt/.cls) or .npy")->required();
  cmd->add_option("OUT", o->out, "Path file to write: .cl, .apt/.cls or .npy (float64)")
      ->required();
  cmd->add_option("--tool", o->tool,
                  "ball:R[:L] | torus:R:r[:L] | flat:R[:L]: the CUTTER record of an APT output "
                  "(required for APT)");
  cmd->add_option("--feed", o->feed_mm_per_min,
                  "mm/min: the FEDRAT of an APT output, over any feed of the input (required "
                  "for APT when the input has no FEDRAT of its own in mm/min)")
      ->check(numberFromTo(common::kMinFeedMmPerMin, common::kMaxFeedMmPerMin, "mm/min"));

  cmd->callback([o] {
    const fs::path in = o->in, out = o->out;
    const PathFormat to = outputFormat(out);
    if (to != PathFormat::Apt && o->feed_mm_per_min > 0.0)
      throw InputError(out.string() + ": --feed is the FEDRAT of an APT output; " + formatName(to) +
                       " has no feed");
    geometry::AptHeader header;
    if (to == PathFormat::Apt) {
      if (o->tool.empty())
        throw InputError(out.string() + ": APT output needs --tool (its CUTTER record)");
      header.tool = geometry::parseToolSpec(o->tool);
    }
    common::checkOutputFile(out, "OUT");  // before the reading, not after

    geometry::PathFile path = readPathFileWhole(in, in.string());
    const std::size_t feeds_read = path.feeds.size();
    if (to == PathFormat::Apt) takeFeeds(path, o->feed_mm_per_min, in, out, header);
    // The safety marks go with the path (`# ...` at the top of a .cl, PPRINT/ in APT): a path
    // that collides must not read as a clean program once converted. .npy has no room for them.
    std::string marks;
    for (const std::string& w : path.warnings) marks += w + "\n";
    header.remarks = path.warnings;
    if (to == PathFormat::Cl)
      geometry::writeClFile(out, path, marks + "converted from " + in.filename().string());
    else if (to == PathFormat::Apt)
      geometry::writeAptFile(out, path, header);
    else
      geometry::writeNpyFile(out, path.postures);
    common::commitOutputs();  // a summary or warning lost from here takes it not away
    for (const std::string& w : path.warnings)
      std::fprintf(stderr, "warning: %s is marked \"%s\": %s\n", in.string().c_str(), w.c_str(),
                   to == PathFormat::Npy ? ".npy cannot carry the mark: DROPPED, the .npy reads "
                                           "as a clean path"
                                         : "the mark is kept at the top of the output");

    const std::size_t passes = path.count(geometry::PathBlock::Kind::Pass);
    const std::size_t links = path.count(geometry::PathBlock::Kind::Link);
    // A loss of information is said even under --quiet (which silences progress, not warnings).
    if (to == PathFormat::Npy && (path.blocks.size() > 1 || !path.limited.empty()))
      std::fprintf(stderr,
                   "note: .npy keeps postures only: %zu pass and %zu link blocks%s dropped\n",
                   passes, links, path.limited.empty() ? "" : " and the # limit marks");
    if (path.from_line > 0)
      std::fprintf(stderr, "note: %s:%zu: FROM/ (the start point) is not carried: no path motion\n",
                   in.string().c_str(), path.from_line);
    if (to != PathFormat::Apt && feeds_read > 0)
      std::fprintf(stderr,
                   "note: %s has no feed: the %zu FEDRAT records dropped (converted back "
                   "to APT, give --feed)\n",
                   formatName(to), feeds_read);
    if (to == PathFormat::Apt) {
      if (o->feed_mm_per_min > 0.0 && feeds_read > 0)
        std::fprintf(stderr, "note: --feed %s mm/min written over the %zu FEDRAT records of %s\n",
                     common::shortNumber(o->feed_mm_per_min).c_str(), feeds_read,
                     in.string().c_str());
      // APT breaks a pass only with RAPID (a link's moves): passes that follow one another with
      // no link between them read back as one.
      std::size_t joined = 0, first = 0;
      for (std::size_t b = 0; b + 1 < path.blocks.size(); ++b)
        if (path.blocks[b].kind == geometry::PathBlock::Kind::Pass &&
            path.blocks[b + 1].kind == geometry::PathBlock::Kind::Pass && joined++ == 0)
          first = b;
      if (joined) {
        std::size_t pass_no = 0;  // 1-based number of the pass of block `first`
        for (std::size_t b = 0; b <= first; ++b)
          pass_no += path.blocks[b].kind == geometry::PathBlock::Kind::Pass;
        std::fprintf(stderr,
                     "note: %zu pass break%s with no link between the passes (first: passes %zu "
                     "and %zu): APT breaks a pass only with RAPID, so the passes either side of "
                     "such a break read back as one (as the machine runs them: straight on at "
                     "the feed)\n",
                     joined, joined > 1 ? "s" : "", pass_no, pass_no + 1);
      }
      if (!path.limited.empty())
        std::fprintf(stderr, "note: APT has no `# limit` marks: %zu dropped\n",
                     path.limited.size());
      // GOTO/x, y, z, i, j, k has no seventh value: the spindle column of a .cl or N×7 .npy.
      const std::size_t spindles =
          std::count_if(path.postures.begin(), path.postures.end(),
                        [](const geometry::Posture& p) { return p.has_spindle; });
      if (spindles > 0)
        std::fprintf(stderr,
                     "note: APT's GOTO has no spindle angle: the 7th column of %zu postures "
                     "dropped\n",
                     spindles);
    }
    std::printf("converted %zu postures (%zu passes, %zu links) from %s %s to %s %s\n",
                path.postures.size(), passes, links, formatName(geometry::pathFormatOf(in)),
                in.string().c_str(), formatName(to), out.string().c_str());
  });
}

}  // namespace fieldpath::app
