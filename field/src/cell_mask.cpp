#include "fieldpath/field/cell_mask.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace fieldpath::field {
namespace {

/// Grows the cells with `bit` set by `reach` cells along one axis (runs of `count` cells
/// `stride` apart, starting at `run_starts`): a cell gets the bit if one within `reach` along the
/// axis has it. Two sweeps a run with a running distance to the last set cell; runs in parallel
/// (each writes its own cells).
void growAlong(std::vector<std::uint8_t>& cells, std::uint8_t bit, long reach, long count,
               long stride, const std::vector<long>& run_starts) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, run_starts.size(), 64), [&](const auto& r) {
    std::vector<char> set(std::size_t(count), 0);
    for (std::size_t run = r.begin(); run != r.end(); ++run) {
      const long start = run_starts[run];
      long last = -(reach + 1);  // the last cell holding the bit before this one
      for (long i = 0; i < count; ++i) {
        if (cells[std::size_t(start + i * stride)] & bit) last = i;
        set[std::size_t(i)] = i - last <= reach;
      }
      last = count + reach + 1;
      for (long i = count - 1; i >= 0; --i) {
        if (cells[std::size_t(start + i * stride)] & bit) last = i;
        if (set[std::size_t(i)] || last - i <= reach) cells[std::size_t(start + i * stride)] |= bit;
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
  Eigen::AlignedBox3d box;
  for (const Vec3& p : points_mm)
    if (p.allFinite() && relevant_mm.contains(p)) box.extend(p);
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
  bits_.assign(std::size_t(dim_[0] * dim_[1] * dim_[2]), 0);
  for (const Vec3& p : points_mm) {
    if (!p.allFinite() || !relevant_mm.contains(p)) continue;
    long c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(long(std::floor((p[a] - lo_mm_[a]) * inv_cell_)), 0L, dim_[a] - 1);
    bits_[std::size_t((c[0] * dim_[1] + c[1]) * dim_[2] + c[2])] = kCore | kOuter;
  }
  // A cube of cells around each marked one: grown along x, then y, then z (separable).
  const long core = long(std::ceil(core_mm / cell_mm_ - 1e-9));
  const long outer = long(std::ceil(outer_mm / cell_mm_ - 1e-9));
  const long nx = dim_[0], ny = dim_[1], nz = dim_[2];
  std::vector<long> starts_x, starts_y, starts_z;
  for (long j = 0; j < ny; ++j)
    for (long k = 0; k < nz; ++k) starts_x.push_back(j * nz + k);
  for (long i = 0; i < nx; ++i)
    for (long k = 0; k < nz; ++k) starts_y.push_back(i * ny * nz + k);
  for (long i = 0; i < nx; ++i)
    for (long j = 0; j < ny; ++j) starts_z.push_back((i * ny + j) * nz);
  for (const auto [bit, reach] : {std::pair{kCore, core}, std::pair{kOuter, outer}}) {
    growAlong(bits_, bit, reach, nx, ny * nz, starts_x);
    growAlong(bits_, bit, reach, ny, nz, starts_y);
    growAlong(bits_, bit, reach, nz, 1, starts_z);
  }
  for (const std::uint8_t b : bits_) {
    outer_cells_ += (b & kOuter) != 0;
    core_cells_ += (b & kCore) != 0;
  }
}

std::uint8_t CellMask::bits(const Vec3& p_mm) const {
  if (!relevant_mm_.contains(p_mm)) return kCore | kOuter;
  if (bits_.empty()) return 0;
  long c[3];
  for (int a = 0; a < 3; ++a) {
    const double f = std::floor((p_mm[a] - lo_mm_[a]) * inv_cell_);
    if (!(f >= 0.0) || f >= double(dim_[a])) return 0;
    c[a] = long(f);
  }
  return bits_[std::size_t((c[0] * dim_[1] + c[1]) * dim_[2] + c[2])];
}

}  // namespace fieldpath::field
