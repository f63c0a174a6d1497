/// CPU reference backend (OpenMP): one work item per posture, line heights lowered with an atomic
/// compare-and-swap minimum (the minimum does not depend on the order of postures).
#include <algorithm>
#include <atomic>

#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer::detail {
namespace {

inline void atomicLower(float& slot, float value) {
  std::atomic_ref<float> a(slot);
  float current = a.load(std::memory_order_relaxed);
  while (value < current && !a.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
}

inline float loadRelaxed(float& slot) {
  return std::atomic_ref<float>(slot).load(std::memory_order_relaxed);
}

class CpuEngine final : public BackendEngine {
 public:
  CpuEngine(const GridView& grid, const ToolData& tool, std::vector<float> heights)
      : grid_(grid),
        tool_(tool),
        heights_(std::move(heights)),
        tile_max_(std::size_t(grid.tiles_x) * grid.tiles_y) {
    // re-point the view at this engine's own copies
    tool_.view.bvh_nodes = tool_.bvh_nodes.data();
    tool_.view.bvh_triangles = tool_.bvh_triangles.data();
    tool_.view.vertices = tool_.vertices.data();
    tool_.view.indices = tool_.indices.data();
    tool_.view.bin_start = tool_.bin_start.data();
    tool_.view.bin_items = tool_.bin_items.data();
    tool_.view.radial_floor_mm = tool_.radial_floor.data();
    const std::size_t lines = std::size_t(grid.nx) * grid.ny;
    refresh_every_ = std::clamp<std::size_t>(lines / 8, 16384, std::size_t{1} << 24);
  }

  std::size_t cut(std::span<const Posture> block, Engine engine) override {
    if (engine == Engine::Coarse) {
      coarse(block);
      return 0;
    }
    std::size_t culled = 0;
    for (std::size_t begin = 0; begin < block.size(); begin += refresh_every_) {
      refreshTiles();
      culled += fast(block.subspan(begin, std::min(refresh_every_, block.size() - begin)));
    }
    return culled;
  }

  std::vector<float> heights() override { return heights_; }

 private:
  void refreshTiles() {
    const GridView& g = grid_;
#pragma omp parallel for schedule(static)
    for (int ty = 0; ty < g.tiles_y; ++ty)
      for (int tx = 0; tx < g.tiles_x; ++tx) {
        float m = -FLT_MAX;
        const int iy1 = std::min(g.ny, (ty + 1) << g.tile_shift),
                  ix1 = std::min(g.nx, (tx + 1) << g.tile_shift);
        for (int iy = ty << g.tile_shift; iy < iy1; ++iy)
          for (int ix = tx << g.tile_shift; ix < ix1; ++ix)
            m = std::max(m, heights_[std::size_t(iy) * g.nx + ix]);
        tile_max_[std::size_t(ty) * g.tiles_x + tx] = m;
      }
  }

  std::size_t fast(std::span<const Posture> block) {
    const GridView g = grid_;
    const ToolView tool = tool_.view;
    float* h = heights_.data();
    const float* tiles = tile_max_.data();
    const long n = static_cast<long>(block.size());
    std::size_t culled = 0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : culled)
    for (long p = 0; p < n; ++p) {
      PreparedPosture pp = preparePosture(g, tool, block[p]);
      if (cullPosture(g, tool, pp, tiles)) {
        ++culled;
        continue;
      }
      for (int iy = pp.iy0; iy <= pp.iy1; ++iy)
        for (int ix = pp.ix0; ix <= pp.ix1; ++ix) {
          float& slot = h[std::size_t(iy) * g.nx + ix];
          const float z = lineCut(g, tool, pp, ix, iy, loadRelaxed(slot));
          if (z != FLT_MAX) atomicLower(slot, z);
        }
    }
    return culled;
  }

  void coarse(std::span<const Posture> block) {
    const GridView g = grid_;
    const ToolView tool = tool_.view;
    float* h = heights_.data();
    const long n = static_cast<long>(block.size());
#pragma omp parallel for schedule(dynamic, 4)
    for (long p = 0; p < n; ++p)
      coarsePosture(g, tool, block[p], [&](int ix, int iy, float z) {
        atomicLower(h[std::size_t(iy) * g.nx + ix], z);
      });
  }

  GridView grid_;
  ToolData tool_;
  std::vector<float> heights_;
  std::vector<float> tile_max_;
  std::size_t refresh_every_;
};

}  // namespace

std::unique_ptr<BackendEngine> makeCpuEngine(const GridView& grid, const ToolData& tool,
                                             std::vector<float> heights_mm) {
  return std::make_unique<CpuEngine>(grid, tool, std::move(heights_mm));
}

}  // namespace fieldpath::zbuffer::detail
