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
  return [=](double fraction, std::string_view what) mutable {
    const auto now = std::chrono::steady_clock::now();
    const double elapsed_s = std::chrono::duration<double>(now - start).count();
    if (elapsed_s < 1.0 || (now - last < every && fraction < 1.0)) return true;
    if (fraction >= 1.0 && finished == what) return true;
    finished = fraction >= 1.0 ? std::string(what) : std::string();
    last = now;
    const bool ends = fraction >= 1.0 || !terminal;
    std::fprintf(stderr, "%s%-24.*s %5.1f%%  %6.1f s%s", terminal ? "\r" : "",
                 static_cast<int>(what.size()), what.data(), 100.0 * fraction, elapsed_s,
                 ends ? "\n" : "");
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
