/// detail::BackendEngine over the CUDA engine (built with CUDA only).
#include "cuda_engine.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

bool cudaAvailable() { return cuda::available(); }

namespace detail {
namespace {
class CudaAdapter final : public BackendEngine {
 public:
  CudaAdapter(const GridView& grid, const ToolData& tool, const std::vector<float>& heights)
      : lines_(heights.size()),
        engine_(grid,
                cuda::ToolArrays{tool.view, tool.bvh_nodes.data(), tool.bvh_nodes.size(),
                                 tool.bvh_triangles.data(), tool.bvh_triangles.size(),
                                 tool.vertices.data(), tool.vertices.size(), tool.indices.data(),
                                 tool.indices.size()},
                heights.data(), heights.size()) {}
  std::size_t cut(std::span<const Posture> block, Engine engine) override {
    return engine_.cut(block.data(), block.size(), engine == Engine::Coarse);
  }
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
                                              std::vector<float> heights) {
  if (!cuda::available()) throw std::runtime_error("no CUDA device");
  return std::make_unique<CudaAdapter>(grid, tool, heights);
}
}  // namespace detail
}  // namespace fieldpath::zbuffer
