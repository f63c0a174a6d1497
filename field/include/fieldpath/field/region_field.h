#pragma once
/// A field sampled only in a region, answered by another (exact) field outside it. The voxels of
/// a job are built only in the box tool + holder can reach (pathgen's reach box, taken at a few
/// stations of each pass and padded); a voxel field is zero where it has no nodes, so a point
/// the box missed (a user's pass turning sharply between two of those stations) would feel no
/// wall at all. Here it gets the exact sum instead, and is counted.
#include <atomic>
#include <cstddef>
#include <memory>
#include <span>

#include <Eigen/Geometry>

#include "fieldpath/field/cell_mask.h"
#include "fieldpath/field/force_field.h"

namespace fieldpath::field {

class RegionField final : public ForceField {
 public:
  /// `inside` answers the points of `region_mm` (world, mm), `outside` the others. Both are
  /// borrowed: they must outlive this field. The region must be where `inside` is valid with
  /// its interpolation's stencil: stencilBox (trilinear reads the cell's corners, quadratic one
  /// node more).
  RegionField(const ForceField& inside, const ForceField& outside,
              const Eigen::AlignedBox3d& region_mm);
  /// The region is the box and the core of `core` (voxels refined near a path only: the
  /// refinement's decisions are those of a build refined everywhere in the core).
  RegionField(const ForceField& inside, const ForceField& outside,
              const Eigen::AlignedBox3d& region_mm, std::shared_ptr<const CellMask> core);

  /// Where voxels built in `built_mm` with node spacing `h_mm` answer with their stencil: the
  /// box shrunk by 2 h (the region to give them here).
  static Eigen::AlignedBox3d stencilBox(Eigen::AlignedBox3d built_mm, double h_mm) {
    built_mm.min().array() += 2.0 * h_mm;
    built_mm.max().array() -= 2.0 * h_mm;
    return built_mm;
  }

  /// Thread-safe. One call's points all inside go to `inside` in one call (the usual case:
  /// nothing copied); otherwise the outside ones are gathered and sent to `outside`.
  void evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const override;

  /// Points answered by `outside` so far (all calls, all threads).
  std::size_t outsidePoints() const { return outside_points_.load(std::memory_order_relaxed); }
  /// In the box and, with a mask, in its core.
  bool contains(const Vec3& p_mm) const {
    return region_.contains(p_mm) && (!core_ || core_->inCore(p_mm));
  }

 private:
  const ForceField& inside_;
  const ForceField& outside_;
  Eigen::AlignedBox3d region_;
  std::shared_ptr<const CellMask> core_;
  mutable std::atomic<std::size_t> outside_points_{0};
};

}  // namespace fieldpath::field
