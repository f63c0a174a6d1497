/// Z-buffer benchmark: synthetic counterparts of seed 000's Table 1 cases 1-8 and seed 001's
/// Random / Spiral / Roughing / Finishing / Cutting cases (with and without zoom). Same tool kinds
/// and triangle counts, same posture counts and grids. For each case, in one run: our engine's
/// median time, the SIMSURF1-style coarse kernel's time (one work item per posture, every
/// triangle: the seeds' algorithm, the in-run peer), the published best time, the ratios, and the
/// height error of both against the exact (analytic tool) result. Prints a markdown table.
///
///   bench_zbuffer [--backend cpu|cuda] [--cases 1,2,R,...|all] [--reps N] [--peer-limit P]
///                 [--no-exact] [--variants] [--tile-shift S] [--block P]
/// --tile-shift: culling tiles of 2^S × 2^S lines instead of the default (--variants start there).
/// --block: postures per streamed block (default 2^22).
/// --variants: instead of the main table, the fast engine's median ms with each EngineTuning knob
/// turned off in turn (the same heights, bit for bit, are checked on the way).
/// --write-cases DIR: instead, writes each chosen case's postures as DIR/case<ID>.cl (shortest
/// float text, as a CAM system writes 32-bit values) and DIR/case<ID>.npy (float32, N×6), and
/// DIR/cases.txt (id, tool, region, grid per line) for bench/zbuffer/process.sh, which times
/// `fieldpath simulate` on them as a process.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "fieldpath/common/stats.h"
#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/tool_mesh.h"

namespace zb = fieldpath::zbuffer;

namespace {

/// Synthetic part surface z = S(x, y) (mm) with its gradient.
struct Surface {
  double amp1, lx, ly, amp2, l2;
  double z(double x, double y) const {
    return amp1 * std::sin(2 * std::numbers::pi * x / lx) *
               std::cos(2 * std::numbers::pi * y / ly) +
           amp2 * std::sin(2 * std::numbers::pi * (x + y) / l2);
  }
  void grad(double x, double y, double& gx, double& gy) const {
    const double w = 2 * std::numbers::pi;
    gx = amp1 * w / lx * std::cos(w * x / lx) * std::cos(w * y / ly) +
         amp2 * w / l2 * std::cos(w * (x + y) / l2);
    gy = -amp1 * w / ly * std::sin(w * x / lx) * std::sin(w * y / ly) +
         amp2 * w / l2 * std::cos(w * (x + y) / l2);
  }
};

enum class Kind { Roughing, Finish3, Finish5, Random, Spiral };

struct Case {
  std::string id, name;
  Kind kind;
  bool torus;       // torus (roughing) or sphere (ball) tool
  int around, arc;  // mesh resolution → triangle count
  double radius_mm, corner_mm, length_mm;
  std::size_t postures;
  int grid;
  double width_mm;  // square region [0, width]²
  Surface surface;
  int lines;                      // raster lines (roughing: per level)
  int levels;                     // roughing z-levels
  double zoom[4] = {0, 0, 0, 0};  // zoom region (x0, y0, x1, y1), or none
  double best_ms;                 // best published time, any device or engine
  const char* best_src;
  double
      xeon_ms;  // published CPU SIMSURF1 time (seed 000: 4-core Xeon E5-1620v3; 001: 6-core X5650)
};

/// Line-raster position of posture k of P: zigzag lines along x over the margin-inset region.
void raster(const Case& c, std::size_t k, std::size_t total, int lines, double& x, double& y,
            int& line, double& w) {
  const double m = c.radius_mm + 1;
  const double u = (k + 0.5) / double(total) * lines;
  line = std::min(lines - 1, int(u));
  w = u - line;
  const double span = c.width_mm - 2 * m;
  x = m + (line % 2 == 0 ? w : 1 - w) * span;
  y = m + (line + 0.5) / lines * span;
}

zb::Posture makePosture(const Case& c, std::size_t k) {
  const double r = c.radius_mm;
  const Surface& s = c.surface;
  double x, y, w;
  int line;
  switch (c.kind) {
    case Kind::Roughing: {
      // z-levels from the stock top down, zigzag at each level, ~8% air moves (retract + traverse)
      raster(c, k, c.postures, c.lines * c.levels, x, y, line, w);
      const int level = line / c.lines;
      const double top = std::abs(s.amp1) + std::abs(s.amp2) + 2;
      const double zl = top - (level + 1) * (2 * top - 2) / c.levels;
      if (w > 0.92) return {{float(x), float(y), float(top + 5)}, {0, 0, 1}};
      return {{float(x), float(y), float(std::max(zl, s.z(x, y) + 0.5))}, {0, 0, 1}};
    }
    case Kind::Finish3:
    case Kind::Finish5: {
      raster(c, k, c.postures, c.lines, x, y, line, w);
      double gx, gy;
      s.grad(x, y, gx, gy);
      double n[3] = {-gx, -gy, 1};
      const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      for (double& v : n) v /= nn;
      const double cx = x + r * n[0], cy = y + r * n[1], cz = s.z(x, y) + r * n[2];  // ball centre
      double a[3] = {0, 0, 1};
      if (c.kind == Kind::Finish5) {
        a[0] = n[0] + 0.25;
        a[1] = n[1] + 0.15;
        a[2] = n[2];
        const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
        for (double& v : a) v /= na;
      }
      return {{float(cx - r * a[0]), float(cy - r * a[1]), float(cz - r * a[2])},
              {float(a[0]), float(a[1]), float(a[2])}};
    }
    case Kind::Random: {
      std::mt19937_64 rng(k * 0x9e3779b97f4a7c15ull + 1);
      std::uniform_real_distribution<double> u(r + 1, c.width_mm - r - 1);
      return {{float(u(rng)), float(u(rng)), -0.05f}, {0, 0, 1}};
    }
    case Kind::Spiral: {
      const double t = (k + 0.5) / double(c.postures);
      const double turns = c.lines;
      const double rad = (c.width_mm / 2 - r - 1) * (1 - t) + 0.5 * t;
      const double th = 2 * std::numbers::pi * turns * t;
      return {{float(c.width_mm / 2 + rad * std::cos(th)),
               float(c.width_mm / 2 + rad * std::sin(th)), float(-0.02 - 0.2 * t)},
              {0, 0, 1}};
    }
  }
  return {};
}

std::vector<Case> allCases() {
  const Surface blade{6, 120, 200, 1.5, 37}, mask{15, 260, 180, 2, 61}, wave{4, 40, 55, 1, 23},
      aero{30, 1800, 1300, 5, 410}, flat{0, 1, 1, 0, 1}, cutting{0.01, 0.7, 0.9, 0, 1};
  std::vector<Case> c;
  // clang-format off
  // One case a line, in Case order: id, name, kind, torus, around, arc, R, r, L, postures, grid,
  // width, surface, lines, levels, zoom, best published ms, its source, published CPU ms.
  // seed 000 Table 1 (grid 1024², case 8: 10000²); torus 25904 = 2·127·102 - 4, sphere 12482 =
  // 2·79·79
  c.push_back({"1", "Blade roughing", Kind::Roughing, true, 127, 100, 5, 1, 25, 47837, 1024, 120, blade, 40, 6, {}, 812, "K40 Sim2", 8353});
  c.push_back({"2", "Mask roughing", Kind::Roughing, true, 127, 100, 5, 1, 25, 345848, 1024, 200, mask, 60, 12, {}, 1198, "TitanZ Sim2", 39304});
  c.push_back({"3", "Wave roughing", Kind::Roughing, true, 127, 100, 5, 1, 25, 8000000, 1024, 150, wave, 90, 20, {}, 7190, "K40 Sim2", 690700});
  c.push_back({"4", "Blade finishing (5-axis)", Kind::Finish5, false, 79, 78, 3, 3, 12, 53667, 1024, 120, blade, 120, 1, {}, 1441, "TitanZ Sim1", 10606});
  c.push_back({"5", "Wave finishing (5-axis)", Kind::Finish5, false, 79, 78, 3, 3, 12, 1000000, 1024, 150, wave, 300, 1, {}, 2960, "K40 Sim1", 59523});
  c.push_back({"6", "Mask finishing (3-axis)", Kind::Finish3, false, 79, 78, 3, 3, 12, 3015072, 1024, 200, mask, 400, 1, {}, 8984, "TitanZ Sim1", 168520});
  c.push_back({"7", "Aero finishing (3-axis)", Kind::Finish3, false, 79, 78, 5, 5, 20, 27425026, 1024, 2000, aero, 700, 1, {}, 3273, "TitanZ Sim1", 45022});
  c.push_back({"8", "Aero finishing 10000²", Kind::Finish3, false, 79, 78, 5, 5, 20, 27425026, 10000, 2000, aero, 700, 1, {}, 28190, "TitanZ Sim1", 206284});
  // seed 001 Tables 1-4 (grid 1024²; sphere 320 = 2·16·10, 1984 = 2·32·31, 36389 → 36380 =
  // 2·170·107)
  c.push_back({"R", "Random", Kind::Random, false, 16, 9, 0.5, 0.5, 2, 200000, 1024, 100, flat, 1, 1, {}, 469 / 6.2, "Q4000 coarse", 469});
  c.push_back({"S", "Spiral", Kind::Spiral, false, 32, 30, 0.5, 0.5, 2, 200000, 1024, 100, flat, 60, 1, {}, 1414 / 4.7, "Q4000 coarse", 1414});
  c.push_back({"Ro", "Roughing (= case 2)", Kind::Roughing, true, 127, 100, 5, 1, 25, 345848, 1024, 200, mask, 60, 12, {}, 37766 / 5.8, "Q4000 coarse", 37766});
  c.push_back({"F", "Finishing (sphere 1984)", Kind::Finish3, false, 32, 30, 3, 3, 12, 3015072, 1024, 200, mask, 400, 1, {}, 218203 / 5.5, "Q4000 coarse", 218203});
  c.push_back({"C", "Cutting (sphere 36380)", Kind::Finish3, false, 170, 106, 0.5, 0.5, 2, 144001, 1024, 4, cutting, 12, 1, {}, 22882 / 8.3, "Q4000 coarse", 22882});
  c.push_back({"Rz", "Random, zoom", Kind::Random, false, 16, 9, 0.5, 0.5, 2, 200000, 1024, 100, flat, 1, 1, {50, 50, 51.6, 51.6}, 195 / 1.8, "Q4000 fine", 195});
  c.push_back({"Sz", "Spiral, zoom", Kind::Spiral, false, 32, 30, 0.5, 0.5, 2, 200000, 1024, 100, flat, 60, 1, {70, 49.5, 71, 50.5}, 368 / 3.2, "Q4000 fine", 368});
  c.push_back({"Fz", "Finishing, zoom", Kind::Finish3, false, 32, 30, 3, 3, 12, 3015072, 1024, 200, mask, 400, 1, {100, 100, 100.3, 100.3}, 825, "X5650 CPU", 825});
  // clang-format on
  return c;
}

struct Run {
  double ms = 0;
  zb::SimulationResult result;
};

Run runOnce(const zb::SimulationRequest& req, std::span<const zb::Posture> postures) {
  const auto t0 = std::chrono::steady_clock::now();
  Run r;
  r.result = zb::simulate(req, postures);
  r.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

/// Postures generated before timing (in parallel), as a CL file would be read.
std::vector<zb::Posture> casePostures(const Case& c) {
  std::vector<zb::Posture> postures(c.postures);
#pragma omp parallel for schedule(static)
  for (long k = 0; k < long(c.postures); ++k) postures[k] = makePosture(c, std::size_t(k));
  return postures;
}

zb::Tool analyticTool(const Case& c) {
  return c.torus ? zb::Tool::torus(c.radius_mm, c.corner_mm, c.length_mm)
                 : zb::Tool::ball(c.radius_mm, c.length_mm);
}

int g_tile_shift = 0;                        ///< --tile-shift; 0: EngineTuning's default
std::size_t g_block = std::size_t{1} << 22;  ///< --block: postures per streamed block

zb::SimulationRequest caseRequest(const Case& c, const zb::Tool& tool, zb::Backend be) {
  zb::SimulationRequest req;
  req.grid = c.zoom[2] > c.zoom[0]
                 ? zb::Grid::fromRegion(c.zoom[0], c.zoom[1], c.zoom[2], c.zoom[3], c.grid, c.grid)
                 : zb::Grid::fromRegion(0, 0, c.width_mm, c.width_mm, c.grid, c.grid);
  req.stock_mm = float(std::abs(c.surface.amp1) + std::abs(c.surface.amp2) + 3);
  req.backend = be;
  req.tool = tool;
  req.block_postures = g_block;
  if (g_tile_shift > 0) req.tuning.tile_shift = g_tile_shift;
  return req;
}

/// Median wall time (ms) of `reps` runs after a warm-up; `last` keeps the last run's result,
/// `first_ms` the first (cold) run's time: it alone pays the tool's preparation, cached for the
/// runs after it, and the device's start. The warm-up repeats the case untimed for at least
/// 0.3 s, so that a few-millisecond case is not timed while the GPU's clocks still ramp up
/// (seen on the H100: case 1 at 3 ms or 12 ms depending on what ran before it).
double medianMs(const zb::SimulationRequest& req, std::span<const zb::Posture> postures, int reps,
                Run& last, double* first_ms = nullptr) {
  last = runOnce(req, postures);
  if (first_ms) *first_ms = last.ms;
  double warm_ms = last.ms;
  while (warm_ms < 300.0) {
    last = runOnce(req, postures);
    warm_ms += last.ms;
  }
  std::vector<double> times;
  for (int r = 0; r < reps; ++r) {
    last = runOnce(req, postures);
    times.push_back(last.ms);
  }
  return fieldpath::common::median(std::move(times));
}

/// --variants: the fast engine (mesh tool) with the default tuning, then one knob changed at a
/// time; the heights must stay the same bits.
int variantTable(const std::string& backend, const std::vector<std::string>& wanted,
                 const std::string& which, int reps) {
  const zb::Backend be = backend == "cuda" ? zb::Backend::Cuda : zb::Backend::Cpu;
  using Knob = std::function<void(zb::EngineTuning&)>;
  const std::vector<std::pair<const char*, Knob>> variants = {
      {"default", [](zb::EngineTuning&) {}},
      {"refresh 2^17", [](zb::EngineTuning& t) { t.refresh_postures = 1 << 17; }},
      {"refresh 2^19", [](zb::EngineTuning& t) { t.refresh_postures = 1 << 19; }},
      {"tiles 16²", [](zb::EngineTuning& t) { t.tile_shift = 4; }},
      {"tiles 4²", [](zb::EngineTuning& t) { t.tile_shift = 2; }},
      {"tiles 32²", [](zb::EngineTuning& t) { t.tile_shift = 5; }},
      {"no lowest first", [](zb::EngineTuning& t) { t.lowest_first = false; }},
      {"no small threads", [](zb::EngineTuning& t) { t.small_threads = false; }},
      {"no overlap", [](zb::EngineTuning& t) { t.overlap_upload = false; }},
      {"no vertical bins", [](zb::EngineTuning& t) { t.vertical_bins = false; }},
      {"no tile skip", [](zb::EngineTuning& t) { t.tile_skip = false; }},
      {"no pinned staging", [](zb::EngineTuning& t) { t.pinned_staging = false; }},
      {"prepass 4", [](zb::EngineTuning& t) { t.prepass_stride = 4; }},
      {"prepass 8", [](zb::EngineTuning& t) { t.prepass_stride = 8; }},
      {"prepass 32", [](zb::EngineTuning& t) { t.prepass_stride = 32; }},
      {"no prepass", [](zb::EngineTuning& t) { t.prepass_stride = 0; }},
      {"no capsule floor", [](zb::EngineTuning& t) { t.capsule_floor = false; }},
      {"no groups", [](zb::EngineTuning& t) { t.group_postures = 0; }},
      {"groups of 16", [](zb::EngineTuning& t) { t.group_postures = 16; }},
      {"groups of 32", [](zb::EngineTuning& t) { t.group_postures = 32; }},
      {"no live tiles", [](zb::EngineTuning& t) { t.live_tiles = false; }},
      {"all knobs off",
       [](zb::EngineTuning& t) {
         t = {false, false, false, false, false, false};
         t.prepass_stride = 0;
         t.capsule_floor = false;
         t.group_postures = 0;
         t.live_tiles = false;
       }},
  };
  bool all_same = true;  // every variant of every case the same bits; else exit 1
  std::printf("| case | P | grid |");
  for (const auto& v : variants) std::printf(" %s ms |", v.first);
  std::printf(" same bits |\n|---|---|---|");
  for (std::size_t k = 0; k <= variants.size(); ++k) std::printf("---|");
  std::printf("\n");
  for (const Case& c : allCases()) {
    if (which != "all" && std::find(wanted.begin(), wanted.end(), c.id) == wanted.end()) continue;
    const std::vector<zb::Posture> postures = casePostures(c);
    const zb::Tool mesh =
        zb::Tool::fromMesh(zb::analyticToolMesh(analyticTool(c), c.around, c.arc));
    std::printf("| %s %s | %zu | %d² |", c.id.c_str(), c.name.c_str(), c.postures, c.grid);
    std::vector<float> first;
    bool same = true;
    for (const auto& v : variants) {
      zb::SimulationRequest req = caseRequest(c, mesh, be);
      v.second(req.tuning);
      Run run;
      std::printf(" %.1f |", medianMs(req, postures, reps, run));
      std::fflush(stdout);
      if (first.empty()) first = run.result.heights_mm;
      same = same && std::memcmp(first.data(), run.result.heights_mm.data(), 4 * first.size()) == 0;
    }
    std::printf(" %s |\n", same ? "yes" : "NO");
    all_same = all_same && same;
    std::fflush(stdout);
  }
  if (!all_same) std::fprintf(stderr, "bench_zbuffer: a variant changed the heights (NO above)\n");
  return all_same ? 0 : 1;
}

/// Max and RMS |Δz| (mm) against the exact heights over the lines both runs lowered, and the
/// number of lines only one of them lowered (grazing lines at the chordal error of the mesh).
std::string heightError(const std::vector<float>& h, const std::vector<float>& exact, float stock) {
  double max_mm = 0, sum = 0;
  std::size_t n = 0, one_sided = 0;
  for (std::size_t i = 0; i < h.size(); ++i) {
    const bool a = h[i] < stock, b = exact[i] < stock;
    one_sided += a != b;
    if (!a || !b) continue;
    const double d = std::abs(double(h[i]) - exact[i]);
    max_mm = std::max(max_mm, d);
    sum += d * d;
    ++n;
  }
  char text[96];
  std::snprintf(text, sizeof text, "%.2f / %.3f (%zu)", max_mm * 1e3,
                n ? std::sqrt(sum / n) * 1e3 : 0.0, one_sided);
  return text;
}

/// One case's postures as `STEM.cl` (shortest float text, as a CAM system writes 32-bit values)
/// and `STEM.npy` (float32, N×6).
void writeCaseFiles(const std::string& stem, const std::vector<zb::Posture>& postures) {
  {
    std::ofstream cl(stem + ".cl", std::ios::binary);
    std::string text;
    char buffer[32];
    for (const zb::Posture& p : postures) {
      const float v[6] = {p.tip_mm.x, p.tip_mm.y, p.tip_mm.z, p.axis.x, p.axis.y, p.axis.z};
      for (int k = 0; k < 6; ++k) {
        text.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, v[k]).ptr);
        text += k < 5 ? ' ' : '\n';
      }
      if (text.size() > (1u << 24)) {
        cl << text;
        text.clear();
      }
    }
    cl << text;
  }
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (" +
                       std::to_string(postures.size()) + ", 6), }";
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::ofstream npy(stem + ".npy", std::ios::binary);
  npy.write("\x93NUMPY\x01\x00", 8);
  const char size[2] = {char(header.size() & 0xff), char(header.size() >> 8)};
  npy.write(size, 2);
  npy << header;
  std::vector<float> rows;  // x y z i j k (the spindle angle, 0 in these cases, left out)
  rows.reserve(postures.size() * 6);
  for (const zb::Posture& p : postures)
    rows.insert(rows.end(), {p.tip_mm.x, p.tip_mm.y, p.tip_mm.z, p.axis.x, p.axis.y, p.axis.z});
  npy.write(reinterpret_cast<const char*>(rows.data()),
            std::streamsize(rows.size() * sizeof(float)));
  std::fprintf(stderr, "wrote %s.cl and %s.npy (%zu postures)\n", stem.c_str(), stem.c_str(),
               postures.size());
}

/// --write-cases: the postures of the chosen cases as `.cl` and `.npy` files, and cases.txt.
int writeCases(const std::string& dir, const std::vector<std::string>& wanted,
               const std::string& which) {
  std::filesystem::create_directories(dir);
  std::ofstream list(dir + "/cases.txt");
  list << "# id tool region(x0,y0,x1,y1 mm) grid postures stock(mm) file\n";
  std::map<std::string, std::string> written;  // a path's key → the file stem that holds it
  for (const Case& c : allCases()) {
    if (which != "all" && std::find(wanted.begin(), wanted.end(), c.id) == wanted.end()) continue;
    if (c.zoom[2] > c.zoom[0]) continue;  // zooms: the same paths as their unzoomed cases
    // cases that differ only in the grid (7 and 8) share one pair of files
    const std::string key = c.name.substr(0, c.name.find(' ')) + std::to_string(c.postures) +
                            "/" + std::to_string(c.width_mm);
    const bool fresh = !written.count(key);
    const std::string stem = fresh ? "case" + c.id : written[key];
    written.emplace(key, stem);
    const std::string tool = c.torus ? "torus:" + std::to_string(c.radius_mm) + ":" +
                                           std::to_string(c.corner_mm) + ":" +
                                           std::to_string(c.length_mm)
                                     : "ball:" + std::to_string(c.radius_mm) + ":" +
                                           std::to_string(c.length_mm);
    list << c.id << ' ' << tool << " 0,0," << c.width_mm << ',' << c.width_mm << ' ' << c.grid
         << 'x' << c.grid << ' ' << c.postures << ' '
         << std::abs(c.surface.amp1) + std::abs(c.surface.amp2) + 3 << ' ' << stem << '\n';
    if (!fresh) continue;
    writeCaseFiles(dir + "/" + stem, casePostures(c));
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  std::string backend = zb::cudaAvailable() ? "cuda" : "cpu", which = "all";
  int reps = 3;
  std::size_t peer_limit = 0;  // 0: the whole case
  bool exact = true;
  bool variants = false;  // time the fast engine with each tuning knob off instead of the table
  std::string write_dir;  // --write-cases: write the cases' path files instead
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const auto value = [&] { return i + 1 < argc ? std::string(argv[++i]) : std::string(); };
    if (a == "--backend")
      backend = value();
    else if (a == "--cases")
      which = value();
    else if (a == "--reps")
      reps = std::max(1, std::stoi(value()));
    else if (a == "--peer-limit")
      peer_limit = std::stoull(value());
    else if (a == "--no-exact")
      exact = false;
    else if (a == "--tile-shift")
      g_tile_shift = std::stoi(value());
    else if (a == "--block")
      g_block = std::stoul(value());
    else if (a == "--variants")
      variants = true;
    else if (a == "--write-cases")
      write_dir = value();
    else {
      std::fprintf(stderr,
                   "usage: %s [--backend cpu|cuda] [--cases 1,2,R,...|all] [--reps N] "
                   "[--peer-limit P] [--no-exact] [--variants] [--tile-shift S] [--block P] "
                   "[--write-cases DIR]\n",
                   argv[0]);
      return 1;
    }
  }
  const zb::Backend be = backend == "cuda" ? zb::Backend::Cuda : zb::Backend::Cpu;
  std::vector<std::string> wanted;
  for (std::size_t p = 0; p <= which.size();) {
    const std::size_t q = std::min(which.find(',', p), which.size());
    wanted.push_back(which.substr(p, q - p));
    p = q + 1;
  }
  if (!write_dir.empty()) return writeCases(write_dir, wanted, which);
  if (variants) return variantTable(backend, wanted, which, reps);
  std::printf(
      "| case | P | T | grid | ours ms (median of %d) | coarse peer ms | best published ms | "
      "best/ours | peer/ours | "
      "CPU Sim1 ms | Sim1/ours | culled | lines touched | |Δz| ours µm: max / rms (one-sided "
      "lines) | |Δz| peer µm | "
      "analytic tool ms | ours, first run ms |\n",
      reps);
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  std::fflush(stdout);
  for (const Case& c : allCases()) {
    if (which != "all" && std::find(wanted.begin(), wanted.end(), c.id) == wanted.end()) continue;
    const std::vector<zb::Posture> postures = casePostures(c);
    const zb::Tool analytic = analyticTool(c);
    const zb::Tool mesh = zb::Tool::fromMesh(zb::analyticToolMesh(analytic, c.around, c.arc));
    const zb::SimulationRequest req = caseRequest(c, mesh, be);
    Run ours;
    double first_ms = 0;
    const double ours_ms = medianMs(req, postures, reps, ours, &first_ms);

    // the peer: SIMSURF1's coarse algorithm, same backend, same mesh
    zb::SimulationRequest peer_req = req;
    peer_req.engine = zb::Engine::Coarse;
    const std::size_t peer_n = peer_limit ? std::min(peer_limit, postures.size()) : postures.size();
    // a limited peer runs an evenly spread subset and is scaled to the whole case
    std::vector<zb::Posture> subset;
    std::span<const zb::Posture> peer_postures = postures;
    if (peer_n < postures.size()) {
      for (std::size_t k = 0; k < peer_n; ++k)
        subset.push_back(postures[k * postures.size() / peer_n]);
      peer_postures = subset;
    }
    const Run peer = runOnce(peer_req, peer_postures);
    const double peer_ms = peer.ms * double(postures.size()) / double(peer_n);
    const bool peer_full = peer_n == postures.size();

    std::string err_ours = "-", err_peer = "-";
    double exact_ms = 0;
    if (exact) {
      zb::SimulationRequest ex = req;
      ex.tool = analytic;
      const Run exact_run = runOnce(ex, postures);
      exact_ms = exact_run.ms;
      err_ours = heightError(ours.result.heights_mm, exact_run.result.heights_mm, req.stock_mm);
      if (peer_full)
        err_peer = heightError(peer.result.heights_mm, exact_run.result.heights_mm, req.stock_mm);
    }
    std::printf(
        "| %s %s | %zu | %zu | %d² | %.1f | %s%.1f | %.0f (%s) | %.1f× | %.1f× | %.0f | %.1f× | "
        "%.1f%% | %zu | %s | %s | %.1f | %.1f |\n",
        c.id.c_str(), c.name.c_str(), c.postures, mesh.mesh.triangles.size(), c.grid, ours_ms,
        peer_full ? "" : "~", peer_ms, c.best_ms, c.best_src, c.best_ms / ours_ms,
        peer_ms / ours_ms, c.xeon_ms, c.xeon_ms / ours_ms,
        100.0 * double(ours.result.postures_culled) / double(c.postures), ours.result.lines_lowered,
        err_ours.c_str(), err_peer.c_str(), exact_ms, first_ms);
    std::fflush(stdout);
  }
  std::printf(
      "\nours: fast engine (lines under the tool through a BVH of the mesh in the tool frame, "
      "culling); "
      "peer: coarse engine (every triangle of every posture), same backend%s; "
      "|Δz|: against the analytic tool (exact envelope, also timed in the last column), over lines "
      "both "
      "runs lowered, with the count of lines only one lowered; "
      "'~': peer timed on an evenly spread subset of %zu postures and scaled to the case; "
      "first run: the first (cold) run, the only one that builds the tool's BVH, bins and "
      "radial floors (cached for the same tool after it); the timed runs follow an untimed warm-up "
      "of at least 0.3 s.\n",
      backend == "cuda" ? " (CUDA)" : " (CPU, OpenMP)", peer_limit);
  return 0;
}
