#pragma once
/// Settings of the repulsive field (scene `field:` block). Defaults are documented here, once.

namespace fieldpath::field {

enum class Weights { Area, Unit };                  ///< area weights, or w_j = 1 (seed 004)
enum class Interpolation { Trilinear, Quadratic };  ///< voxel sampler

struct FieldParams {
  double r0_mm = 5.0;           ///< neighbourhood of eq. 1: φ = 0 for r >= r0
  double r_min_mm = 0.25;       ///< φ held at φ(r_min) below this distance
  double gain = 1.0;            ///< scales the whole field
  double sample_step_mm = 1.0;  ///< obstacle sampling spacing
  Weights weights = Weights::Area;
  double voxel_size_mm = 0.5;  ///< h of the sparse grid
  Interpolation interpolation = Interpolation::Trilinear;
};

}  // namespace fieldpath::field
