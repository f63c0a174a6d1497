#include "fieldpath/field/voxel_field.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <openvdb/io/Stream.h>
#include <openvdb/tools/Interpolation.h>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/memory.h"
#include "fieldpath/common/short_number.h"
#include "node_cuda.h"
#include "voxel_grid.h"

/// The voxel field's queries and the block form of its levels (the build: voxel_build.cpp).
namespace fieldpath::field {
namespace voxel {

bool locate(const Level& level, const IndexAccessor& acc, const Vec3& x_mm, CellRef& out) {
  const Vec3 p = x_mm / level.h_mm;  // index space
  const Vec3 base = p.array().floor();
  const int i = int(base.x()), j = int(base.y()), k = int(base.z());
  const openvdb::Coord leaf(i >> 3, j >> 3, k >> 3);  // floor division by 8
  const int b = blockAt(level, acc, leaf);
  if (b < 0) return false;
  ensureBlock(level, std::size_t(b));
  const int li = i & (kLeafDim - 1), lj = j & (kLeafDim - 1), lk = k & (kLeafDim - 1);
  out.block = std::size_t(b);
  out.node0 = out.block * kBlockNodes + std::size_t((li * kBlockDim + lj) * kBlockDim + lk);
  out.cell = std::size_t((li * kLeafDim + lj) * kLeafDim + lk);
  out.t = p - base;
  return true;
}

namespace {

/// Fills block b of the level from its leaf and the leaf's +x, +y, +z neighbours, found through
/// `values` and `closeness` (accessors of the level's trees, or none: the trees' own probes).
template <class ValueProbe, class FloatProbe>
void fillBlock(const Level& level, std::size_t b, ValueProbe&& values, FloatProbe&& closeness) {
  const bool ratio = level.ratio;
  const openvdb::Vec3s value_background = level.grid->background();
  const float closeness_background = ratio ? level.closeness->background() : 0.0f;
  const Leaf& leaf = *level.block_leaves[b];
  const openvdb::Coord o = leaf.origin();
  // From the buffers of the leaf and of its +x, +y, +z neighbours (side = which of them:
  // bit 2 for i = 8, 1 for j = 8, 0 for k = 8), looked up once each; an absent leaf holds
  // the background (the trees have no active tiles).
  // Their buffers' data read directly (LeafBuffer's accessors check for out-of-core data
  // at every value: most of this loop's time).
  const openvdb::Vec3s* values_of[8];
  const float* floats_of[8];
  const openvdb::util::NodeMask<3>* over_of[8];
  for (int side = 0; side < 8; ++side) {
    const openvdb::Coord n =
        o.offsetBy(side & 4 ? kLeafDim : 0, side & 2 ? kLeafDim : 0, side & 1 ? kLeafDim : 0);
    const Leaf* v = side == 0 ? &leaf : values(n);
    const FloatLeaf* f = ratio ? closeness(n) : nullptr;
    values_of[side] = v ? v->buffer().data() : nullptr;
    floats_of[side] = f ? f->buffer().data() : nullptr;
    over_of[side] = f ? &f->getValueMask() : nullptr;
  }
  std::uint64_t* over = &level.over[b * kBlockWords];
  std::fill(over, over + kBlockWords, std::uint64_t{0});
  std::array<float, 4>* block = &level.nodes[b * kBlockNodes];
  // A run along k at a time: k = 0..7 from the leaf of (i, j)'s side, k = 8 from the one
  // above it in z (the per-node side lookup and its branches were most of this loop).
  for (int i = 0; i < kBlockDim; ++i)
    for (int j = 0; j < kBlockDim; ++j) {
      const int side_ij = (i >> 3) << 2 | (j >> 3) << 1;
      const openvdb::Index first = openvdb::Index(((i & 7) * kLeafDim + (j & 7)) * kLeafDim);
      const int n0 = (i * kBlockDim + j) * kBlockDim;
      for (int part = 0; part < 2; ++part) {  // k = 0..7, then k = 8
        const int side = side_ij | part;
        const int count = part == 0 ? kLeafDim : 1;
        const int n = n0 + (part == 0 ? 0 : kLeafDim);
        const openvdb::Vec3s* values = values_of[side];
        const float* floats = floats_of[side];
        for (int k = 0; k < count; ++k) {
          const openvdb::Vec3s v = values ? values[first + k] : value_background;
          block[n + k] = {v.x(), v.y(), v.z(), floats ? floats[first + k] : closeness_background};
        }
        if (const auto* mask = over_of[side])
          for (int k = 0; k < count; ++k)
            if (mask->isOn(first + openvdb::Index(k)))
              over[(n + k) >> 6] |= std::uint64_t{1} << ((n + k) & 63);
      }
    }
}

}  // namespace

void makeBlocks(Level& level, bool ratio) {
  level.ratio = ratio;
  std::vector<const Leaf*>& leaves = level.block_leaves;
  leaves.clear();
  for (auto it = level.grid->tree().cbeginLeaf(); it; ++it) leaves.push_back(&*it);
  level.block_of = IndexGrid::create(-1);
  level.dense.clear();
  if (!leaves.empty()) {
    openvdb::CoordBBox box;
    for (const Leaf* leaf : leaves) box.expand(leaf->origin() >> 3);
    const openvdb::Coord dim = box.dim();
    if (double(dim.x()) * dim.y() * dim.z() <= double(kDenseIndexMax)) {
      level.dense_lo = box.min();
      level.dense_dim = dim;
      level.dense.assign(std::size_t(dim.x()) * dim.y() * dim.z(), -1);
      for (std::size_t b = 0; b < leaves.size(); ++b) {
        const openvdb::Coord d = (leaves[b]->origin() >> 3) - box.min();
        level.dense[(std::size_t(d.x()) * dim.y() + d.y()) * dim.z() + d.z()] = int(b);
      }
    }
  }
  {
    auto acc = level.block_of->getAccessor();
    for (std::size_t b = 0; b < leaves.size(); ++b)
      acc.setValueOn(leaves[b]->origin() >> 3, static_cast<int>(b));
  }
  level.nodes.clear();
  level.nodes.resize(leaves.size() * kBlockNodes);  // a block's entries written when it is filled
  level.over.assign(leaves.size() * kBlockWords, 0);
  level.refined.assign(leaves.size() * kCellWords, 0);
  level.block_state = std::make_unique<std::atomic<std::uint8_t>[]>(leaves.size());
  for (std::size_t b = 0; b < leaves.size(); ++b)
    level.block_state[b].store(kBlockEmpty, std::memory_order_relaxed);
}

void fillBlockOnce(const Level& level, std::size_t b) {
  std::atomic<std::uint8_t>& state = level.block_state[b];
  std::uint8_t expected = kBlockEmpty;
  if (state.compare_exchange_strong(expected, kBlockFilling, std::memory_order_acquire)) {
    // The trees are not changed once built: probes from their roots (8 a block, no accessor
    // to register).
    fillBlock(
        level, b, [&](const openvdb::Coord& c) { return level.grid->tree().probeConstLeaf(c); },
        [&](const openvdb::Coord& c) { return level.closeness->tree().probeConstLeaf(c); });
    state.store(kBlockReady, std::memory_order_release);
    return;
  }
  while (state.load(std::memory_order_acquire) != kBlockReady) std::this_thread::yield();
}

void fillBlocks(const Level& level) {
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, level.block_leaves.size()), [&](const auto& range) {
        auto values = level.grid->getConstUnsafeAccessor();
        std::optional<FloatGrid::ConstUnsafeAccessor> closeness;
        if (level.ratio) closeness.emplace(level.closeness->getConstUnsafeAccessor());
        for (std::size_t b = range.begin(); b != range.end(); ++b) {
          std::uint8_t expected = kBlockEmpty;
          if (!level.block_state[b].compare_exchange_strong(expected, kBlockFilling,
                                                            std::memory_order_acquire)) {
            ensureBlock(level, b);  // filled, or being filled by a query
            continue;
          }
          fillBlock(
              level, b, [&](const openvdb::Coord& c) { return values.probeConstLeaf(c); },
              [&](const openvdb::Coord& c) { return closeness->probeConstLeaf(c); });
          level.block_state[b].store(kBlockReady, std::memory_order_release);
        }
      });
}

/// The trilinear value of one level's cell (no refinement): F, or for the plane ratio

Vec3 cellValue(const Level& level, const CellRef& cell, const std::optional<PlaneLaw>& law) {
  const std::array<float, 4>* n = &level.nodes[cell.node0];
  const Vec3& t = cell.t;
  const double w[2][3] = {{1 - t.x(), 1 - t.y(), 1 - t.z()}, {t.x(), t.y(), t.z()}};
  double weight[8];
  for (int c = 0; c < 8; ++c) weight[c] = w[c >> 2][0] * w[(c >> 1) & 1][1] * w[c & 1][2];
  if (!law) {
    Vec3 f = Vec3::Zero();
    for (int c = 0; c < 8; ++c) {
      const auto& v = n[kCornerOffset[c]];
      f += weight[c] * Vec3(v[0], v[1], v[2]);
    }
    return f;
  }
  double s[8];
  bool under = false;
  for (int c = 0; c < 8; ++c) {
    s[c] = law->r0_mm - n[kCornerOffset[c]][3];
    under |= s[c] < 0.0;
  }
  Vec3 g = Vec3::Zero();
  bool holds = true;
  if (under) {  // the over/under flags only matter with a corner under the surface
    bool over[8];
    const std::size_t first =
        cell.block * kBlockWords * 64 + (cell.node0 - cell.block * kBlockNodes);
    for (int c = 0; c < 8; ++c) over[c] = bit(level.over, first + kCornerOffset[c]);
    holds = ratioHolds(s, over);
  }
  if (!holds) {  // the node forces
    for (int c = 0; c < 8; ++c) {
      const auto& v = n[kCornerOffset[c]];
      g += weight[c] * law->at(s[c]) * Vec3(v[0], v[1], v[2]);
    }
    return g;
  }
  double closeness = 0.0;
  for (int c = 0; c < 8; ++c) {
    const auto& v = n[kCornerOffset[c]];
    g += weight[c] * Vec3(v[0], v[1], v[2]);
    closeness += weight[c] * v[3];
  }
  return law->at(law->r0_mm - closeness) * g;
}

/// Per-thread query state: one index accessor per level.

LevelAccessors accessorsOf(const std::vector<Level>& levels) {
  LevelAccessors a;
  a.index.reserve(levels.size());
  for (const Level& level : levels) a.index.push_back(level.block_of->getConstUnsafeAccessor());
  return a;
}

/// The cell that holds x at the finest level there (not refined), and that level; false
/// outside every block.
bool finestCell(const std::vector<Level>& levels, LevelAccessors& acc, const Vec3& x_mm,
                CellRef& cell, std::size_t& level) {
  if (!locate(levels[0], acc.index[0], x_mm, cell)) return false;
  level = 0;
  while (level + 1 < levels.size() &&
         bit(levels[level].refined, cell.block * Leaf::SIZE + cell.cell)) {
    CellRef fine;
    if (!locate(levels[level + 1], acc.index[level + 1], x_mm, fine)) break;
    cell = fine;
    ++level;
  }
  return true;
}

/// The trilinear field at x: the finest level whose cell holds x and is not refined.
Vec3 trilinearAt(const std::vector<Level>& levels, LevelAccessors& acc, const Vec3& x_mm,
                 const std::optional<PlaneLaw>& law) {
  CellRef cell;
  std::size_t l = 0;
  if (!finestCell(levels, acc, x_mm, cell, l)) return Vec3::Zero();
  return cellValue(levels[l], cell, law);
}

namespace {

/// matchCoarserLevels for the nodes of one leaf of the new level (and its closeness leaf).
void matchLeaf(Leaf& leaf, FloatLeaf* closeness, const std::vector<Level>& coarser,
               LevelAccessors& acc) {
  const Level& parent = coarser.back();
  const double fine_h_mm = 0.5 * parent.h_mm;
  for (auto it = leaf.beginValueOn(); it; ++it) {
    const openvdb::Coord f = it.getCoord();
    if ((f.x() & 1) && (f.y() & 1) && (f.z() & 1)) continue;  // inside one parent cell
    // The parent cells that share this node: one or two along each axis.
    bool hanging = false;
    for (int c = 0; c < 8 && !hanging; ++c) {
      openvdb::Coord cell;
      bool valid = true;
      for (int a = 0; a < 3; ++a) {
        const int side = (c >> a) & 1;
        if (f[a] & 1) {
          if (side) valid = false;  // one parent cell along this axis
          cell[a] = (f[a] - 1) >> 1;
        } else {
          cell[a] = (f[a] >> 1) - side;
        }
      }
      if (!valid) continue;
      // The parent cell's block and offset from its index (locate's, without the world point).
      const int b = blockAt(parent, acc.index.back(),
                            openvdb::Coord(cell.x() >> 3, cell.y() >> 3, cell.z() >> 3));
      hanging =
          b < 0 || !bit(parent.refined, std::size_t(b) * Leaf::SIZE + Leaf::coordToOffset(cell));
    }
    if (!hanging) continue;
    const Vec3 x = Vec3(f.x(), f.y(), f.z()) * fine_h_mm;
    CellRef cell;
    std::size_t l = 0;
    if (!finestCell(coarser, acc, x, cell, l)) continue;
    const std::array<float, 4>* n = &coarser[l].nodes[cell.node0];
    const Vec3& t = cell.t;
    double v[4] = {0, 0, 0, 0};
    for (int c = 0; c < 8; ++c) {
      const double w =
          (c & 4 ? t.x() : 1 - t.x()) * (c & 2 ? t.y() : 1 - t.y()) * (c & 1 ? t.z() : 1 - t.z());
      for (int k = 0; k < 4; ++k) v[k] += w * n[kCornerOffset[c]][k];
    }
    it.setValue(openvdb::Vec3s(float(v[0]), float(v[1]), float(v[2])));
    if (closeness) closeness->setValueOnly(it.pos(), float(v[3]));
  }
}

}  // namespace

/// Hanging nodes (voxel_grid.h).
void matchCoarserLevels(Level& fine, const std::vector<Level>& coarser, bool ratio) {
  // By leaves in parallel: each writes its own value and closeness leaf.
  std::vector<Leaf*> leaves;
  std::vector<FloatLeaf*> closeness_leaves;
  for (auto it = fine.grid->tree().beginLeaf(); it; ++it) {
    leaves.push_back(&*it);
    closeness_leaves.push_back(ratio ? fine.closeness->tree().probeLeaf(it->origin()) : nullptr);
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& range) {
    LevelAccessors acc = accessorsOf(coarser);
    for (std::size_t l = range.begin(); l != range.end(); ++l)
      matchLeaf(*leaves[l], closeness_leaves[l], coarser, acc);
  });
}

}  // namespace voxel

using namespace voxel;

struct VoxelField::Impl {
  std::vector<Level> levels;  ///< [0]: h, then h/2, h/4, ... where refined
  VoxelStats stats;
  double voxel_size_mm = 0.0;
  Interpolation interpolation = Interpolation::Trilinear;
  StoredQuantity stored = StoredQuantity::Force;
  std::optional<PlaneLaw> law;  ///< PlaneRatio
  /// The levels' bytes, held against --max-memory while the field lives (a study's grids are
  /// built one after another; a job's is held through its steering and checks).
  common::HeldMemory held;
};

VoxelRequest levelZeroRequest(const VoxelRequest& refined, double r_min_mm) {
  VoxelRequest uniform = refined;
  uniform.refine_tolerance = 0.0;
  uniform.refine_mask = nullptr;
  if (refined.refine_tolerance > 0.0)
    uniform.plane_near_mm = refined.plane_near_mm.value_or(kRefinedNearFactor * r_min_mm);
  return uniform;
}

VoxelField::VoxelField(const DirectField& direct, const VoxelRequest& request)
    : VoxelField(direct, request, static_cast<Level*>(nullptr)) {}

VoxelField::VoxelField(const DirectField& direct, const VoxelRequest& request, VoxelField&& uniform)
    : VoxelField(direct, request, [&] {
        Impl& u = *uniform.impl_;
        if (u.levels.size() != 1 || u.voxel_size_mm != request.voxel_size_mm ||
            u.stored != request.stored || u.interpolation != request.interpolation)
          throw std::invalid_argument(
              "VoxelField: the uniform grid to refine is not this request's level 0");
        u.held.release();  // its level 0 moves into the refined field, counted there
        return &u.levels[0];
      }()) {}

VoxelField::VoxelField(const DirectField& direct, const VoxelRequest& request, Level* level0)
    : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  BuiltLevels built = buildLevels(direct, request,
                                  level0 ? std::optional<Level>(std::move(*level0)) : std::nullopt);
  impl_->levels = std::move(built.levels);
  impl_->stats = built.stats;
  impl_->law = built.law;
  VoxelStats& stats = impl_->stats;
  const std::vector<Level>& levels = impl_->levels;
  stats.levels = int(levels.size());
  stats.active_nodes = 0;
  stats.memory_bytes = 0;
  for (const Level& level : levels) {
    stats.active_nodes += level.grid->activeVoxelCount();
    stats.memory_bytes += level.memUsage();
  }
  // Its bytes as built, against what is left (the estimates before the build are bounds of the
  // nodes, not of their bytes: a field of 21.5 MiB estimated at 18 passed a limit unsaid until
  // the cutter's test, after the steering: a diff review's), then held while it lives.
  common::requireMemory("the voxel field", double(stats.memory_bytes),
                        std::to_string(stats.active_nodes) + " nodes built at h = " +
                            common::shortNumber(request.voxel_size_mm) + " mm",
                        common::MemoryUse::kPassing);
  impl_->held = common::HeldMemory("the voxel field", double(stats.memory_bytes));
  const openvdb::CoordBBox active_box = levels[0].grid->evalActiveVoxelBoundingBox();
  stats.dense_box_nodes = active_box.empty() ? 0 : active_box.volume();
  stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  impl_->voxel_size_mm = request.voxel_size_mm;
  impl_->interpolation = request.interpolation;
  impl_->stored = request.stored;
  common::report(request.progress, 1.0, "field");
}

VoxelField::~VoxelField() = default;
VoxelField::VoxelField(VoxelField&&) noexcept = default;
VoxelField& VoxelField::operator=(VoxelField&&) noexcept = default;

const VoxelStats& VoxelField::stats() const { return impl_->stats; }
double VoxelField::voxelSizeMm() const { return impl_->voxel_size_mm; }
Interpolation VoxelField::interpolation() const { return impl_->interpolation; }
StoredQuantity VoxelField::stored() const { return impl_->stored; }

void VoxelField::evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const {
  checkSpans(points_mm, forces);
  const Impl& impl = *impl_;
  const std::vector<Level>& levels = impl.levels;
  const bool ratio = impl.stored == StoredQuantity::PlaneRatio;
  // A sample costs tens of ns: below a few thousand points (one tool's nodes) threads cost more
  // than they give.
  constexpr std::size_t kSerialBelow = 4096;
  if (impl.interpolation == Interpolation::Trilinear) {
    parallelOverPoints(
        points_mm.size(), [&] { return accessorsOf(levels); },
        [&](std::size_t i, LevelAccessors& acc) {
          forces[i] = trilinearAt(levels, acc, points_mm[i], impl.law);
        },
        kSerialBelow);
    return;
  }
  // Quadratic: OpenVDB's QuadraticSampler on the (single) level's grids.
  const Level& level = levels[0];
  const double inv_h = 1.0 / level.h_mm;
  parallelOverPoints(
      points_mm.size(),
      [&] {
        Accessors a{level.grid->getConstAccessor(), std::nullopt};
        if (ratio) a.closeness.emplace(level.closeness->getConstAccessor());
        return a;
      },
      [&](std::size_t i, Accessors& acc) {
        const Vec3 p = points_mm[i] * inv_h;  // index space
        const openvdb::Vec3R at(p.x(), p.y(), p.z());
        openvdb::Vec3s v;
        openvdb::tools::QuadraticSampler::sample(acc.grid, at, v);
        if (!ratio) {
          forces[i] = widen(v);
          return;
        }
        const Vec3 base = p.array().floor();
        const openvdb::Coord ijk(int(base.x()), int(base.y()), int(base.z()));
        openvdb::Vec3s c[8];
        if (!cellCorners(acc.grid, ijk, c)) {
          forces[i] = Vec3::Zero();  // background at every corner
          return;
        }
        const PlaneLaw& law = *impl.law;
        float cc[8];
        bool over[8] = {};
        cellCorners(*acc.closeness, ijk, cc, over);
        double s[8];
        for (int k = 0; k < 8; ++k) s[k] = law.r0_mm - cc[k];
        if (!ratioHolds(s, over, /*whole_under_holds=*/false)) {
          for (int k = 0; k < 8; ++k) c[k] *= float(law.at(s[k]));  // the node forces
          forces[i] = blend(c, p - base);
          return;
        }
        float cv = 0.0f;
        openvdb::tools::QuadraticSampler::sample(*acc.closeness, at, cv);
        forces[i] = law.at(law.r0_mm - cv) * widen(v);
      },
      kSerialBelow);
}

std::vector<Vec3> VoxelField::activeNodes(std::size_t max_count) const {
  std::vector<Vec3> nodes;
  for (const Level& level : impl_->levels) {
    const double h = level.h_mm;
    for (auto it = level.grid->cbeginValueOn(); it && nodes.size() < max_count; ++it) {
      const openvdb::Coord ijk = it.getCoord();
      nodes.emplace_back(ijk.x() * h, ijk.y() * h, ijk.z() * h);
    }
  }
  return nodes;
}

std::vector<StoredNode> VoxelField::storedNodes() const {
  std::vector<StoredNode> nodes;
  for (std::size_t l = 0; l < impl_->levels.size(); ++l) {
    const Level& level = impl_->levels[l];
    std::optional<FloatGrid::ConstAccessor> closeness;
    if (level.closeness) closeness.emplace(level.closeness->getConstAccessor());
    for (auto it = level.grid->cbeginValueOn(); it; ++it) {
      const openvdb::Coord ijk = it.getCoord();
      StoredNode n;
      n.x_mm = Vec3(ijk.x(), ijk.y(), ijk.z()) * level.h_mm;
      n.level = int(l);
      n.value = widen(*it);
      if (closeness) {
        n.closeness_mm = closeness->getValue(ijk);
        n.over = closeness->isValueOn(ijk);
      }
      nodes.push_back(n);
    }
  }
  return nodes;
}

bool cudaFieldBackendAvailable() { return kernel::cudaNodeBuildAvailable(); }

void VoxelField::save(const std::filesystem::path& file) const {
  initializeOpenVdb();
  openvdb::GridCPtrVec grids;
  for (std::size_t l = 0; l < impl_->levels.size(); ++l) {
    const Level& level = impl_->levels[l];
    const std::string suffix = l ? "_level" + std::to_string(l) : "";
    if (impl_->stored == StoredQuantity::PlaneRatio) {
      // The node forces P(s)·G (what users look at), then the two stored grids.
      Grid::Ptr force = level.grid->deepCopy();
      force->setName("force" + suffix);
      auto closeness = level.closeness->getConstAccessor();
      for (auto it = force->beginValueOn(); it; ++it) {
        const double s = impl_->law->r0_mm - closeness.getValue(it.getCoord());
        it.setValue(*it * float(impl_->law->at(s)));
      }
      grids.push_back(force);
      grids.push_back(level.grid);
      grids.push_back(level.closeness);
    } else {
      grids.push_back(level.grid);
    }
  }
  common::writeFileAtomically(
      file, [&](std::ostream& out) { openvdb::io::Stream(out).write(grids); },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::field
