#pragma once
/// Settings of the repulsive field (scene `field:` block). Defaults are documented here, once.
#include <optional>
#include <string_view>

namespace fieldpath::field {

enum class Weights { Area, Unit };                  ///< area weights, or w_j = 1 (seed 004)
enum class Interpolation { Trilinear, Quadratic };  ///< voxel sampler
/// What the voxel nodes store (scene `field.stored`).
/// - Force: F itself; interpolated F has a large relative error where the field rises like 1/d
///   towards a wall or fades at r0 (a cell spans much of either at h >= 1 mm).
/// - PlaneRatio: the signed equivalent height s (the height above a plane whose field has |F|,
///   signed by the side of the surface; a plane's height, linear across it) and G = F / P(s), P
///   the plane law (law.h PlaneLaw; G is the unit field direction away from the wall's r_min
///   zone); the query returns P(s~)·G~. Exact for a plane at any h, on both sides of it and
///   through r0; the same at the nodes. One more float a node and a second lookup.
enum class StoredQuantity { Force, PlaneRatio };
/// Where the voxel nodes are computed (scene `field.backend`, `--backend`): Auto is the GPU when
/// the program has CUDA and a device is present, else the CPU block build; Reference is the
/// per-node build the block builds are checked against (tests, bench_field).
enum class FieldBackend { Auto, Cpu, Cuda, Reference };
/// "auto", "cpu", "cuda", "reference" (scene key and `--backend`); nothing for another word.
inline std::optional<FieldBackend> fieldBackendNamed(std::string_view name) {
  if (name == "auto") return FieldBackend::Auto;
  if (name == "cpu") return FieldBackend::Cpu;
  if (name == "cuda") return FieldBackend::Cuda;
  if (name == "reference") return FieldBackend::Reference;
  return std::nullopt;
}

/// Where a job's refinement splits cells (scene `field.refine_region`): VoxelSettings says.
enum class RefineRegion { Path, Reach };
/// "path", "reach"; nothing for another word.
inline std::optional<RefineRegion> refineRegionNamed(std::string_view name) {
  if (name == "path") return RefineRegion::Path;
  if (name == "reach") return RefineRegion::Reach;
  return std::nullopt;
}

/// How the field is sampled on voxels (scene `field.voxel_size`, `interpolation`, `stored`,
/// `refine_tolerance`, `refine_levels`, `refine_region`), written once: FieldParams holds the
/// scene's, a VoxelRequest (voxel_field.h) starts from them and adds how to build.
struct VoxelSettings {
  double voxel_size_mm = 0.5;  ///< h of the sparse grid
  Interpolation interpolation = Interpolation::Trilinear;
  StoredQuantity stored = StoredQuantity::PlaneRatio;  ///< what voxel nodes hold
  /// Voxel refinement: a cell whose estimated trilinear error exceeds this fraction of its
  /// force is split in 2³ at half the size, down to `refine_levels` levels below voxel_size_mm;
  /// 0: a uniform grid (voxel_field.h VoxelRequest says how the error is estimated).
  double refine_tolerance = 0.0;
  int refine_levels = 2;
  FieldBackend backend = FieldBackend::Auto;  ///< same node values on each, to float rounding
  /// Where a job's refinement splits cells: Path, only near where the tool + holder nodes go
  /// (the path steered on the uniform grid first, pathgen/generate.cpp); Reach, everywhere the
  /// tool could reach. `fieldpath field build` has no path: everywhere.
  RefineRegion refine_region = RefineRegion::Path;
};

struct FieldParams {
  double r0_mm = 5.0;           ///< neighbourhood of eq. 1: φ = 0 for r >= r0
  double r_min_mm = 0.25;       ///< φ held at φ(r_min) below this distance
  double gain = 1.0;            ///< scales the whole field
  double sample_step_mm = 1.0;  ///< obstacle sampling spacing
  Weights weights = Weights::Area;
  VoxelSettings voxel;  ///< `generate --direct` and the direct fields ignore it
};

}  // namespace fieldpath::field
