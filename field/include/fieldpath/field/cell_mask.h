#pragma once
/// Where a job's tool + holder nodes went, on a uniform grid of cells: the voxel refinement of a
/// job splits cells only near its path (VoxelRequest::refine_mask), and the refined field answers
/// only in the mask's core (RegionField), the exact field beyond. No OpenVDB here.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

using geometry::Vec3;

class CellMask {
 public:
  /// The cells (edge cell_mm) holding `points_mm`, grown by `core_mm` (the core) and by
  /// `outer_mm` >= core_mm (the whole mask), each as a cube of cells around a marked one
  /// (Chebyshev distance, rounded up to whole cells). Only `relevant_mm` is masked: points
  /// beyond it are not marked and every point beyond it counts as in the core (a job passes the
  /// samples' box grown by r0 and more: there nothing is refined and the voxels are exactly
  /// zero, as the field is); default: everywhere. The cells are stored densely over the
  /// points' box (within `relevant_mm`); where that would pass kMaxCells the cell edge grows
  /// (the distances in mm are kept). Throws std::invalid_argument for cell_mm <= 0 or
  /// outer_mm < core_mm.
  CellMask(std::span<const Vec3> points_mm, double cell_mm, double core_mm, double outer_mm,
           const Eigen::AlignedBox3d& relevant_mm = everywhere());
  static Eigen::AlignedBox3d everywhere() {
    return Eigen::AlignedBox3d(Vec3::Constant(-HUGE_VAL), Vec3::Constant(HUGE_VAL));
  }

  /// In the whole mask / in its core: true beyond `relevant_mm`; within it, false outside the
  /// stored cells (and everywhere for a mask no point marked).
  bool contains(const Vec3& p_mm) const { return lookUp(outer_, p_mm); }
  bool inCore(const Vec3& p_mm) const { return lookUp(core_, p_mm); }

  double cellMm() const { return cell_mm_; }
  std::size_t cells() const { return outer_cells_; }     ///< of the whole mask
  std::size_t coreCells() const { return core_cells_; }  ///< of the core

  static constexpr std::size_t kMaxCells = std::size_t{1} << 27;

 private:
  bool lookUp(const std::vector<std::uint64_t>& bits, const Vec3& p_mm) const;

  Eigen::AlignedBox3d relevant_mm_;
  Vec3 lo_mm_ = Vec3::Zero();
  double cell_mm_ = 1.0, inv_cell_ = 1.0;
  long dim_[3] = {0, 0, 0};
  std::vector<std::uint64_t> core_, outer_;  ///< a bit a cell, x-major, z fastest
  std::size_t outer_cells_ = 0, core_cells_ = 0;
};

}  // namespace fieldpath::field
