/// CUDA backend: same per-line / per-triangle code as the CPU reference (kernels.h), compiled with
/// -fmad=false and IEEE division and square root, so the heights are bit-identical to the CPU's.
/// Heights live on the device as order-preserving int32 keys (one atomicMin per lowered line).
/// Per block: upload (overlapping the previous block's kernels), sort lowest point first (CUB),
/// then chunks of postures between tile-maximum refreshes; one thread per small-footprint
/// posture, one warp per large one. This file: device memory, streams and the pipeline; the
/// kernels: cuda_kernels.cuh.
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
#include <utility>
#include <vector>

#include "cuda_engine.h"
#include "cuda_kernels.cuh"
#include "fieldpath/common/cuda_check.h"

namespace fieldpath::zbuffer::cuda {
namespace {

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
    for (void* p : buffers) FIELDPATH_CUDA_WARN(cudaFree(p));
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
      FIELDPATH_CUDA_CHECK(cudaEventDestroy(mk.begin));
      FIELDPATH_CUDA_CHECK(cudaEventDestroy(mk.end));
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
    if (copy_stream) FIELDPATH_CUDA_WARN(cudaStreamSynchronize(copy_stream));
    if (!compute_stream) return;
    FIELDPATH_CUDA_WARN(cudaStreamSynchronize(compute_stream));
    for (void* p :
         {static_cast<void*>(keys), static_cast<void*>(tile_max), static_cast<void*>(tile_live),
          static_cast<void*>(culled), static_cast<void*>(queued), static_cast<void*>(queue),
          sort_temp, static_cast<void*>(stats)})
      if (p) FIELDPATH_CUDA_WARN(cudaFreeAsync(p, compute_stream));
    for (int k = 0; k < 2; ++k) {
      for (void* p : {static_cast<void*>(postures[k]), static_cast<void*>(sort_keys[k]),
                      static_cast<void*>(sort_index[k])})
        if (p) FIELDPATH_CUDA_WARN(cudaFreeAsync(p, compute_stream));
      if (copied[k]) FIELDPATH_CUDA_WARN(cudaEventDestroy(copied[k]));
      if (computed[k]) FIELDPATH_CUDA_WARN(cudaEventDestroy(computed[k]));
      if (staged[k]) {
        FIELDPATH_CUDA_WARN(cudaEventSynchronize(staged[k]));
        FIELDPATH_CUDA_WARN(cudaEventDestroy(staged[k]));
      }
      if (stage[k]) releasePinned(stage[k]);
    }
    FIELDPATH_CUDA_WARN(cudaStreamSynchronize(compute_stream));
    if (copy_stream) FIELDPATH_CUDA_WARN(cudaStreamDestroy(copy_stream));
    FIELDPATH_CUDA_WARN(cudaStreamDestroy(compute_stream));
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
  // (freed on the stream however this ends: a failed download threw past a bare free)
  struct Bits {
    std::int32_t* ptr = nullptr;
    cudaStream_t stream;
    ~Bits() {
      if (ptr) FIELDPATH_CUDA_WARN(cudaFreeAsync(ptr, stream));
    }
  } bits{nullptr, st};
  deviceAlloc(bits.ptr, m.lines, st);
  FIELDPATH_CUDA_CHECK(
      cudaMemcpyAsync(bits.ptr, m.keys, m.lines * 4, cudaMemcpyDeviceToDevice, st));
  orderBitsKernel<<<unsigned((m.lines + 255) / 256), 256, 0, st>>>(bits.ptr, m.lines);
  FIELDPATH_CUDA_CHECK(cudaGetLastError());
  Impl& mm = const_cast<Impl&>(m);
  mm.timed("download", st, [&] { mm.download(out_mm, bits.ptr, m.lines * 4, st); });
  FIELDPATH_CUDA_CHECK(cudaFreeAsync(std::exchange(bits.ptr, nullptr), st));  // (freed once)
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
