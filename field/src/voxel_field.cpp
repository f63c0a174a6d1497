#include "fieldpath/field/voxel_field.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

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

double insideBandMm(const FieldParams& params, const VoxelRequest& request) {
  return request.inside_band_mm >= 0.0 ? request.inside_band_mm
                                       : 2.0 * request.voxel_size_mm + params.r_min_mm;
}

void checkVoxelSize(double h_mm) {
  if (!(h_mm > 0.0) || !std::isfinite(h_mm))
    throw common::InputError("voxel size must be > 0 mm (got " + std::to_string(h_mm) + ")");
}

/// World box of the samples padded by r0, clipped to the region; empty if no sample.
Eigen::AlignedBox3d reachBox(const ObstacleSamples& samples, const FieldParams& params,
                             const VoxelRequest& request) {
  Eigen::AlignedBox3d box;
  for (const Vec3& q : samples.points_mm) box.extend(q);
  if (box.isEmpty()) return box;
  box.min().array() -= params.r0_mm;
  box.max().array() += params.r0_mm;
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
  // Every built node lies within r0 of a sample, so in a cell (edge r0/2) at most two cells from
  // one holding a sample: count the nodes of those cells (clipped to the box) on a coarse mask.
  const double cell_mm = 0.5 * params.r0_mm;
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

struct VoxelField::Impl {
  Grid::Ptr grid;
  VoxelStats stats;
  double voxel_size_mm = 0.0;
  Interpolation interpolation = Interpolation::Trilinear;
};

VoxelField::VoxelField(const DirectField& direct, const VoxelRequest& request)
    : impl_(std::make_unique<Impl>()) {
  const auto start = std::chrono::steady_clock::now();
  const DirectField::Index& index = direct.index();
  const ObstacleSamples& samples = index.samples;
  const FieldParams& params = index.params;
  const double h = request.voxel_size_mm;
  checkVoxelSize(h);
  const double band_in_mm = insideBandMm(params, request);

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
  refuse("estimated", static_cast<double>(impl_->stats.estimated_nodes), kVoxelBytesPerNode);

  // Candidate leaves (8³ nodes): those within r0 of a sample, inside the region.
  const Eigen::AlignedBox3d reach = reachBox(samples, params, request);
  std::vector<openvdb::Coord> origins;
  if (!reach.isEmpty()) {
    const Vec3 lo_region = reach.min() / h, hi_region = reach.max() / h;
    const double leaf_mm = kLeafDim * h;
    for (const Vec3& q : samples.points_mm) {
      const Vec3 lo = ((q.array() - params.r0_mm) / h).max(lo_region.array()).ceil();
      const Vec3 hi = ((q.array() + params.r0_mm) / h).min(hi_region.array()).floor();
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
            if ((nearest - q).squaredNorm() < params.r0_mm * params.r0_mm)
              origins.emplace_back(i, j, k);
          }
    }
  }
  std::sort(origins.begin(), origins.end());
  origins.erase(std::unique(origins.begin(), origins.end()), origins.end());
  // Full leaves: a Vec3f a node, masks and header.
  refuse("candidate leaves hold", static_cast<double>(origins.size()) * Leaf::SIZE,
         static_cast<double>(sizeof(Leaf)) / Leaf::SIZE + 12.0);

  auto grid = Grid::create(openvdb::Vec3s(0.0f));
  grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
  grid->setName("force");
  grid->setVectorType(openvdb::VEC_INVARIANT);
  std::vector<Leaf*> leaves;
  leaves.reserve(origins.size());
  for (const auto& o : origins) leaves.push_back(grid->tree().touchLeaf(o));

  // Node values from the exact law, per leaf over the samples near it; in batches between
  // which the progress hook is called (from this thread only).
  const std::size_t batches =
      std::max<std::size_t>(1, std::min<std::size_t>(20, leaves.size() / 64));
  for (std::size_t batch = 0; batch < batches; ++batch) {
    const std::size_t begin = leaves.size() * batch / batches;
    const std::size_t end = leaves.size() * (batch + 1) / batches;
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1), [&](const auto& range) {
      auto searcher = index.searcher();
      std::vector<std::size_t> near;
      for (std::size_t l = range.begin(); l != range.end(); ++l) {
        Leaf& leaf = *leaves[l];
        const openvdb::Coord o = leaf.origin();
        const Vec3 lo = Vec3(o.x(), o.y(), o.z()) * h;
        const Vec3 hi = lo + Vec3::Constant((kLeafDim - 1) * h);
        // Samples within r0 of the leaf's nodes, gathered once; the surface rule's second sum, at
        // a point lifted off the wall (rare: nodes within r_min or inside), searches the index.
        near.clear();
        index.forEachInBox(searcher, lo.array() - params.r0_mm, hi.array() + params.r0_mm,
                           [&](std::size_t j) { near.push_back(j); });
        for (auto it = leaf.beginValueAll(); it; ++it) {
          const openvdb::Coord ijk = it.getCoord();
          const Vec3 x(ijk.x() * h, ijk.y() * h, ijk.z() * h);
          if (request.region_mm && !request.region_mm->contains(x)) continue;
          auto for_each_near = [&](const Vec3& center, double radius, auto&& fn) {
            if (center == x)
              for (std::size_t j : near) fn(j);
            else
              index.forEachNear(searcher, center, radius, fn);
          };
          const auto f = detail::fieldAt(x, for_each_near, samples.points_mm, samples.normals,
                                         samples.weights, params, band_in_mm);
          if (!f) continue;
          it.setValue(openvdb::Vec3s(float(f->x()), float(f->y()), float(f->z())));
          it.setValueOn();
        }
      }
    });
    common::report(request.progress, double(batch + 1) / double(batches), "field");
  }
  openvdb::tools::pruneInactive(grid->tree());

  VoxelStats& stats = impl_->stats;
  stats.active_nodes = grid->activeVoxelCount();
  const openvdb::CoordBBox active_box = grid->evalActiveVoxelBoundingBox();
  stats.dense_box_nodes = active_box.empty() ? 0 : active_box.volume();
  stats.memory_bytes = grid->memUsage();
  stats.build_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  impl_->grid = std::move(grid);
  impl_->voxel_size_mm = h;
  impl_->interpolation = request.interpolation;
}

VoxelField::~VoxelField() = default;
VoxelField::VoxelField(VoxelField&&) noexcept = default;
VoxelField& VoxelField::operator=(VoxelField&&) noexcept = default;

const VoxelStats& VoxelField::stats() const { return impl_->stats; }
double VoxelField::voxelSizeMm() const { return impl_->voxel_size_mm; }
Interpolation VoxelField::interpolation() const { return impl_->interpolation; }

namespace {

/// Trilinear interpolation in index space (OpenVDB BoxSampler's weights), with a fast path that
/// reads the 8 corners straight from the leaf buffer when they share a leaf (7 cells in 8 along
/// each axis), the accessor otherwise.
Vec3 trilinear(Grid::ConstAccessor& acc, const Vec3& p) {
  const Eigen::Vector3d base = p.array().floor();
  const openvdb::Coord ijk(int(base.x()), int(base.y()), int(base.z()));
  const Vec3 t = p - base;
  openvdb::Vec3s c[8];
  const openvdb::Coord in_leaf = ijk & (kLeafDim - 1);
  if (in_leaf.x() < kLeafDim - 1 && in_leaf.y() < kLeafDim - 1 && in_leaf.z() < kLeafDim - 1) {
    const Leaf* leaf = acc.probeConstLeaf(ijk);
    if (!leaf) return Vec3::Zero();  // background everywhere in the cell
    const openvdb::Vec3s* v = leaf->buffer().data() + Leaf::coordToOffset(ijk);
    constexpr int dx = kLeafDim * kLeafDim, dy = kLeafDim;
    for (int i = 0; i < 8; ++i) c[i] = v[(i & 4 ? dx : 0) + (i & 2 ? dy : 0) + (i & 1)];
  } else {
    for (int i = 0; i < 8; ++i)
      c[i] = acc.getValue(ijk.offsetBy(i & 4 ? 1 : 0, i & 2 ? 1 : 0, i & 1));
  }
  auto lerp = [](const openvdb::Vec3s& a, const openvdb::Vec3s& b, double w) {
    return Vec3(a.x() + w * (b.x() - a.x()), a.y() + w * (b.y() - a.y()),
                a.z() + w * (b.z() - a.z()));
  };
  // c index bits: x (4), y (2), z (1)
  const Vec3 c00 = lerp(c[0], c[1], t.z()), c01 = lerp(c[2], c[3], t.z());
  const Vec3 c10 = lerp(c[4], c[5], t.z()), c11 = lerp(c[6], c[7], t.z());
  const Vec3 c0 = c00 + t.y() * (c01 - c00), c1 = c10 + t.y() * (c11 - c10);
  return c0 + t.x() * (c1 - c0);
}

}  // namespace

void VoxelField::evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const {
  checkSpans(points_mm, forces);
  const Grid& grid = *impl_->grid;
  const double inv_h = 1.0 / impl_->voxel_size_mm;
  const bool quadratic = impl_->interpolation == Interpolation::Quadratic;
  // A sample costs tens of ns: below a few thousand points (one tool's nodes) threads cost more
  // than they give.
  constexpr std::size_t kSerialBelow = 4096;
  parallelOverPoints(
      points_mm.size(), [&] { return grid.getConstAccessor(); },
      [&](std::size_t i, Grid::ConstAccessor& acc) {
        const Vec3 p = points_mm[i] * inv_h;  // index space
        if (!quadratic) {
          forces[i] = trilinear(acc, p);
          return;
        }
        openvdb::Vec3s v;
        openvdb::tools::QuadraticSampler::sample(acc, openvdb::Vec3R(p.x(), p.y(), p.z()), v);
        forces[i] = Vec3(v.x(), v.y(), v.z());
      },
      kSerialBelow);
}

std::vector<Vec3> VoxelField::activeNodes(std::size_t max_count) const {
  std::vector<Vec3> nodes;
  const double h = impl_->voxel_size_mm;
  for (auto it = impl_->grid->cbeginValueOn(); it && nodes.size() < max_count; ++it) {
    const openvdb::Coord ijk = it.getCoord();
    nodes.emplace_back(ijk.x() * h, ijk.y() * h, ijk.z() * h);
  }
  return nodes;
}

void VoxelField::save(const std::filesystem::path& file) const {
  initializeOpenVdb();
  openvdb::GridCPtrVec grids{impl_->grid};
  common::writeFileAtomically(
      file, [&](std::ofstream& out) { openvdb::io::Stream(out).write(grids); },
      std::ios::out | std::ios::binary);
}

}  // namespace fieldpath::field
