#pragma once
/// Internal to pathgen/: the clear start axis of a pass whose settled start is still within
/// `clearance` (generate.cpp, GenerateResult::turned_starts).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <numbers>
#include <optional>
#include <utility>
#include <vector>

#include "fieldpath/dynamics/params.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/generate.h"  // kClearStartStepDeg

namespace fieldpath::pathgen {

/// The (lead, tilt) nearest (lead0, tilt0) on the grid kClearStartStepDeg apart about it, within
/// the angle limits (as the steering holds them), whose clearance(lead, tilt) is at least
/// `required_mm`; nothing if none is. (lead0, tilt0) itself first (a settled start within
/// clearance beside a clear nominal axis was turned 5 deg), then nearest first, ties in the
/// order of the lead step, then the tilt step, from -5 deg up: the search stops at the first
/// clear one.
template <class Clearance>
std::optional<std::pair<double, double>> clearStart(double lead0, double tilt0,
                                                    const dynamics::DynamicsParams& params,
                                                    Clearance&& clearance, double required_mm) {
  const double step = kClearStartStepDeg * geometry::kDegToRad;
  const double max_lead = params.maxLeadRad(), max_tilt = params.maxTiltRad();
  std::vector<std::pair<int, int>> grid;
  const int nl = int(std::floor(2.0 * max_lead / step)) + 1,
            nt = int(std::floor(2.0 * max_tilt / step)) + 1;
  for (int i = -nl; i <= nl; ++i)
    for (int j = -nt; j <= nt; ++j)
      if (std::abs(lead0 + i * step) <= max_lead && std::abs(tilt0 + j * step) <= max_tilt)
        grid.emplace_back(i, j);
  std::stable_sort(grid.begin(), grid.end(), [](const auto& a, const auto& b) {
    return a.first * a.first + a.second * a.second < b.first * b.first + b.second * b.second;
  });
  for (const auto& [i, j] : grid)
    if (clearance(lead0 + i * step, tilt0 + j * step) >= required_mm)
      return std::pair<double, double>{lead0 + i * step, tilt0 + j * step};
  return std::nullopt;
}

}  // namespace fieldpath::pathgen
