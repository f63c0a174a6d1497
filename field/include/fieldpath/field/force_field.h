#pragma once
/// The one interface through which later stages (dynamics, pathgen, study) read a repulsive field,
/// whether direct (exact sum) or voxel (sampled). A runtime choice, hence a small virtual
/// interface.
#include <span>

#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

using geometry::Vec3;

class ForceField {
 public:
  virtual ~ForceField() = default;
  /// Force at each point. points: mm, world frame; forces: same size, world frame, units of
  /// gain · weight / mm² (eq. 1). Thread-safe; implementations may parallelise internally.
  virtual void evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const = 0;
  /// Convenience for one point.
  Vec3 at(const Vec3& point_mm) const {
    Vec3 f;
    evaluate(std::span<const Vec3>(&point_mm, 1), std::span<Vec3>(&f, 1));
    return f;
  }
};

}  // namespace fieldpath::field
