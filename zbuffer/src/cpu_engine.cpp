/// CPU reference backend (OpenMP): one work item per posture (lowest first within a block), line
/// heights lowered with an atomic compare-and-swap minimum (the minimum does not depend on the
/// order of postures).
#include <algorithm>
#include <atomic>

#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"
#include "host_memory.h"

namespace fieldpath::zbuffer::detail {
namespace {

inline void atomicLower(float& slot, float value) {
  std::atomic_ref<float> a(slot);
  float current = a.load(std::memory_order_relaxed);
  while (value < current && !a.compare_exchange_weak(current, value, std::memory_order_relaxed)) {
  }
}

class CpuEngine final : public BackendEngine {
 public:
  explicit CpuEngine(const EngineSetup& setup)
      : grid_(setup.grid),
        keep_tool_(setup.tool),
        view_(setup.view),
        tuning_(setup.tuning),
        tile_max_(std::size_t(setup.grid.tiles_x) * setup.grid.tiles_y) {
    const GridView& grid = setup.grid;
    const EngineTuning& tuning = setup.tuning;
    heights_ = reserveHuge<float>(std::size_t(grid.nx) * grid.ny);
    if (setup.heights_mm.empty())
      heights_.assign(std::size_t(grid.nx) * grid.ny, setup.stock_mm);
    else
      heights_.assign(setup.heights_mm.begin(), setup.heights_mm.end());
    // Tile maxima are refreshed between chunks: often when postures come lowest first (each
    // refresh lets the tiles cut so far cull the higher postures), bounded by the refresh cost.
    const std::size_t lines = std::size_t(grid.nx) * grid.ny;
    refresh_every_ = tuning.refresh_postures ? tuning.refresh_postures
                     : tuning.lowest_first
                         ? std::clamp<std::size_t>(lines / 64, 2048, std::size_t{1} << 24)
                         : std::clamp<std::size_t>(lines / 8, 16384, std::size_t{1} << 24);
  }

  void cut(std::span<const Posture> block, Engine engine) override {
    if (engine == Engine::Coarse) {
      coarse(block);
      return;
    }
    // `count` postures, at(k) the k-th, in chunks with the tile maxima refreshed before each
    const auto pass = [&](std::size_t count, auto at) {
      std::size_t culled = 0;
      for (std::size_t begin = 0; begin < count; begin += refresh_every_) {
        refreshTiles();
        culled += fast(at, begin, std::min(count, begin + refresh_every_));
      }
      return culled;
    };
    const std::size_t stride = std::size_t(std::max(tuning_.prepass_stride, 0));
    if (stride > 1 && !tuning_.lowest_first && block.size() >= 2 * stride)
      // every stride-th posture in path order first (see EngineTuning::prepass_stride); its
      // culls are not counted (the main pass meets the same postures again)
      (void)pass((block.size() + stride - 1) / stride,
                 [&](std::size_t k) { return block[k * stride]; });  // culls not counted
    if (tuning_.lowest_first) {
      const std::vector<std::uint32_t> order = lowestFirstOrder(block);
      culled_ += pass(block.size(), [&](std::size_t k) { return block[order[k]]; });
    } else {
      culled_ += pass(block.size(), [&](std::size_t k) { return block[k]; });
    }
  }

  std::vector<float> heights() override { return std::move(heights_); }
  std::size_t culled() override { return culled_; }

 private:
  /// Indices of the block's postures, lowest point over the grid first (see lowestKey).
  std::vector<std::uint32_t> lowestFirstOrder(std::span<const Posture> block) const {
    std::vector<std::uint32_t> order(block.size());
    std::vector<std::uint64_t> keyed(block.size());
    const GridView g = grid_;
    const ToolView tool = view_;
    const long n = static_cast<long>(block.size());
#pragma omp parallel for schedule(static)
    for (long p = 0; p < n; ++p)
      keyed[p] = (std::uint64_t{lowestKey(g, tool, block[p])} << 32) | std::uint64_t(p);
    // those that miss the grid (a zoom's nearly all) go last in any order: sort only the others
    const auto miss = std::partition(keyed.begin(), keyed.end(),
                                     [](std::uint64_t k) { return (k >> 32) != 0xffffffffu; });
    std::sort(keyed.begin(), miss);
    for (std::size_t k = 0; k < order.size(); ++k) order[k] = static_cast<std::uint32_t>(keyed[k]);
    return order;
  }

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

  /// Cuts postures at(begin) ... at(end - 1) in parallel; returns how many were culled.
  template <class PostureAt>
  std::size_t fast(PostureAt at, std::size_t begin, std::size_t end) {
    const GridView g = grid_;
    const ToolView tool = view_;
    float* h = heights_.data();
    float* tiles = tile_max_.data();
    const bool skip = tuning_.tile_skip, live = tuning_.live_tiles;
    std::size_t culled = 0;
#pragma omp parallel for schedule(dynamic, 16) reduction(+ : culled)
    for (long k = long(begin); k < long(end); ++k) {
      const Posture pose = at(std::size_t(k));
      if (missesGrid(g, tool, pose)) {  // a zoom's nearly all: no preparation
        ++culled;
        continue;
      }
      PreparedPosture pp = preparePosture(g, tool, pose);
      if (cullPosture(g, tool, pp, tiles)) {
        ++culled;
        continue;
      }
      const auto top = [&](int tile) { return readTileMax(tiles, tile); };
      forEachLiveTile(
          g, tool, pp, skip, 0, 1, top, [&](int ix0, int ix1, int iy0, int iy1, int tile) {
            const float highest = cutRect(
                g, tool, pp, ix0, ix1, iy0, iy1, 0, 1,
                [&](int ix, int iy) { return loadRelaxed(&h[std::size_t(iy) * g.nx + ix]); },
                [&](int ix, int iy, float z) { atomicLower(h[std::size_t(iy) * g.nx + ix], z); });
            if (live && wholeTile(g, ix0, ix1, iy0, iy1)) atomicLower(tiles[tile], highest);
          });
    }
    return culled;
  }

  void coarse(std::span<const Posture> block) {
    const GridView g = grid_;
    const ToolView tool = view_;
    float* h = heights_.data();
    const long n = static_cast<long>(block.size());
#pragma omp parallel for schedule(dynamic, 4)
    for (long p = 0; p < n; ++p)
      coarsePosture(g, tool, block[p], [&](int ix, int iy, float z) {
        atomicLower(h[std::size_t(iy) * g.nx + ix], z);
      });
  }

  GridView grid_;
  std::shared_ptr<const ToolData> keep_tool_;  ///< owns the arrays view_ points into
  ToolView view_;
  EngineTuning tuning_;
  std::vector<float> heights_;
  std::vector<float> tile_max_;
  std::size_t refresh_every_;
  std::size_t culled_ = 0;
};

}  // namespace

std::unique_ptr<BackendEngine> makeCpuEngine(const EngineSetup& setup) {
  return std::make_unique<CpuEngine>(setup);
}

}  // namespace fieldpath::zbuffer::detail
