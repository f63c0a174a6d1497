#pragma once
/// The CLI's progress line on stderr (for work over a second; silenced by --quiet).
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <string>

#include <unistd.h>

#include "fieldpath/common/progress.h"

namespace fieldpath::app {

/// Whether a progress line is drawn without its line end: a message now would run on from it
/// ("passes  30.0%  1.0 sfieldpath: error: ...", a helper's finding).
inline bool& progressLineOpen() {
  static bool open = false;
  return open;
}

/// --quiet, for the lines drawn outside a command's own Progress hook (set once its options are
/// parsed).
inline bool& progressQuiet() {
  static bool quiet = false;
  return quiet;
}

/// Ends a progress line left open, before a message of its own.
inline void endProgressLine() {
  if (!progressLineOpen()) return;
  std::fputc('\n', stderr);
  progressLineOpen() = false;
}

/// The time a stage still needs at its pace so far, as the progress line says it ("  ~40 s left",
/// "  ~12 min left", "  ~2.5 h left"); empty until 5 s and 2 % of the stage have passed (the first
/// moments' pace says little) and at its end. A slow job (the direct field over a dense scene ran
/// 0.1 % in 15 s: a helper took it for hung) tells its user what waiting means.
/// `fraction` is the whole work's, `from` where it stood when the stage began.
inline std::string timeLeftText(double stage_s, double fraction, double from = 0.0) {
  const double done = (fraction - from) / (1.0 - from);  // of the stage
  if (!(done >= 0.02 && done < 1.0 && stage_s >= 5.0)) return {};
  const double rest_s = stage_s * (1.0 - done) / done;
  char text[32];
  if (rest_s < 90.0)
    std::snprintf(text, sizeof text, "  ~%.0f s left", rest_s);
  else if (rest_s < 5400.0)
    std::snprintf(text, sizeof text, "  ~%.0f min left", rest_s / 60.0);
  else
    std::snprintf(text, sizeof text, "  ~%.1f h left", rest_s / 3600.0);
  return text;
}

/// Makes a Progress hook that, on a terminal, redraws one stderr line at most 10 times a second,
/// and only once the work has run for a second. Into a file or a pipe (a log) the redraws would
/// pile up on one line (a newcomer's log): there a whole line at most every 10 s, and at 100 %.
/// Quiet → a hook that never prints.
inline common::Progress makeProgressLine(bool quiet) {
  if (quiet) return [](double, std::string_view) { return true; };
  const bool terminal = isatty(fileno(stderr)) != 0;
  const auto every = terminal ? std::chrono::milliseconds(100) : std::chrono::milliseconds(10000);
  const auto start = std::chrono::steady_clock::now();
  auto last = start;
  std::string finished;  // the work whose 100 % line was printed (a second report of it is not)
  std::string stage;     // the work now reported, and since when (its time left is its own)
  auto stage_start = start;
  double stage_from = 0.0;
  return [=](double fraction, std::string_view what) mutable {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed_s = std::chrono::duration<double>(now - start).count();
    if (what != stage) {
      stage = what;
      stage_start = now;
      stage_from = fraction < 1.0 ? fraction : 0.0;
    }
    if (elapsed_s < 1.0 || (now - last < every && fraction < 1.0)) return true;
    if (fraction >= 1.0 && finished == what) return true;
    finished = fraction >= 1.0 ? std::string(what) : std::string();
    last = now;
    const bool ends = fraction >= 1.0 || !terminal;
    std::string left = timeLeftText(std::chrono::duration<double>(now - stage_start).count(),
                                    fraction, stage_from);
    // Padded on a terminal: a shorter line drawn over a longer one leaves none of it.
    if (terminal && left.size() < 16) left.append(16 - left.size(), ' ');
    std::fprintf(stderr, "%s%-24.*s %5.1f%%  %6.1f s%s%s", terminal ? "\r" : "",
                 static_cast<int>(what.size()), what.data(), 100.0 * fraction, elapsed_s,
                 left.c_str(), ends ? "\n" : "");
    progressLineOpen() = !ends;
    std::fflush(stderr);
    return true;
  };
}

/// A line before a big mesh file is read (assimp says nothing while it reads: a 300 MB STL took
/// 133 s before the first progress line, a scale sweep's finding). Files under 32 MiB read in
/// about a second: nothing.
inline void sayReading(const std::filesystem::path& file) {
  std::error_code ec;
  const std::uintmax_t size = std::filesystem::file_size(file, ec);
  if (progressQuiet() || ec || size < (std::uintmax_t{32} << 20)) return;
  endProgressLine();
  std::fprintf(stderr, "reading %s (%ju MiB) ...\n", file.string().c_str(),
               static_cast<std::uintmax_t>(size >> 20));
  std::fflush(stderr);
}

}  // namespace fieldpath::app
