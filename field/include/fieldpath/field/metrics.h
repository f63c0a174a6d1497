#pragma once
/// Error of an approximate field against a reference (voxel against direct, in tests and benches).
///
/// The relative error at a point is e = |F_approx - F_ref| / |F_ref|. The field fades to zero at
/// r0 (and cancels between two walls), where e of any approximation grows without meaning and
/// those points add nothing to a moment; so e is counted only where |F_ref| is at least a floor.
/// The floor used by the study (app/study.h) and bench_field is 1 % of the largest |F_ref| of
/// the point set (a line, the nodes of a tool), among points at least the clearance from the
/// walls: with r0 = 5 mm and the largest force 0.5 mm off a wall, it keeps points up to ~3.8 mm
/// off it. Seed 004 reports its errors along lines the same way (relative, near the walls).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>

#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

struct FieldError {
  double max_relative = 0.0;  ///< max |a - r| / |r| over the counted points
  double rms_relative = 0.0;  ///< sqrt(mean (|a - r| / |r|)²) over the counted points
  std::size_t count = 0;      ///< points counted (|r| at or above the floor)
};

/// Relative error over the points where |reference| >= min_reference (an absolute floor, in
/// the field's units; below it the relative error of a field that fades to zero at r0 means
/// nothing). Zero references are never counted.
inline FieldError relativeError(std::span<const geometry::Vec3> approx,
                                std::span<const geometry::Vec3> reference, double min_reference) {
  if (approx.size() != reference.size()) throw std::invalid_argument("relativeError: sizes differ");
  FieldError e;
  double sum_sq = 0.0;
  for (std::size_t i = 0; i < approx.size(); ++i) {
    const double ref = reference[i].norm();
    if (!(ref >= min_reference) || ref == 0.0) continue;
    const double rel = (approx[i] - reference[i]).norm() / ref;
    e.max_relative = std::max(e.max_relative, rel);
    sum_sq += rel * rel;
    ++e.count;
  }
  if (e.count) e.rms_relative = std::sqrt(sum_sq / static_cast<double>(e.count));
  return e;
}

/// Relative error with the floor set to `floor_fraction` (0.01 in the study) of the largest
/// |reference| of the set.
inline FieldError relativeErrorAboveFloor(std::span<const geometry::Vec3> approx,
                                          std::span<const geometry::Vec3> reference,
                                          double floor_fraction) {
  double max_ref = 0.0;
  for (const auto& r : reference) max_ref = std::max(max_ref, r.norm());
  return relativeError(approx, reference, floor_fraction * max_ref);
}

}  // namespace fieldpath::field
