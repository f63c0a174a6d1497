/// detail::BackendEngine over the CUDA engine (built with CUDA only).
#include <future>

#include "cuda_engine.h"
#include "fieldpath/zbuffer/engine.h"
#include "fieldpath/zbuffer/simulator.h"
#include "host_memory.h"

namespace fieldpath::zbuffer {

bool cudaAvailable() { return cuda::available(); }

namespace detail {
namespace {
cuda::ToolArrays arrays(const ToolData& tool, const ToolView& view) {
  cuda::ToolArrays a;
  a.view = view;
  a.id = tool.id;
  a.nodes = tool.bvh_nodes.data();
  a.node_count = tool.bvh_nodes.size();
  a.triangles = tool.bvh_triangles.data();
  a.triangle_floats = tool.bvh_triangles.size();
  a.vertices = tool.vertices.data();
  a.vertex_count = tool.vertices.size();
  a.indices = tool.indices.data();
  a.index_count = tool.indices.size();
  a.bin_start = tool.bin_start.data();
  a.bin_start_count = tool.bin_start.size();
  a.bin_items = tool.bin_items.data();
  a.bin_item_count = tool.bin_items.size();
  a.radial_floor = tool.radial_floor.data();
  a.radial_count = tool.radial_floor.size();
  return a;
}

cuda::Engine::Options options(const EngineTuning& t) {
  return {t.lowest_first,     t.small_threads,  t.overlap_upload, t.tile_skip, t.pinned_staging,
          t.refresh_postures, t.prepass_stride, t.group_postures, t.live_tiles};
}

class CudaAdapter final : public BackendEngine {
 public:
  explicit CudaAdapter(const EngineSetup& s)
      : lines_(std::size_t(s.grid.nx) * s.grid.ny),
        engine_(s.grid, arrays(*s.tool, s.view),
                s.heights_mm.empty() ? nullptr : s.heights_mm.data(), s.stock_mm, lines_,
                options(s.tuning)) {
    // A large output vector is zeroed (and its pages faulted in) by another thread while the
    // device works: 400 MB for a 10000² grid is ~0.1 s of one core.
    if (lines_ >= (std::size_t{1} << 24))
      output_ = std::async(std::launch::async, [n = lines_] {
        std::vector<float> v = reserveHuge<float>(n);
        v.resize(n);
        return v;
      });
  }

  void cut(std::span<const Posture> block, Engine engine) override {
    engine_.cut(block.data(), block.size(), engine == Engine::Coarse);
  }
  std::size_t culled() override { return engine_.culled(); }
  std::vector<float> heights() override {
    std::vector<float> h = output_.valid() ? output_.get() : std::vector<float>(lines_);
    engine_.heights(h.data());
    return h;
  }

 private:
  std::size_t lines_;
  cuda::Engine engine_;
  std::future<std::vector<float>> output_;
};
}  // namespace

void warmUpCuda(const ToolData& tool) {
  if (cuda::available()) cuda::warmUp(arrays(tool, tool.view));
}

std::unique_ptr<BackendEngine> makeCudaEngine(const EngineSetup& setup) {
  if (!cuda::available()) throw std::runtime_error("no CUDA device");
  return std::make_unique<CudaAdapter>(setup);
}
}  // namespace detail
}  // namespace fieldpath::zbuffer
