#pragma once
/// What the Z-buffer's kernels see (kernels.h, tool_entry.h): the grid, the tool and a prepared
/// posture as plain structs of values and non-owning pointers, so that the CPU reference
/// (OpenMP) and the CUDA backend pass them by value alike.
#include <cfloat>
#include <cstdint>

#include "fieldpath/zbuffer/hd.h"

namespace fieldpath::zbuffer {
/// The lines of a height map: line (ix, iy) stands at x = x0 + (ix+0.5) dx, y = y0 + (iy+0.5) dy
/// (mm, world). Line coordinates are formed in double and rounded once, so a zoom grid aligned
/// with a coarser one gives its lines the very same float coordinates.
struct GridView {
  double x0_mm = 0, y0_mm = 0, dx_mm = 1, dy_mm = 1;
  int nx = 0, ny = 0;
  int tile_shift = 4;  ///< culling tiles of 2^shift × 2^shift lines
  int tiles_x = 0, tiles_y = 0;
};

enum class ToolKind : int { Ball = 0, Torus = 1, Flat = 2, Mesh = 3 };

/// Bounding volume hierarchy node (tool frame, mm). Interior: left child at this+1, right child
/// at `first`, count == 0. Leaf: triangles [first, first+count) of the leaf-ordered array.
struct BvhNode {
  float lo[3];
  float hi[3];
  std::int32_t first;
  std::int32_t count;
};

/// A tool as the kernels see it (tool frame: tip at origin, axis +z, mm).
struct ToolView {
  ToolKind kind = ToolKind::Ball;
  float radius_mm = 0, corner_radius_mm = 0, length_mm = 0;      ///< analytic shapes
  float hull_radius_mm = 0, hull_zmin_mm = 0, hull_zmax_mm = 0;  ///< bounds the solid (all kinds)
  // Mesh tools: triangles in BVH leaf order (9 floats each, shared vertices copied bit-exactly).
  const float* bvh_triangles = nullptr;
  const BvhNode* bvh_nodes = nullptr;
  // Mesh tools, coarse engine: the indexed mesh as given.
  const Vec3f* vertices = nullptr;
  const std::uint32_t* indices = nullptr;  ///< 3 per triangle, CCW seen from outside
  std::int32_t triangle_count = 0;
  // Mesh tools, vertical postures: down-facing triangles binned on a uniform grid over the tool's
  // xy (tool frame), so a vertical line tests only the few triangles of its bin.
  float bin_x0_mm = 0, bin_y0_mm = 0, bin_inv_mm = 0;
  std::int32_t bins = 0;                    ///< per side; 0: no bins
  const std::int32_t* bin_start = nullptr;  ///< bins²+1 offsets into bin_items
  const std::int32_t* bin_items = nullptr;  ///< leaf-order triangle indices
  // Mesh tools, vertical postures: per annulus of radius about the axis, a floor (tool frame z, mm)
  // below which no down-facing triangle lies; FLT_MAX where none does. Lets a vertical line that
  // the tool cannot lower be skipped after one table look-up.
  const float* radial_floor_mm = nullptr;
  std::int32_t radial_bins = 0;
  /// The annuli are even in the squared radius (no square root per line; a ball's floor is
  /// linear in it): bin = int(ρ² · radial_inv_mm2), lines with ρ² > radial_max_mm2 missed.
  float radial_inv_mm2 = 0, radial_max_mm2 = 0;
  // All kinds: a capsule that contains the tool, the points within cap_radius_mm of the axis
  // segment z in [cap_z0_mm, cap_z1_mm] (tool frame). Its lower envelope is a floor of the heights
  // any posture (tilted ones too) can give a line or a tile, at a square root's cost; 0: none.
  float cap_radius_mm = 0, cap_z0_mm = 0, cap_z1_mm = 0;
};

/// Everything a posture needs, computed once per posture.
struct PreparedPosture {
  Mat3f rot;  ///< tool → world
  Vec3f tip_mm;
  Vec3f dir;          ///< world +z expressed in the tool frame (third row of rot)
  float lowest_z_mm;  ///< no point of the placed tool is below this (conservative)
  bool vertical;      ///< axis exactly +z: rot is the identity
  int ix0, ix1, iy0,
      iy1;  ///< lines that may meet the tool (inclusive, clipped); empty if ix0 > ix1
  // Watertight ray/triangle test (Woop, Benthin, Wald 2013): axis permutation and shear.
  int kx, ky, kz;
  float sx, sy, sz;
  Vec3f inv_dir;  ///< 1/dir with zeros replaced by ±1e-30 (no 0·∞ in the slab test)
  // The tool's capsule (ToolView::cap_*) placed: its axis segment seen from above, a → b (mm,
  // world xy relative to the tip), the world z of its ends, and a rounding margin (mm).
  float cap_ax, cap_ay, cap_bx, cap_by, cap_za_mm, cap_zb_mm, cap_margin_mm;
  // ... and, per posture once for every line: the segment's length seen from above (0 when
  // within the margin: nearly vertical), its direction, z per mm along it, slope / sqrt(1 + slope²)
  float cap_len_mm, cap_ux, cap_uy, cap_slope, cap_kstar;
};

FIELDPATH_HD float safeInverse(float v) { return 1.f / (v == 0.f ? 1e-30f : v); }

FIELDPATH_HD int clampi(int v, int lo, int hi) { return v < lo ? lo : (v > hi ? hi : v); }

}  // namespace fieldpath::zbuffer
