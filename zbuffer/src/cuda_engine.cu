/// CUDA backend: same per-line / per-triangle code as the CPU reference (kernels.h), compiled with
/// -fmad=false and IEEE division and square root, so the heights are bit-identical to the CPU's.
/// Heights live on the device as order-preserving int32 keys (one atomicMin per lowered line).
/// Per block: upload (overlapping the previous block's kernels), sort lowest point first (CUB),
/// then chunks of postures between tile-maximum refreshes; one thread per small-footprint
/// posture, one warp per large one.
#include <cuda_runtime.h>
#include <omp.h>

#include <cub/device/device_radix_sort.cuh>

#include <algorithm>
#include <cfloat>
#include <chrono>
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "cuda_engine.h"
#include "fieldpath/common/cuda_check.h"

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

/// Device memory comes from the stream-ordered pool, kept across engines (its release threshold
/// is raised once), so that a simulation does not pay cudaMalloc/cudaFree for its buffers.
void usePersistentPool() {
  static const bool done = [] {
    int device = 0;
    cudaMemPool_t pool;
    if (cudaGetDevice(&device) != cudaSuccess ||
        cudaDeviceGetDefaultMemPool(&pool, device) != cudaSuccess)
      return false;
    std::uint64_t keep = UINT64_MAX;
    return cudaMemPoolSetAttribute(pool, cudaMemPoolAttrReleaseThreshold, &keep) == cudaSuccess;
  }();
  (void)done;
}

template <class T>
void deviceAlloc(T*& ptr, std::size_t n, cudaStream_t st) {
  if (ptr) FIELDPATH_CUDA_CHECK(cudaFreeAsync(ptr, st));
  ptr = nullptr;
  FIELDPATH_CUDA_CHECK(
      cudaMallocAsync(reinterpret_cast<void**>(&ptr), std::max<std::size_t>(n, 1) * sizeof(T), st));
}

/// Pinned host staging buffers, kept for the process: pinning costs milliseconds per call.
constexpr std::size_t kStageBytes = std::size_t{16} << 20;

std::mutex& pinnedMutex() {
  static std::mutex mutex;
  return mutex;
}
std::vector<void*>& pinnedFree() {
  static std::vector<void*> free;
  return free;
}
void* acquirePinned() {
  {
    std::lock_guard lock(pinnedMutex());
    if (!pinnedFree().empty()) {
      void* p = pinnedFree().back();
      pinnedFree().pop_back();
      return p;
    }
  }
  void* p = nullptr;
  FIELDPATH_CUDA_CHECK(cudaMallocHost(&p, kStageBytes));
  return p;
}
void releasePinned(void* p) {
  std::lock_guard lock(pinnedMutex());
  pinnedFree().push_back(p);
}

/// memcpy on all cores but two: one thread moves ~7 GB/s, 16 alone ~48 (the PCIe link takes 52).
/// Two are left for the caller's other threads (the output's pages being faulted in): with one
/// core short, the split waits for the descheduled thread (H100 machine, 96 MB: 2 ms on 16
/// threads alone, 44 ms beside that thread; bench/results/zbuffer-h100.md, runs 30-32).
int copyThreads() {
  static const int threads = std::clamp(omp_get_num_procs() - 2, 1, 16);
  return threads;
}
void parallelCopy(void* dst, const void* src, std::size_t bytes) {
  const long parts = bytes >= (std::size_t{1} << 20) ? 32 : 1;
  const int threads = copyThreads();
#pragma omp parallel for schedule(dynamic) num_threads(threads) if (parts > 1)
  for (long k = 0; k < parts; ++k) {
    const std::size_t a = bytes * std::size_t(k) / std::size_t(parts),
                      b = bytes * std::size_t(k + 1) / std::size_t(parts);
    std::memcpy(static_cast<char*>(dst) + a, static_cast<const char*>(src) + a, b - a);
  }
}

/// A tool's arrays on the device. The last tool used stays there (keyed by ToolData::id) for the
/// next simulation with it: a mesh tool's BVH, bins and floors are megabytes, uploaded once.
struct DeviceTool {
  ToolView view;
  std::vector<void*> buffers;
  DeviceTool() = default;
  DeviceTool(const DeviceTool&) = delete;
  DeviceTool& operator=(const DeviceTool&) = delete;
  ~DeviceTool() {
    for (void* p : buffers) cudaFree(p);
  }
  template <class T>
  const T* copy(const T* host, std::size_t n) {
    if (n == 0) return nullptr;
    void* p = nullptr;
    FIELDPATH_CUDA_CHECK(cudaMalloc(&p, n * sizeof(T)));
    buffers.push_back(p);
    FIELDPATH_CUDA_CHECK(cudaMemcpy(p, host, n * sizeof(T), cudaMemcpyHostToDevice));
    return static_cast<const T*>(p);
  }
};

/// The device copy of `tool`: the cached one if it has the same id, else a new upload.
std::shared_ptr<const DeviceTool> deviceTool(const ToolArrays& tool) {
  static std::mutex mutex;
  static std::uint64_t cached_id = 0;
  static std::shared_ptr<const DeviceTool> cached;
  std::lock_guard lock(mutex);
  if (cached && tool.id != 0 && cached_id == tool.id) return cached;
  auto d = std::make_shared<DeviceTool>();
  d->view = tool.view;
  d->view.bvh_nodes = d->copy(tool.nodes, tool.node_count);
  d->view.bvh_triangles = d->copy(tool.triangles, tool.triangle_floats);
  d->view.vertices = d->copy(tool.vertices, tool.vertex_count);
  d->view.indices = d->copy(tool.indices, tool.index_count);
  d->view.bin_start = d->copy(tool.bin_start, tool.bin_start_count);
  d->view.bin_items = d->copy(tool.bin_items, tool.bin_item_count);
  d->view.radial_floor_mm = d->copy(tool.radial_floor, tool.radial_count);
  cached_id = tool.id;
  cached = d;
  return d;
}

}  // namespace

struct Engine::Impl {
  GridView grid;
  ToolView tool;  ///< the run's view (scalars, knobs) with the device tool's arrays
  std::shared_ptr<const DeviceTool> device_tool;
  Options options;
  std::int32_t* keys = nullptr;
  // Tile maxima, refreshed before each chunk: a fixed copy for culling and footprints, which the
  // blocks that split a posture's tiles (gridDim.y) must see alike, and a live copy for the tile
  // skips, lowered during the chunk (EngineTuning::live_tiles).
  float *tile_max = nullptr, *tile_live = nullptr;
  unsigned long long* culled = nullptr;
  int* queued = nullptr;
  // per-block buffers, two of each so that one block uploads while the other computes
  Posture* postures[2] = {nullptr, nullptr};
  std::uint32_t *sort_keys[2] = {nullptr, nullptr}, *sort_index[2] = {nullptr, nullptr};
  int* queue = nullptr;
  void* sort_temp = nullptr;
  std::size_t sort_temp_bytes = 0;
  std::size_t capacity = 0, lines = 0, refresh_every = 0;
  bool use_groups = false;
  int slot = 0;
  cudaStream_t copy_stream = nullptr, compute_stream = nullptr;
  cudaEvent_t copied[2] = {nullptr, nullptr}, computed[2] = {nullptr, nullptr};
  // pinned staging: two buffers, the host copy into one overlaps the DMA of the other
  void* stage[2] = {nullptr, nullptr};
  cudaEvent_t staged[2] = {nullptr, nullptr};
  int stage_next = 0;
  // FIELDPATH_ZB_TRACE=1 (benchmarks only): device time per stage (events around each launch) and
  // the lines visited / lowered, printed to stderr when the heights are read.
  bool trace = false;
  unsigned long long* stats = nullptr;
  struct Mark {
    const char* stage;
    cudaEvent_t begin, end;
  };
  std::vector<Mark> marks;
  std::chrono::steady_clock::time_point created;

  template <class Launch>
  void timed(const char* stage_name, cudaStream_t st, Launch launch) {
    if (!trace) return launch();
    Mark mk{stage_name, nullptr, nullptr};
    FIELDPATH_CUDA_CHECK(cudaEventCreate(&mk.begin));
    FIELDPATH_CUDA_CHECK(cudaEventCreate(&mk.end));
    FIELDPATH_CUDA_CHECK(cudaEventRecord(mk.begin, st));
    launch();
    FIELDPATH_CUDA_CHECK(cudaEventRecord(mk.end, st));
    marks.push_back(mk);
  }

  void printTrace() {
    if (!trace) return;
    FIELDPATH_CUDA_CHECK(cudaDeviceSynchronize());
    std::map<std::string, std::pair<double, int>> total;
    for (const Mark& mk : marks) {
      float ms = 0;
      FIELDPATH_CUDA_CHECK(cudaEventElapsedTime(&ms, mk.begin, mk.end));
      total[mk.stage].first += ms;
      ++total[mk.stage].second;
      cudaEventDestroy(mk.begin);
      cudaEventDestroy(mk.end);
    }
    marks.clear();
    unsigned long long counts[kStats] = {};
    FIELDPATH_CUDA_CHECK(cudaMemcpy(counts, stats, sizeof counts, cudaMemcpyDeviceToHost));
    std::fprintf(
        stderr,
        "trace: wall since engine start %.2f ms; lines visited %llu, lowered %llu; grouped: past "
        "the group floor %llu, exact cuts %llu, tiles cut %llu, skipped %llu\n",
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - created)
            .count(),
        counts[0], counts[1], counts[2], counts[3], counts[4], counts[5]);
    for (const auto& [name, t] : total)
      std::fprintf(stderr, "trace:   %-10s %9.2f ms in %d launches\n", name.c_str(), t.first,
                   t.second);
  }

  /// Host → device through the pinned buffers (or directly from pageable memory without them).
  void upload(void* dst, const void* src, std::size_t bytes, cudaStream_t st) {
    if (!stage[0]) {
      FIELDPATH_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyHostToDevice, st));
      return;
    }
    for (std::size_t off = 0; off < bytes; off += kStageBytes) {
      const std::size_t n = std::min(kStageBytes, bytes - off);
      const int b = stage_next;
      stage_next ^= 1;
      FIELDPATH_CUDA_CHECK(cudaEventSynchronize(staged[b]));  // its previous DMA is done
      parallelCopy(stage[b], static_cast<const char*>(src) + off, n);
      FIELDPATH_CUDA_CHECK(
          cudaMemcpyAsync(static_cast<char*>(dst) + off, stage[b], n, cudaMemcpyHostToDevice, st));
      FIELDPATH_CUDA_CHECK(cudaEventRecord(staged[b], st));
    }
  }

  /// Device → host through the pinned buffers: the host copy of a piece overlaps the next DMA.
  void download(void* dst, const void* src, std::size_t bytes, cudaStream_t st) {
    if (!stage[0]) {
      FIELDPATH_CUDA_CHECK(cudaMemcpyAsync(dst, src, bytes, cudaMemcpyDeviceToHost, st));
      FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(st));
      return;
    }
    const auto enqueue = [&](std::size_t off, int b) {
      const std::size_t n = std::min(kStageBytes, bytes - off);
      FIELDPATH_CUDA_CHECK(cudaEventSynchronize(staged[b]));
      FIELDPATH_CUDA_CHECK(cudaMemcpyAsync(stage[b], static_cast<const char*>(src) + off, n,
                                           cudaMemcpyDeviceToHost, st));
      FIELDPATH_CUDA_CHECK(cudaEventRecord(staged[b], st));
    };
    int b = stage_next;
    if (bytes > 0) enqueue(0, b);
    for (std::size_t off = 0; off < bytes; off += kStageBytes, b ^= 1) {
      if (off + kStageBytes < bytes) enqueue(off + kStageBytes, b ^ 1);
      FIELDPATH_CUDA_CHECK(cudaEventSynchronize(staged[b]));
      parallelCopy(static_cast<char*>(dst) + off, stage[b], std::min(kStageBytes, bytes - off));
    }
    stage_next = b;
  }

  /// Cuts `count` postures (in `order`, or as they come), chunk by chunk with the tile maxima
  /// refreshed before each; `culled_count` (may be null) counts the culled postures. `prepass`:
  /// the trace counts the cutting kernels' time as the prepass's, not the main pass's.
  void chunks(const Posture* postures, const std::uint32_t* order, std::size_t count,
              unsigned long long* culled_count, bool prepass = false) {
    const auto stage = [&](const char* main_pass) { return prepass ? "prepass" : main_pass; };
    cudaStream_t st = compute_stream;
    const int tiles = grid.tiles_x * grid.tiles_y;
    for (std::size_t begin = 0; begin < count; begin += refresh_every) {
      const int chunk = static_cast<int>(std::min(refresh_every, count - begin));
      const std::uint32_t* chunk_order = order ? order + begin : nullptr;
      const Posture* chunk_postures = order ? postures : postures + begin;
      timed("tile max", st, [&] {
        tileMaxKernel<<<(tiles + 255) / 256, 256, 0, st>>>(grid, keys, tile_max, tile_live);
        FIELDPATH_CUDA_CHECK(cudaGetLastError());
      });
      const int splits = std::clamp(16384 / std::max(1, chunk), 1, 1024);
      const dim3 warps((chunk + kWarpsPerBlock - 1) / kWarpsPerBlock, splits);
      if (use_groups) {
        const int group = options.group_postures;
        const int groups = (chunk + group - 1) / group;
        const dim3 blocks((groups + kWarpsPerBlock - 1) / kWarpsPerBlock,
                          std::clamp(16384 / std::max(1, groups), 1, 1024));
        timed(stage("group"), st, [&] {
          const auto kernel =
              group > 16 ? groupKernel<32> : (group > 8 ? groupKernel<16> : groupKernel<8>);
          kernel<<<blocks, 32 * kWarpsPerBlock, 0, st>>>(
              grid, tool, chunk_postures, chunk_order, chunk, tile_max, tile_live, keys,
              culled_count, options.tile_skip, options.live_tiles, stats);
          FIELDPATH_CUDA_CHECK(cudaGetLastError());
        });
      } else if (options.small_threads) {
        FIELDPATH_CUDA_CHECK(cudaMemsetAsync(queued, 0, sizeof(int), st));
        timed(stage("small"), st, [&] {
          smallKernel<<<(chunk + 127) / 128, 128, 0, st>>>(
              grid, tool, chunk_postures, chunk_order, chunk, tile_max, tile_live, keys,
              culled_count, queue, queued, options.tile_skip, options.live_tiles, stats);
          FIELDPATH_CUDA_CHECK(cudaGetLastError());
        });
        timed(stage("large"), st, [&] {
          largeKernel<<<warps, 32 * kWarpsPerBlock, 0, st>>>(
              grid, tool, chunk_postures, chunk_order, queue, queued, tile_max, tile_live, keys,
              options.tile_skip, options.live_tiles, stats);
          FIELDPATH_CUDA_CHECK(cudaGetLastError());
        });
      } else {
        timed(stage("warp"), st, [&] {
          warpKernel<<<warps, 32 * kWarpsPerBlock, 0, st>>>(
              grid, tool, chunk_postures, chunk_order, chunk, tile_max, tile_live, keys,
              culled_count, options.tile_skip, options.live_tiles, stats);
          FIELDPATH_CUDA_CHECK(cudaGetLastError());
        });
      }
    }
  }

  ~Impl() {
    if (copy_stream) cudaStreamSynchronize(copy_stream);
    if (!compute_stream) return;
    cudaStreamSynchronize(compute_stream);
    for (void* p :
         {static_cast<void*>(keys), static_cast<void*>(tile_max), static_cast<void*>(tile_live),
          static_cast<void*>(culled), static_cast<void*>(queued), static_cast<void*>(queue),
          sort_temp, static_cast<void*>(stats)})
      if (p) cudaFreeAsync(p, compute_stream);
    for (int k = 0; k < 2; ++k) {
      for (void* p : {static_cast<void*>(postures[k]), static_cast<void*>(sort_keys[k]),
                      static_cast<void*>(sort_index[k])})
        if (p) cudaFreeAsync(p, compute_stream);
      if (copied[k]) cudaEventDestroy(copied[k]);
      if (computed[k]) cudaEventDestroy(computed[k]);
      if (staged[k]) cudaEventSynchronize(staged[k]), cudaEventDestroy(staged[k]);
      if (stage[k]) releasePinned(stage[k]);
    }
    cudaStreamSynchronize(compute_stream);
    if (copy_stream) cudaStreamDestroy(copy_stream);
    cudaStreamDestroy(compute_stream);
  }

  /// Room for blocks of `count` postures (waits for the queued work before reallocating).
  void reserve(std::size_t count) {
    if (count <= capacity) return;
    FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(copy_stream));
    cudaStream_t st = compute_stream;
    for (int k = 0; k < 2; ++k) {
      deviceAlloc(postures[k], count, st);
      deviceAlloc(sort_keys[k], count, st);
      deviceAlloc(sort_index[k], count, st);
    }
    deviceAlloc(queue, count, st);
    std::size_t bytes = 0;
    FIELDPATH_CUDA_CHECK(cub::DeviceRadixSort::SortPairs(nullptr, bytes, sort_keys[0], sort_keys[1],
                                                         sort_index[0], sort_index[1], int(count)));
    unsigned char* temp = static_cast<unsigned char*>(sort_temp);
    deviceAlloc(temp, bytes, st);
    sort_temp = temp;
    sort_temp_bytes = bytes;
    capacity = count;
    // the copy stream writes the new posture buffers: it must see them allocated
    FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(st));
  }
};

Engine::Engine(const GridView& grid, const ToolArrays& tool, const float* heights_mm,
               float stock_mm, std::size_t lines, Options options)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.grid = grid;
  m.options = options;
  m.tool = tool.view;
  m.created = std::chrono::steady_clock::now();
  m.trace = std::getenv("FIELDPATH_ZB_TRACE") != nullptr;
  usePersistentPool();
  FIELDPATH_CUDA_CHECK(cudaStreamCreateWithFlags(&m.copy_stream, cudaStreamNonBlocking));
  FIELDPATH_CUDA_CHECK(cudaStreamCreateWithFlags(&m.compute_stream, cudaStreamNonBlocking));
  for (int k = 0; k < 2; ++k) {
    FIELDPATH_CUDA_CHECK(cudaEventCreateWithFlags(&m.copied[k], cudaEventDisableTiming));
    FIELDPATH_CUDA_CHECK(cudaEventCreateWithFlags(&m.computed[k], cudaEventDisableTiming));
    FIELDPATH_CUDA_CHECK(cudaEventCreateWithFlags(&m.staged[k], cudaEventDisableTiming));
    if (options.pinned_staging) m.stage[k] = acquirePinned();
  }
  cudaStream_t st = m.compute_stream;
  m.device_tool = deviceTool(tool);
  const ToolView& dv = m.device_tool->view;
  m.tool.bvh_nodes = dv.bvh_nodes;
  m.tool.bvh_triangles = dv.bvh_triangles;
  m.tool.vertices = dv.vertices;
  m.tool.indices = dv.indices;
  m.tool.bin_start = dv.bin_start;
  m.tool.bin_items = dv.bin_items;
  m.tool.radial_floor_mm = dv.radial_floor_mm;
  // heights → ordered keys on the device
  deviceAlloc(m.keys, lines, st);
  if (heights_mm) {
    m.upload(m.keys, heights_mm, lines * 4, st);
    orderBitsKernel<<<unsigned((lines + 255) / 256), 256, 0, st>>>(m.keys, lines);
  } else {
    std::int32_t bits;
    std::memcpy(&bits, &stock_mm, 4);
    fillKernel<<<unsigned((lines + 255) / 256), 256, 0, st>>>(m.keys, lines, orderedBits(bits));
  }
  FIELDPATH_CUDA_CHECK(cudaGetLastError());
  deviceAlloc(m.tile_max, std::max(1, grid.tiles_x * grid.tiles_y), st);
  deviceAlloc(m.tile_live, std::max(1, grid.tiles_x * grid.tiles_y), st);
  deviceAlloc(m.culled, 1, st);
  FIELDPATH_CUDA_CHECK(cudaMemsetAsync(m.culled, 0, sizeof(unsigned long long), st));
  deviceAlloc(m.queued, 1, st);
  if (m.trace) {
    deviceAlloc(m.stats, kStats, st);
    FIELDPATH_CUDA_CHECK(cudaMemsetAsync(m.stats, 0, kStats * sizeof(unsigned long long), st));
  }
  // the host arrays may go once this returns
  FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(st));
  m.lines = lines;
  // (whether to sort lowest first is decided by the caller, simulate(), for both backends)
  // Groups of consecutive postures where footprints are larger than a thread's; a thread per
  // posture where they are smaller (its few lines are cut without sharing anything).
  const double span_x = 2.0 * m.tool.hull_radius_mm / grid.dx_mm + 1.0,
               span_y = 2.0 * m.tool.hull_radius_mm / grid.dy_mm + 1.0;
  // Not where the block is sorted lowest first: its consecutive postures are scattered, and a
  // zoom's few live ones need a warp each (Rz, run 19: 53 ms grouped, 12 not).
  m.use_groups =
      options.group_postures && !options.lowest_first && span_x * span_y > kSmallFootprintLines;
  // Tile maxima are refreshed between chunks. Lowest first, 2^17 postures per chunk: smaller
  // chunks cull more but leave the GPU half idle (2^15: case 3 378 ms, 2^17: 255 ms, 2^19: 259 ms).
  // In path order, refreshes pay less: lines/2 (case 7, 2^19: 42 ms, 2^17: 58 ms; run 9).
  m.refresh_every =
      options.refresh_postures ? options.refresh_postures
      : m.options.lowest_first
          ? std::size_t{1} << 17
          : std::clamp<std::size_t>(lines / 2, std::size_t{1} << 16, std::size_t{1} << 24);
}

Engine::~Engine() = default;

void Engine::cut(const Posture* block, std::size_t count, bool coarse) {
  Impl& m = *impl_;
  if (count == 0) return;
  m.reserve(count);
  const int s = m.slot;
  m.slot ^= 1;
  // Upload into this slot once the block that used it two calls ago is done; with overlap the
  // copy runs on its own stream while the previous block's kernels still run.
  cudaStream_t copy = m.options.overlap_upload ? m.copy_stream : m.compute_stream;
  FIELDPATH_CUDA_CHECK(cudaStreamWaitEvent(copy, m.computed[s], 0));
  m.timed("upload", copy, [&] { m.upload(m.postures[s], block, count * sizeof(Posture), copy); });
  FIELDPATH_CUDA_CHECK(cudaEventRecord(m.copied[s], copy));
  FIELDPATH_CUDA_CHECK(cudaStreamWaitEvent(m.compute_stream, m.copied[s], 0));

  cudaStream_t st = m.compute_stream;
  const Posture* postures = m.postures[s];
  const int n = static_cast<int>(count);
  if (coarse) {
    coarseKernel<<<(n + 127) / 128, 128, 0, st>>>(m.grid, m.tool, postures, n, m.keys);
    FIELDPATH_CUDA_CHECK(cudaGetLastError());
  } else {
    const int stride = m.options.prepass_stride;
    if (stride > 1 && !m.options.lowest_first && count >= 2 * std::size_t(stride)) {
      // every stride-th posture in path order first (EngineTuning::prepass_stride), its order in
      // the other slot's scratch (same stream; the sort below reuses it after); culls not counted
      const int sparse = static_cast<int>((count + stride - 1) / stride);
      std::uint32_t* sparse_order = m.sort_index[s ^ 1];
      strideOrderKernel<<<(sparse + 255) / 256, 256, 0, st>>>(sparse_order, sparse, stride);
      FIELDPATH_CUDA_CHECK(cudaGetLastError());
      m.chunks(postures, sparse_order, std::size_t(sparse), nullptr, /*prepass=*/true);
    }
    const std::uint32_t* order = nullptr;
    if (m.options.lowest_first) {
      m.timed("sort", st, [&] {
        lowestKeyKernel<<<(n + 127) / 128, 128, 0, st>>>(m.grid, m.tool, postures, n,
                                                         m.sort_keys[s], m.sort_index[s]);
        FIELDPATH_CUDA_CHECK(cudaGetLastError());
        std::uint32_t* keys_out = m.sort_keys[s ^ 1];  // the other slot's scratch: same stream
        std::uint32_t* index_out = m.sort_index[s ^ 1];
        FIELDPATH_CUDA_CHECK(
            cub::DeviceRadixSort::SortPairs(m.sort_temp, m.sort_temp_bytes, m.sort_keys[s],
                                            keys_out, m.sort_index[s], index_out, n, 0, 32, st));
        // keep the sorted order in this slot's index array (the other slot's is free after the
        // sort)
        FIELDPATH_CUDA_CHECK(
            cudaMemcpyAsync(m.sort_index[s], index_out, count * 4, cudaMemcpyDeviceToDevice, st));
      });
      order = m.sort_index[s];
    }
    m.chunks(postures, order, count, m.culled);
  }
  FIELDPATH_CUDA_CHECK(cudaEventRecord(m.computed[s], st));
  // the caller may overwrite `block` once this returns (staged: already copied)
  if (!m.stage[0]) FIELDPATH_CUDA_CHECK(cudaEventSynchronize(m.copied[s]));
}

void Engine::heights(float* out_mm) const {
  const Impl& m = *impl_;
  cudaStream_t st = m.compute_stream;
  std::int32_t* bits = nullptr;
  deviceAlloc(bits, m.lines, st);
  FIELDPATH_CUDA_CHECK(cudaMemcpyAsync(bits, m.keys, m.lines * 4, cudaMemcpyDeviceToDevice, st));
  orderBitsKernel<<<unsigned((m.lines + 255) / 256), 256, 0, st>>>(bits, m.lines);
  FIELDPATH_CUDA_CHECK(cudaGetLastError());
  Impl& mm = const_cast<Impl&>(m);
  mm.timed("download", st, [&] { mm.download(out_mm, bits, m.lines * 4, st); });
  FIELDPATH_CUDA_CHECK(cudaFreeAsync(bits, st));
  FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(st));
  mm.printTrace();
}

std::size_t Engine::culled() const {
  const Impl& m = *impl_;
  FIELDPATH_CUDA_CHECK(cudaStreamSynchronize(m.compute_stream));
  unsigned long long n = 0;
  FIELDPATH_CUDA_CHECK(cudaMemcpy(&n, m.culled, sizeof(n), cudaMemcpyDeviceToHost));
  return static_cast<std::size_t>(n);
}

void warmUp(const ToolArrays& tool) {
  FIELDPATH_CUDA_CHECK(cudaFree(nullptr));  // the context, created here rather than in a cut
  deviceTool(tool);
}

bool available() {
  static const bool ok = [] {
    int n = 0;
    return cudaGetDeviceCount(&n) == cudaSuccess && n > 0;
  }();
  return ok;
}

}  // namespace fieldpath::zbuffer::cuda
