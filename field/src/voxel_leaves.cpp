/// Which leaves and nodes a level of the voxel field has (voxel_grid.h): the estimate of a
/// build's nodes before it allocates, the candidate leaves within reach of a sample, the trees
/// made from a level's leaves, and the nodes of the halves of a level's split cells. Split out
/// of voxel_build.cpp.
#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <type_traits>
#include <vector>

#include <openvdb/tools/Morphology.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

#include "voxel_grid.h"

namespace fieldpath::field {

using namespace voxel;

std::size_t estimateVoxelNodes(const ObstacleSamples& samples, const FieldParams& params,
                               const VoxelRequest& request) {
  return detail::estimateVoxelNodes(samples, params, request, double(std::size_t{1} << 24));
}

std::size_t detail::estimateVoxelNodes(const ObstacleSamples& samples, const FieldParams& params,
                                       const VoxelRequest& request, double dense_limit_cells) {
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
  // The nodes of one cell (clipped to the box).
  auto cellNodes = [&](const openvdb::Coord& c) {
    double nodes = 1.0;
    for (int a = 0; a < 3; ++a) {
      const double lo = std::max(c[a] * cell_mm, box.min()[a]);
      const double hi = (c[a] + 1) * cell_mm;
      // half-open cell [lo, hi), except where the box's own (closed) end cuts it
      nodes *= hi > box.max()[a] ? count(lo, box.max()[a])
                                 : std::max(0.0, std::ceil(hi / h) - std::ceil(lo / h));
    }
    return nodes;
  };
  auto cellOf = [&](const Vec3& q) {
    const Vec3 c = (q / cell_mm).array().floor();
    return openvdb::Coord(int(c.x()), int(c.y()), int(c.z()));
  };
  double cells = 0.0;
  // The cells within two of a sample's (Chebyshev distance <= 2: a 5³ box, separable): on a
  // dense bitmap over the samples' cells ± 2 where it is small (every scene of a part: ~0.1 ms,
  // a twentieth of a uniform CUDA build's budget went to the mask grid below), else on a mask
  // grid dilated twice across faces, edges and vertices (the same set).
  const openvdb::Coord c_lo = cellOf(all.min()).offsetBy(-2), c_hi = cellOf(all.max()).offsetBy(2);
  std::int64_t dim[3];  // (64 bits: checkExtent allows ~2e9 cells a side)
  for (int a = 0; a < 3; ++a) dim[a] = std::int64_t(c_hi[a]) - c_lo[a] + 1;
  const double dense_cells = double(dim[0]) * double(dim[1]) * double(dim[2]);
  if (dense_cells <= dense_limit_cells) {
    const std::size_t nx = std::size_t(dim[0]), ny = std::size_t(dim[1]), nz = std::size_t(dim[2]);
    auto at = [&](std::size_t i, std::size_t j, std::size_t k) { return (i * ny + j) * nz + k; };
    std::vector<std::uint8_t> on(nx * ny * nz, 0), grown(on.size(), 0);
    for (const Vec3& q : samples.points_mm) {
      const openvdb::Coord c = cellOf(q) - c_lo;
      on[at(std::size_t(c.x()), std::size_t(c.y()), std::size_t(c.z()))] = 1;
    }
    // Dilate by 2 along z, then y, then x (on and grown swap roles).
    const std::size_t step[3] = {ny * nz, nz, 1}, size[3] = {nx, ny, nz};
    for (int axis = 2; axis >= 0; --axis) {
      for (std::size_t n = 0; n < on.size(); ++n) {
        const std::size_t pos = (n / step[axis]) % size[axis];
        std::uint8_t v = 0;
        for (int d = -2; d <= 2 && !v; ++d) {
          const long p = long(pos) + d;
          if (p >= 0 && p < long(size[axis])) v = on[std::size_t(long(n) + d * long(step[axis]))];
        }
        grown[n] = v;
      }
      on.swap(grown);
    }
    for (std::size_t i = 0; i < nx; ++i)
      for (std::size_t j = 0; j < ny; ++j)
        for (std::size_t k = 0; k < nz; ++k)
          if (on[at(i, j, k)]) cells += cellNodes(c_lo.offsetBy(int(i), int(j), int(k)));
  } else {
    auto mask = openvdb::MaskGrid::create(false);
    {
      auto acc = mask->getAccessor();
      for (const Vec3& q : samples.points_mm) acc.setValueOn(cellOf(q));
    }
    openvdb::tools::dilateActiveValues(mask->tree(), 2, openvdb::tools::NN_FACE_EDGE_VERTEX,
                                       openvdb::tools::IGNORE_TILES);
    for (auto it = mask->cbeginValueOn(); it; ++it) cells += cellNodes(it.getCoord());
  }
  const double estimate = std::min(dense, cells);
  return estimate >= 1e18 ? std::size_t(1e18) : static_cast<std::size_t>(estimate);
}

namespace voxel {

/// Origins (index space) of the leaves within reach_mm of a sample and inside `reach` (the
/// region's box), sorted. Marked on a byte per leaf of that box (a sample touches ~60 leaves:
/// a list of them all, sorted and made unique, cost more than the uniform grid's nodes on the
/// GPU), or listed and sorted where the box has too many leaves.
LeafCandidates candidateLeaves(const ObstacleSamples& samples, const Eigen::AlignedBox3d& reach,
                               double h, double reach_mm, std::size_t max_leaves) {
  LeafCandidates found;
  std::vector<openvdb::Coord>& origins = found.origins;
  if (reach.isEmpty()) return found;
  const Vec3 lo_region = reach.min() / h, hi_region = reach.max() / h;
  const double leaf_mm = kLeafDim * h;
  // Calls hit(i, j, k) for each leaf origin within reach of q (inside the region) while it
  // returns true.
  auto leavesNear = [&](const Vec3& q, auto&& hit) {
    const Vec3 lo = ((q.array() - reach_mm) / h).max(lo_region.array()).ceil();
    const Vec3 hi = ((q.array() + reach_mm) / h).min(hi_region.array()).floor();
    if ((lo.array() > hi.array()).any()) return;
    const openvdb::Coord a(int(lo.x()), int(lo.y()), int(lo.z()));
    const openvdb::Coord b(int(hi.x()), int(hi.y()), int(hi.z()));
    const openvdb::Coord la = a & ~(kLeafDim - 1), lb = b & ~(kLeafDim - 1);
    for (int i = la.x(); i <= lb.x(); i += kLeafDim)
      for (int j = la.y(); j <= lb.y(); j += kLeafDim)
        for (int k = la.z(); k <= lb.z(); k += kLeafDim) {
          // Distance from q to the leaf's node box.
          const Vec3 box_lo = Vec3(i, j, k) * h;
          const Vec3 nearest = q.cwiseMax(box_lo).cwiseMin(box_lo + Vec3::Constant(leaf_mm - h));
          if ((nearest - q).squaredNorm() < reach_mm * reach_mm && !hit(i, j, k)) return;
        }
  };
  const Vec3 lo_all = lo_region.array().ceil(), hi_all = hi_region.array().floor();
  if ((lo_all.array() > hi_all.array()).any()) return found;
  // The leaves one sample has at least (those holding a node of the cube inscribed in its
  // ball): more than max_leaves refused before listing any (a sample at a grid of 0.1 um walked
  // 1e8 leaf positions of its ball's box before its first ones came).
  const double inscribed = reach_mm / std::sqrt(3.0) * (1.0 - 1e-9);
  for (const Vec3& q : samples.points_mm) {
    const Vec3 lo = ((q.array() - inscribed) / h).max(lo_all.array()).ceil();
    const Vec3 hi = ((q.array() + inscribed) / h).min(hi_all.array()).floor();
    double leaves = 1.0;
    for (int a = 0; a < 3; ++a)
      leaves *=
          lo[a] > hi[a] ? 0.0 : std::floor(hi[a] / kLeafDim) - std::floor(lo[a] / kLeafDim) + 1.0;
    if (leaves > double(max_leaves)) {
      found.more = true;
      found.at_least = std::size_t(std::min(leaves, 1e18));
      return found;
    }
  }
  const openvdb::Coord box_lo =
      openvdb::Coord(int(lo_all.x()), int(lo_all.y()), int(lo_all.z())) & ~(kLeafDim - 1);
  const openvdb::Coord box_hi =
      openvdb::Coord(int(hi_all.x()), int(hi_all.y()), int(hi_all.z())) & ~(kLeafDim - 1);
  const openvdb::Coord dim((box_hi.x() - box_lo.x()) / kLeafDim + 1,
                          (box_hi.y() - box_lo.y()) / kLeafDim + 1,
                          (box_hi.z() - box_lo.z()) / kLeafDim + 1);
  const double box_leaves = double(dim.x()) * dim.y() * dim.z();
  auto compact = [&origins] {
    std::sort(origins.begin(), origins.end());
    origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
  };
  if (box_leaves > double(kDenseIndexMax)) {
    // Listed, and made unique whenever the list passes twice the most wanted: past max_leaves
    // unique ones the search stops (within a sample too: one may reach millions of leaves).
    const std::size_t compact_at = std::max<std::size_t>(
        std::size_t{1} << 16,
        max_leaves > (std::size_t(-1) >> 2) ? std::size_t(-1) : 2 * max_leaves);
    for (const Vec3& q : samples.points_mm) {
      leavesNear(q, [&](int i, int j, int k) {
        origins.emplace_back(i, j, k);
        if (origins.size() > compact_at) {
          compact();
          found.more = origins.size() > max_leaves;
        }
        return !found.more;
      });
      if (found.more) break;
    }
    compact();
    found.more = origins.size() > max_leaves;
    if (found.more) found.at_least = origins.size();
    return found;
  }
  std::vector<std::uint8_t> near(std::size_t(box_leaves), 0);
  auto at = [&](int i, int j, int k) {
    return (std::size_t((i - box_lo.x()) / kLeafDim) * dim.y() + (j - box_lo.y()) / kLeafDim) *
               dim.z() + (k - box_lo.z()) / kLeafDim;
  };
  // The samples in parallel: a leaf's byte may be set by several threads (the same 1); the
  // leaves set first counted, the samples left skipped once more than max_leaves are (a grid far
  // finer than memory allows: a sample alone may reach millions of leaves).
  std::atomic<std::size_t> marked{0};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, samples.size(), 256), [&](const auto& r) {
    for (std::size_t s = r.begin(); s != r.end(); ++s) {
      if (marked.load(std::memory_order_relaxed) > max_leaves) return;
      std::size_t fresh = 0;
      leavesNear(samples.points_mm[s], [&](int i, int j, int k) {
        fresh += std::atomic_ref<std::uint8_t>(near[at(i, j, k)])
                     .exchange(1, std::memory_order_relaxed) == 0;
        return true;
      });
      marked.fetch_add(fresh, std::memory_order_relaxed);
    }
  });
  if (marked.load() > max_leaves) {
    found.more = true;
    found.at_least = marked.load();
    return found;
  }
  for (int i = box_lo.x(); i <= box_hi.x(); i += kLeafDim)  // sorted: x, then y, then z
    for (int j = box_lo.y(); j <= box_hi.y(); j += kLeafDim)
      for (int k = box_lo.z(); k <= box_hi.z(); k += kLeafDim)
        if (near[at(i, j, k)]) origins.emplace_back(i, j, k);
  return found;
}

namespace {

/// Malloc's bookkeeping a heap block, at most (glibc: 16 bytes on 64 bits; rounded up).
constexpr double kHeapBlockBytes = 32.0;

/// How many distinct coordinates `coords` has once each is masked to its parent of span 2^log2.
std::size_t distinctParents(std::vector<openvdb::Coord> coords, int log2) {
  const int mask = ~((1 << log2) - 1);
  for (openvdb::Coord& c : coords) c = openvdb::Coord(c.x() & mask, c.y() & mask, c.z() & mask);
  std::sort(coords.begin(), coords.end());
  return std::size_t(std::unique(coords.begin(), coords.end()) - coords.begin());
}

/// Bytes of a tree whose leaves have the origins `leaves` (index space of the tree): each leaf
/// (its node, its buffer on the heap), the internal nodes above them and the root's entries.
template <class TreeT>
double treeBytesBound(const std::vector<openvdb::Coord>& leaves) {
  using LeafT = typename TreeT::LeafNodeType;
  using Node2 = typename TreeT::RootNodeType::ChildNodeType;
  using Node1 = typename Node2::ChildNodeType;
  const double leaf = double(sizeof(LeafT)) + kHeapBlockBytes +
                      double(LeafT::SIZE) * sizeof(typename LeafT::ValueType) + kHeapBlockBytes;
  const std::size_t n1 = distinctParents(leaves, int(Node1::TOTAL));
  const std::size_t n2 = distinctParents(leaves, int(Node2::TOTAL));
  // A root entry: a std::map node holding the child's pointer and its tile (~64 bytes).
  return double(leaves.size()) * leaf + double(n1) * (sizeof(Node1) + kHeapBlockBytes) +
         double(n2) * (sizeof(Node2) + kHeapBlockBytes + 64.0) + double(sizeof(TreeT));
}

/// A leaf's block (makeBlocks): 9³ entries, its flags, the leaf's pointer and its state.
double blockBytes() {
  return double(kBlockNodes) * sizeof(std::array<float, 4>) + 8.0 * (kBlockWords + kCellWords) +
         sizeof(const Leaf*) + 1.0;
}

}  // namespace

double levelBytesPerLeaf(bool ratio) {
  const double value_leaf = double(sizeof(Leaf)) + Leaf::SIZE * sizeof(Leaf::ValueType);
  const double closeness_leaf =
      ratio ? double(sizeof(FloatLeaf)) + FloatLeaf::SIZE * sizeof(float) : 0.0;
  return value_leaf + closeness_leaf + blockBytes();
}

double levelBytesBound(const std::vector<openvdb::Coord>& origins, bool ratio) {
  double bytes = treeBytesBound<Grid::TreeType>(origins);
  if (ratio) bytes += treeBytesBound<FloatGrid::TreeType>(origins);
  // The block index (makeBlocks): an int a leaf coordinate (origin >> 3), as a tree, and as a
  // dense array over their box where that is small enough.
  std::vector<openvdb::Coord> index_leaves(origins.size());
  openvdb::CoordBBox box;
  for (std::size_t l = 0; l < origins.size(); ++l) {
    const openvdb::Coord c = origins[l] >> 3;
    box.expand(c);
    const int m = ~(int(IndexGrid::TreeType::LeafNodeType::DIM) - 1);
    index_leaves[l] = openvdb::Coord(c.x() & m, c.y() & m, c.z() & m);
  }
  std::sort(index_leaves.begin(), index_leaves.end());
  index_leaves.erase(std::unique(index_leaves.begin(), index_leaves.end()), index_leaves.end());
  bytes += treeBytesBound<IndexGrid::TreeType>(index_leaves);
  if (!origins.empty()) {
    const openvdb::Coord dim = box.dim();
    const double entries = double(dim.x()) * dim.y() * dim.z();
    if (entries <= double(kDenseIndexMax)) bytes += entries * sizeof(std::int32_t);
  }
  return bytes + double(origins.size()) * blockBytes() + 4.0 * kHeapBlockBytes;
}

namespace {

/// Adds the leaves to the tree, which takes them: the leaves grouped by their parent (the
/// internal nodes one level up, 16³ leaves), each group's parent made and filled in parallel,
/// then the parents added to their own parents and to the root (a few dozen). One accessor
/// adding every leaf was 25-55 ms, serial, at a refined level on the GPU machine.
template <class TreeT>
void addLeavesTo(std::vector<std::unique_ptr<typename TreeT::LeafNodeType>>& made, TreeT& tree) {
  using Leaf1 = typename TreeT::LeafNodeType;
  using Node1 = typename TreeT::RootNodeType::ChildNodeType::ChildNodeType;  // 16³ leaves
  using Node2 = typename TreeT::RootNodeType::ChildNodeType;                  // 32³ of those
  static_assert(std::is_same_v<typename Node1::ChildNodeType, Leaf1>);
  const auto parentOf = [](const openvdb::Coord& xyz, int log2_span) {
    const int mask = ~((1 << log2_span) - 1);
    return openvdb::Coord(xyz.x() & mask, xyz.y() & mask, xyz.z() & mask);
  };
  // The leaves in their parents' order (then their own).
  std::vector<std::uint32_t> order(made.size());
  for (std::size_t l = 0; l < made.size(); ++l) order[l] = std::uint32_t(l);
  tbb::parallel_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const openvdb::Coord pa = parentOf(made[a]->origin(), Node1::TOTAL);
    const openvdb::Coord pb = parentOf(made[b]->origin(), Node1::TOTAL);
    return pa != pb ? pa < pb : made[a]->origin() < made[b]->origin();
  });
  std::vector<std::size_t> starts;  // first leaf (in `order`) of each parent
  for (std::size_t i = 0; i < order.size(); ++i)
    if (i == 0 || parentOf(made[order[i]]->origin(), Node1::TOTAL) !=
                      parentOf(made[order[i - 1]]->origin(), Node1::TOTAL))
      starts.push_back(i);
  starts.push_back(order.size());
  const std::size_t parents = starts.size() - 1;
  std::vector<std::unique_ptr<Node1>> nodes(parents);
  const auto background = tree.background();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, parents, 1), [&](const auto& range) {
    for (std::size_t p = range.begin(); p != range.end(); ++p) {
      nodes[p] = std::make_unique<Node1>(
          parentOf(made[order[starts[p]]]->origin(), Node1::TOTAL), background);
      for (std::size_t i = starts[p]; i < starts[p + 1]; ++i)
        nodes[p]->addLeaf(made[order[i]].release());  // the node owns it
    }
  });
  // Their parents: a node of 32³ children holds 32768 entries (512 KiB for a Vec3f grid),
  // written whole when made, and a part around the origin has up to 8 of them: made in
  // parallel (serial, they were most of a uniform GPU build's 4.6 ms here).
  std::vector<openvdb::Coord> top_origins;
  for (const auto& node : nodes) top_origins.push_back(parentOf(node->origin(), Node2::TOTAL));
  std::sort(top_origins.begin(), top_origins.end());
  top_origins.erase(std::unique(top_origins.begin(), top_origins.end()), top_origins.end());
  std::vector<std::unique_ptr<Node2>> tops(top_origins.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tops.size(), 1), [&](const auto& range) {
    for (std::size_t t = range.begin(); t != range.end(); ++t)
      tops[t] = std::make_unique<Node2>(top_origins[t], background);
  });
  for (auto& node : nodes) {
    const openvdb::Coord origin = parentOf(node->origin(), Node2::TOTAL);
    const auto t = std::lower_bound(top_origins.begin(), top_origins.end(), origin);
    tops[std::size_t(t - top_origins.begin())]->addChild(node.release());
  }
  for (auto& top : tops) tree.root().addChild(top.release());
}

}  // namespace

void addLeaves(std::vector<std::unique_ptr<Leaf>>& made, Grid::TreeType& tree) {
  addLeavesTo(made, tree);
}
void addLeaves(std::vector<std::unique_ptr<FloatLeaf>>& made, FloatGrid::TreeType& tree) {
  addLeavesTo(made, tree);
}

/// The nodes of the halves of `cells` (3³ a cell at the next level), marked on a mask per task
/// and merged (the same set as one serial pass).
openvdb::MaskGrid::Ptr nodesOfHalves(const CellList& cells) {
  struct Marker {
    const CellList* cells;
    openvdb::MaskGrid::Ptr mask = openvdb::MaskGrid::create(false);
    explicit Marker(const CellList* c) : cells(c) {}
    Marker(Marker& other, tbb::split) : cells(other.cells) {}
    void operator()(const tbb::blocked_range<std::size_t>& range) {
      auto acc = mask->getAccessor();
      for (std::size_t c = range.begin(); c != range.end(); ++c) {
        const openvdb::Coord fine = (*cells)[c].coord() << 1;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) acc.setValueOn(fine.offsetBy(i, j, k));
      }
    }
    void join(Marker& other) { mask->tree().topologyUnion(other.mask->tree()); }
  };
  Marker marker(&cells);
  tbb::parallel_reduce(tbb::blocked_range<std::size_t>(0, cells.size(), 4096), marker);
  return marker.mask;
}

}  // namespace voxel
}  // namespace fieldpath::field
