/// detail::BackendEngine over the CUDA engine (built with CUDA only).
#include "cuda_engine.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

bool cudaAvailable() { return cuda::available(); }

namespace detail {
namespace {
cuda::ToolArrays arrays(const ToolData& tool) {
  cuda::ToolArrays a;
  a.view = tool.view;
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

class CudaAdapter final : public BackendEngine {
 public:
  CudaAdapter(const GridView& grid, const ToolData& tool, std::span<const float> heights,
              const EngineTuning& t)
      : lines_(heights.size()),
        engine_(grid, arrays(tool), heights.data(), heights.size(),
                {t.lowest_first, t.small_threads, t.overlap_upload, t.tile_skip, t.pinned_staging,
                 t.refresh_postures}) {}

  void cut(std::span<const Posture> block, Engine engine) override {
    engine_.cut(block.data(), block.size(), engine == Engine::Coarse);
  }
  std::size_t culled() override { return engine_.culled(); }
  std::vector<float> heights() override {
    std::vector<float> h(lines_);
    engine_.heights(h.data());
    return h;
  }

 private:
  std::size_t lines_;
  cuda::Engine engine_;
};
}  // namespace

std::unique_ptr<BackendEngine> makeCudaEngine(const GridView& grid, const ToolData& tool,
                                              std::span<const float> heights,
                                              const EngineTuning& tuning) {
  if (!cuda::available()) throw std::runtime_error("no CUDA device");
  return std::make_unique<CudaAdapter>(grid, tool, heights, tuning);
}
}  // namespace detail
}  // namespace fieldpath::zbuffer
