#pragma once
/// The machined surface of a path against its part (`check`, DESIGN.md): the Z-buffer simulates
/// the path's postures and the motions between them over the part's region, starting a stock
/// allowance above the part, and every line is compared with the part's own height: gouge (below)
/// and scallop (above), µm, told along the part's normal (the vertical difference times the cosine
/// of the slope of the facet under the line: exact over a plane facet), as a profile tolerance is.
#include <cstddef>
#include <filesystem>
#include <limits>
#include <optional>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::pathgen {
class ClearanceChecker;
}

namespace fieldpath::app {

/// Initial stock above the part, mm: lines no tool reaches stay this far above it.
inline constexpr float kStockAllowanceMm = 2.0f;
/// Deviation below the part that counts as a gouge by default, µm. The part is a mesh: where it is
/// concave its facets lie above the true surface by up to its chordal error (the impeller's hub
/// mesh: 10 µm; measured there: 1.3 µm), so an exact cut reads as a shallow gouge.
inline constexpr double kGougeToleranceUm = 5.0;
/// Lines at most; a finer `spacing` over a larger region is coarsened (and says so).
inline constexpr std::size_t kMaxSurfaceLines = 6'000'000;

struct SurfaceRequest {
  const geometry::TriangleMesh* part = nullptr;
  const geometry::PathFile* path = nullptr;
  geometry::ToolSpec tool;
  double spacing_mm = 0.05;  ///< line spacing asked for
  double gouge_tolerance_um = kGougeToleranceUm;
  zbuffer::Backend backend = zbuffer::Backend::Auto;
  common::Progress progress;
  /// The scene's obstacles (their checker, built for the clearance): where given, the band's
  /// highest lines are told apart where the ball cannot touch the part without meeting one
  /// (SurfaceResult::unreachable_band_lines). Ball tools only.
  const pathgen::ClearanceChecker* obstacles = nullptr;
};

struct SurfaceResult {
  zbuffer::Grid grid;
  /// Per line: (machined height − part height) · |n_z| of the part's facet there, µm: the
  /// deviation along the part's normal; NaN where the line misses the part.
  std::vector<float> deviation_um;
  /// Per line: in the machined band (between passes side by side: machinedBand), where scallops
  /// count; a lone pass has none (band_lines 0: no scallop figures).
  std::vector<char> in_band;
  /// Per line: 1 where the tool lowered it (0: the stock allowance stands; deviation.png shows
  /// such lines in the stock's colour, not as the largest scallop).
  std::vector<char> lowered;
  std::size_t part_lines = 0, band_lines = 0;
  /// Lines between two passes (in the band) that no pass lowered: the stock allowance stands
  /// there, passes too far apart to meet (not in band_lines nor the scallop figures: they read
  /// the allowance, 2000 um, as a scallop).
  std::size_t uncut_band_lines = 0;
  std::size_t gouged_lines = 0;  ///< anywhere on the part, deeper than the tolerance
  double gouge_tolerance_um = kGougeToleranceUm;
  double max_gouge_um = 0, max_scallop_um = 0, mean_um = 0, rms_um = 0;  ///< scallop stats: band
  /// The band's lines above the highest one the ball can touch, told by the ball set on the part
  /// there (its centre R along the part's normal, R less 0.01 mm) meeting an obstacle: stock
  /// beside a wall or a rib that no ball of R reaches, not a cusp the passes leave (a mould's
  /// 1994 um "scallop" beside its ribs, its cusps 95 um). `max_reachable_scallop_um`: the highest
  /// band line the ball can touch; NaN where not told (no obstacles, not a ball) or where it can
  /// touch none (unreachable_band_lines is then band_lines).
  std::size_t unreachable_band_lines = 0;
  double max_reachable_scallop_um = std::numeric_limits<double>::quiet_NaN();
  /// How far the highest cusp may stand above max_scallop_um, µm: a cusp between two cuts of
  /// the cutting edge (curvature radius ρ: a ball's R, a torus's corner r) may fall up to a
  /// spacing/√2 from every line, where the vertical deviation climbs at most tan(θ + α) − tan(θ)
  /// a mm (θ the part's slope there, α the edge's angle at a cusp of that height): the largest
  /// line's deviation plus its own bound (along the normal, as the deviation), over the band,
  /// less max_scallop_um. Infinite where a band
  /// line lies on a wall of 85° with its cusp (not bounded); 0 without a band.
  double scallop_grid_error_um = 0;
  zbuffer::Backend backend = zbuffer::Backend::Cpu;
  double simulation_s = 0;
  bool coarsened = false;  ///< the spacing was widened to stay within kMaxSurfaceLines
  /// The motions are swept: postures interpolated no farther apart than this (mm) where the tool
  /// can reach the stock; the cut between two of them is at most sweep_error_um shallower (the
  /// cutting edge's curvature: a ball's R, a torus's corner r) along the edge's normal there:
  /// along the part's normal where the edge finishes the part, as the deviation is told; 1/cos
  /// of the edge's slope more vertically (stock left to the ball's side at a pass's end: a
  /// claims audit read 3.1 um against 1.25).
  double sweep_step_mm = 0, sweep_error_um = 0;
  std::size_t simulated_postures = 0;  ///< the path's and the interpolated ones
  std::size_t cut_lines = 0;           ///< lines the tool lowered, over the part or not
  /// Lines over the part the tool lowered (0: it never cut the stock over the part: a path in
  /// inches whose tips fell in the bore of a hub lowered 179 981 lines, none over the part, and
  /// read `ok`).
  std::size_t part_cut_lines = 0;
  /// Lines the tool reached beneath the layer of the part's top (under an overhang, or through
  /// the part): measured against the top of the part under that layer, if any
  /// (`beneath_unmeasured` have none: not measured, as lines off the part).
  std::size_t beneath_lines = 0, beneath_unmeasured = 0;
};

/// The Z-buffer's lines over what the passes reach of the part: the grid, its spacing (mm), and
/// whether it was widened to stay within kMaxSurfaceLines; nothing when the passes do not pass
/// over the part. Checked against the memory left (zbuffer::checkGridFits), so that check can
/// refuse it before its clearance work (a grid refused after minutes of it: a memory sweep's).
struct SurfaceGrid {
  zbuffer::Grid grid;
  double spacing_mm = 0.0;
  bool coarsened = false;
};
std::optional<SurfaceGrid> surfaceGrid(const SurfaceRequest& request);

/// Simulates and compares on the grid surfaceGrid gave for `request` (sized once, before the
/// command's other work); nothing when no line of it falls on the part.
std::optional<SurfaceResult> checkSurface(const SurfaceRequest& request, const SurfaceGrid& plan);

/// deviation.png: the map (row 0 = largest y, grey off the part, sand where no pass cut: the
/// stock allowance) with a colour bar and its scale in µm on the right.
void writeDeviationPng(const std::filesystem::path& file, const SurfaceResult& surface);

}  // namespace fieldpath::app
