/// The refinement's error estimate (voxel_grid.h CellErrors, cellsWithValues): each node's
/// error once, by leaves in parallel, then the cells' from their corners. Split out of
/// voxel_build.cpp (issue 15: the estimate read 56 nodes through accessors a cell, serially
/// per cell, each node again for each of its 8 cells).
#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "voxel_grid.h"

namespace fieldpath::field::voxel {
namespace {

/// A node's share of the estimate: along each axis with both neighbours built, the second
/// difference of what is interpolated (s and G for the plane ratio, F for the stored force) over
/// 8 (linear interpolation's error is h²/8 |f''|), turned into a force error:
/// |dP/ds|·|G|·|Δ²s| + P(s)·|Δ²G|, or |Δ²F|; the largest over the axes; and its force.
class NodeCurvature {
 public:
  NodeCurvature(const Level& level, const std::optional<PlaneLaw>& law)
      : values_(level.grid->getConstAccessor()), law_(law) {
    if (law) closeness_.emplace(level.closeness->getConstAccessor());
  }

  /// Of a built node (its value on) of `leaf` (closeness: its closeness leaf); `inside`:
  /// s <= -depth_mm (under the surface).
  void at(const Leaf& leaf, const FloatLeaf* closeness, openvdb::Index offset, double depth_mm,
          double& force, double& error, bool& inside) {
    if (leaf_ != &leaf) {  // the leaf's buffers read directly (no out-of-core check a value)
      leaf_ = &leaf;
      float_leaf_ = closeness;
      origin_ = leaf.origin();
      values_data_ = leaf.buffer().data();
      floats_data_ = closeness ? closeness->buffer().data() : nullptr;
    }
    const openvdb::Coord ijk = leaf.offsetToGlobalCoord(offset);
    const Read here = read(ijk);
    // s < 0 only over the surface (the signed height), or at a node under it that holds its own
    // force (the plane's continuation did not fit there), whose height is η <= s
    // (voxel_build.cpp planeRatio).
    inside = law_ && here.s <= -depth_mm;
    double slope = 0.0, plane = 0.0;
    if (law_) {
      constexpr double kStepMm = 1e-4;
      plane = law_->at(here.s);
      force = plane * here.v.norm();
      slope =
          std::abs(law_->at(std::abs(here.s) + kStepMm) - law_->at(std::abs(here.s) - kStepMm)) /
          (2 * kStepMm);
    } else {
      force = here.v.norm();
    }
    error = 0.0;
    for (int a = 0; a < 3; ++a) {
      openvdb::Coord lo = ijk, hi = ijk;
      lo[a] -= 1;
      hi[a] += 1;
      const Read m = read(lo), p = read(hi);
      if (!m.built || !p.built) continue;
      const Vec3 dv = m.v - 2.0 * here.v + p.v;
      const double e = law_ ? slope * here.v.norm() * std::abs(m.s - 2.0 * here.s + p.s) +
                                  plane * dv.norm()
                            : dv.norm();
      error = std::max(error, e / 8.0);
    }
  }

 private:
  struct Read {
    bool built, over;
    double s;
    Vec3 v;
  };
  /// From the current leaf's buffers when ijk is in it (most reads), else through accessors.
  Read read(const openvdb::Coord& ijk) {
    const openvdb::Coord& o = origin_;
    if (((ijk.x() - o.x()) | (ijk.y() - o.y()) | (ijk.z() - o.z())) >> 3 == 0 &&
        (float_leaf_ || !law_)) {
      const openvdb::Index n = Leaf::coordToOffset(ijk);
      const openvdb::Vec3s& v = values_data_[n];
      return {leaf_->getValueMask().isOn(n), law_ && float_leaf_->getValueMask().isOn(n),
              law_ ? law_->r0_mm - floats_data_[n] : 0.0, Vec3(v.x(), v.y(), v.z())};
    }
    const openvdb::Vec3s v = values_.getValue(ijk);
    return {values_.isValueOn(ijk), law_ && closeness_->isValueOn(ijk),
            law_ ? law_->r0_mm - closeness_->getValue(ijk) : 0.0, Vec3(v.x(), v.y(), v.z())};
  }
  Grid::ConstAccessor values_;
  std::optional<FloatGrid::ConstAccessor> closeness_;
  const std::optional<PlaneLaw>& law_;
  const Leaf* leaf_ = nullptr;
  const FloatLeaf* float_leaf_ = nullptr;
  openvdb::Coord origin_;
  const openvdb::Vec3s* values_data_ = nullptr;
  const float* floats_data_ = nullptr;
};

}  // namespace

CellErrors::CellErrors(const Level& level, const std::optional<PlaneLaw>& law, double floor)
    : level_(level), floor_(floor) {
  // The leaves in makeBlocks' order: leaf b is block b.
  std::vector<const Leaf*> leaves;
  for (auto it = level.grid->tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  if (leaves.size() != level.blocks())
    throw std::logic_error("CellErrors: the level's blocks are not its leaves");
  force_.resize(leaves.size() * Leaf::SIZE);  // written for the built nodes, read for them only
  error_.resize(leaves.size() * Leaf::SIZE);
  built_.assign(leaves.size() * kCellWords, 0);
  inside_.assign(leaves.size() * kCellWords, 0);
  const double depth_mm = 0.5 * std::sqrt(3.0) * level.h_mm;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& range) {
    NodeCurvature curvature(level, law);
    std::optional<FloatGrid::ConstAccessor> closeness;
    if (law) closeness.emplace(level.closeness->getConstAccessor());
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      const FloatLeaf* float_leaf = law ? closeness->probeConstLeaf(leaves[b]->origin()) : nullptr;
      for (auto it = leaves[b]->cbeginValueOn(); it; ++it) {
        const std::size_t n = b * Leaf::SIZE + it.pos();
        bool inside = false;
        curvature.at(*leaves[b], float_leaf, it.pos(), depth_mm, force_[n], error_[n], inside);
        built_[n >> 6] |= std::uint64_t{1} << (n & 63);
        if (inside) inside_[n >> 6] |= std::uint64_t{1} << (n & 63);
      }
    }
  });
}

double CellErrors::cellError(const openvdb::Coord& cell, const IndexAccessor& acc) const {
  // The same terms in the same order as reading the corners one by one: the largest corner
  // error over max(mean corner force, floor).
  double worst = 0.0, sum = 0.0;
  int built = 0, inside = 0;
  for (int c = 0; c < 8; ++c) {
    const openvdb::Coord ijk = cell.offsetBy(c >> 2, (c >> 1) & 1, c & 1);
    const int b = blockAt(level_, acc, openvdb::Coord(ijk.x() >> 3, ijk.y() >> 3, ijk.z() >> 3));
    if (b < 0) continue;
    const std::size_t n = std::size_t(b) * Leaf::SIZE + Leaf::coordToOffset(ijk);
    if (!bit(built_, n)) continue;
    worst = std::max(worst, error_[n]);
    sum += force_[n];
    ++built;
    inside += bit(inside_, n);
  }
  if (inside == built) return 0.0;  // none built, or every built one inside (the others lie
                                    // deeper than the inside band)
  return worst / std::max(sum / built, floor_);
}

CellList cellsWithValues(const Level& level) {
  // Block by block in parallel, then joined in the blocks' order (the index grid's).
  std::vector<std::pair<openvdb::Coord, std::size_t>> blocks;
  for (auto it = level.block_of->cbeginValueOn(); it; ++it)
    blocks.emplace_back(it.getCoord() << 3, std::size_t(*it));
  std::vector<std::vector<CellIjk>> per_block(blocks.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()), [&](const auto& range) {
    for (std::size_t q = range.begin(); q != range.end(); ++q) {
      const auto& [o, b] = blocks[q];
      std::vector<CellIjk>& cells = per_block[q];
      for (int i = 0; i < kLeafDim; ++i)
        for (int j = 0; j < kLeafDim; ++j)
          for (int k = 0; k < kLeafDim; ++k) {
            const std::size_t n0 =
                b * kBlockNodes + std::size_t((i * kBlockDim + j) * kBlockDim + k);
            bool any = false;
            for (int c = 0; c < 8 && !any; ++c) {
              const auto& v = level.nodes[n0 + kCornerOffset[c]];
              any = v[0] != 0.0f || v[1] != 0.0f || v[2] != 0.0f;
            }
            if (any) cells.push_back({o.x() + i, o.y() + j, o.z() + k});
          }
    }
  });
  std::vector<std::size_t> start(blocks.size() + 1, 0);
  for (std::size_t q = 0; q < blocks.size(); ++q) start[q + 1] = start[q] + per_block[q].size();
  CellList cells(start.back());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks.size()), [&](const auto& range) {
    for (std::size_t q = range.begin(); q != range.end(); ++q)
      std::copy(per_block[q].begin(), per_block[q].end(), cells.begin() + long(start[q]));
  });
  return cells;
}

}  // namespace fieldpath::field::voxel
