#pragma once
/// The CUDA engine behind a C++17 interface (nvcc gets C++17 under CMake 3.25; the public API is
/// C++20). Wrapped into detail::BackendEngine by cuda_adapter.cpp.
#include <cstddef>
#include <cstdint>
#include <memory>

#include "fieldpath/zbuffer/kernels.h"

namespace fieldpath::zbuffer::cuda {

/// Host arrays of a prepared tool (see detail::ToolData); copied to the device by the engine.
struct ToolArrays {
  ToolView view;
  std::uint64_t id = 0;  ///< detail::ToolData::id: the device copy is kept for the same id
  const BvhNode* nodes = nullptr;
  std::size_t node_count = 0;
  const float* triangles = nullptr;  ///< 9 floats per triangle
  std::size_t triangle_floats = 0;
  const Vec3f* vertices = nullptr;
  std::size_t vertex_count = 0;
  const std::uint32_t* indices = nullptr;
  std::size_t index_count = 0;
  const std::int32_t* bin_start = nullptr;
  std::size_t bin_start_count = 0;
  const std::int32_t* bin_items = nullptr;
  std::size_t bin_item_count = 0;
  const float* radial_floor = nullptr;
  std::size_t radial_count = 0;
};

bool available();
/// Creates the device's context and uploads the tool (kept for the engines with its id).
void warmUp(const ToolArrays& tool);

class Engine {
 public:
  /// Tuning flags (see EngineTuning): lowest-first order, thread-per-posture for small
  /// footprints, upload of the next block overlapping this block's kernels.
  struct Options {
    bool lowest_first = true, small_threads = true, overlap_upload = true, tile_skip = true,
         pinned_staging = true;
    std::size_t refresh_postures = 0;  ///< 0: from the grid size
    int prepass_stride = 0;            ///< see EngineTuning::prepass_stride
    int group_postures = 8;            ///< see EngineTuning::group_postures
    bool live_tiles = true;            ///< see EngineTuning::live_tiles
  };
  /// `heights_mm`: the initial heights (`lines` of them), or null: every line at `stock_mm`.
  Engine(const GridView& grid, const ToolArrays& tool, const float* heights_mm, float stock_mm,
         std::size_t lines, Options options);
  ~Engine();
  Engine(const Engine&) = delete;
  Engine& operator=(const Engine&) = delete;
  /// Queues the lowering of the heights by `count` postures; returns once `postures` has been
  /// read (the kernels may still run).
  void cut(const Posture* postures, std::size_t count, bool coarse);
  /// Waits for the queued work; the heights.
  void heights(float* out_mm) const;
  /// Postures culled so far (fast engine); waits for the queued work.
  std::size_t culled() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldpath::zbuffer::cuda
