#pragma once
/// Each sub-command lives in its own cmd_*.cpp and registers itself here. A registration adds the
/// sub-command and its options to `app` and sets its callback; the callback throws InputError for
/// bad input (exit 1) and returns normally on success (exit 0).
#include <cmath>
#include <cstdlib>
#include <string>

#include <CLI/CLI.hpp>

#include "fieldpath/common/short_number.h"

namespace fieldpath::app {

/// A CLI11 check of a number: "'x' is not a number" for no number at all, else `wanted` (the
/// rule in words) unless `ok(value)`; text after the number, nan and inf fail `ok`'s caller.
template <class Ok>
CLI::Validator numberCheck(Ok ok, const std::string& wanted, const std::string& description) {
  return CLI::Validator(
      [ok, wanted](std::string& text) -> std::string {
        // strtod, not stod: a number too small or too large for a double is one (stod throws
        // out_of_range and it read "not a number").
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str()) return "'" + text + "' is not a number";
        if (end != text.c_str() + text.size() || !std::isfinite(value) || !ok(value))
          return "must be " + wanted + ", got '" + text + "'";
        return {};
      },
      description);
}

/// CLI11 check for a size option: a finite number > 0 (or >= 0 with `zero_ok`), in `unit`, with
/// a short message otherwise (CLI::PositiveNumber lets NaN through and prints its range as a
/// 300-digit number).
inline CLI::Validator finiteNumber(const std::string& unit, bool zero_ok) {
  const std::string bound = zero_ok ? ">= 0" : "> 0";
  return numberCheck([zero_ok](double v) { return v > 0.0 || (zero_ok && v == 0.0); },
                     "a finite number " + bound + (unit.empty() ? "" : " " + unit),
                     (unit.empty() ? "" : unit + " ") + bound);
}
inline CLI::Validator positiveFinite(const std::string& unit) { return finiteNumber(unit, false); }

/// CLI11 check for a number in [lo, hi] (`unit` may be empty), with finiteNumber's short
/// message (CLI::Range printed "not in range 0.001000 to 10.000000" and let nan through).
inline CLI::Validator numberFromTo(double lo, double hi, const std::string& unit) {
  const std::string range =
      common::shortNumber(lo) + " to " + common::shortNumber(hi) + (unit.empty() ? "" : " " + unit);
  return numberCheck([lo, hi](double v) { return v >= lo && v <= hi; }, "a number from " + range,
                     range);
}

struct GlobalOptions {
  bool quiet = false;  ///< silence progress lines on stderr
};

/// Exit code of a command that ran to its end with a verdict against it: 3 for `check
/// --fail-unsafe` NOT OK and `generate --fail-unsafe` UNSAFE TO RUN (a script's `check && post`
/// posted a path check had marked unsafe: a CAM engineer's), else 0. The outputs are written.
inline constexpr int kVerdictExitCode = 3;
inline int& verdictExitCode() {
  static int code = 0;
  return code;
}

void addToolCommand(CLI::App& app, const GlobalOptions& global);
void addSimulateCommand(CLI::App& app, const GlobalOptions& global);
void addFieldCommand(CLI::App& app, const GlobalOptions& global);
void addGenerateCommand(CLI::App& app, const GlobalOptions& global);
void addCheckCommand(CLI::App& app, const GlobalOptions& global);
void addStudyCommand(CLI::App& app, const GlobalOptions& global);
void addViewCommand(CLI::App& app, const GlobalOptions& global);
void addConvertCommand(CLI::App& app, const GlobalOptions& global);

}  // namespace fieldpath::app
