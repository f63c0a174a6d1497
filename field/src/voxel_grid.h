#pragma once
/// Internal to field/: the voxel field's grid levels and the pieces its two OpenVDB translation
/// units share (voxel_build.cpp: the nodes and the refinement; voxel_field.cpp: the block form
/// of a level and the queries). Includes OpenVDB: never include from a public header.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <openvdb/openvdb.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/field/voxel_field.h"
#include "huge_pages.h"  // UninitVector
#include "point_index.h"

namespace fieldpath::field::voxel {

using Grid = openvdb::Vec3SGrid;
using Leaf = Grid::TreeType::LeafNodeType;
constexpr int kLeafDim = static_cast<int>(Leaf::DIM);  // 8 nodes a side

using FloatGrid = openvdb::FloatGrid;
using FloatLeaf = FloatGrid::TreeType::LeafNodeType;

/// How far from a sample nodes are built (mm): r0, plus for the plane ratio a shell one cell
/// diagonal beyond it, whose nodes carry the plane height past r0 (so that a cell straddling
/// r0 interpolates s linearly through it instead of towards the zero background).
inline double reachMm(const FieldParams& params, const VoxelRequest& request) {
  return request.stored == StoredQuantity::PlaneRatio
             ? params.r0_mm + std::sqrt(3.0) * request.voxel_size_mm
             : params.r0_mm;
}

/// Weight per mm² of sampled surface (κ of law.h PlaneLaw): 1 for area weights.
inline double weightPerMm2(const ObstacleSamples& samples, const FieldParams& params) {
  if (params.weights == Weights::Area || !(samples.area_mm2 > 0.0)) return 1.0;
  double sum = 0.0;
  for (double w : samples.weights) sum += w;
  return sum / samples.area_mm2;
}

inline double insideBandMm(const FieldParams& params, const VoxelRequest& request) {
  if (request.inside_band_mm >= 0.0) return request.inside_band_mm;
  const double cells_mm = 2.0 * request.voxel_size_mm + params.r_min_mm;
  return request.stored == StoredQuantity::PlaneRatio ? std::max(cells_mm, params.r0_mm) : cells_mm;
}

inline void checkVoxelSize(double h_mm) {
  if (!(h_mm > 0.0) || !std::isfinite(h_mm))
    throw common::InputError("voxel size must be > 0 mm (got " + std::to_string(h_mm) + ")");
}

/// World box of the samples padded by reachMm, clipped to the region; empty if no sample.
inline Eigen::AlignedBox3d reachBox(const ObstacleSamples& samples, const FieldParams& params,
                             const VoxelRequest& request) {
  Eigen::AlignedBox3d box;
  for (const Vec3& q : samples.points_mm) box.extend(q);
  if (box.isEmpty()) return box;
  box.min().array() -= reachMm(params, request);
  box.max().array() += reachMm(params, request);
  if (request.region_mm) box = box.intersection(*request.region_mm);
  return box;
}

inline std::string mib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024.0));
  return text;
}

/// Index coordinates must fit OpenVDB's 32-bit Coord with room to spare.
inline void checkExtent(const Eigen::AlignedBox3d& box, double cell_mm, const char* what) {
  if (box.isEmpty()) return;
  const double reach = std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff());
  if (reach / cell_mm > 1e9)
    throw common::InputError(std::string(what) + " too small for the scene's extent (" +
                             std::to_string(reach) + " mm from the origin)");
}


/// The 8 corner values of the cell at ijk (index bits: x 4, y 2, z 1), read straight from the
/// leaf buffer when they share a leaf (7 cells in 8 along each axis), through the accessor
/// otherwise. False where the cell lies in an absent leaf (background everywhere).
/// `on`, if given, receives the corners' active states.
template <class Accessor, class Value>
bool cellCorners(Accessor& acc, const openvdb::Coord& ijk, Value (&c)[8], bool* on = nullptr) {
  using LeafT = typename Accessor::TreeType::LeafNodeType;
  const openvdb::Coord in_leaf = ijk & (kLeafDim - 1);
  if (in_leaf.x() < kLeafDim - 1 && in_leaf.y() < kLeafDim - 1 && in_leaf.z() < kLeafDim - 1) {
    const LeafT* leaf = acc.probeConstLeaf(ijk);
    if (!leaf) return false;
    const openvdb::Index base = LeafT::coordToOffset(ijk);
    const Value* v = leaf->buffer().data() + base;
    constexpr int dx = kLeafDim * kLeafDim, dy = kLeafDim;
    for (int i = 0; i < 8; ++i) {
      const int offset = (i & 4 ? dx : 0) + (i & 2 ? dy : 0) + (i & 1);
      c[i] = v[offset];
      if (on) on[i] = leaf->isValueOn(base + offset);
    }
  } else {
    for (int i = 0; i < 8; ++i) {
      const openvdb::Coord corner = ijk.offsetBy(i & 4 ? 1 : 0, i & 2 ? 1 : 0, i & 1);
      c[i] = acc.getValue(corner);
      if (on) on[i] = acc.isValueOn(corner);
    }
  }
  return true;
}

inline Vec3 widen(const openvdb::Vec3s& v) { return Vec3(v.x(), v.y(), v.z()); }
inline double widen(float v) { return v; }

/// Trilinear blend (OpenVDB BoxSampler's weights) of the corners at fractions t in the cell.
template <class Value>
auto blend(const Value (&c)[8], const Vec3& t) {
  using R = decltype(widen(c[0]));
  auto lerp = [](const R& a, const R& b, double w) -> R { return a + w * (b - a); };
  const R c00 = lerp(widen(c[0]), widen(c[1]), t.z()), c01 = lerp(widen(c[2]), widen(c[3]), t.z());
  const R c10 = lerp(widen(c[4]), widen(c[5]), t.z()), c11 = lerp(widen(c[6]), widen(c[7]), t.z());
  return lerp(lerp(c00, c01, t.y()), lerp(c10, c11, t.y()), t.x());
}

struct Accessors {
  Grid::ConstAccessor grid;
  std::optional<FloatGrid::ConstAccessor> closeness;
};

/// Whether the plane-ratio blend holds in a cell, from its corner heights s (mm) and whether
/// each corner lies over/under the surface (the closeness grid's active mask): everywhere but
/// where corners under the surface (s < 0) meet corners that are not (beyond the edge of an open
/// wall, where s > 0 on both sides of the wall's plane; past the inner end of the inside band).
/// s jumps there, and P(s~) would read the wall's r_min value in mid-air; the corner forces are
/// blended instead. A cell wholly under the surface holds it too (s~ < 0 throughout), also with
/// corners not over it: nodes under a surface that is no plane's hold their own force with
/// s = -P⁻¹(|F|) (past kPlaneRescaleLimit), whose decay the blend follows where forces blended
/// trilinearly overshoot (+27 % 1 mm under a lone triangle at h = 0.5).
/// (`whole_under_holds` false: not so for quadratic interpolation, whose 27 nodes reach past
/// the cell's 8 corners this tests.)
inline bool ratioHolds(const double (&s)[8], const bool (&over)[8], bool whole_under_holds = true) {
  const bool under = std::any_of(s, s + 8, [](double v) { return v < 0.0; });
  return !under || std::all_of(over, over + 8, [](bool v) { return v; }) ||
         (whole_under_holds && std::all_of(s, s + 8, [](double v) { return v < 0.0; }));
}

using IndexGrid = openvdb::Int32Grid;
constexpr int kBlockDim = kLeafDim + 1;                         ///< a leaf's nodes and the +1 layer
constexpr int kBlockNodes = kBlockDim * kBlockDim * kBlockDim;  // 729
constexpr int kBlockWords = (kBlockNodes + 63) / 64;            ///< bits of one flag per block node
constexpr int kCellWords = Leaf::SIZE / 64;                     ///< bits of one flag per leaf cell
/// Offsets of a cell's 8 corners in a block (index bits: x 4, y 2, z 1, as cellCorners).
constexpr int kCornerOffset[8] = {0,
                                  1,
                                  kBlockDim,
                                  kBlockDim + 1,
                                  kBlockDim* kBlockDim,
                                  kBlockDim* kBlockDim + 1,
                                  kBlockDim* kBlockDim + kBlockDim,
                                  kBlockDim* kBlockDim + kBlockDim + 1};

inline bool bit(const std::vector<std::uint64_t>& words, std::size_t i) {
  return (words[i >> 6] >> (i & 63)) & 1u;
}


/// One level of the grid: the OpenVDB grids (build, save) and their query form, a block per
/// leaf holding its 8³ nodes and the first layer of its +x, +y, +z neighbours (9³), so that every
/// cell of the leaf reads its 8 corners from one place after one index lookup.
struct Level {
  double h_mm = 0.0;
  Grid::Ptr grid;            ///< F (Force) or G = F / P(s) (PlaneRatio), world frame
  FloatGrid::Ptr closeness;  ///< PlaneRatio: r0 - s (mm), same topology; background 0 (s = r0)
  IndexGrid::Ptr block_of;   ///< leaf coordinate (node ijk >> 3) → block number; background -1
  /// The same as a dense array over the leaves' bounding box (when it has at most
  /// kDenseIndexMax entries; empty otherwise): a query outside the box is rejected by three
  /// compares, one inside costs one load instead of a walk down the tree.
  std::vector<std::int32_t> dense;
  openvdb::Coord dense_lo, dense_dim;
  /// Blocks are filled when first read (ensureBlock: a query's locate; fillBlocks: all of a
  /// level, for the refinement's estimate), not when the level is made: `field build` reads
  /// none (8 of the uniform example's ~65 ms were its blocks: 16 MB of fresh pages, copied),
  /// a job those its tool reaches. Hence mutable: a const query fills its block once.
  mutable UninitVector<std::array<float, 4>> nodes;  ///< per block: value xyz, closeness
  mutable std::vector<std::uint64_t> over;  ///< per block node: over/under the surface (ratioHolds)
  std::vector<std::uint64_t> refined;       ///< per leaf cell: read the next level instead
  std::vector<const Leaf*> block_leaves;    ///< the leaf of each block
  std::unique_ptr<std::atomic<std::uint8_t>[]>
      block_state;     ///< kBlockEmpty, kBlockFilling, kBlockReady
  bool ratio = false;  ///< closeness read into the blocks

  std::size_t blocks() const { return nodes.size() / kBlockNodes; }
  std::size_t memUsage() const {
    return grid->memUsage() + (closeness ? closeness->memUsage() : 0) + block_of->memUsage() +
           dense.size() * sizeof(dense[0]) + nodes.size() * sizeof(nodes[0]) +
           (over.size() + refined.size()) * 8;
  }
};

/// Where a point falls at one level: its block, the cell's first node in it, the cell in the
/// leaf and the fractions in the cell. False outside every block (zero field).
struct CellRef {
  std::size_t node0 = 0, cell = 0, block = 0;
  Vec3 t;
};

/// Index lookups without registering with the tree (the trees are not changed once built): an
/// evaluate call makes one per level, and a registered accessor costs a concurrent-map insert.
using IndexAccessor = IndexGrid::ConstUnsafeAccessor;

/// Entries of Level::dense at most (64 MiB).
constexpr std::size_t kDenseIndexMax = std::size_t{16} << 20;

/// The block of the leaf at `leaf` (node ijk >> 3), -1 where there is none.
inline int blockAt(const Level& level, const IndexAccessor& acc, const openvdb::Coord& leaf) {
  if (level.dense.empty()) return acc.getValue(leaf);
  const openvdb::Coord d = leaf - level.dense_lo;
  if (unsigned(d.x()) >= unsigned(level.dense_dim.x()) ||
      unsigned(d.y()) >= unsigned(level.dense_dim.y()) ||
      unsigned(d.z()) >= unsigned(level.dense_dim.z()))
    return -1;
  return level.dense[(std::size_t(d.x()) * level.dense_dim.y() + d.y()) * level.dense_dim.z() +
                     d.z()];
}

bool locate(const Level& level, const IndexAccessor& acc, const Vec3& x_mm, CellRef& out);
/// The block form of a level's grids: the index from leaves to blocks, refined cleared, the
/// blocks (Level::nodes, over) allocated but not filled (ensureBlock, fillBlocks).
void makeBlocks(Level& level, bool ratio);
constexpr std::uint8_t kBlockEmpty = 0, kBlockFilling = 1, kBlockReady = 2;
/// Fills block b unless another thread has or is (then waits for it).
void fillBlockOnce(const Level& level, std::size_t b);
/// Block b filled before it is read: one load once it is.
inline void ensureBlock(const Level& level, std::size_t b) {
  if (level.block_state[b].load(std::memory_order_acquire) != kBlockReady) fillBlockOnce(level, b);
}
/// Every block of the level filled (in parallel).
void fillBlocks(const Level& level);
/// The trilinear value of one level's cell (no refinement): F, or for the plane ratio
/// P(s~)·G~ where ratioHolds, else the blend of the corner forces.
Vec3 cellValue(const Level& level, const CellRef& cell, const std::optional<PlaneLaw>& law);

/// Per-thread query state: one index accessor per level.
struct LevelAccessors {
  std::vector<IndexAccessor> index;
};
LevelAccessors accessorsOf(const std::vector<Level>& levels);
/// The cell that holds x at the finest level there (not refined), and that level; false
/// outside every block.
bool finestCell(const std::vector<Level>& levels, LevelAccessors& acc, const Vec3& x_mm,
                CellRef& cell, std::size_t& level);
/// The trilinear field at x: the finest level whose cell holds x and is not refined.
Vec3 trilinearAt(const std::vector<Level>& levels, LevelAccessors& acc, const Vec3& x_mm,
                 const std::optional<PlaneLaw>& law);
/// Hanging nodes: the nodes of a new finer level that lie on a face, edge or corner of a cell
/// of the level above that is not split (or not built) take the value the levels above give
/// there (the trilinear blend of value and closeness, which on a face is the face's bilinear
/// blend, itself exact on the finer nodes of that face). The field is then continuous across
/// the levels' boundaries (the blend of corner forces of the few cells under open edges aside):
/// no jump for the ODE solver to resolve. Nodes inside split cells keep their exact values.
void matchCoarserLevels(Level& fine, const std::vector<Level>& coarser, bool ratio);

/// The refinement's error estimate of a level's cells (voxel_refine.cpp), from its nodes alone:
/// at each built node, along each axis with both neighbours built, the second difference of
/// what is interpolated (s and G for the plane ratio, F for the stored force) over 8 (linear
/// interpolation's error is h²/8 |f''|) as a force error, |dP/ds|·|G|·|Δ²s| + P(s)·|Δ²G| or
/// |Δ²F|; a cell's is the largest of its corners' over max(their mean force, floor). The nodes'
/// are computed once, by leaves in parallel (the level's blocks made: makeBlocks).
/// A plane-ratio cell whose built corners (at least one) all lie under the surface, deeper than
/// half its diagonal (s <= -√3 h / 2: over the surface s is the signed height; a node under it
/// holding its own force has η <= s < 0) is wholly inside the obstacle (the height is 1-Lipschitz):
/// no tool node of a valid path is ever there, and one that has entered still gets the coarse
/// level's outward field, so its error is 0 and it is never split (issue 15: these cells were
/// 59 % of the finest nodes of the impeller refined to 0.5 %).
class CellErrors {
 public:
  CellErrors(const Level& level, const std::optional<PlaneLaw>& law, double floor);
  /// Of the cell whose lowest corner is `cell` (index space); 0 where no corner is built.
  double cellError(const openvdb::Coord& cell, const IndexAccessor& acc) const;

 private:
  const Level& level_;
  double floor_;
  UninitVector<double> force_, error_;  ///< per node of each block's leaf (Leaf::SIZE a block;
                                        ///< set where built_ is)
  std::vector<std::uint64_t> built_;   ///< a bit per such node: value on
  std::vector<std::uint64_t> inside_;  ///< ... and under the surface by >= √3 h / 2 (plane ratio)
};
/// A cell's lowest corner (index coordinates), trivially constructible: the refinement's lists
/// of millions of cells are made without zeroing them first (serial, it was a third of the
/// refinement's host work on the GPU machine), then written in parallel.
struct CellIjk {
  std::int32_t x, y, z;
  openvdb::Coord coord() const { return {x, y, z}; }
};
using CellList = UninitVector<CellIjk>;

/// Cells of a level to test: every cell of a block with a non-zero corner.
CellList cellsWithValues(const Level& level);

/// Origins (index space) of the leaves of a level of size h within reach_mm of a sample and
/// inside `reach` (the region's box), sorted (voxel_leaves.cpp). Stops once more than
/// `max_leaves` are found (`more` set, `origins` then incomplete), its own list held to about
/// twice that: a grid far finer than memory allows is refused from its leaves' count, not after
/// listing them all.
struct LeafCandidates {
  std::vector<openvdb::Coord> origins;
  bool more = false;         ///< more than max_leaves
  std::size_t at_least = 0;  ///< with `more`: how many were found before the search stopped
};
LeafCandidates candidateLeaves(const ObstacleSamples& samples, const Eigen::AlignedBox3d& reach,
                               double h, double reach_mm, std::size_t max_leaves = std::size_t(-1));
/// Bytes a level holds at most when it has the leaves at `origins` (sorted candidateLeaves, all
/// of them made before the prune): the value and closeness trees (leaves, their buffers and
/// internal nodes, from the parents the origins have), the block index and the blocks
/// (Level::memUsage's parts), from the types' sizes (voxel_leaves.cpp).
double levelBytesBound(const std::vector<openvdb::Coord>& origins, bool ratio);
/// Bytes a level's leaf costs at least in levelBytesBound (its share without internal nodes).
double levelBytesPerLeaf(bool ratio);
/// Adds a level's leaves (made apart, in parallel) to its tree, which takes them: grouped by
/// their parent nodes, each parent filled by one task (voxel_leaves.cpp).
void addLeaves(std::vector<std::unique_ptr<Leaf>>& made, Grid::TreeType& tree);
void addLeaves(std::vector<std::unique_ptr<FloatLeaf>>& made, FloatGrid::TreeType& tree);
/// The nodes of the halves of `cells` (3³ a cell at the next level) on a mask (voxel_leaves.cpp).
openvdb::MaskGrid::Ptr nodesOfHalves(const CellList& cells);

/// The levels of a voxel field built from the samples (voxel_build.cpp): level 0 at h, then
/// the refined levels; the stats but for memory and the dense box.
struct BuiltLevels {
  std::vector<Level> levels;
  VoxelStats stats;
  std::optional<PlaneLaw> law;  ///< PlaneRatio
};
/// `level0`: the level 0 of a uniform build (levelZeroRequest(request)), refined here instead
/// of building it again.
BuiltLevels buildLevels(const DirectField& direct, const VoxelRequest& request,
                        std::optional<Level> level0 = std::nullopt);

}  // namespace fieldpath::field::voxel
