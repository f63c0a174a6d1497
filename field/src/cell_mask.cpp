#include "fieldpath/field/cell_mask.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace fieldpath::field {
namespace {

/// A cell's bits while the mask is made (packed into two bitsets after).
constexpr std::uint8_t kCore = 1, kOuter = 2;

/// One axis of the growth: `out` holds kCore where a cell of `in` within `core` steps along the
/// axis has kCore, kOuter likewise within `outer`. The cells are `blocks` blocks of `count`
/// steps along the axis, a step `inner` contiguous cells: each step is read whole (a plane or a
/// row, so that the sweeps along x and y stay in the cache), in parallel over blocks and runs of
/// a step's cells.
void growAxis(const std::vector<std::uint8_t>& in, std::vector<std::uint8_t>& out, long core,
              long outer, long blocks, long count, long inner) {
  constexpr long kRun = 1024;
  const long runs = (inner + kRun - 1) / kRun;
  tbb::parallel_for(tbb::blocked_range<long>(0, blocks * runs), [&](const auto& r) {
    std::vector<long> last_core(std::size_t(std::min(inner, kRun)));
    std::vector<long> last_outer(last_core.size());
    for (long task = r.begin(); task != r.end(); ++task) {
      const long b = task / runs, q0 = (task % runs) * kRun, n = std::min(kRun, inner - q0);
      const std::size_t base = std::size_t(b * count * inner + q0);
      auto at = [&](long i, long q) { return base + std::size_t(i * inner + q); };
      std::fill_n(last_core.begin(), n, -(outer + 1));
      std::fill_n(last_outer.begin(), n, -(outer + 1));
      for (long i = 0; i < count; ++i)
        for (long q = 0; q < n; ++q) {
          const std::uint8_t v = in[at(i, q)];
          if (v & kCore) last_core[std::size_t(q)] = i;
          if (v & kOuter) last_outer[std::size_t(q)] = i;
          out[at(i, q)] = std::uint8_t((i - last_core[std::size_t(q)] <= core ? kCore : 0) |
                                       (i - last_outer[std::size_t(q)] <= outer ? kOuter : 0));
        }
      std::fill_n(last_core.begin(), n, count + outer + 1);
      std::fill_n(last_outer.begin(), n, count + outer + 1);
      for (long i = count - 1; i >= 0; --i)
        for (long q = 0; q < n; ++q) {
          const std::uint8_t v = in[at(i, q)];
          if (v & kCore) last_core[std::size_t(q)] = i;
          if (v & kOuter) last_outer[std::size_t(q)] = i;
          out[at(i, q)] |= std::uint8_t((last_core[std::size_t(q)] - i <= core ? kCore : 0) |
                                        (last_outer[std::size_t(q)] - i <= outer ? kOuter : 0));
        }
    }
  });
}

}  // namespace

CellMask::CellMask(std::span<const Vec3> points_mm, double cell_mm, double core_mm, double outer_mm,
                   const Eigen::AlignedBox3d& relevant_mm)
    : relevant_mm_(relevant_mm) {
  if (!(cell_mm > 0.0) || !std::isfinite(cell_mm))
    throw std::invalid_argument("CellMask: the cell edge must be > 0 mm");
  if (!(outer_mm >= core_mm) || !(core_mm >= 0.0))
    throw std::invalid_argument("CellMask: need 0 <= core_mm <= outer_mm");
  // Hundreds of thousands of points (a job's nodes at every posture): boxed, marked and the
  // cells packed in parallel.
  using Range = tbb::blocked_range<std::size_t>;
  const Eigen::AlignedBox3d box = tbb::parallel_reduce(
      Range(0, points_mm.size(), 4096), Eigen::AlignedBox3d(),
      [&](const Range& r, Eigen::AlignedBox3d b) {
        for (std::size_t i = r.begin(); i != r.end(); ++i)
          if (points_mm[i].allFinite() && relevant_mm.contains(points_mm[i]))
            b.extend(points_mm[i]);
        return b;
      },
      [](Eigen::AlignedBox3d a, const Eigen::AlignedBox3d& b) { return a.extend(b); });
  if (box.isEmpty()) return;
  // The cell edge: as asked, or larger where the box (grown by the dilation and a cell) would
  // hold too many cells.
  cell_mm_ = cell_mm;
  long pad = 0;
  for (;;) {
    pad = long(std::ceil(outer_mm / cell_mm_ - 1e-9)) + 1;
    double cells = 1.0;
    for (int a = 0; a < 3; ++a) cells *= std::floor(box.sizes()[a] / cell_mm_) + 1.0 + 2.0 * pad;
    if (cells <= double(kMaxCells)) break;
    cell_mm_ *= 1.25;
  }
  lo_mm_ = box.min().array() - double(pad) * cell_mm_;
  inv_cell_ = 1.0 / cell_mm_;
  for (int a = 0; a < 3; ++a) dim_[a] = long(std::floor(box.sizes()[a] / cell_mm_)) + 1 + 2 * pad;
  std::vector<std::uint8_t> cells(std::size_t(dim_[0] * dim_[1] * dim_[2]), 0);
  tbb::parallel_for(Range(0, points_mm.size(), 4096), [&](const Range& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      const Vec3& p = points_mm[i];
      if (!p.allFinite() || !relevant_mm.contains(p)) continue;
      long c[3];
      for (int a = 0; a < 3; ++a)
        c[a] = std::clamp(long(std::floor((p[a] - lo_mm_[a]) * inv_cell_)), 0L, dim_[a] - 1);
      // Several threads may mark a cell: the same value, stored atomically.
      std::atomic_ref<std::uint8_t>(cells[std::size_t((c[0] * dim_[1] + c[1]) * dim_[2] + c[2])])
          .store(kCore | kOuter, std::memory_order_relaxed);
    }
  });
  // A cube of cells around each marked one: grown along x, then y, then z (separable).
  const long core = long(std::ceil(core_mm / cell_mm_ - 1e-9));
  const long outer = long(std::ceil(outer_mm / cell_mm_ - 1e-9));
  const long nx = dim_[0], ny = dim_[1], nz = dim_[2];
  std::vector<std::uint8_t> grown(cells.size());
  growAxis(cells, grown, core, outer, 1, nx, ny * nz);  // x: planes of y, z
  growAxis(grown, cells, core, outer, nx, ny, nz);      // y: rows of z
  growAxis(cells, grown, core, outer, nx * ny, nz, 1);  // z
  cells.swap(grown);
  // Packed a bit a cell: the steering looks the core up at every node of every step, and a
  // byte a cell (a few MB) missed the cache on the GPU machine (0.048 against 0.032 s a job).
  const std::size_t words = (cells.size() + 63) / 64;
  core_.assign(words, 0);
  outer_.assign(words, 0);
  tbb::parallel_for(Range(0, words, 256), [&](const Range& r) {
    for (std::size_t w = r.begin(); w != r.end(); ++w)
      for (std::size_t i = 64 * w; i < std::min(cells.size(), 64 * w + 64); ++i) {
        if (cells[i] & kCore) core_[w] |= std::uint64_t{1} << (i & 63);
        if (cells[i] & kOuter) outer_[w] |= std::uint64_t{1} << (i & 63);
      }
  });
  for (std::size_t w = 0; w < words; ++w) {
    core_cells_ += std::size_t(std::popcount(core_[w]));
    outer_cells_ += std::size_t(std::popcount(outer_[w]));
  }
}

bool CellMask::lookUp(const std::vector<std::uint64_t>& bits, const Vec3& p_mm) const {
  if (!relevant_mm_.contains(p_mm)) return true;
  if (bits.empty()) return false;
  long c[3];
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p_mm[a] - lo_mm_[a]) * inv_cell_);
    if (!(f >= 0.0) || f >= double(dim_[a])) return false;
    c[a] = long(f);
  }
  const std::size_t i = std::size_t((c[0] * dim_[1] + c[1]) * dim_[2] + c[2]);
  return (bits[i >> 6] >> (i & 63)) & 1u;
}

}  // namespace fieldpath::field
