#pragma once
/// Progress/interrupt hook for long work (like OpenVDB's Interrupter). Libraries call it now and
/// then; the CLI turns it into a progress line on stderr and Ctrl-C into an interruption.
#include <functional>
#include <stdexcept>
#include <string>
#include <string_view>

namespace fieldpath::common {

/// Called with the fraction done in [0, 1] and a short label ("field", "pass 3/7").
/// Returns false to ask the work to stop; the library then throws Interrupted.
using Progress = std::function<bool(double fraction, std::string_view what)>;

struct Interrupted : std::runtime_error {
  Interrupted() : std::runtime_error("interrupted") {}
};

/// The fraction [begin, end) of the whole reported by `progress`, under `label`: a stage of a
/// longer job reports 0 to 1 of its own.
inline Progress scaled(const Progress& progress, double begin, double end, std::string label) {
  if (!progress) return {};
  return [=](double fraction, std::string_view) {
    return progress(begin + (end - begin) * fraction, label);
  };
}

/// Reports to `progress` if set; throws Interrupted if it asks to stop.
inline void report(const Progress& progress, double fraction, std::string_view what) {
  if (progress && !progress(fraction, what)) throw Interrupted();
}

}  // namespace fieldpath::common
