#pragma once
/// The field sampled at the nodes of a sparse OpenVDB Vec3SGrid (hidden in the .cpp) and
/// interpolated between them (DESIGN.md "The field", seed 004 §2).
#include <cstddef>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/common/progress.h"
#include "fieldpath/field/cell_mask.h"
#include "fieldpath/field/direct_field.h"

namespace fieldpath::field {

/// A build: the voxel settings (h: nodes at (i h, j h, k h), world frame; what they hold; the
/// interpolation; the refinement) and how to build. VoxelRequest(params.voxel) starts from the
/// scene's settings; a default one has FieldParams' defaults.
///
/// Refinement where the grid misses (refine_tolerance > 0, down to refine_levels levels below
/// h): after a level is built, every cell with a non-zero corner (level 0) or inside a split cell
/// (deeper) gets an error estimate from its nodes alone (no exact evaluation): at each corner
/// and along each axis, the second difference of what is interpolated (s and G of the plane
/// ratio, or F) over 8 — linear interpolation's error h²/8·|f''| — as a force error,
/// |dP/ds|·|G|·|Δ²s| + P(s)·|Δ²G| (or |Δ²F|); the largest over the corners, divided by
/// max(mean corner |F|, floor), floor = kRefineFloorFraction · P(2 r_min) (law.h PlaneLaw).
/// Where that exceeds the tolerance the cell's 3³ nodes at half the size are built from the
/// exact law and queries inside it read the finer level; fine nodes on a face shared with an
/// unsplit cell (hanging nodes) take the coarser level's value, so a stored force is continuous
/// across levels (the plane ratio is not across a face whose two cells read it differently:
/// ratioHolds, voxel_grid.h). Trilinear only (quadratic with a tolerance > 0 is refused).
struct VoxelRequest : VoxelSettings {
  VoxelRequest() = default;
  explicit VoxelRequest(const VoxelSettings& settings) : VoxelSettings(settings) {}

  /// PlaneRatio: nodes over the sampled surface closer than this (mm) and those under it hold
  /// the continuation of the field this far above the surface, not their own (voxel_field.cpp
  /// planeRatio); unset: 2 r_min (closer in, a sampled wall's field is far from a plane's), or
  /// kRefinedNearFactor · r_min with refinement, whose fine cells follow the samples' ripple
  /// further in (impeller, samples 0.5 mm apart, 1 mm refined to 2.5 %: line b 0.6 → 0.34 % at
  /// 0.5-1 mm from the wall; bench/results/study/study.md).
  std::optional<double> plane_near_mm;
  /// Depth of the band of nodes kept inside obstacles (where the surface rule of law.h pushes a
  /// node out); negative: for PlaneRatio max(2 h + r_min, r0), as deep as the direct field
  /// pushes out (a node that starts deep in a wall keeps P(depth); ≈40 % more nodes on open
  /// walls at 0.5 mm); for Force 2 h + r_min, so that every interpolation cell a node r_min deep
  /// reaches is built.
  double inside_band_mm = -1.0;
  /// Only nodes in this world box (mm): the region the tool can reach. Default: everywhere the
  /// field can be non-zero.
  std::optional<Eigen::AlignedBox3d> region_mm;
  /// Refinement only where this mask holds a cell's centre (a job's path, pathgen); null:
  /// wherever the error asks, in the region.
  std::shared_ptr<const CellMask> refine_mask;
  /// A build whose level would hold more than this is refused (InputError): its bytes bound
  /// from the leaves it makes, before they are made (the levels' types' sizes, voxel_grid.h
  /// levelBytesBound).
  /// 0: the process's limit when the build starts (common::memoryLimitBytes: `--max-memory`, else
  /// the memory available): generate's grid was built past --max-memory (a fixed 4 GiB here; a
  /// helper's 10M gave a 35 MB grid).
  std::size_t max_memory_bytes = 0;
  common::Progress progress;  ///< "field" fraction of leaves built
};

/// Node counts and costs of a built voxel field.
struct VoxelStats {
  std::size_t estimated_nodes = 0;  ///< estimateVoxelNodes, before allocation
  std::size_t active_nodes = 0;     ///< nodes holding a value (the sparse grid)
  std::size_t dense_box_nodes =
      0;                         ///< nodes of a dense grid over the bounding box of the active ones
  std::size_t memory_bytes = 0;  ///< OpenVDB's memUsage of the grids + the query blocks
  double build_seconds = 0.0;
  int levels = 1;                 ///< grid levels built (1: uniform)
  std::size_t refined_cells = 0;  ///< cells split, all levels
  std::size_t refined_nodes = 0;  ///< nodes of the finer levels (part of active_nodes)
  std::size_t tested_cells = 0;   ///< cells given an error estimate
  std::string backend;            ///< where the nodes were computed: cpu, cuda or reference
  double nodes_seconds = 0.0;     ///< of build_seconds: node values (all levels, transfers in)
  /// of build_seconds: the refinement's host work but the nodes (error estimates, split
  /// cells, hanging nodes, query blocks of the finer levels)
  double refine_seconds = 0.0;
};

/// Nodes of a refined grid follow the field down to this many r_min over the surface.
inline constexpr double kRefinedNearFactor = 1.4;
/// The plane ratio's lifted continuation is kept as it is at a node only where it gives back the
/// node's own exact force within this fraction above it (or less): under a lone small triangle
/// it gave 35 × the law's largest value (a wall's plane continued 5 mm into a solid that is not
/// there), on a face between its samples 2.7 × the direct field.
inline constexpr double kPlaneFitTolerance = 0.1;
/// Where the continuation overstates the node's own force by up to this factor (near a blade's
/// open edge, between a face's samples), the node keeps the continuation's height s and its side
/// and scales G to give back its own force (G = F / P(s)): its cells still interpolate a plane's
/// s. Beyond it (a plane continued into nothing: the lone triangle), the node holds its own
/// force, s = ±P⁻¹(|F|) (negative under the surface, no deeper than the node), is not counted
/// over the surface (its cells blend the corner forces) and the refinement still reads it
/// inside. Holding the own force from 10 % on (as first written) made the impeller study's
/// errors 2-5 × worse: 2 mm nodes 105 -> 252 %, line a 8.8 -> 66 %, 1 mm nodes 7.0 -> 38.5 %
/// (those cells blended forces of a 1/r³ field); rescaled: 90.9, 8.8, 7.2 % (a researcher's
/// re-run of the study, 2026-11-29).
inline constexpr double kPlaneRescaleLimit = 2.0;
/// The refinement floor: a fraction of the plane law at 2 r_min (VoxelRequest::refine_tolerance).
inline constexpr double kRefineFloorFraction = 0.005;

/// Upper bound of the nodes a build will make active, from the samples alone (no fine-grid
/// allocation): the lesser of the dense box (samples padded by r0, clipped to the region) and
/// the nodes of the coarse cells (edge r0/2) within two cells of a sample. Throws InputError
/// for h <= 0.
std::size_t estimateVoxelNodes(const ObstacleSamples& samples, const FieldParams& params,
                               const VoxelRequest& request);
namespace detail {
/// estimateVoxelNodes marking the cells near samples on a dense bitmap when the samples' cells
/// ± 2 are at most `dense_limit_cells`, on a sparse mask otherwise (the same count; tests
/// compare the two).
std::size_t estimateVoxelNodes(const ObstacleSamples& samples, const FieldParams& params,
                               const VoxelRequest& request, double dense_limit_cells);
}  // namespace detail
/// Bytes per node of the estimates before a build (app's checks of a scene's voxel size, the
/// least a refined level adds): a Vec3f per node of leaves that are ~2/3 full (18), and the
/// query block of the leaf, 16 bytes per node of 9³ (≈ 34 per active node). Measured with the
/// plane ratio's closeness grid on top (× 16/12): 74-95 bytes per active node.
inline constexpr double kVoxelBytesPerNode = 52.0;

/// One active node as stored (VoxelField::storedNodes): for tests and tools.
struct StoredNode {
  Vec3 x_mm;                  ///< world position
  int level = 0;              ///< 0: h, 1: h/2, ...
  Vec3 value;                 ///< F (Force) or G (PlaneRatio), float-rounded
  double closeness_mm = 0.0;  ///< PlaneRatio: r0 - s
  bool over = false;  ///< PlaneRatio: over/under the surface (the closeness grid's active mask)
};

/// The uniform grid whose nodes are those of `refined`'s level 0: no refinement, and the plane
/// ratio's near band a refined build takes (kRefinedNearFactor · r_min unless set).
VoxelRequest levelZeroRequest(const VoxelRequest& refined, double r_min_mm);

/// Whether `field.backend: cuda` can run here: the program has CUDA and a GPU is present.
bool cudaFieldBackendAvailable();

namespace voxel {
struct Level;
}

class VoxelField final : public ForceField {
 public:
  /// Builds the nodes from the exact field (node values equal `direct` up to float rounding),
  /// in parallel. Throws common::InputError for h <= 0 or when the estimate exceeds
  /// request.max_memory_bytes (the message gives the estimate); common::Interrupted if the
  /// progress hook asks to stop.
  VoxelField(const DirectField& direct, const VoxelRequest& request);
  /// The refined build of `request` from `uniform`'s level 0 instead of building it again:
  /// `uniform` built from `direct` with levelZeroRequest(request) (its nodes are then those of
  /// this build's level 0; a job steers on it first, pathgen). Throws std::invalid_argument
  /// when `uniform` is refined or of another voxel size or stored quantity.
  VoxelField(const DirectField& direct, const VoxelRequest& request, VoxelField&& uniform);
  ~VoxelField() override;
  VoxelField(VoxelField&&) noexcept;
  VoxelField& operator=(VoxelField&&) noexcept;

  /// Trilinear (the BoxSampler's weights, read from per-leaf blocks of 9³ nodes so that a cell's
  /// 8 corners are one lookup) or quadratic (OpenVDB QuadraticSampler) interpolation; zero
  /// outside the band. Refined cells read the finest level built there.
  void evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const override;

  const VoxelStats& stats() const;
  double voxelSizeMm() const;
  Interpolation interpolation() const;
  StoredQuantity stored() const;
  /// World positions (mm) of the active nodes of every level, at most `max_count` of them.
  std::vector<Vec3> activeNodes(std::size_t max_count = std::size_t(-1)) const;
  /// Every active node of every level with what it stores, level by level in grid order.
  std::vector<StoredNode> storedNodes() const;
  /// Writes the grid (named "force"; finer levels "force_level1", ...) to a .vdb file
  /// atomically; Houdini and Blender open it.
  void save(const std::filesystem::path& file) const;

 private:
  /// Builds all levels, or takes `level0` (moved from; null: built here) and refines it.
  VoxelField(const DirectField& direct, const VoxelRequest& request, voxel::Level* level0);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fieldpath::field
