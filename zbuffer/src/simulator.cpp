#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/engine.h"

#include <unistd.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <mutex>
#include <sstream>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/common/short_number.h"

namespace fieldpath::zbuffer {

using common::InputError;

Grid Grid::fromRegion(double x0_mm, double y0_mm, double x1_mm, double y1_mm, int nx, int ny) {
  if (!std::isfinite(x0_mm) || !std::isfinite(y0_mm) || !std::isfinite(x1_mm) ||
      !std::isfinite(y1_mm))
    throw InputError("region: non-finite coordinate");
  for (const double v : {x0_mm, y0_mm, x1_mm, y1_mm})
    if (std::abs(v) > common::kMaxCoordinateMm)
      throw InputError("region: coordinate " + common::shortNumber(v) +
                       " mm is beyond +-1e6 mm (outside any machine)");
  if (!(x1_mm > x0_mm) || !(y1_mm > y0_mm))
    throw InputError("region: zero or negative area (need x0 < x1 and y0 < y1)");
  if (nx <= 0 || ny <= 0)
    throw InputError("grid: " + std::to_string(nx) + "x" + std::to_string(ny) +
                     " has no lines (need >= 1 in each direction)");
  Grid g;
  g.x0_mm = x0_mm;
  g.y0_mm = y0_mm;
  g.nx = nx;
  g.ny = ny;
  g.dx_mm = (x1_mm - x0_mm) / nx;
  g.dy_mm = (y1_mm - y0_mm) / ny;
  // A spacing that rounds to nothing next to the origin would stack lines on one another.
  const double tiny =
      1e-12 * std::max({1.0, std::abs(x0_mm), std::abs(y0_mm), std::abs(x1_mm), std::abs(y1_mm)});
  if (!(g.dx_mm > tiny) || !(g.dy_mm > tiny) || !std::isfinite(g.dx_mm) || !std::isfinite(g.dy_mm))
    throw InputError("region: degenerate grid spacing " + common::shortNumber(g.dx_mm) + " x " +
                     common::shortNumber(g.dy_mm) + " mm");
  return g;
}

namespace {
void requireDims(bool ok, const char* what) {
  if (!ok) throw InputError(std::string("tool: ") + what);
}
}  // namespace

Tool Tool::ball(double radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "ball radius must be finite and > 0");
  requireDims(std::isfinite(length_mm) && length_mm >= radius_mm,
              "length must be >= the ball radius");
  return Tool{ToolKind::Ball, float(radius_mm), float(radius_mm), float(length_mm), {}};
}
Tool Tool::torus(double radius_mm, double corner_radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "torus radius must be finite and > 0");
  requireDims(
      std::isfinite(corner_radius_mm) && corner_radius_mm > 0 && corner_radius_mm <= radius_mm,
      "torus corner radius must be in (0, R]");
  requireDims(std::isfinite(length_mm) && length_mm >= corner_radius_mm,
              "length must be >= the corner radius");
  return Tool{ToolKind::Torus, float(radius_mm), float(corner_radius_mm), float(length_mm), {}};
}
Tool Tool::flat(double radius_mm, double length_mm) {
  requireDims(std::isfinite(radius_mm) && radius_mm > 0, "flat radius must be finite and > 0");
  requireDims(std::isfinite(length_mm) && length_mm > 0, "length must be > 0");
  return Tool{ToolKind::Flat, float(radius_mm), 0.f, float(length_mm), {}};
}
Tool Tool::fromMesh(ToolMesh mesh) {
  requireDims(!mesh.triangles.empty(), "mesh has no triangles");
  for (const auto& v : mesh.vertices)
    requireDims(std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z),
                "mesh has a non-finite vertex");
  for (const auto& t : mesh.triangles)
    for (auto i : t) requireDims(i < mesh.vertices.size(), "mesh triangle index out of range");
  Tool tool;
  tool.kind = ToolKind::Mesh;
  tool.mesh = std::move(mesh);
  return tool;
}

void limitCpuThreads(int threads) { omp_set_num_threads(std::max(1, threads)); }

const char* backendName(Backend backend) {
  switch (backend) {
    case Backend::Auto:
      return "auto";
    case Backend::Cpu:
      return "cpu";
    case Backend::Cuda:
      return "cuda";
  }
  return "?";
}

Backend backendFromName(const std::string& name, const std::string& key) {
  for (Backend b : {Backend::Auto, Backend::Cpu, Backend::Cuda})
    if (name == backendName(b)) return b;
  throw InputError(key + " '" + name + "': expected auto, cpu or cuda");
}

namespace detail {

GridView makeGridView(const Grid& grid, int tile_shift) {
  GridView g;
  g.x0_mm = grid.x0_mm;
  g.y0_mm = grid.y0_mm;
  g.dx_mm = grid.dx_mm;
  g.dy_mm = grid.dy_mm;
  g.nx = grid.nx;
  g.ny = grid.ny;
  g.tile_shift = tile_shift;
  g.tiles_x = (grid.nx + (1 << tile_shift) - 1) >> tile_shift;
  g.tiles_y = (grid.ny + (1 << tile_shift) - 1) >> tile_shift;
  return g;
}

}  // namespace detail

std::size_t estimateHostBytes(const Grid& grid) {
  // Heights + initial copy (float each), culling tiles and the outputs (STL/PNG are decimated):
  // simulate's peak grew 16.7 B a line from 2048² to 4096² lines and held 6 MiB beyond the
  // lines and the program at 1024² (the program's own memory is held apart: 64 MiB were
  // assumed here before it was, which refused check's grids under limits they kept).
  const double lines = double(grid.nx) * double(grid.ny);
  return static_cast<std::size_t>(std::min(lines * 20.0 + 16.0 * 1024 * 1024, 1e19));
}

void checkGridFits(const Grid& grid, std::size_t available_bytes) {
  // --max-memory less what the run holds (its meshes, field, postures), else the memory available.
  const bool given = available_bytes != 0;
  if (!given) available_bytes = std::size_t(common::memoryLeftBytes());
  const std::size_t need = estimateHostBytes(grid);
  if (need > available_bytes || grid.lineCount() > (std::size_t{1} << 31)) {
    std::ostringstream os;
    os << "grid " << grid.nx << "x" << grid.ny << " is too large: it needs about "
       << common::formatBytes(double(need)) << " of memory, "
       << common::formatBytes(double(available_bytes)) << " available (and at most 2^31 lines"
       << (given ? std::string("; --max-memory)") : ")" + common::memoryLimitText());
    throw InputError(os.str());
  }
}

namespace {

/// A facet's |n_z| (the cosine of its slope), in double: a sliver's cross product loses floats.
float facetCosSlope(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  const double ux = double(b.x) - a.x, uy = double(b.y) - a.y, uz = double(b.z) - a.z;
  const double vx = double(c.x) - a.x, vy = double(c.y) - a.y, vz = double(c.z) - a.z;
  const double nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
  const double length = std::sqrt(nx * nx + ny * ny + nz * nz);
  return length > 0.0 ? static_cast<float>(std::abs(nz) / length) : 0.f;
}

}  // namespace

std::vector<float> partTop(const Grid& grid, std::span<const Vec3f> vertices,
                           std::span<const std::array<std::uint32_t, 3>> triangles,
                           std::vector<float>* normal_z) {
  if (triangles.empty()) throw InputError("part: mesh has no triangles");
  const GridView g = detail::makeGridView(grid);
  std::vector<float> top(grid.lineCount(), -FLT_MAX);
  if (normal_z) normal_z->assign(grid.lineCount(), std::numeric_limits<float>::quiet_NaN());
  for (const auto& t : triangles) {
    if (t[0] >= vertices.size() || t[1] >= vertices.size() || t[2] >= vertices.size())
      throw InputError("part: triangle index out of range");
    const Vec3f a = vertices[t[0]], b = vertices[t[1]], c = vertices[t[2]];
    const float nz = normal_z ? facetCosSlope(a, b, c) : 0.f;
    // Either way round: an open sheet wound downward (as CAD exports of surfaces often are)
    // is still the part's top; on a closed solid the highest crossing faces up anyway.
    for (const float sign : {1.f, -1.f})
      rasterTriangle(g, a, b, c, sign, [&](int ix, int iy, float z) {
        const std::size_t i = std::size_t(iy) * grid.nx + ix;
        float& h = top[i];
        if (normal_z) {
          // Two facets meeting on a line give its height a few ulps apart (each interpolates
          // its own plane): within 4 ulps they tie, and the flattest facet's |n_z| counts.
          const float tie = 4.f * FLT_EPSILON * std::max(1.f, std::abs(z));
          float& n = (*normal_z)[i];
          if (z > h + tie || std::isnan(n))
            n = nz;
          else if (z >= h - tie)
            n = std::max(n, nz);
        }
        h = std::max(h, z);
      });
  }
  for (auto& h : top)
    if (h == -FLT_MAX) h = std::numeric_limits<float>::quiet_NaN();
  return top;
}

namespace {

/// Two crossings closer than this are one surface (facets meeting on a line interpolate its
/// height a few ulps apart; a layer thinner than 0.1 um is no layer).
float crossingTie(float z) { return std::max(1e-4f, 4.f * FLT_EPSILON * std::abs(z)); }

/// A line whose cut lies under its top by more than `depth_mm`: only such a line can have the
/// part above its cut (a layer thinner than that is no layer to the check).
bool cutUnderTop(float top_mm, float cut_mm, float depth_mm) {
  return !std::isnan(top_mm) && cut_mm < top_mm - std::max(depth_mm, crossingTie(top_mm));
}

}  // namespace

bool anyCutUnderTop(const std::vector<float>& top_mm, const std::vector<float>& cut_mm,
                    float depth_mm) {
  for (std::size_t i = 0; i < top_mm.size() && i < cut_mm.size(); ++i)
    if (cutUnderTop(top_mm[i], cut_mm[i], depth_mm)) return true;
  return false;
}

PartUnderCut partUnderCut(const Grid& grid, std::span<const Vec3f> vertices,
                          std::span<const std::array<std::uint32_t, 3>> triangles,
                          const std::vector<float>& top_mm, const std::vector<float>& cut_mm,
                          std::span<const std::uint8_t> open, float depth_mm) {
  const GridView g = detail::makeGridView(grid);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  PartUnderCut out;
  out.surface_mm.assign(grid.lineCount(), nan);
  out.normal_z.assign(grid.lineCount(), nan);
  out.beneath.assign(grid.lineCount(), 0);
  // Only lines cut under their top can be beneath anything (on a clean path: none, gouges only):
  // the part's facets are rasterised over the box of those lines alone, or not at all.
  std::vector<std::uint8_t> under(grid.lineCount(), 0);
  int ix0 = grid.nx, ix1 = -1, iy0 = grid.ny, iy1 = -1;
  for (std::size_t i = 0; i < under.size(); ++i) {
    if (!(under[i] = cutUnderTop(top_mm[i], cut_mm[i], depth_mm))) continue;
    const int ix = int(i % grid.nx), iy = int(i / grid.nx);
    ix0 = std::min(ix0, ix), ix1 = std::max(ix1, ix), iy0 = std::min(iy0, iy),
    iy1 = std::max(iy1, iy);
  }
  if (ix1 < 0) return out;
  // The candidates' box in mm, a line wider each way than the rasteriser's reach.
  const float bx0 = float(grid.x0_mm + (ix0 - 1) * grid.dx_mm);
  const float bx1 = float(grid.x0_mm + (ix1 + 2) * grid.dx_mm);
  const float by0 = float(grid.y0_mm + (iy0 - 1) * grid.dy_mm);
  const float by1 = float(grid.y0_mm + (iy1 + 2) * grid.dy_mm);
  // A closed shell's facets face out: up-facing ones rasterise with sign +1 (a layer's top),
  // down-facing ones with −1 (an underside); rasterTriangle keeps those whose projection turns
  // the sign's way. An open sheet's winding says nothing: both, a layer of no thickness.
  const auto each = [&](auto&& visit) {
    for (std::size_t k = 0; k < triangles.size(); ++k) {
      const auto& t = triangles[k];
      const Vec3f a = vertices[t[0]], b = vertices[t[1]], c = vertices[t[2]];
      if (std::max({a.x, b.x, c.x}) < bx0 || std::min({a.x, b.x, c.x}) > bx1 ||
          std::max({a.y, b.y, c.y}) < by0 || std::min({a.y, b.y, c.y}) > by1)
        continue;
      const float cos_slope = facetCosSlope(a, b, c);
      const bool sheet = k < open.size() && open[k];
      for (const float sign : {1.f, -1.f})
        rasterTriangle(g, a, b, c, sign, [&](int ix, int iy, float z) {
          const std::size_t i = std::size_t(iy) * grid.nx + ix;
          if (under[i]) visit(i, z, sign > 0, sheet || sign < 0, cos_slope);
        });
    }
  };
  // The lowest underside above the line's cut: the tool's lowest point is beneath it.
  std::vector<float> roof(grid.lineCount(), HUGE_VALF);
  each([&](std::size_t i, float z, bool, bool underside, float) {
    if (underside && z > cut_mm[i] + crossingTie(cut_mm[i])) roof[i] = std::min(roof[i], z);
  });
  // The surface measured: the highest top under that roof (the top itself without one).
  each([&](std::size_t i, float z, bool top, bool, float cos_slope) {
    if (!top || !(z < roof[i] - crossingTie(roof[i]))) return;
    float& s = out.surface_mm[i];
    if (std::isnan(s) || z > s) {
      s = z;
      out.normal_z[i] = cos_slope;
    } else if (z == s) {
      out.normal_z[i] = std::max(out.normal_z[i], cos_slope);
    }
  });
  for (std::size_t i = 0; i < roof.size(); ++i) {
    if (!under[i] || roof[i] == HUGE_VALF) continue;  // not cut under its top; under no roof
    // Nothing under a roof that is the top itself: a lone sheet, which the cut went through.
    if (std::isnan(out.surface_mm[i]) && roof[i] >= top_mm[i] - crossingTie(top_mm[i])) continue;
    out.beneath[i] = 1;
  }
  return out;
}

std::vector<float> stockFromPart(const Grid& grid, std::span<const Vec3f> vertices,
                                 std::span<const std::array<std::uint32_t, 3>> triangles) {
  std::vector<float> top = partTop(grid, vertices, triangles);
  float zmin = FLT_MAX;
  for (const auto& v : vertices) zmin = std::min(zmin, v.z);
  for (auto& h : top)
    if (std::isnan(h)) h = zmin;
  return top;
}

namespace {

bool sameTool(const Tool& a, const Tool& b) {
  const auto bytesEqual = [](const auto& x, const auto& y) {
    return x.size() == y.size() &&
           (x.empty() || std::memcmp(x.data(), y.data(), x.size() * sizeof(x[0])) == 0);
  };
  return a.kind == b.kind && a.radius_mm == b.radius_mm &&
         a.corner_radius_mm == b.corner_radius_mm && a.length_mm == b.length_mm &&
         bytesEqual(a.mesh.vertices, b.mesh.vertices) &&
         bytesEqual(a.mesh.triangles, b.mesh.triangles);
}

/// prepareTool with a one-entry cache: a mesh tool's BVH, bins and radial floors (several ms for
/// 25 000 triangles) are built once for a run of simulations with the same tool (compared bit
/// for bit, a fraction of a millisecond).
std::shared_ptr<const detail::ToolData> preparedTool(const Tool& tool) {
  static std::mutex mutex;
  static Tool cached_tool;
  static std::shared_ptr<const detail::ToolData> cached;
  {
    std::lock_guard lock(mutex);
    if (cached && sameTool(cached_tool, tool)) return cached;
  }
  auto data = std::make_shared<detail::ToolData>(detail::prepareTool(tool));
  data->pointViewAtVectors();
  std::lock_guard lock(mutex);
  cached_tool = tool;
  cached = data;
  return data;
}

/// Runs the blocks that `next` hands out (an empty span ends), without copying them;
/// `expected_postures` (0: unknown) scales the progress.
template <class NextBlock>
SimulationResult run(const SimulationRequest& request, std::size_t expected_postures,
                     NextBlock next) {
  const Grid& grid = request.grid;
  if (grid.nx <= 0 || grid.ny <= 0) throw InputError("grid: no lines");
  Backend backend = request.backend;
  if (backend == Backend::Auto) backend = cudaAvailable() ? Backend::Cuda : Backend::Cpu;
  if (backend == Backend::Cuda && !cudaAvailable())
    throw InputError("backend cuda: no CUDA device available (built without CUDA or no GPU)");
  if (backend == Backend::Cuda) common::requireCudaContext();  // before the grid, with it
  checkGridFits(grid);
  if (!request.initial_heights_mm.empty() && request.initial_heights_mm.size() != grid.lineCount())
    throw InputError("initial heights: size does not match the grid");
  // A NaN line would differ by backend: never lowered on the CPU (x < NaN is false), lowered on
  // the GPU (NaN's ordered key is the largest); an infinite one has no stock to cut.
  for (const float h : request.initial_heights_mm)
    if (!std::isfinite(h)) throw InputError("initial heights: a line is not a finite number");
  if (request.engine == Engine::Coarse && request.tool.kind != ToolKind::Mesh)
    throw InputError("the coarse engine needs a mesh tool");

  const auto entered = std::chrono::steady_clock::now();
  const int shift = request.tuning.tile_shift;
  if (shift < 1 || shift > 8) throw InputError("tuning: tile_shift must be in [1, 8]");
  if (request.tuning.prepass_stride < 0)
    throw InputError("tuning: prepass_stride must be 0 (off) or positive");
  if (request.tuning.group_postures != 0 && request.tuning.group_postures != 8 &&
      request.tuning.group_postures != 16 && request.tuning.group_postures != 32)
    throw InputError("tuning: group_postures must be 0 (off), 8, 16 or 32");
  detail::EngineSetup setup;
  setup.grid = detail::makeGridView(grid, shift);
  setup.tool = preparedTool(request.tool);  // shared, never copied: the view points into it
  setup.view = setup.tool->view;
  if (!request.tuning.vertical_bins) setup.view.bins = 0;
  if (!request.tuning.capsule_floor) setup.view.cap_radius_mm = 0.f;
  setup.heights_mm = request.initial_heights_mm;  // empty: every line at the stock
  setup.stock_mm = request.stock_mm;
  setup.tuning = request.tuning;
  // Lowest first pays where one footprint covers a quarter of the grid or more (a zoom: the first
  // cut of a line is then nearly its last); elsewhere the prepass does that and path order keeps
  // the neighbours of a path together (bench/results/zbuffer-h200.md, runs 13-22: path order vs
  // sorted, case 3 105 vs 119 ms, case 8 859 vs 1014, C (a footprint is 1/16 of its grid) 25 vs
  // 177; zooms sorted vs path order: Fz 64 vs 415, Rz 13 vs 30).
  const double span_x = 2.0 * setup.view.hull_radius_mm / grid.dx_mm + 1.0,
               span_y = 2.0 * setup.view.hull_radius_mm / grid.dy_mm + 1.0;
  setup.tuning.lowest_first =
      request.tuning.lowest_first && span_x * span_y * 4.0 > double(grid.lineCount());

  const auto start = std::chrono::steady_clock::now();
  std::unique_ptr<detail::BackendEngine> engine =
      backend == Backend::Cuda ? detail::makeCudaEngine(setup) : detail::makeCpuEngine(setup);
  SimulationResult result;
  result.backend = backend;
  for (;;) {
    const std::span<const Posture> block = next();
    if (block.empty()) break;
    // On the CPU, with a progress to tell, in pieces of about progress_piece_s, measured on a
    // first piece of 4096 postures: the progress moves within a block too (the result does not
    // depend on the order or grouping of the postures), and a fast block pays one call more
    // only (each call costs ~12 ms on a 1024² zoom: 20 fixed pieces took the zoomed random
    // case from 150 to 390 ms). Not on the GPU: a block is cut there in a fraction of a second,
    // and each piece costs an upload and a synchronisation (20 pieces: 11 → 107 ms on the H200).
    const bool in_pieces = request.progress && backend == Backend::Cpu;
    std::size_t piece = in_pieces ? std::size_t{4096} : block.size();
    for (std::size_t at = 0; at < block.size();) {
      const std::span<const Posture> part = block.subspan(at, std::min(piece, block.size() - at));
      const auto cut_start = std::chrono::steady_clock::now();
      engine->cut(part, request.engine);
      const double cut_s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - cut_start).count();
      at += part.size();
      result.postures += part.size();
      if (in_pieces) {  // the next piece from this one's rate
        const double per_posture_s = cut_s / double(part.size());
        const double wanted =
            per_posture_s > 0.0 ? request.progress_piece_s / per_posture_s : double(block.size());
        piece = static_cast<std::size_t>(std::clamp(
            wanted, 4096.0, static_cast<double>(std::max<std::size_t>(block.size(), 1))));
      }
      // Unknown (0): the source reports (its share of a file read); postures done over postures
      // done read 100 % after the first block of a 3 M-posture file, and minutes of cutting
      // went on.
      if (expected_postures > 0)
        common::report(
            request.progress,
            double(result.postures) / double(std::max(expected_postures, result.postures)),
            "simulate");
    }
  }
  const auto cut_done = std::chrono::steady_clock::now();
  result.heights_mm = engine->heights();
  result.postures_culled = engine->culled();
  const auto read = std::chrono::steady_clock::now();
  result.seconds = std::chrono::duration<double>(read - start).count();
  const float* h = result.heights_mm.data();
  const float* initial =
      request.initial_heights_mm.empty() ? nullptr : request.initial_heights_mm.data();
  const float stock = request.stock_mm;
  const long lines = static_cast<long>(result.heights_mm.size());
  std::size_t lowered = 0;
#pragma omp parallel for schedule(static) reduction(+ : lowered) if (lines > (1 << 20))
  for (long i = 0; i < lines; ++i) lowered += h[i] < (initial ? initial[i] : stock);
  result.lines_lowered = lowered;
  if (std::getenv("FIELDPATH_ZB_TRACE")) {  // benchmarks: where the host's time goes
    const auto ms = [](auto a, auto b) {
      return std::chrono::duration<double, std::milli>(b - a).count();
    };
    std::fprintf(stderr,
                 "trace: host: set-up %.2f ms, engine + cut calls %.2f, heights %.2f, count %.2f\n",
                 ms(entered, start), ms(start, cut_done), ms(cut_done, read),
                 ms(read, std::chrono::steady_clock::now()));
  }
  common::report(request.progress, 1.0, "simulate");
  return result;
}

}  // namespace

SimulationResult simulate(const SimulationRequest& request, const PostureSource& source) {
  std::vector<Posture> buffer(std::max<std::size_t>(1, request.block_postures));
  return run(request, request.expected_postures, [&] {
    const std::size_t n = std::min(source(std::span<Posture>(buffer)), buffer.size());
    return std::span<const Posture>(buffer.data(), n);
  });
}

SimulationResult simulateBlocks(const SimulationRequest& request, const BlockSource& next) {
  return run(request, request.expected_postures, [&] { return next(); });
}

void prepare(const Tool& tool, Backend backend) {
  const std::shared_ptr<const detail::ToolData> data = preparedTool(tool);
  if (backend != Backend::Cpu && cudaAvailable()) {
    common::requireCudaContext();  // before the context is made
    detail::warmUpCuda(*data);
  }
}

SimulationResult simulate(const SimulationRequest& request, std::span<const Posture> postures) {
  const std::size_t block = std::max<std::size_t>(1, request.block_postures);
  std::size_t next = 0;
  // no copy of the request (its tool mesh and initial heights) to fill in the expected count
  const std::size_t expected =
      request.expected_postures ? request.expected_postures : postures.size();
  return run(request, expected, [&] {
    const std::size_t n = std::min(block, postures.size() - next);
    const auto out = postures.subspan(next, n);
    next += n;
    return out;
  });
}

bool cpuFinishesFirst(const Tool& tool, const Grid& grid, double postures, double* cpu_seconds) {
  constexpr double kGpuStartSeconds = 0.25;           // driver + context, before the first cut
  constexpr double kLineVisitsPerCoreSecond = 5e7;    // the CPU engine, ball R 3 at 1024²
  const double reach_mm = toolReach(tool);
  const double footprint_lines =
      std::min(double(grid.lineCount()),
               3.14159 * (reach_mm / grid.dx_mm + 1.0) * (reach_mm / grid.dy_mm + 1.0));
  const double cores = std::max(1, omp_get_max_threads());  // the process's CPUs (affinity)
  const double seconds = postures * footprint_lines / (kLineVisitsPerCoreSecond * cores);
  if (cpu_seconds) *cpu_seconds = seconds;
  return seconds < kGpuStartSeconds;
}

double toolReach(const Tool& tool) {
  if (tool.kind != ToolKind::Mesh) return tool.radius_mm;
  double reach = 0;
  for (const auto& p : tool.mesh.vertices)
    reach = std::max(reach, std::sqrt(double(p.x) * p.x + double(p.y) * p.y));
  return reach;
}

double toolExtent(const Tool& tool) {
  if (tool.kind != ToolKind::Mesh)
    return std::hypot(double(tool.length_mm), double(tool.radius_mm));
  double extent = 0;
  for (const auto& p : tool.mesh.vertices)
    extent = std::max(extent, std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z));
  return extent;
}

}  // namespace fieldpath::zbuffer
