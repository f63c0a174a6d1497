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

/// CLI11 check for a size option: a finite number > 0 (or >= 0 with `zero_ok`), in `unit`, with
/// a short message otherwise (CLI::PositiveNumber lets NaN through and prints its range as a
/// 300-digit number).
inline CLI::Validator finiteNumber(const std::string& unit, bool zero_ok) {
  const std::string bound = zero_ok ? ">= 0" : "> 0";
  return CLI::Validator(
      [unit, zero_ok, bound](std::string& text) -> std::string {
        // strtod, not stod: a number too small or too large for a double is one (stod throws
        // out_of_range and it read "not a number").
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str()) return "'" + text + "' is not a number";
        if (end != text.c_str() + text.size() || !std::isfinite(value) || value < 0.0 ||
            (value == 0.0 && !zero_ok))
          return "must be a finite number " + bound + (unit.empty() ? "" : " " + unit) + ", got '" +
                 text + "'";
        return {};
      },
      (unit.empty() ? "" : unit + " ") + bound);
}
inline CLI::Validator positiveFinite(const std::string& unit) { return finiteNumber(unit, false); }

/// CLI11 check for a number in [lo, hi] (`unit` may be empty), with the short message of
/// finiteNumber (CLI::Range printed "not in range 0.001000 to 10.000000").
inline CLI::Validator numberFromTo(double lo, double hi, const std::string& unit) {
  const std::string range =
      common::shortNumber(lo) + " to " + common::shortNumber(hi) + (unit.empty() ? "" : " " + unit);
  return CLI::Validator(
      [lo, hi, range](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (text.empty() || end == text.c_str()) return "'" + text + "' is not a number";
        if (end != text.c_str() + text.size() || !(value >= lo && value <= hi))
          return "must be a number from " + range + ", got '" + text + "'";
        return {};
      },
      range);
}

struct GlobalOptions {
  bool quiet = false;  ///< silence progress lines on stderr
};

void addToolCommand(CLI::App& app, const GlobalOptions& global);
void addSimulateCommand(CLI::App& app, const GlobalOptions& global);
void addFieldCommand(CLI::App& app, const GlobalOptions& global);
void addGenerateCommand(CLI::App& app, const GlobalOptions& global);
void addCheckCommand(CLI::App& app, const GlobalOptions& global);
void addStudyCommand(CLI::App& app, const GlobalOptions& global);
void addViewCommand(CLI::App& app, const GlobalOptions& global);
void addConvertCommand(CLI::App& app, const GlobalOptions& global);

}  // namespace fieldpath::app
