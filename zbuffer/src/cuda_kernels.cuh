#pragma once
/// Internal to zbuffer/: the CUDA backend's device code (cuda_engine.cu includes it, once): the
/// height keys, the tile maxima, and the cutting kernels: one thread a small-footprint posture,
/// a warp a large one, a warp a group of consecutive postures (the path's), SIMSURF1's coarse
/// kernel. The per-line and per-triangle math is kernels.h's, the CPU's, so that heights are
/// bit-identical (compiled with -fmad=false, IEEE division and square root).
#include <cuda_runtime.h>

#include <cfloat>
#include <climits>
#include <cstddef>
#include <cstdint>

#include "cuda_engine.h"

namespace fieldpath::zbuffer::cuda {
namespace {

constexpr int kWarpsPerBlock = 4;
/// Trace counters (FIELDPATH_ZB_TRACE): lines visited, lowered; the group kernel's lines past its
/// group floor, exact cuts, tiles cut and skipped.
constexpr int kStats = 6;

__device__ inline float keyToFloat(std::int32_t key) { return __int_as_float(orderedBits(key)); }
__device__ inline std::int32_t floatToKey(float h) { return orderedBits(__float_as_int(h)); }

/// Float bits ↔ ordered keys in place (the map is its own inverse).
__global__ void orderBitsKernel(std::int32_t* values, std::size_t n) {
  const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) values[i] = orderedBits(values[i]);
}

/// Every line at the same height (as an ordered key): a constant stock needs no upload.
__global__ void fillKernel(std::int32_t* keys, std::size_t n, std::int32_t key) {
  const std::size_t i = std::size_t(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i < n) keys[i] = key;
}

/// Processing order of a prepass: postures 0, stride, 2 stride, ... of the block.
__global__ void strideOrderKernel(std::uint32_t* order, int count, int stride) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k < count) order[k] = std::uint32_t(k) * std::uint32_t(stride);
}

/// The tiles' maxima from the heights: the chunk's fixed copy (culling, footprints) and the live
/// one (tile skips, lowered as tiles are cut whole).
__global__ void tileMaxKernel(GridView g, const std::int32_t* keys, float* tile_max,
                              float* tile_live) {
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t >= g.tiles_x * g.tiles_y) return;
  const int tx = t % g.tiles_x, ty = t / g.tiles_x;
  const int iy1 = min(g.ny, (ty + 1) << g.tile_shift), ix1 = min(g.nx, (tx + 1) << g.tile_shift);
  std::int32_t m = INT_MIN;
  for (int iy = ty << g.tile_shift; iy < iy1; ++iy)
    for (int ix = tx << g.tile_shift; ix < ix1; ++ix) m = max(m, keys[std::size_t(iy) * g.nx + ix]);
  tile_max[t] = tile_live[t] = keyToFloat(m);
}

/// Footprints of at most this many lines are cut by one thread (few lines per posture, as in a
/// fine finishing path over a coarse grid); larger ones go to a warp.
constexpr int kSmallFootprintLines = 48;

/// Posture `k` of the chunk in processing order.
__device__ inline Posture postureAt(const Posture* postures, const std::uint32_t* order, int k) {
  return postures[order ? order[k] : std::uint32_t(k)];
}

/// Lowers a tile's maximum to `highest` (a bound of its lines' heights; see readTileMax): a
/// compare-and-swap loop, as there is no float atomicMin.
__device__ inline void lowerTileMax(float* tile_max, int tile, float highest) {
  int* slot = reinterpret_cast<int*>(tile_max + tile);
  int seen = *slot;
  while (__int_as_float(seen) > highest) {
    const int was = atomicCAS(slot, seen, __float_as_int(highest));
    if (was == seen) break;
    seen = was;
  }
}

/// The least / largest / sum of the warp's values, on every lane (all 32 lanes must call).
template <class T>
__device__ inline T warpMin(T v) {
  for (int o = 16; o > 0; o >>= 1) v = min(v, __shfl_xor_sync(0xffffffffu, v, o));
  return v;
}
template <class T>
__device__ inline T warpMax(T v) {
  for (int o = 16; o > 0; o >>= 1) v = max(v, __shfl_xor_sync(0xffffffffu, v, o));
  return v;
}
template <class T>
__device__ inline T warpSum(T v) {
  for (int o = 16; o > 0; o >>= 1) v += __shfl_xor_sync(0xffffffffu, v, o);
  return v;
}

/// Lowers the live lines of the culled footprint: tiles tile_first, +tile_step, ...; lines first,
/// +step, ... of each (the shared per-line code path of both backends is lineCut). Warp: the 32
/// lanes share each tile (one lane reads its maximum for all, so that they take the same tiles);
/// else one thread cuts every line. `live`: a tile cut whole has its maximum lowered
/// (EngineTuning::live_tiles). `stats` (trace runs only, else null): lines visited and lowered.
template <bool Warp>
__device__ inline void cutLines(const GridView& g, const ToolView& tool, const PreparedPosture& pp,
                                float* tile_live, bool skip, bool live, int tile_first,
                                int tile_step, int first, int step, std::int32_t* keys,
                                unsigned long long* stats) {
  unsigned visited = 0, lowered = 0;
  const auto top = [&](int tile) {
    const float m = readTileMax(tile_live, tile);
    return Warp ? __shfl_sync(0xffffffffu, m, 0) : m;
  };
  forEachLiveTile(g, tool, pp, skip, tile_first, tile_step, top,
                  [&](int ix0, int ix1, int iy0, int iy1, int tile) {
                    float highest = cutRect(
                        g, tool, pp, ix0, ix1, iy0, iy1, first, step,
                        [&](int ix, int iy) {
                          ++visited;
                          return keyToFloat(keys[std::size_t(iy) * g.nx + ix]);
                        },
                        [&](int ix, int iy, float z) {
                          ++lowered;
                          atomicMin(keys + std::size_t(iy) * g.nx + ix, floatToKey(z));
                        });
                    if (live && wholeTile(g, ix0, ix1, iy0, iy1)) {
                      if (Warp) highest = warpMax(highest);
                      if (!Warp || first == 0) lowerTileMax(tile_live, tile, highest);
                    }
                  });
  if (stats) {  // a warp's counts in one atomic each
    if (Warp) visited = warpSum(visited), lowered = warpSum(lowered);
    if (!Warp || first == 0) {
      atomicAdd(stats, static_cast<unsigned long long>(visited));
      atomicAdd(stats + 1, static_cast<unsigned long long>(lowered));
    }
  }
}

/// Sort keys (lowest point, see lowestKey) and identity indices of a block.
__global__ void lowestKeyKernel(GridView g, ToolView tool, const Posture* postures, int count,
                                std::uint32_t* keys, std::uint32_t* index) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= count) return;
  keys[p] = lowestKey(g, tool, postures[p]);
  index[p] = std::uint32_t(p);
}

/// One thread per posture: prepare, cull, cut a small footprint here; a large one is queued for
/// largeKernel (its warp repeats the same preparation and cull, hence the same footprint).
__global__ void smallKernel(GridView g, ToolView tool, const Posture* postures,
                            const std::uint32_t* order, int count, const float* tile_max,
                            float* tile_live, std::int32_t* keys, unsigned long long* culled,
                            int* queue, int* queued, bool skip, bool live,
                            unsigned long long* stats) {
  const int k = blockIdx.x * blockDim.x + threadIdx.x;
  if (k >= count) return;
  PreparedPosture pp = preparePosture(g, tool, postureAt(postures, order, k));
  if (cullPosture(g, tool, pp, tile_max)) {
    if (culled) atomicAdd(culled, 1ull);
    return;
  }
  if ((pp.ix1 - pp.ix0 + 1) * (pp.iy1 - pp.iy0 + 1) <= kSmallFootprintLines)
    cutLines<false>(g, tool, pp, tile_live, skip, live, 0, 1, 0, 1, keys, stats);
  else
    queue[atomicAdd(queued, 1)] = k;
}

/// One warp per queued posture (split into gridDim.y chunks of lines when postures are few, as
/// in a zoom): the lanes share the footprint's lines.
__global__ void largeKernel(GridView g, ToolView tool, const Posture* postures,
                            const std::uint32_t* order, const int* queue, const int* queued,
                            const float* tile_max, float* tile_live, std::int32_t* keys, bool skip,
                            bool live, unsigned long long* stats) {
  const int q = blockIdx.x * kWarpsPerBlock + (threadIdx.x >> 5);
  if (q >= *queued) return;
  PreparedPosture pp = preparePosture(g, tool, postureAt(postures, order, queue[q]));
  if (cullPosture(g, tool, pp, tile_max)) return;
  cutLines<true>(g, tool, pp, tile_live, skip, live, blockIdx.y, gridDim.y, threadIdx.x & 31, 32,
                 keys, stats);
}

/// One warp per posture, every footprint (the variant without small_threads).
__global__ void warpKernel(GridView g, ToolView tool, const Posture* postures,
                           const std::uint32_t* order, int count, const float* tile_max,
                           float* tile_live, std::int32_t* keys, unsigned long long* culled,
                           bool skip, bool live, unsigned long long* stats) {
  const int k = blockIdx.x * kWarpsPerBlock + (threadIdx.x >> 5);
  if (k >= count) return;
  PreparedPosture pp = preparePosture(g, tool, postureAt(postures, order, k));
  if (cullPosture(g, tool, pp, tile_max)) {
    if (culled && (threadIdx.x & 31) == 0 && blockIdx.y == 0) atomicAdd(culled, 1ull);
    return;
  }
  cutLines<true>(g, tool, pp, tile_live, skip, live, blockIdx.y, gridDim.y, threadIdx.x & 31, 32,
                 keys, stats);
}

/// Blocks per SM the group kernel is built for: 64 registers a thread, 50 % occupancy (8 rather
/// than the compiler's 80 registers: 4-5 % on cases 3, 5 and 8 on the H100; bench/results/
/// zbuffer-h100.md, run 30).
constexpr int kGroupMinBlocks = 8;

/// One warp per Group (<= 32) consecutive postures of a path, which cut nearly the same lines:
/// each lane < Group prepares and culls one posture into shared memory; then the lanes walk the
/// live tiles of the group's union footprint, and for each line load its height once, apply every
/// posture whose footprint holds the line (lineCut, running minimum) and store once. A posture's
/// cut does not depend on the current height it is given, only whether it is returned, so the
/// minimum (every bit) is the CPU's. A scattered group (union much larger than its footprints: a
/// sorted block, ends of passes) is cut posture by posture instead.
template <int Group>
__global__ void __launch_bounds__(32 * kWarpsPerBlock, kGroupMinBlocks)
    groupKernel(GridView g, ToolView tool, const Posture* postures, const std::uint32_t* order,
                int count, const float* tile_max, float* tile_live, std::int32_t* keys,
                unsigned long long* culled, bool skip, bool live_tiles, unsigned long long* stats) {
  // raw storage: PreparedPosture's members have initialisers, which __shared__ cannot run
  __shared__ alignas(
      PreparedPosture) unsigned char storage[kWarpsPerBlock * Group * sizeof(PreparedPosture)];
  PreparedPosture(*group)[Group] = reinterpret_cast<PreparedPosture(*)[Group]>(storage);
  __shared__ float floors[kWarpsPerBlock][Group][32];  ///< per lane: each posture's (lineFloorNear)
  const int warp = threadIdx.x >> 5, lane = threadIdx.x & 31;
  const int first = (blockIdx.x * kWarpsPerBlock + warp) * Group;
  if (first >= count) return;  // warp-uniform
  const int n = min(Group, count - first);
  bool live = false;
  int ix0 = INT_MAX, ix1 = INT_MIN, iy0 = INT_MAX, iy1 = INT_MIN;
  long long area = 0;
  if (lane < n) {
    PreparedPosture pp = preparePosture(g, tool, postureAt(postures, order, first + lane));
    live = !cullPosture(g, tool, pp, tile_max);
    if (live) {
      ix0 = pp.ix0, ix1 = pp.ix1, iy0 = pp.iy0, iy1 = pp.iy1;
      area = (long long)(ix1 - ix0 + 1) * (iy1 - iy0 + 1);
    } else if (culled && blockIdx.y == 0) {
      atomicAdd(culled, 1ull);
    }
    group[warp][lane] = pp;
  }
  const unsigned live_mask = __ballot_sync(0xffffffffu, live);
  if (!live_mask) return;
  ix0 = warpMin(ix0), iy0 = warpMin(iy0), ix1 = warpMax(ix1), iy1 = warpMax(iy1);
  area = warpSum(area);
  // A floor for the whole group on a line, where every live posture is vertical and the tool has
  // radial floors: the lowest tip plus the radial floor at the line's distance from the box of
  // the tips (shrunk by far more than the rounding of each posture's own line radius). No
  // posture's own floor is below it, so a line at or under it is left after one look-up.
  float tx_lo = FLT_MAX, tx_hi = -FLT_MAX, ty_lo = FLT_MAX, ty_hi = -FLT_MAX, tz_lo = FLT_MAX;
  int all_vertical = 1;
  if (live) {
    const PreparedPosture& pp = group[warp][lane];
    tx_lo = tx_hi = pp.tip_mm.x;
    ty_lo = ty_hi = pp.tip_mm.y;
    tz_lo = pp.tip_mm.z;
    all_vertical = pp.vertical;
  }
  tx_lo = warpMin(tx_lo), tx_hi = warpMax(tx_hi), ty_lo = warpMin(ty_lo), ty_hi = warpMax(ty_hi);
  tz_lo = warpMin(tz_lo);
  const bool group_floor = __all_sync(0xffffffffu, all_vertical) && tool.radial_bins > 0;
  TipBox box{tx_lo, tx_hi, ty_lo, ty_hi, tz_lo, 0.f};
  box.pad_mm = tipBoxPad(box, tool);
  __syncwarp();
  unsigned visited = 0, lowered = 0, reached = 0, exact = 0, tiles_cut = 0, tiles_skipped = 0;
  const long long union_area = (long long)(ix1 - ix0 + 1) * (iy1 - iy0 + 1);
  if (union_area > 2 * area) {  // scattered: posture by posture, the lanes share its lines
    for (unsigned mask = live_mask; mask; mask &= mask - 1)
      cutLines<true>(g, tool, group[warp][__ffs(mask) - 1], tile_live, skip, live_tiles, blockIdx.y,
                     gridDim.y, lane, 32, keys, stats);
  } else {
    const int tx0 = ix0 >> g.tile_shift, tx1 = ix1 >> g.tile_shift;
    const int ty0 = iy0 >> g.tile_shift, ty1 = iy1 >> g.tile_shift;
    const int tw = tx1 - tx0 + 1, tiles = tw * (ty1 - ty0 + 1);
    for (int t = blockIdx.y; t < tiles; t += gridDim.y) {
      const int tx = tx0 + t % tw, ty = ty0 + t / tw;
      const int rx0 = max(tx << g.tile_shift, ix0), ry0 = max(ty << g.tile_shift, iy0);
      const int rx1 = min(((tx + 1) << g.tile_shift) - 1, ix1);
      const int ry1 = min(((ty + 1) << g.tile_shift) - 1, iy1);
      const int tile = ty * g.tiles_x + tx;
      // skipped if no posture of the group can lower a line of it: first the group floor at the
      // tile's distance from the tips' box (all lanes alike), then each posture's (lane-parallel)
      const float tile_top =
          skip ? __shfl_sync(0xffffffffu, readTileMax(tile_live, tile), 0) : FLT_MAX;
      if (skip && group_floor &&
          !(tile_top > groupFloor(tool, box, static_cast<float>(lineX(g, rx0)),
                                  static_cast<float>(lineX(g, rx1)),
                                  static_cast<float>(lineY(g, ry0)),
                                  static_cast<float>(lineY(g, ry1))))) {
        ++tiles_skipped;
        continue;
      }
      if (skip) {
        float floor = FLT_MAX;
        if (lane < n && ((live_mask >> lane) & 1u)) {
          const PreparedPosture& pp = group[warp][lane];
          const int a0 = max(rx0, pp.ix0), a1 = min(rx1, pp.ix1);
          const int b0 = max(ry0, pp.iy0), b1 = min(ry1, pp.iy1);
          if (a0 <= a1 && b0 <= b1) floor = rectFloor(g, tool, pp, a0, a1, b0, b1);
        }
        floor = warpMin(floor);
        if (tile_top <= floor) {  // one lane's read for all: the lanes take the same tiles
          ++tiles_skipped;
          continue;
        }
      }
      ++tiles_cut;
      const int w = rx1 - rx0 + 1, lines = w * (ry1 - ry0 + 1);
      float highest = -FLT_MAX;  // the lane's lines' heights after the group (or lower)
      for (int l = lane; l < lines; l += 32) {
        const int ix = rx0 + l % w, iy = ry0 + l / w;
        std::int32_t* slot = keys + std::size_t(iy) * g.nx + ix;
        const std::int32_t loaded = *slot;
        float best = keyToFloat(loaded);
        ++visited;
        bool reach = true;  // false: no posture of the group can lower the line
        // the line's coordinates once for every posture: in double for the exact cuts, split
        // for the floors (offsetNear: float only, no conversion per posture)
        const double xd = lineX(g, ix), yd = lineY(g, iy);
        const SplitCoord xs = splitCoord(xd), ys = splitCoord(yd);
        if (group_floor) reach = best > groupFloor(tool, box, xs.hi, xs.hi, ys.hi, ys.hi);
        if (!reach) {
          highest = fmaxf(highest, best);
          continue;
        }
        ++reached;
        // The floors first (from float offsets: a floor of each posture's exact one), then the
        // posture of the lowest floor: it nearly always cuts lowest, after which the others'
        // floors turn them away without a triangle test.
        float lowest = FLT_MAX;
        int first_k = -1;
        for (unsigned mask = live_mask; mask; mask &= mask - 1) {
          const int k = __ffs(mask) - 1;
          const PreparedPosture& pp = group[warp][k];
          float f = FLT_MAX;
          if (ix >= pp.ix0 && ix <= pp.ix1 && iy >= pp.iy0 && iy <= pp.iy1) {
            float eps = 0.f;
            const float rx = offsetNear(xs, pp.tip_mm.x, eps),
                        ry = offsetNear(ys, pp.tip_mm.y, eps);
            f = lineFloorNear(tool, pp, rx, ry, eps);
          }
          floors[warp][k][lane] = f;
          if (f < lowest) lowest = f, first_k = k;
        }
        if (first_k >= 0 && best > lowest) {  // (none: every floor FLT_MAX, best +inf)
          for (unsigned mask = live_mask & ~(1u << first_k), k = first_k;;) {
            if (best > floors[warp][k][lane]) {  // then the exact offsets and floors
              const PreparedPosture& pp = group[warp][k];
              float rx, ry;
              lineOffsetAt(xd, yd, pp, rx, ry);
              const float z = lineCutAt(tool, pp, rx, ry, lineFloors(tool, pp, rx, ry), best);
              ++exact;
              if (z != FLT_MAX) best = z;
            }
            if (!mask) break;
            k = __ffs(mask) - 1;
            mask &= mask - 1;
          }
        }
        if (floatToKey(best) < loaded) ++lowered, atomicMin(slot, floatToKey(best));
        highest = fmaxf(highest, best);
      }
      if (live_tiles && wholeTile(g, rx0, rx1, ry0, ry1)) {
        highest = warpMax(highest);
        if (lane == 0) lowerTileMax(tile_live, tile, highest);
      }
    }
  }
  if (stats) {  // one atomic per counter per warp (per lane, they serialised case 8's trace)
    const unsigned counts[kStats] = {visited, lowered, reached, exact, tiles_cut, tiles_skipped};
    for (int c = 0; c < kStats; ++c) {
      // tiles are counted by every lane alike: lane 0's count
      const unsigned sum = c < 4 ? __reduce_add_sync(0xffffffffu, counts[c]) : counts[c];
      if (lane == 0) atomicAdd(stats + c, static_cast<unsigned long long>(sum));
    }
  }
}

/// SIMSURF1's coarse kernel: one thread per posture, every triangle.
__global__ void coarseKernel(GridView g, ToolView tool, const Posture* postures, int count,
                             std::int32_t* keys) {
  const int p = blockIdx.x * blockDim.x + threadIdx.x;
  if (p >= count) return;
  coarsePosture(g, tool, postures[p], [&](int ix, int iy, float z) {
    atomicMin(keys + std::size_t(iy) * g.nx + ix, floatToKey(z));
  });
}

}  // namespace
}  // namespace fieldpath::zbuffer::cuda
