#pragma once
/// Error of an approximate field against a reference (voxel against direct, in tests and benches).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <stdexcept>

#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

struct FieldError {
  double max_relative = 0.0;  ///< max |a - r| / |r|
  double rms_relative = 0.0;  ///< sqrt(mean (|a - r| / |r|)²)
  std::size_t count = 0;      ///< points compared
};

/// Relative error over the points where |reference| >= min_reference (below, the relative error
/// of a field that fades to zero at r0 means nothing).
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

}  // namespace fieldpath::field
