#include "fieldpath/field/region_field.h"

#include <stdexcept>
#include <utility>
#include <vector>

namespace fieldpath::field {

RegionField::RegionField(const ForceField& inside, const ForceField& outside,
                         const Eigen::AlignedBox3d& region_mm)
    : inside_(inside), outside_(outside), region_(region_mm) {}

RegionField::RegionField(const ForceField& inside, const ForceField& outside,
                         const Eigen::AlignedBox3d& region_mm, std::shared_ptr<const CellMask> core)
    : inside_(inside), outside_(outside), region_(region_mm), core_(std::move(core)) {}

void RegionField::evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const {
  if (points_mm.size() != forces.size())
    throw std::invalid_argument("RegionField::evaluate: points and forces differ in size");
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < points_mm.size(); ++i)
    if (!contains(points_mm[i])) out.push_back(i);
  if (out.empty()) {
    inside_.evaluate(points_mm, forces);
    return;
  }
  // The inside ones in one call too (the voxels read a block per cell: no per-point calls).
  std::vector<Vec3> in_points, in_forces, out_points(out.size()), out_forces(out.size());
  std::vector<std::size_t> in;
  in.reserve(points_mm.size() - out.size());
  for (std::size_t i = 0, k = 0; i < points_mm.size(); ++i) {
    if (k < out.size() && out[k] == i) {
      out_points[k++] = points_mm[i];
      continue;
    }
    in.push_back(i);
    in_points.push_back(points_mm[i]);
  }
  in_forces.resize(in_points.size());
  if (!in_points.empty()) inside_.evaluate(in_points, in_forces);
  outside_.evaluate(out_points, out_forces);
  for (std::size_t k = 0; k < in.size(); ++k) forces[in[k]] = in_forces[k];
  for (std::size_t k = 0; k < out.size(); ++k) forces[out[k]] = out_forces[k];
  outside_points_.fetch_add(out.size(), std::memory_order_relaxed);
}

}  // namespace fieldpath::field
