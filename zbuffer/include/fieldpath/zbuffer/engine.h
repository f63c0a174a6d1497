#pragma once
/// Internals of the Z-buffer shared by its two backends and its tests, not part of the user API
/// (simulator.h): the prepared tool, the grid view, and the engine interface the CPU and CUDA
/// backends implement.
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "fieldpath/zbuffer/kernels.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

namespace detail {

/// Flattened tool data shared by the backends (leaf-ordered BVH triangles, nodes, indices).
struct ToolData {
  ToolView view;  ///< pointers into the vectors below (host copies)
  /// Distinct for every prepareTool call: lets the CUDA backend keep the tool on the device for a
  /// run of simulations with the same tool.
  std::uint64_t id = 0;
  std::vector<float> bvh_triangles;
  std::vector<BvhNode> bvh_nodes;
  std::vector<Vec3f> vertices;
  std::vector<std::uint32_t> indices;
  std::vector<std::int32_t> bin_start, bin_items;
  std::vector<float> radial_floor;
  /// Points the view's arrays at this object's vectors (after a copy).
  void pointViewAtVectors();
};
ToolData prepareTool(const Tool& tool);
/// Culling tiles of 2^tile_shift × 2^tile_shift lines.
GridView makeGridView(const Grid& grid, int tile_shift = 4);

/// A backend: keeps the heights between blocks. The CPU and CUDA engines implement the same calls.
class BackendEngine {
 public:
  virtual ~BackendEngine() = default;
  /// Lowers the heights by every posture of the block (the engine may still be working on it
  /// when this returns, but no longer reads `block`).
  virtual void cut(std::span<const Posture> block, Engine engine) = 0;
  /// Waits for all blocks; the final heights (called once, at the end: the CPU engine hands over
  /// its buffer).
  virtual std::vector<float> heights() = 0;
  /// Postures culled so far by the fast engine (valid after heights()).
  virtual std::size_t culled() = 0;
};
/// What an engine starts from. `tool` is kept alive by the engine; `view` is the tool's view as
/// this run uses it (its pointers into `tool`'s arrays; e.g. bins switched off by a knob).
/// `heights_mm`: the initial heights, read during the call only; empty: every line at `stock_mm`.
struct EngineSetup {
  GridView grid;
  std::shared_ptr<const ToolData> tool;
  ToolView view;
  std::span<const float> heights_mm;
  float stock_mm = 0.f;
  EngineTuning tuning;
};
std::unique_ptr<BackendEngine> makeCpuEngine(const EngineSetup& setup);
/// Throws std::runtime_error if built without CUDA or no device is present.
std::unique_ptr<BackendEngine> makeCudaEngine(const EngineSetup& setup);
/// Creates the CUDA context and uploads `tool` (kept on the device for the engines after it with
/// the same ToolData::id). Nothing without CUDA.
void warmUpCuda(const ToolData& tool);

}  // namespace detail
}  // namespace fieldpath::zbuffer
