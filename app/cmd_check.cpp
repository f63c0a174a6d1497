/// `fieldpath check SCENE --path FILE.cl [--out DIR]`: (a) exact clearance of tool + holder
/// against the obstacles (FCL) at every posture; (b) the Z-buffer simulation of the path over the
/// hub compared with the nominal hub heights: gouge (below) and scallop (above), deviation.png.
/// Exit 0 even when collisions are found (they are reported); 1 on bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/zbuffer/outputs.h"
#include "fieldpath/zbuffer/simulator.h"
#include "impeller_job.h"
#include "progress.h"
#include "scene.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

/// Initial stock above the nominal hub, mm: lines no tool reaches stay this far above it.
constexpr float kStockAllowanceMm = 2.0f;
/// Deviation below the nominal that counts as a gouge, µm (float heights near z = 12 mm are
/// exact to ~0.001 µm).
constexpr double kGougeToleranceUm = 0.5;

struct SurfaceStats {
  std::size_t lines = 0;  ///< lines in the machined band
  std::size_t gouged_lines = 0;
  double max_gouge_um = 0, max_scallop_um = 0, mean_um = 0, rms_um = 0;
};

/// 3 × 5 pixel glyphs for the legend of deviation.png: digits, '-', '.', 'u', 'm'.
const char* glyph(char c) {
  switch (c) {
    case '0':
      return "111101101101111";
    case '1':
      return "010110010010111";
    case '2':
      return "111001111100111";
    case '3':
      return "111001111001111";
    case '4':
      return "101101111001001";
    case '5':
      return "111100111001111";
    case '6':
      return "111100111101111";
    case '7':
      return "111001001001001";
    case '8':
      return "111101111101111";
    case '9':
      return "111101111001111";
    case '-':
      return "000000111000000";
    case '.':
      return "000000000000010";
    case 'u':
      return "000000101101111";
    case 'm':
      return "000000111111101";
    default:
      return "000000000000000";
  }
}

struct Image {
  int width, height;
  std::vector<std::uint8_t> rgb;
  void set(int x, int y, std::array<std::uint8_t, 3> c) {
    if (x < 0 || y < 0 || x >= width || y >= height) return;
    std::copy(c.begin(), c.end(), rgb.begin() + 3 * (static_cast<std::size_t>(y) * width + x));
  }
  void text(int x, int y, const std::string& s, int scale) {
    for (char ch : s) {
      const char* g = glyph(ch);
      for (int r = 0; r < 5; ++r)
        for (int c = 0; c < 3; ++c)
          if (g[r * 3 + c] == '1')
            for (int dy = 0; dy < scale; ++dy)
              for (int dx = 0; dx < scale; ++dx)
                set(x + c * scale + dx, y + r * scale + dy, {0, 0, 0});
      x += 4 * scale;
    }
  }
};

/// Diverging colours: blue for gouge (down to -gouge_scale), white at 0, red for scallop.
std::array<std::uint8_t, 3> deviationColour(double dev_um, double gouge_scale_um,
                                            double scallop_scale_um) {
  const double t = dev_um < 0 ? std::min(1.0, -dev_um / gouge_scale_um)
                              : std::min(1.0, dev_um / scallop_scale_um);
  const auto fade = static_cast<std::uint8_t>(255.0 * (1.0 - t));
  return dev_um < 0 ? std::array<std::uint8_t, 3>{fade, fade, 255}
                    : std::array<std::uint8_t, 3>{255, fade, fade};
}

std::string microns(double um) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0fum", um);
  return text;
}

/// deviation.png: the map (row 0 = largest y, grey outside the band) with a colour bar and its
/// scale in µm on the right.
void writeDeviationPng(const std::filesystem::path& file, const zbuffer::Grid& grid,
                       const std::vector<float>& dev_um, const SurfaceStats& stats) {
  const int max_side = 1200;
  const int k =
      std::max(1, static_cast<int>(std::ceil(std::max(grid.nx, grid.ny) / double(max_side))));
  const int map_w = grid.nx / k, map_h = grid.ny / k;
  const int scale = std::max(2, map_h / 120), bar_w = 12 * scale, legend_w = bar_w + 28 * scale;
  Image img{map_w + legend_w, std::max(map_h, 60 * scale), {}};
  img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 255);
  const double gouge_scale = std::max(1.0, stats.max_gouge_um);
  const double scallop_scale = std::max(1.0, stats.max_scallop_um);
  for (int py = 0; py < map_h; ++py) {
    for (int px = 0; px < map_w; ++px) {
      const int ix = px * k, iy = (map_h - 1 - py) * k;
      const float d = dev_um[static_cast<std::size_t>(iy) * grid.nx + ix];
      img.set(px, py,
              std::isnan(d) ? std::array<std::uint8_t, 3>{200, 200, 200}
                            : deviationColour(d, gouge_scale, scallop_scale));
    }
  }
  // Colour bar: top = max scallop, middle = 0, bottom = max gouge.
  const int bar_x = map_w + 4 * scale, bar_top = 4 * scale, bar_h = img.height - 8 * scale;
  for (int y = 0; y < bar_h; ++y) {
    const double t = 1.0 - 2.0 * y / (bar_h - 1);  // +1 top, -1 bottom
    const double dev = t >= 0 ? t * scallop_scale : t * gouge_scale;
    for (int x = 0; x < bar_w; ++x)
      img.set(bar_x + x, bar_top + y, deviationColour(dev, gouge_scale, scallop_scale));
  }
  const int label_x = bar_x + bar_w + 2 * scale;
  img.text(label_x, bar_top, microns(scallop_scale), scale);
  img.text(label_x, bar_top + bar_h / 2 - 3 * scale, "0um", scale);
  img.text(label_x, bar_top + bar_h - 5 * scale, microns(-gouge_scale), scale);
  const std::string png = zbuffer::encodePng(img.width, img.height, img.rgb);
  common::writeTextAtomically(file, png);
}

}  // namespace

void addCheckCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "check",
      "Check a path of an impeller scene: exact clearance of tool + holder (FCL) and the machined "
      "hub (Z-buffer) against the nominal: gouge, scallop, deviation.png. Exit 0 even when "
      "postures collide (they are reported)");
  struct Options {
    std::string scene, path, out;
    double spacing_mm = 0.05;
    std::string backend = "auto";
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("scene", options->scene, "Scene file (YAML)")->required();
  cmd->add_option("--path", options->path, "Path file (.cl: x y z i j k per line)")->required();
  cmd->add_option("--out", options->out,
                  "Output folder (check.json, deviation.png, deviation.npy)");
  cmd->add_option("--spacing", options->spacing_mm, "Z-buffer line spacing, mm")
      ->check(positiveFinite("mm"))
      ->capture_default_str();
  cmd->add_option("--backend", options->backend, "Z-buffer backend: auto | cpu | cuda")
      ->check(CLI::IsMember({"auto", "cpu", "cuda"}))
      ->capture_default_str();
  cmd->callback([options, &global] {
    const zbuffer::Backend backend = zbuffer::backendFromName(options->backend, "--backend");
    const Scene scene = loadScene(options->scene);
    const pathgen::GenerateRequest job = impellerJob(scene);
    const std::vector<geometry::Posture> postures = geometry::readClFile(options->path);
    const common::Progress progress = makeProgressLine(global.quiet);
    const auto& impeller = *scene.impeller_model;
    const auto& ip = impeller.params();

    // (a) exact clearance
    const pathgen::ClearanceChecker checker(
        geometry::toolMesh(job.tool, job.holder, pathgen::kClearanceMeshTolMm), scene.obstacles);
    const pathgen::ClearanceResult clearance = checker.check(postures, {}, progress);

    // (b) the machined hub: the band between the first and last pass over u_range
    const double v0 = std::min(ip.passes_v[0], ip.passes_v[1]);
    const double v1 = std::max(ip.passes_v[0], ip.passes_v[1]);
    Eigen::AlignedBox3d band;
    for (int i = 0; i <= 64; ++i)
      for (int j = 0; j <= 16; ++j)
        band.extend(impeller.hub(ip.u_range[0] + (ip.u_range[1] - ip.u_range[0]) * i / 64.0,
                                 v0 + (v1 - v0) * j / 16.0));
    const double margin = job.tool.radius_mm;
    const int nx = std::max(
        2, static_cast<int>(std::ceil((band.sizes().x() + 2 * margin) / options->spacing_mm)));
    const int ny = std::max(
        2, static_cast<int>(std::ceil((band.sizes().y() + 2 * margin) / options->spacing_mm)));
    zbuffer::SimulationRequest sim;
    sim.grid =
        zbuffer::Grid::fromRegion(band.min().x() - margin, band.min().y() - margin,
                                  band.min().x() - margin + nx * options->spacing_mm,
                                  band.min().y() - margin + ny * options->spacing_mm, nx, ny);
    zbuffer::checkGridFits(sim.grid);
    sim.tool = zbuffer::Tool::ball(job.tool.radius_mm, job.tool.length_mm);
    sim.backend = backend;
    std::vector<float> nominal(sim.grid.lineCount());
    std::vector<char> in_band(sim.grid.lineCount());
    for (int iy = 0; iy < ny; ++iy) {
      for (int ix = 0; ix < nx; ++ix) {
        const double x = sim.grid.x0_mm + (ix + 0.5) * sim.grid.dx_mm;
        const double y = sim.grid.y0_mm + (iy + 0.5) * sim.grid.dy_mm;
        const std::size_t i = static_cast<std::size_t>(iy) * nx + ix;
        nominal[i] = static_cast<float>(impeller.hubHeight(x, y));
        const auto uv = impeller.hubUV(x, y);
        in_band[i] = uv[0] >= ip.u_range[0] && uv[0] <= ip.u_range[1] && uv[1] >= v0 && uv[1] <= v1;
      }
    }
    sim.initial_heights_mm = nominal;
    for (float& h : sim.initial_heights_mm) h += kStockAllowanceMm;
    sim.progress = progress;
    sim.expected_postures = postures.size();
    const zbuffer::SimulationResult simulated = zbuffer::simulate(sim, toZbuffer(postures));

    SurfaceStats stats;
    std::vector<float> dev_um(sim.grid.lineCount(), std::numeric_limits<float>::quiet_NaN());
    double sum = 0, sum2 = 0, min_dev = 0, max_dev = 0;
    for (std::size_t i = 0; i < dev_um.size(); ++i) {
      if (!in_band[i]) continue;
      const double d = 1000.0 * (double(simulated.heights_mm[i]) - double(nominal[i]));
      dev_um[i] = static_cast<float>(d);
      ++stats.lines;
      sum += d;
      sum2 += d * d;
      min_dev = std::min(min_dev, d);
      max_dev = std::max(max_dev, d);
      stats.gouged_lines += d < -kGougeToleranceUm;
    }
    if (stats.lines > 0) {
      stats.mean_um = sum / stats.lines;
      stats.rms_um = std::sqrt(sum2 / stats.lines);
    }
    stats.max_gouge_um = std::max(0.0, -min_dev);
    stats.max_scallop_um = max_dev;

    using nlohmann::json;
    const json report = {
        {"scene", scene.file.string()},
        {"path", options->path},
        {"postures", postures.size()},
        {"clearance", clearanceJson(clearance, job.clearance_mm)},
        {"surface",
         {{"grid",
           {{"origin", {sim.grid.x0_mm, sim.grid.y0_mm}},
            {"spacing", {sim.grid.dx_mm, sim.grid.dy_mm}},
            {"shape", {sim.grid.ny, sim.grid.nx}}}},
          {"backend", zbuffer::backendName(simulated.backend)},
          {"simulation_s", simulated.seconds},
          {"band_lines", stats.lines},
          {"gouged_lines", stats.gouged_lines},
          {"gouge_tolerance_um", kGougeToleranceUm},
          {"max_gouge_um", stats.max_gouge_um},
          {"max_scallop_um", stats.max_scallop_um},
          {"mean_deviation_um", stats.mean_um},
          {"rms_deviation_um", stats.rms_um}}},
    };
    if (!options->out.empty()) {
      const std::filesystem::path out = options->out;
      zbuffer::writeHeightsNpy(out / "deviation.npy", sim.grid, dev_um);
      zbuffer::writeHeightsJson(out / "deviation.json", sim.grid);
      writeDeviationPng(out / "deviation.png", sim.grid, dev_um, stats);
      common::writeTextAtomically(out / "check.json", report.dump(2) + "\n");
    }
    std::printf(
        "clearance: %zu postures, min %.3f mm (required %.3f) at posture %s, %zu colliding%s\n"
        "surface: %zu lines, max gouge %.2f um (%zu lines below %.1f um), max scallop %.1f um, "
        "rms %.1f um (%s, %.2f s)\n",
        postures.size(), clearance.min_clearance_mm, job.clearance_mm,
        clearance.min_index == pathgen::ClearanceResult::npos
            ? "-"
            : std::to_string(clearance.min_index + 1).c_str(),
        clearance.colliding, clearance.colliding ? " (COLLISIONS)" : "", stats.lines,
        stats.max_gouge_um, stats.gouged_lines, -kGougeToleranceUm, stats.max_scallop_um,
        stats.rms_um, zbuffer::backendName(simulated.backend), simulated.seconds);
  });
}

}  // namespace fieldpath::app
