#pragma once
/// Z-buffer machining simulation (DESIGN.md "The Z-buffer", seeds 000 and 001): vertical lines on
/// an nx × ny grid start at the stock height and are lowered, for every posture, to the lowest
/// point of the placed tool. CPU (OpenMP) reference and CUDA backend, same results bit for bit.
#include <array>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/zbuffer/kernels.h"

namespace fieldpath::zbuffer {

/// Region and line spacing of a height map (mm, world). Line (ix, iy) stands at
/// x = x0 + (ix+0.5) dx, y = y0 + (iy+0.5) dy; heights are stored row by row (row = iy).
struct Grid {
  double x0_mm = 0, y0_mm = 0;
  double dx_mm = 1, dy_mm = 1;
  int nx = 0, ny = 0;

  /// nx × ny lines covering [x0, x1] × [y0, y1]. Throws common::InputError for a region of zero
  /// or negative area, a zero grid, or non-finite numbers.
  static Grid fromRegion(double x0_mm, double y0_mm, double x1_mm, double y1_mm, int nx, int ny);
  std::size_t lineCount() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  }
};

/// A closed, outward-oriented (CCW seen from outside) triangle mesh in the tool frame: tip at the
/// origin, axis +z, mm.
struct ToolMesh {
  std::vector<Vec3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
};

/// The tool: an analytic ball / torus / flat end mill with its cylindrical shank closed at L, or a
/// mesh. Build with the factories; they throw common::InputError for impossible dimensions.
struct Tool {
  ToolKind kind = ToolKind::Ball;
  float radius_mm = 0, corner_radius_mm = 0, length_mm = 0;
  ToolMesh mesh;  ///< kind == Mesh only

  static Tool ball(double radius_mm, double length_mm);
  static Tool torus(double radius_mm, double corner_radius_mm, double length_mm);
  static Tool flat(double radius_mm, double length_mm);
  static Tool fromMesh(ToolMesh mesh);
};

/// The radius (mm, about the tool's axis) that contains the whole tool: how far from a posture's
/// tip its cut can reach on the grid. Cheap: no BVH is built.
double toolReach(const Tool& tool);
/// How far the tool's farthest point lies from its tip (mm): how far a point of it moves, at
/// most, for a turn of its axis about the tip of one radian (an analytic tool's hypot(length, R);
/// a mesh's farthest vertex).
double toolExtent(const Tool& tool);

enum class Backend { Auto, Cpu, Cuda };
/// Fast: per posture, only the lines under the tool (analytic envelope, or the line in the tool
/// frame through a BVH of the mesh) plus conservative culling. Coarse: SIMSURF1's algorithm (one
/// work item per posture, every triangle transformed and rasterised), kept as the benchmark peer.
enum class Engine { Fast, Coarse };

const char* backendName(Backend backend);
/// The backend named `name` (auto, cpu, cuda); common::InputError naming `key` otherwise.
Backend backendFromName(const std::string& name, const std::string& key = "backend");
/// True if a CUDA device can be used (built with CUDA and cudaGetDeviceCount succeeds with >= 1).
bool cudaAvailable();
/// The CPU backend's threads (OpenMP) from now on: at most `threads` (>= 1).
void limitCpuThreads(int threads);

/// For Backend::Auto, without any CUDA call: whether the CPU engine would finish about `postures`
/// postures of `tool` on `grid` before the GPU is even ready to cut. Starting the GPU (the driver
/// and a context) costs ~0.25 s on the H100 machine before its first cut and ~0.1 s to end; the
/// CPU engine visits ~5e7 grid lines a second per core (both bench/results/zbuffer-process.md).
/// `cpu_seconds` receives the CPU estimate (a rough one: culling and tilt are not counted).
bool cpuFinishesFirst(const Tool& tool, const Grid& grid, double postures,
                      double* cpu_seconds = nullptr);

/// Supplies postures block by block: fills `out` from the front and returns how many it wrote;
/// 0 ends the stream. Lets 27 million postures pass through a fixed buffer.
using PostureSource = std::function<std::size_t(std::span<Posture> out)>;

/// Knobs of the fast engine that change its speed only, never a height bit (the minimum over
/// postures does not depend on their order or on which ones are culled). Defaults are the fastest
/// measured (bench/results/zbuffer-*.md); bench_zbuffer --variants times the others.
struct EngineTuning {
  bool vertical_bins = true;  ///< vertical mesh postures: bin look-up instead of the BVH walk
  /// Each block's postures processed lowest point first, where one footprint covers a quarter of
  /// the grid or more (a zoom); elsewhere the prepass gets the same culling and path order is
  /// faster (bench/results/zbuffer-h200.md, run 17).
  bool lowest_first = true;
  bool small_threads = true;   ///< CUDA: one thread per small-footprint posture, warps for the rest
  bool overlap_upload = true;  ///< CUDA: a block's upload overlaps the previous block's kernels
  bool tile_skip = true;       ///< footprint tiles whose lines the posture cannot lower skipped
  bool pinned_staging = true;  ///< CUDA: transfers through pinned buffers, host copies on all cores
  /// Postures between refreshes of the culling tiles' maxima; 0: chosen from the grid size.
  std::size_t refresh_postures = 0;
  /// Culling tiles of 2^shift × 2^shift lines, shift in [1, 8]; 8 × 8 since the group kernel
  /// (H200, run 19: case 8 400 ms vs 492 at 16 × 16, case 5 35 vs 42).
  int tile_shift = 3;
  /// Every prepass_stride-th posture of a block (in path order) cuts first, then the tile maxima
  /// are refreshed and the whole block cuts: neighbours along a path cut nearly the same heights,
  /// so the lines start near their final height and the floors (radial, capsule) and tile skips
  /// turn most of the block's line visits away at one compare. 0 or 1: no prepass. Not where the
  /// block is sorted lowest first (that order gets the same, and a zoom's few postures that
  /// cover the grid would cut it twice).
  int prepass_stride = 16;
  /// Capsule floor (ToolView::cap_*) for lines and tiles without a radial floor (tilted postures,
  /// analytic tools).
  bool capsule_floor = true;
  /// CUDA, footprints larger than a thread's, path order: a warp cuts this many consecutive
  /// postures together (8, 16 or 32), each line's height loaded and stored once for the group, its
  /// postures tried lowest floor first. 0: a warp per posture.
  int group_postures = 8;
  /// Live tile maxima: a work item that has cut every line of a tile lowers the tile's maximum to
  /// the highest height it left there, so later postures skip the tile without waiting for the
  /// next refresh (a zoom's few postures each cover the whole grid: without it they all met
  /// the stock's maxima).
  bool live_tiles = true;
};

struct SimulationRequest {
  Grid grid;
  Tool tool;
  /// Initial heights (mm), row-major ny × nx; empty → every line starts at stock_mm.
  std::vector<float> initial_heights_mm;
  float stock_mm = 0.f;
  Backend backend = Backend::Auto;
  Engine engine = Engine::Fast;
  std::size_t block_postures = std::size_t{1} << 20;  ///< postures per streamed block
  common::Progress progress;  ///< postures done / expected_postures (if known; else the caller's)
  std::size_t expected_postures = 0;
  /// On the CPU, with a progress: a block is cut in pieces of about this long (≥ 4096 postures)
  /// so that the progress moves within it; a block faster than that is cut in two calls.
  double progress_piece_s = 0.5;
  EngineTuning tuning;
};

struct SimulationResult {
  std::vector<float> heights_mm;   ///< ny × nx, row = iy
  Backend backend = Backend::Cpu;  ///< the one that ran
  std::size_t postures = 0;
  std::size_t postures_culled = 0;  ///< Fast engine: skipped by the footprint/height test
  std::size_t lines_lowered = 0;    ///< lines below their initial height at the end
  double seconds = 0;               ///< simulation proper (upload + kernels + download)
};

/// Runs the simulation over every posture of `source`. Throws common::InputError for an invalid
/// grid or tool, or Backend::Cuda without a device; common::Interrupted if progress says stop.
SimulationResult simulate(const SimulationRequest& request, const PostureSource& source);
/// Convenience: all postures from memory.
SimulationResult simulate(const SimulationRequest& request, std::span<const Posture> postures);
/// Hands the next block out without a copy: the span stays valid until the next call; an empty
/// span ends the stream.
using BlockSource = std::function<std::span<const Posture>()>;
/// Runs the simulation over the blocks of `next` (e.g. postures parsed in parallel chunks).
SimulationResult simulateBlocks(const SimulationRequest& request, const BlockSource& next);

/// Does ahead what the first simulation with `tool` on `backend` would pay for: the tool's BVH,
/// bins and floors (cached for the same tool), and with CUDA the device's context and the tool's
/// upload. A command calls it on a thread of its own while it reads its path; simulate() needs
/// nothing of it (it does what is not done yet).
void prepare(const Tool& tool, Backend backend);

/// Bytes the simulation of `grid` needs on the host (heights, initial copy, tiles, outputs).
std::size_t estimateHostBytes(const Grid& grid);
/// Throws common::InputError with the estimate if the grid cannot fit in `available_bytes`
/// (default: half the physical memory).
void checkGridFits(const Grid& grid, std::size_t available_bytes = 0);

/// The highest point of a part mesh on each line (world frame, mm), whichever way its triangles
/// face (an open sheet wound downward is the top all the same); NaN where the line misses the
/// part. With `normal_z`, also each line's |n_z| of the facet that gives its top (the cosine of
/// the part's slope there: a vertical deviation d stands d·|n_z| off that facet's plane; where
/// facets meet on a line, the flattest's); NaN where the line misses the part.
std::vector<float> partTop(const Grid& grid, std::span<const Vec3f> vertices,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           std::vector<float>* normal_z = nullptr);

/// The part's surface a line's cut is measured against, where the tool passed beneath an
/// overhang. A Z-buffer line keeps the tool's lowest point only (`cut_mm`): under an overhang that
/// point is in the air beneath it, and against the part's top it read as a cut through the
/// overhang (14.5 mm of gouge for a clear tool). Per line: `beneath` 1 where an underside of the
/// part lies above the cut (a down-facing crossing, shells wound outward as read; or any crossing
/// of an open sheet, `open[k]` for its triangles: a surface of no thickness, either winding), and
/// then `surface_mm`, the highest top (an up-facing crossing) under the lowest such underside, with
/// its facet's |n_z| in `normal_z`; NaN where there is none (a closed overhang with nothing under
/// it, or a cut through the part's bottom: the cutter's exact test tells those). Under a lone sheet
/// (nothing under it) a cut went through the sheet: `beneath` 0, measured against the top as any
/// line. Only lines cut under their top by more than `depth_mm` are looked at (anyCutUnderTop).
struct PartUnderCut {
  std::vector<float> surface_mm, normal_z;
  std::vector<std::uint8_t> beneath;
};
/// Whether any line's cut lies under its top by more than `depth_mm` (and 0.1 um): without one, no
/// line is beneath anything and `partUnderCut` need not run (a clean path's check, `depth_mm` the
/// gouge tolerance: a layer thinner than it is no layer to the check).
bool anyCutUnderTop(const std::vector<float>& top_mm, const std::vector<float>& cut_mm,
                    float depth_mm);
PartUnderCut partUnderCut(const Grid& grid, std::span<const Vec3f> vertices,
                          std::span<const std::array<std::uint32_t, 3>> triangles,
                          const std::vector<float>& top_mm, const std::vector<float>& cut_mm,
                          std::span<const std::uint8_t> open, float depth_mm);

/// Stock as the top of a part mesh (world frame, mm): the highest up-facing point on each line;
/// lines that miss the part start at its lowest z.
std::vector<float> stockFromPart(const Grid& grid, std::span<const Vec3f> vertices,
                                 std::span<const std::array<std::uint32_t, 3>> triangles);

}  // namespace fieldpath::zbuffer
