#include "fieldpath/field/voxel_field.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <openvdb/io/Stream.h>
#include <openvdb/tools/Interpolation.h>
#include <openvdb/tools/Morphology.h>
#include <openvdb/tools/Prune.h>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "point_index.h"

namespace fieldpath::field {

namespace {

using Grid = openvdb::Vec3SGrid;
using Leaf = Grid::TreeType::LeafNodeType;
constexpr int kLeafDim = static_cast<int>(Leaf::DIM);  // 8 nodes a side

using FloatGrid = openvdb::FloatGrid;
using FloatLeaf = FloatGrid::TreeType::LeafNodeType;

/// How far from a sample nodes are built (mm): r0, plus for the plane ratio a shell one cell
/// diagonal beyond it, whose nodes carry the plane height past r0 (so that a cell straddling
/// r0 interpolates s linearly through it instead of towards the zero background).
double reachMm(const FieldParams& params, const VoxelRequest& request) {
  return request.stored == StoredQuantity::PlaneRatio
             ? params.r0_mm + std::sqrt(3.0) * request.voxel_size_mm
             : params.r0_mm;
}

/// Weight per mm² of sampled surface (κ of law.h PlaneLaw): 1 for area weights.
double weightPerMm2(const ObstacleSamples& samples, const FieldParams& params) {
  if (params.weights == Weights::Area || !(samples.area_mm2 > 0.0)) return 1.0;
  double sum = 0.0;
  for (double w : samples.weights) sum += w;
  return sum / samples.area_mm2;
}

double insideBandMm(const FieldParams& params, const VoxelRequest& request) {
  if (request.inside_band_mm >= 0.0) return request.inside_band_mm;
  const double cells_mm = 2.0 * request.voxel_size_mm + params.r_min_mm;
  return request.stored == StoredQuantity::PlaneRatio ? std::max(cells_mm, params.r0_mm) : cells_mm;
}

void checkVoxelSize(double h_mm) {
  if (!(h_mm > 0.0) || !std::isfinite(h_mm))
    throw common::InputError("voxel size must be > 0 mm (got " + std::to_string(h_mm) + ")");
}

/// World box of the samples padded by reachMm, clipped to the region; empty if no sample.
Eigen::AlignedBox3d reachBox(const ObstacleSamples& samples, const FieldParams& params,
                             const VoxelRequest& request) {
  Eigen::AlignedBox3d box;
  for (const Vec3& q : samples.points_mm) box.extend(q);
  if (box.isEmpty()) return box;
  box.min().array() -= reachMm(params, request);
  box.max().array() += reachMm(params, request);
  if (request.region_mm) box = box.intersection(*request.region_mm);
  return box;
}

std::string mib(double bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0f MiB", bytes / (1024.0 * 1024.0));
  return text;
}

/// Index coordinates must fit OpenVDB's 32-bit Coord with room to spare.
void checkExtent(const Eigen::AlignedBox3d& box, double cell_mm, const char* what) {
  if (box.isEmpty()) return;
  const double reach = std::max(box.min().cwiseAbs().maxCoeff(), box.max().cwiseAbs().maxCoeff());
  if (reach / cell_mm > 1e9)
    throw common::InputError(std::string(what) + " too small for the scene's extent (" +
                             std::to_string(reach) + " mm from the origin)");
}

}  // namespace

std::size_t estimateVoxelNodes(const ObstacleSamples& samples, const FieldParams& params,
                               const VoxelRequest& request) {
  const double h = request.voxel_size_mm;
  checkVoxelSize(h);
  const Eigen::AlignedBox3d box = reachBox(samples, params, request);
  if (box.isEmpty()) return 0;
  // Nodes of the lattice i·h in [lo, hi] along one axis.
  auto count = [h](double lo, double hi) {
    return std::max(0.0, std::floor(hi / h) - std::ceil(lo / h) + 1.0);
  };
  double dense = 1.0;
  for (int a = 0; a < 3; ++a) dense *= count(box.min()[a], box.max()[a]);
  // Every built node lies within reachMm of a sample, so in a cell (edge reach/2) at most two
  // cells from one holding a sample: count the nodes of those cells (clipped to the box) on a
  // coarse mask.
  const double cell_mm = 0.5 * reachMm(params, request);
  checkExtent(box, h, "voxel size");
  Eigen::AlignedBox3d all;
  for (const Vec3& q : samples.points_mm) all.extend(q);
  checkExtent(all, cell_mm, "field.r0");
  auto mask = openvdb::MaskGrid::create(false);
  {
    auto acc = mask->getAccessor();
    for (const Vec3& q : samples.points_mm) {
      const Vec3 c = (q / cell_mm).array().floor();
      acc.setValueOn(openvdb::Coord(int(c.x()), int(c.y()), int(c.z())));
    }
  }
  openvdb::tools::dilateActiveValues(mask->tree(), 2, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                     openvdb::tools::IGNORE_TILES);
  double cells = 0.0;
  for (auto it = mask->cbeginValueOn(); it; ++it) {
    const openvdb::Coord c = it.getCoord();
    double nodes = 1.0;
    for (int a = 0; a < 3; ++a) {
      const double lo = std::max(c[a] * cell_mm, box.min()[a]);
      const double hi = (c[a] + 1) * cell_mm;
      // half-open cell [lo, hi), except where the box's own (closed) end cuts it
      nodes *= hi > box.max()[a] ? count(lo, box.max()[a])
                                 : std::max(0.0, std::ceil(hi / h) - std::ceil(lo / h));
    }
    cells += nodes;
  }
  const double estimate = std::min(dense, cells);
  return estimate >= 1e18 ? std::size_t(1e18) : static_cast<std::size_t>(estimate);
}

namespace {

/// Whether x lies over (or under) the sampled surface: its nearest sample less than `over_mm`
/// sideways. Beyond the edge of an open wall it does not, and "inside" means nothing there.
bool overSurface(const detail::Probe& p, double over_mm) {
  const double lateral_sq = p.nearest_mm * p.nearest_mm - p.height_mm * p.height_mm;
  return lateral_sq <= over_mm * over_mm;
}

constexpr double kOverCos = 0.7;  ///< |cos| of the field's angle to n* over the surface

/// One node of the plane ratio: s (mm), G, and whether it lies over/under the surface.
struct RatioNode {
  double s_mm;
  Vec3 g;
  bool over;
};

/// The plane-ratio pair (s, G) of one node from its probe (law.h): P(s)·G is the field there
/// and s is the plane height η on both sides of a plane, G the plane's normal.
/// - Elsewhere than below: s = P⁻¹(|F|), the height at which a plane gives |F|, and
///   G = F / P(s), the unit field direction: the node gives back F.
/// - Over the sampled surface closer than `near_mm` above it, or under it (inside the obstacle,
///   down to the inside band): the samples' own field there is not yet a plane's (each sample's
///   1/r³ shows, the r_min hold; inside, the surface rule's mirror), so the node holds the
///   continuation of the field at the point x' lifted to near_mm above the surface: s = s' - δ
///   (δ the lift) and G = G' of x'. Cells that reach down to or through the wall then
///   interpolate the field above it, and a node inside gets P(|s|)·G, finite and outward.
/// - Past r0 (the shell, no sample within r0): s = max(η, r0) and G the wall's direction, the
///   plane's continuation, so that a cell straddling r0 interpolates s linearly through it.
/// "Over the surface" (overSurface, and a field along n*) decides the side: beyond the edge of
/// an open wall the field is even about the wall's plane and s stays positive there.
/// `field_at(x')` is the direct field at a point.
template <class FieldAt>
RatioNode planeRatio(const detail::Probe& p, const Vec3& x, const Vec3& q, const Vec3& n,
                     const PlaneLaw& law, double gain, double over_mm, double near_mm,
                     FieldAt&& field_at) {
  const double eta = p.height_mm;
  // Over the surface, and the field along its normal (beyond an edge it turns sideways, away
  // from the edge, and the sign of η says nothing).
  const bool over = overSurface(p, over_mm) &&
                    (!p.force || std::abs(p.force->dot(n)) >= kOverCos * p.force->norm());
  const double sign = gain < 0.0 ? -1.0 : 1.0;
  if (!p.force) {  // shell: no sample within r0
    if (!over) return {std::max(p.nearest_mm, law.r0_mm), sign * (x - q) / p.nearest_mm, false};
    if (eta >= 0.0) return {std::max(eta, law.r0_mm), sign * n, true};
    return {-std::max(-eta, law.r0_mm), Vec3::Zero(), true};
  }
  auto ratioOf = [&](const Vec3& f, double lift_mm) {
    const double e = law.height(f.norm());
    const double plane = law.at(e);
    return RatioNode{e - lift_mm, plane > 0.0 ? Vec3(f / plane) : Vec3::Zero(), over};
  };
  if (!over || eta >= near_mm) return ratioOf(*p.force, 0.0);
  const double lift_mm = near_mm - eta;
  return ratioOf(field_at(Vec3(x + lift_mm * n)), lift_mm);
}

}  // namespace

namespace {

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

Vec3 widen(const openvdb::Vec3s& v) { return Vec3(v.x(), v.y(), v.z()); }
double widen(float v) { return v; }

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
/// blended instead.
bool ratioHolds(const double (&s)[8], const bool (&over)[8]) {
  const bool under = std::any_of(s, s + 8, [](double v) { return v < 0.0; });
  return !under || std::all_of(over, over + 8, [](bool v) { return v; });
}

}  // namespace

namespace {

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

bool bit(const std::vector<std::uint64_t>& words, std::size_t i) {
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
  std::vector<std::array<float, 4>> nodes;  ///< per block: value xyz, closeness
  std::vector<std::uint64_t> over;          ///< per block node: over/under the surface (ratioHolds)
  std::vector<std::uint64_t> refined;       ///< per leaf cell: read the next level instead

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

bool locate(const Level& level, const IndexAccessor& acc, const Vec3& x_mm, CellRef& out) {
  const Vec3 p = x_mm / level.h_mm;  // index space
  const Vec3 base = p.array().floor();
  const int i = int(base.x()), j = int(base.y()), k = int(base.z());
  const openvdb::Coord leaf(i >> 3, j >> 3, k >> 3);  // floor division by 8
  int b;
  if (!level.dense.empty()) {
    const openvdb::Coord d = leaf - level.dense_lo;
    if (unsigned(d.x()) >= unsigned(level.dense_dim.x()) ||
        unsigned(d.y()) >= unsigned(level.dense_dim.y()) ||
        unsigned(d.z()) >= unsigned(level.dense_dim.z()))
      return false;
    b = level.dense[(std::size_t(d.x()) * level.dense_dim.y() + d.y()) * level.dense_dim.z() +
                    d.z()];
  } else {
    b = acc.getValue(leaf);
  }
  if (b < 0) return false;
  const int li = i & (kLeafDim - 1), lj = j & (kLeafDim - 1), lk = k & (kLeafDim - 1);
  out.block = std::size_t(b);
  out.node0 = out.block * kBlockNodes + std::size_t((li * kBlockDim + lj) * kBlockDim + lk);
  out.cell = std::size_t((li * kLeafDim + lj) * kLeafDim + lk);
  out.t = p - base;
  return true;
}

/// The block form of a level's grids (Level::nodes, over; refined cleared).
void makeBlocks(Level& level, bool ratio) {
  std::vector<const Leaf*> leaves;
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
  level.nodes.assign(leaves.size() * kBlockNodes, {0.0f, 0.0f, 0.0f, 0.0f});
  level.over.assign(leaves.size() * kBlockWords, 0);
  level.refined.assign(leaves.size() * kCellWords, 0);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, leaves.size()), [&](const auto& range) {
    auto values = level.grid->getConstAccessor();
    std::optional<FloatGrid::ConstAccessor> closeness;
    if (ratio) closeness.emplace(level.closeness->getConstAccessor());
    for (std::size_t b = range.begin(); b != range.end(); ++b) {
      const openvdb::Coord o = leaves[b]->origin();
      std::uint64_t* over = &level.over[b * kBlockWords];
      for (int i = 0, n = 0; i < kBlockDim; ++i)
        for (int j = 0; j < kBlockDim; ++j)
          for (int k = 0; k < kBlockDim; ++k, ++n) {
            const openvdb::Coord ijk = o.offsetBy(i, j, k);
            const openvdb::Vec3s v = values.getValue(ijk);
            float c = 0.0f;
            if (ratio) {
              c = closeness->getValue(ijk);
              if (closeness->isValueOn(ijk)) over[n >> 6] |= std::uint64_t{1} << (n & 63);
            }
            level.nodes[b * kBlockNodes + n] = {v.x(), v.y(), v.z(), c};
          }
    }
  });
}

/// The trilinear value of one level's cell (no refinement): F, or for the plane ratio
/// P(s~)·G~ where ratioHolds, else the blend of the corner forces.
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
struct LevelAccessors {
  std::vector<IndexAccessor> index;
};

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

/// Hanging nodes: the nodes of a new finer level that lie on a face, edge or corner of a cell
/// of the level above that is not split (or not built) take the value the levels above give
/// there (the trilinear blend of value and closeness, which on a face is the face's bilinear
/// blend, itself exact on the finer nodes of that face). The field is then continuous across
/// the levels' boundaries (the blend of corner forces of the few cells under open edges aside):
/// no jump for the ODE solver to resolve. Nodes inside split cells keep their exact values.
void matchCoarserLevels(Level& fine, const std::vector<Level>& coarser, bool ratio) {
  const Level& parent = coarser.back();
  LevelAccessors acc = accessorsOf(coarser);
  std::optional<FloatGrid::Accessor> closeness;
  if (ratio) closeness.emplace(fine.closeness->getAccessor());
  for (auto it = fine.grid->beginValueOn(); it; ++it) {
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
      const Vec3 centre = (Vec3(cell.x(), cell.y(), cell.z()) + Vec3::Constant(0.5)) * parent.h_mm;
      CellRef ref;
      hanging = !locate(parent, acc.index.back(), centre, ref) ||
                !bit(parent.refined, ref.block * Leaf::SIZE + ref.cell);
    }
    if (!hanging) continue;
    const Vec3 x = Vec3(f.x(), f.y(), f.z()) * fine.h_mm;
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
    if (closeness) closeness->setValueOnly(f, float(v[3]));
  }
}

}  // namespace

struct VoxelField::Impl {
  std::vector<Level> levels;  ///< [0]: h, then h/2, h/4, ... where refined
  VoxelStats stats;
  double voxel_size_mm = 0.0;
  Interpolation interpolation = Interpolation::Trilinear;
  StoredQuantity stored = StoredQuantity::Force;
  std::optional<PlaneLaw> law;  ///< PlaneRatio
};

namespace {

/// What the node values of every level are made from.
struct NodeBuilder {
  const DirectField::Index& index;
  const VoxelRequest& request;
  bool ratio;
  double band_in_mm, reach_mm, over_mm, near_mm;
  PlaneLaw law;

  /// Computes the nodes of `origins` (leaves of a level of size h): all of a leaf's nodes, or
  /// those on in `only`. Returns the level's grids (inactive nodes pruned from the value grid).
  /// Progress between batches, from this thread only.
  std::pair<Grid::Ptr, FloatGrid::Ptr> build(double h, const std::vector<openvdb::Coord>& origins,
                                             const openvdb::MaskGrid* only,
                                             const std::function<void(double)>& progress) const {
    const ObstacleSamples& samples = index.samples;
    const FieldParams& params = index.params;
    auto grid = Grid::create(openvdb::Vec3s(0.0f));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
    grid->setName(ratio ? "plane_ratio" : "force");
    grid->setVectorType(openvdb::VEC_INVARIANT);
    FloatGrid::Ptr closeness;
    if (ratio) {
      closeness = FloatGrid::create(0.0f);
      closeness->setTransform(grid->transform().copy());
      closeness->setName("plane_closeness");
    }
    std::vector<Leaf*> leaves;
    std::vector<FloatLeaf*> float_leaves;
    leaves.reserve(origins.size());
    for (const auto& o : origins) {
      leaves.push_back(grid->tree().touchLeaf(o));
      if (ratio) float_leaves.push_back(closeness->tree().touchLeaf(o));
    }
    const std::size_t batches =
        std::max<std::size_t>(1, std::min<std::size_t>(20, leaves.size() / 64));
    for (std::size_t batch = 0; batch < batches; ++batch) {
      const std::size_t begin = leaves.size() * batch / batches;
      const std::size_t end = leaves.size() * (batch + 1) / batches;
      tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1), [&](const auto& range) {
        auto searcher = index.searcher();
        std::optional<openvdb::MaskGrid::ConstAccessor> wanted;
        if (only) wanted.emplace(only->getConstAccessor());
        std::vector<std::size_t> near;
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
          Leaf& leaf = *leaves[l];
          const openvdb::Coord o = leaf.origin();
          const Vec3 lo = Vec3(o.x(), o.y(), o.z()) * h;
          const Vec3 hi = lo + Vec3::Constant((kLeafDim - 1) * h);
          // Samples within reach of the leaf's nodes, gathered once; the surface rule's second
          // sum, at a point lifted off the wall (rare: nodes within r_min or inside), searches
          // the index.
          near.clear();
          index.forEachInBox(searcher, lo.array() - reach_mm, hi.array() + reach_mm,
                             [&](std::size_t j) { near.push_back(j); });
          for (auto it = leaf.beginValueAll(); it; ++it) {
            const openvdb::Coord ijk = it.getCoord();
            if (wanted && !wanted->isValueOn(ijk)) continue;
            const Vec3 x(ijk.x() * h, ijk.y() * h, ijk.z() * h);
            if (request.region_mm && !request.region_mm->contains(x)) continue;
            auto for_each_near = [&](const Vec3& center, double radius, auto&& fn) {
              if (center == x)
                for (std::size_t j : near) fn(j);
              else
                index.forEachNear(searcher, center, radius, fn);
            };
            const detail::Probe p =
                detail::probe(x, for_each_near, samples.points_mm, samples.normals, samples.weights,
                              params, reach_mm);
            if (p.nearest < 0 || (p.height_mm < -band_in_mm && overSurface(p, over_mm))) continue;
            Vec3 value;
            if (ratio) {
              const RatioNode node =
                  planeRatio(p, x, samples.points_mm[p.nearest], samples.normals[p.nearest], law,
                             params.gain, over_mm, near_mm, [&](const Vec3& at) {
                               return index.fieldAt(searcher, at).value_or(Vec3::Zero());
                             });
              // The closeness grid's active mask carries `over` (see ratioHolds).
              const float closeness_mm = float(params.r0_mm - node.s_mm);
              if (node.over)
                float_leaves[l]->setValueOn(it.pos(), closeness_mm);
              else
                float_leaves[l]->setValueOff(it.pos(), closeness_mm);
              value = node.g;
            } else {
              if (!p.force) continue;
              value = *p.force;
            }
            it.setValue(openvdb::Vec3s(float(value.x()), float(value.y()), float(value.z())));
            it.setValueOn();
          }
        }
      });
      if (progress) progress(double(batch + 1) / double(batches));
    }
    openvdb::tools::pruneInactive(grid->tree());
    // (closeness keeps its leaves: its inactive nodes hold values, those beyond open edges.)
    return {grid, closeness};
  }
};

/// The trilinear error of a cell estimated from its nodes alone: at each corner, along each axis
/// with both neighbours built, the second difference of what is interpolated (s and G for the
/// plane ratio, F for the stored force) over 8 (linear interpolation's error is h²/8 |f''|),
/// turned into a force error: |dP/ds|·|G|·|Δ²s| + P(s)·|Δ²G|, or |Δ²F|. The cell's value is
/// the largest corner error over max(least corner force, floor).
class CurvatureProbe {
 public:
  CurvatureProbe(const Level& level, const std::optional<PlaneLaw>& law, double floor)
      : values_(level.grid->getConstAccessor()), law_(law), floor_(floor) {
    if (law) closeness_.emplace(level.closeness->getConstAccessor());
  }

  double cellError(const openvdb::Coord& cell) {
    double worst = 0.0, sum = 0.0;
    int built = 0;
    for (int c = 0; c < 8; ++c) {
      const Node n = node(cell.offsetBy(c >> 2, (c >> 1) & 1, c & 1));
      if (!n.built) continue;
      worst = std::max(worst, n.error);
      sum += n.force;
      ++built;
    }
    if (!built) return 0.0;
    return worst / std::max(sum / built, floor_);
  }

 private:
  struct Node {
    bool built = false;
    double force = 0.0, error = 0.0;
  };
  struct Read {
    bool built;
    double s;
    Vec3 v;
  };
  Read read(const openvdb::Coord& ijk) {
    const openvdb::Vec3s v = values_.getValue(ijk);
    return {values_.isValueOn(ijk), law_ ? law_->r0_mm - closeness_->getValue(ijk) : 0.0,
            Vec3(v.x(), v.y(), v.z())};
  }
  Node node(const openvdb::Coord& ijk) {
    const Read at = read(ijk);
    Node out;
    if (!at.built) return out;
    out.built = true;
    double slope = 0.0;
    if (law_) {
      constexpr double kStepMm = 1e-4;
      out.force = law_->at(at.s) * at.v.norm();
      slope = std::abs(law_->at(std::abs(at.s) + kStepMm) - law_->at(std::abs(at.s) - kStepMm)) /
              (2 * kStepMm);
    } else {
      out.force = at.v.norm();
    }
    for (int a = 0; a < 3; ++a) {
      openvdb::Coord lo = ijk, hi = ijk;
      lo[a] -= 1;
      hi[a] += 1;
      const Read m = read(lo), p = read(hi);
      if (!m.built || !p.built) continue;
      const Vec3 dv = m.v - 2.0 * at.v + p.v;
      const double e =
          law_ ? slope * at.v.norm() * std::abs(m.s - 2.0 * at.s + p.s) + law_->at(at.s) * dv.norm()
               : dv.norm();
      out.error = std::max(out.error, e / 8.0);
    }
    return out;
  }
  Grid::ConstAccessor values_;
  std::optional<FloatGrid::ConstAccessor> closeness_;
  const std::optional<PlaneLaw>& law_;
  double floor_;
};

/// Cells of level 0 to test: every cell of a block with a non-zero corner (index coordinates).
std::vector<openvdb::Coord> cellsWithValues(const Level& level) {
  std::vector<openvdb::Coord> cells;
  auto acc = level.block_of->getConstAccessor();
  for (auto it = level.block_of->cbeginValueOn(); it; ++it) {
    const std::size_t b = std::size_t(*it);
    const openvdb::Coord o = it.getCoord() << 3;
    for (int i = 0; i < kLeafDim; ++i)
      for (int j = 0; j < kLeafDim; ++j)
        for (int k = 0; k < kLeafDim; ++k) {
          const std::size_t n0 = b * kBlockNodes + std::size_t((i * kBlockDim + j) * kBlockDim + k);
          bool any = false;
          for (int c = 0; c < 8 && !any; ++c) {
            const auto& v = level.nodes[n0 + kCornerOffset[c]];
            any = v[0] != 0.0f || v[1] != 0.0f || v[2] != 0.0f;
          }
          if (any) cells.push_back(o.offsetBy(i, j, k));
        }
  }
  return cells;
}

}  // namespace

VoxelField::VoxelField(const DirectField& direct, const VoxelRequest& request)
    : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  const DirectField::Index& index = direct.index();
  const ObstacleSamples& samples = index.samples;
  const FieldParams& params = index.params;
  const double h = request.voxel_size_mm;
  checkVoxelSize(h);
  const StoredQuantity stored = request.stored;
  const bool ratio = stored == StoredQuantity::PlaneRatio;
  const double tolerance = request.refine_tolerance;
  const int refine_levels = request.refine_levels;
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw common::InputError("field.refine_tolerance: must be >= 0 (got " +
                             std::to_string(tolerance) + ")");
  if (refine_levels < 0 || refine_levels > 6)
    throw common::InputError("field.refine_levels: must be in [0, 6] (got " +
                             std::to_string(refine_levels) + ")");
  if (tolerance > 0.0 && request.interpolation == Interpolation::Quadratic)
    throw common::InputError(
        "field.refine_tolerance: refinement is trilinear only (field.interpolation: quadratic)");
  // Sideways reach of a sample (sub-triangle centroids: within 0.87 step of any surface point);
  // closer to the surface than about one spacing the samples' field is not yet a plane's.
  const NodeBuilder builder{index,
                            request,
                            ratio,
                            insideBandMm(params, request),
                            reachMm(params, request),
                            params.sample_step_mm,
                            request.plane_near_mm.value_or(
                                (tolerance > 0.0 ? kRefinedNearFactor : 2.0) * params.r_min_mm),
                            PlaneLaw(params, weightPerMm2(samples, params))};
  const double reach_mm = builder.reach_mm;

  auto refuse = [&](const std::string& what, double nodes, double bytes_per_node) {
    const double bytes = nodes * bytes_per_node;
    if (bytes <= static_cast<double>(request.max_memory_bytes)) return;
    throw common::InputError("voxel field at h = " + std::to_string(h) + " mm: " + what + " " +
                             std::to_string(static_cast<long long>(nodes)) + " nodes (" +
                             mib(bytes) + "), over the limit of " +
                             mib(static_cast<double>(request.max_memory_bytes)) +
                             "; use a coarser voxel size or a smaller region");
  };
  impl_->stats.estimated_nodes = estimateVoxelNodes(samples, params, request);
  // The plane ratio adds a float to the Vec3f of a node.
  const double value_bytes = ratio ? 16.0 : 12.0;
  refuse("estimated", static_cast<double>(impl_->stats.estimated_nodes),
         kVoxelBytesPerNode * value_bytes / 12.0);

  // Candidate leaves (8³ nodes): those within reach of a sample, inside the region.
  const Eigen::AlignedBox3d reach = reachBox(samples, params, request);
  std::vector<openvdb::Coord> origins;
  if (!reach.isEmpty()) {
    const Vec3 lo_region = reach.min() / h, hi_region = reach.max() / h;
    const double leaf_mm = kLeafDim * h;
    for (const Vec3& q : samples.points_mm) {
      const Vec3 lo = ((q.array() - reach_mm) / h).max(lo_region.array()).ceil();
      const Vec3 hi = ((q.array() + reach_mm) / h).min(hi_region.array()).floor();
      if ((lo.array() > hi.array()).any()) continue;
      const openvdb::Coord a(int(lo.x()), int(lo.y()), int(lo.z()));
      const openvdb::Coord b(int(hi.x()), int(hi.y()), int(hi.z()));
      const openvdb::Coord la = a & ~(kLeafDim - 1), lb = b & ~(kLeafDim - 1);
      for (int i = la.x(); i <= lb.x(); i += kLeafDim)
        for (int j = la.y(); j <= lb.y(); j += kLeafDim)
          for (int k = la.z(); k <= lb.z(); k += kLeafDim) {
            // Distance from q to the leaf's node box.
            const Vec3 box_lo = Vec3(i, j, k) * h;
            const Vec3 nearest = q.cwiseMax(box_lo).cwiseMin(box_lo + Vec3::Constant(leaf_mm - h));
            if ((nearest - q).squaredNorm() < reach_mm * reach_mm) origins.emplace_back(i, j, k);
          }
    }
  }
  std::sort(origins.begin(), origins.end());
  origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
  // Full leaves: the values of a node, masks and header, and the query block (9³ × 16 bytes).
  refuse("candidate leaves hold", static_cast<double>(origins.size()) * Leaf::SIZE,
         static_cast<double>(sizeof(Leaf)) / Leaf::SIZE * value_bytes / 12.0 + 12.0 +
             16.0 * kBlockNodes / Leaf::SIZE);

  // Progress: level 0 takes the whole bar without refinement, half of it with.
  const double level0_share = tolerance > 0.0 ? 0.5 : 1.0;
  std::vector<Level>& levels = impl_->levels;
  levels.emplace_back();
  levels[0].h_mm = h;
  std::tie(levels[0].grid, levels[0].closeness) = builder.build(h, origins, nullptr, [&](double f) {
    common::report(request.progress, level0_share * f, "field");
  });
  makeBlocks(levels[0], ratio);
  std::optional<PlaneLaw> law;
  if (ratio) law = builder.law;

  // Refinement: estimate each candidate cell's error from its nodes, split those that miss.
  VoxelStats& stats = impl_->stats;
  if (tolerance > 0.0 && refine_levels > 0) {
    const double floor = kRefineFloorFraction * builder.law.at(2.0 * params.r_min_mm);
    std::vector<openvdb::Coord> cells = cellsWithValues(levels[0]);
    for (int l = 0; l < refine_levels && !cells.empty(); ++l) {
      const double hl = levels[l].h_mm;
      std::vector<char> split(cells.size(), 0);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size()), [&](const auto& range) {
        CurvatureProbe curvature(levels[std::size_t(l)], law, floor);
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          const openvdb::Coord& ijk = cells[c];
          const Vec3 x = (Vec3(ijk.x(), ijk.y(), ijk.z()) + Vec3::Constant(0.5)) * hl;
          if (request.region_mm && !request.region_mm->contains(x)) continue;
          split[c] = curvature.cellError(ijk) > tolerance;
        }
      });
      stats.tested_cells += cells.size();
      // Mark the split cells and gather the nodes of their halves.
      auto fine_nodes = openvdb::MaskGrid::create(false);
      std::vector<openvdb::Coord> next_cells;
      {
        auto mask = fine_nodes->getAccessor();
        auto acc = levels[l].block_of->getConstUnsafeAccessor();
        for (std::size_t c = 0; c < cells.size(); ++c) {
          if (!split[c]) continue;
          const openvdb::Coord& ijk = cells[c];
          CellRef ref;
          const Vec3 x = (Vec3(ijk.x(), ijk.y(), ijk.z()) + Vec3::Constant(0.5)) * hl;
          if (!locate(levels[l], acc, x, ref)) continue;
          levels[l].refined[ref.block * kCellWords + (ref.cell >> 6)] |= std::uint64_t{1}
                                                                         << (ref.cell & 63);
          ++stats.refined_cells;
          const openvdb::Coord fine = ijk << 1;
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              for (int k = 0; k < 3; ++k) {
                mask.setValueOn(fine.offsetBy(i, j, k));
                if (i < 2 && j < 2 && k < 2) next_cells.push_back(fine.offsetBy(i, j, k));
              }
        }
      }
      if (next_cells.empty()) break;
      std::vector<openvdb::Coord> fine_origins;
      for (auto leaf = fine_nodes->tree().cbeginLeaf(); leaf; ++leaf)
        fine_origins.push_back(leaf->origin());
      // All levels so far and the new one, at the estimate's bytes per node.
      double built_nodes = double(fine_nodes->activeVoxelCount());
      for (const Level& level : levels) built_nodes += double(level.grid->activeVoxelCount());
      refuse("refined level " + std::to_string(l + 1) + " makes", built_nodes,
             kVoxelBytesPerNode * value_bytes / 12.0);
      Level fine;
      fine.h_mm = 0.5 * hl;
      const double share_begin = level0_share + (1.0 - level0_share) * l / refine_levels;
      const double share_end = level0_share + (1.0 - level0_share) * (l + 1) / refine_levels;
      std::tie(fine.grid, fine.closeness) =
          builder.build(fine.h_mm, fine_origins, fine_nodes.get(), [&](double f) {
            common::report(request.progress, share_begin + (share_end - share_begin) * f, "field");
          });
      fine.grid->setName(fine.grid->getName() + "_level" + std::to_string(l + 1));
      if (fine.closeness) fine.closeness->setName("plane_closeness_level" + std::to_string(l + 1));
      matchCoarserLevels(fine, levels, ratio);
      makeBlocks(fine, ratio);
      stats.refined_nodes += fine.grid->activeVoxelCount();
      levels.push_back(std::move(fine));
      cells = std::move(next_cells);
    }
  }

  stats.levels = int(levels.size());
  stats.active_nodes = 0;
  stats.memory_bytes = 0;
  for (const Level& level : levels) {
    stats.active_nodes += level.grid->activeVoxelCount();
    stats.memory_bytes += level.memUsage();
  }
  const openvdb::CoordBBox active_box = levels[0].grid->evalActiveVoxelBoundingBox();
  stats.dense_box_nodes = active_box.empty() ? 0 : active_box.volume();
  stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  impl_->voxel_size_mm = h;
  impl_->interpolation = request.interpolation;
  impl_->stored = stored;
  impl_->law = law;
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
        if (!ratioHolds(s, over)) {
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
      file, [&](std::ofstream& out) { openvdb::io::Stream(out).write(grids); },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::field
