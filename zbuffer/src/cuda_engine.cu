/// CUDA backend: same per-line / per-triangle code as the CPU reference (kernels.h), compiled with
/// -fmad=false and IEEE division and square root, so the heights are bit-identical to the CPU's.
/// Heights live on the device as order-preserving int32 keys (one atomicMin per lowered line).
#include <cuda_runtime.h>

#include <algorithm>
#include <cfloat>
#include <climits>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

#include "cuda_engine.h"

namespace fieldpath::zbuffer::cuda {
namespace {

void checkCuda(cudaError_t err, const char* what, const char* file, int line) {
  if (err != cudaSuccess)
    throw std::runtime_error(std::string(file) + ":" + std::to_string(line) + ": " + what + ": " +
                             cudaGetErrorString(err));
}
#define FIELDPATH_CUDA_CHECK(call) checkCuda((call), #call, __FILE__, __LINE__)

constexpr int kWarpsPerBlock = 4;

__device__ inline float keyToFloat(std::int32_t key) { return __int_as_float(orderedBits(key)); }
__device__ inline std::int32_t floatToKey(float h) { return orderedBits(__float_as_int(h)); }

__global__ void tileMaxKernel(GridView g, const std::int32_t* keys, float* tile_max) {
  const int t = blockIdx.x * blockDim.x + threadIdx.x;
  if (t >= g.tiles_x * g.tiles_y) return;
  const int tx = t % g.tiles_x, ty = t / g.tiles_x;
  const int iy1 = min(g.ny, (ty + 1) << g.tile_shift), ix1 = min(g.nx, (tx + 1) << g.tile_shift);
  std::int32_t m = INT_MIN;
  for (int iy = ty << g.tile_shift; iy < iy1; ++iy)
    for (int ix = tx << g.tile_shift; ix < ix1; ++ix) m = max(m, keys[std::size_t(iy) * g.nx + ix]);
  tile_max[t] = keyToFloat(m);
}

/// One warp per posture (split into gridDim.y chunks of lines when postures are few, as in a zoom):
/// the lanes share the posture's footprint lines.
__global__ void fastKernel(GridView g, ToolView tool, const Posture* postures, int count,
                           const float* tile_max, std::int32_t* keys, unsigned long long* culled) {
  const int lane = threadIdx.x & 31;
  const int p = blockIdx.x * kWarpsPerBlock + (threadIdx.x >> 5);
  if (p >= count) return;
  PreparedPosture pp = preparePosture(g, tool, postures[p]);
  if (cullPosture(g, tool, pp, tile_max)) {
    if (lane == 0 && blockIdx.y == 0) atomicAdd(culled, 1ull);
    return;
  }
  const int w = pp.ix1 - pp.ix0 + 1;
  const int lines = w * (pp.iy1 - pp.iy0 + 1);
  for (int l = blockIdx.y * 32 + lane; l < lines; l += 32 * gridDim.y) {
    const int ix = pp.ix0 + l % w, iy = pp.iy0 + l / w;
    std::int32_t* slot = keys + std::size_t(iy) * g.nx + ix;
    const float z = lineCut(g, tool, pp, ix, iy, keyToFloat(*slot));
    if (z != FLT_MAX) atomicMin(slot, floatToKey(z));
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

template <class T>
T* deviceCopy(const T* host, std::size_t n) {
  if (n == 0) return nullptr;
  T* ptr = nullptr;
  FIELDPATH_CUDA_CHECK(cudaMalloc(&ptr, n * sizeof(T)));
  FIELDPATH_CUDA_CHECK(cudaMemcpy(ptr, host, n * sizeof(T), cudaMemcpyHostToDevice));
  return ptr;
}

}  // namespace

struct Engine::Impl {
  GridView grid;
  ToolView tool;
  BvhNode* nodes = nullptr;
  float* triangles = nullptr;
  Vec3f* vertices = nullptr;
  std::uint32_t* indices = nullptr;
  std::int32_t* bin_start = nullptr;
  std::int32_t* bin_items = nullptr;
  float* radial_floor = nullptr;
  std::int32_t* keys = nullptr;
  float* tile_max = nullptr;
  unsigned long long* culled = nullptr;
  Posture* postures = nullptr;
  std::size_t capacity = 0, lines = 0, refresh_every = 0;

  ~Impl() {
    for (void* p :
         {static_cast<void*>(nodes), static_cast<void*>(triangles), static_cast<void*>(vertices),
          static_cast<void*>(indices), static_cast<void*>(keys), static_cast<void*>(tile_max),
          static_cast<void*>(culled), static_cast<void*>(postures), static_cast<void*>(bin_start),
          static_cast<void*>(bin_items), static_cast<void*>(radial_floor)})
      if (p) cudaFree(p);
  }
};

Engine::Engine(const GridView& grid, const ToolArrays& tool, const float* heights_mm,
               std::size_t lines)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.grid = grid;
  m.tool = tool.view;
  m.tool.bvh_nodes = m.nodes = deviceCopy(tool.nodes, tool.node_count);
  m.tool.bvh_triangles = m.triangles = deviceCopy(tool.triangles, tool.triangle_floats);
  m.tool.vertices = m.vertices = deviceCopy(tool.vertices, tool.vertex_count);
  m.tool.indices = m.indices = deviceCopy(tool.indices, tool.index_count);
  m.tool.bin_start = m.bin_start = deviceCopy(tool.bin_start, tool.bin_start_count);
  m.tool.bin_items = m.bin_items = deviceCopy(tool.bin_items, tool.bin_item_count);
  m.tool.radial_floor_mm = m.radial_floor = deviceCopy(tool.radial_floor, tool.radial_count);
  std::vector<std::int32_t> keys(lines);
  for (std::size_t i = 0; i < lines; ++i) {
    std::int32_t bits;
    std::memcpy(&bits, heights_mm + i, 4);
    keys[i] = orderedBits(bits);
  }
  m.keys = deviceCopy(keys.data(), lines);
  FIELDPATH_CUDA_CHECK(
      cudaMalloc(&m.tile_max, sizeof(float) * std::max(1, grid.tiles_x * grid.tiles_y)));
  FIELDPATH_CUDA_CHECK(cudaMalloc(&m.culled, sizeof(unsigned long long)));
  FIELDPATH_CUDA_CHECK(cudaMemset(m.culled, 0, sizeof(unsigned long long)));
  m.lines = lines;
  m.refresh_every = std::clamp<std::size_t>(lines / 8, std::size_t{1} << 16, std::size_t{1} << 24);
}

Engine::~Engine() = default;

std::size_t Engine::cut(const Posture* block, std::size_t count, bool coarse) {
  Impl& m = *impl_;
  if (count == 0) return 0;
  if (count > m.capacity) {
    if (m.postures) FIELDPATH_CUDA_CHECK(cudaFree(m.postures));
    m.postures = nullptr;
    FIELDPATH_CUDA_CHECK(cudaMalloc(&m.postures, count * sizeof(Posture)));
    m.capacity = count;
  }
  FIELDPATH_CUDA_CHECK(
      cudaMemcpy(m.postures, block, count * sizeof(Posture), cudaMemcpyHostToDevice));
  unsigned long long before = 0;
  FIELDPATH_CUDA_CHECK(cudaMemcpy(&before, m.culled, sizeof(before), cudaMemcpyDeviceToHost));
  if (coarse) {
    const int n = static_cast<int>(count);
    coarseKernel<<<(n + 127) / 128, 128>>>(m.grid, m.tool, m.postures, n, m.keys);
    FIELDPATH_CUDA_CHECK(cudaGetLastError());
  } else {
    const int tiles = m.grid.tiles_x * m.grid.tiles_y;
    for (std::size_t begin = 0; begin < count; begin += m.refresh_every) {
      const int n = static_cast<int>(std::min(m.refresh_every, count - begin));
      tileMaxKernel<<<(tiles + 255) / 256, 256>>>(m.grid, m.keys, m.tile_max);
      FIELDPATH_CUDA_CHECK(cudaGetLastError());
      const int chunks = std::clamp(16384 / std::max(1, n), 1, 1024);
      const dim3 blocks((n + kWarpsPerBlock - 1) / kWarpsPerBlock, chunks);
      fastKernel<<<blocks, 32 * kWarpsPerBlock>>>(m.grid, m.tool, m.postures + begin, n, m.tile_max,
                                                  m.keys, m.culled);
      FIELDPATH_CUDA_CHECK(cudaGetLastError());
    }
  }
  unsigned long long after = 0;
  FIELDPATH_CUDA_CHECK(cudaMemcpy(&after, m.culled, sizeof(after), cudaMemcpyDeviceToHost));
  return static_cast<std::size_t>(after - before);
}

void Engine::heights(float* out_mm) const {
  const Impl& m = *impl_;
  std::vector<std::int32_t> keys(m.lines);
  FIELDPATH_CUDA_CHECK(cudaMemcpy(keys.data(), m.keys, m.lines * 4, cudaMemcpyDeviceToHost));
  for (std::size_t i = 0; i < m.lines; ++i) {
    const std::int32_t bits = orderedBits(keys[i]);
    std::memcpy(out_mm + i, &bits, 4);
  }
}

bool available() {
  static const bool ok = [] {
    int n = 0;
    return cudaGetDeviceCount(&n) == cudaSuccess && n > 0;
  }();
  return ok;
}

}  // namespace fieldpath::zbuffer::cuda
