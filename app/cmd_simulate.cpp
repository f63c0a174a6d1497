/// fieldpath simulate: Z-buffer machining simulation of a `.cl` path (DESIGN.md command line).
#include <algorithm>
#include <cfloat>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "commands.h"
#include "errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/zbuffer/outputs.h"
#include "fieldpath/zbuffer/simulator.h"
#include "progress.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

namespace zb = zbuffer;

bool isAnalyticToolText(const std::string& text) {
  return text.rfind("ball:", 0) == 0 || text.rfind("torus:", 0) == 0 || text.rfind("flat:", 0) == 0;
}

/// TOOL: ball:R[:L] | torus:R:r[:L] | flat:R[:L], or a mesh file (tool frame).
zb::Tool parseTool(const std::string& text) {
  if (isAnalyticToolText(text)) {
    const geometry::ToolSpec spec = geometry::parseToolSpec(text);
    switch (spec.shape) {
      case geometry::ToolShape::Ball:
        return zb::Tool::ball(spec.radius_mm, spec.length_mm);
      case geometry::ToolShape::Torus:
        return zb::Tool::torus(spec.radius_mm, spec.corner_radius_mm, spec.length_mm);
      case geometry::ToolShape::Flat:
        return zb::Tool::flat(spec.radius_mm, spec.length_mm);
    }
  }
  const geometry::TriangleMesh mesh = geometry::loadMesh(text);
  try {
    return zb::Tool::fromMesh(toZbuffer(mesh));
  } catch (const InputError& e) {
    throw InputError("--tool " + text + ": " + e.what());
  }
}

/// "NXxNY" → (nx, ny); refuses zero and counts beyond int.
std::pair<int, int> parseGrid(const std::string& text) {
  const auto x = text.find('x');
  long long v[2] = {0, 0};
  const std::string parts[2] = {text.substr(0, x),
                                x == std::string::npos ? "" : text.substr(x + 1)};
  for (int k = 0; k < 2; ++k) {
    const auto& s = parts[k];
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v[k]);
    if (s.empty() || ec != std::errc() || end != s.data() + s.size())
      throw InputError("--grid '" + text + "': expected NXxNY, e.g. 1024x1024");
  }
  if (v[0] <= 0 || v[1] <= 0)
    throw InputError("--grid '" + text + "': needs at least one line each way");
  if (v[0] > std::numeric_limits<int>::max() / 2 || v[1] > std::numeric_limits<int>::max() / 2)
    throw InputError("--grid '" + text + "' is too large: it needs about " +
                     std::to_string(static_cast<long double>(v[0]) * v[1] * 12 / (1 << 20)) +
                     " MiB of memory");
  return {static_cast<int>(v[0]), static_cast<int>(v[1])};
}

std::vector<double> parseNumbers(const std::string& text, const char* option, std::size_t count) {
  std::vector<double> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const auto comma = std::min(text.find(',', pos), text.size());
    const std::string field = text.substr(pos, comma - pos);
    std::size_t used = 0;
    double value = 0;
    try {
      value = std::stod(field, &used);
    } catch (...) {
      used = 0;
    }
    if (field.empty() || used != field.size() || !std::isfinite(value))
      throw InputError(std::string(option) + " '" + text + "': '" + field +
                       "' is not a finite number");
    out.push_back(value);
    pos = comma + 1;
  }
  if (out.size() != count)
    throw InputError(std::string(option) + " '" + text + "': expected " + std::to_string(count) +
                     " numbers");
  return out;
}

}  // namespace

void addSimulateCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand("simulate",
                                 "Z-buffer machining simulation of a path: heights.npy (+ .json), "
                                 "surface.stl, heights.png and a summary");
  struct Options {
    std::string tool, path, grid = "1024x1024", region, part, backend = "auto", out;
    double stock_mm = std::numeric_limits<double>::quiet_NaN();
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--tool", o->tool,
                  "Mesh file (tip at origin, axis +z) or ball:R[:L] | torus:R:r[:L] | flat:R[:L]")
      ->required();
  cmd->add_option("--path", o->path, "Path file: .cl (x y z i j k per line), APT (.apt/.cls) or .npy (N×6/7 float32/64)")->required();
  cmd->add_option("--grid", o->grid, "Lines NXxNY")->capture_default_str();
  cmd->add_option("--region", o->region,
                  "x0,y0,x1,y1 mm (default: the tips' XY range plus the tool radius)");
  auto* stock =
      cmd->add_option("--stock", o->stock_mm, "Stock top plane z, mm (default: the highest tip)");
  cmd->add_option("--part", o->part, "Part mesh whose top is the initial surface")->excludes(stock);
  cmd->add_option("--backend", o->backend, "auto | cpu | cuda")->capture_default_str();
  cmd->add_option("--out", o->out, "Output directory")->required();

  cmd->callback([o, &global] {
    zb::SimulationRequest req;
    req.backend = zb::backendFromName(o->backend, "--backend");
    if (req.backend == zb::Backend::Cuda && !zb::cudaAvailable())
      throw InputError("--backend cuda: no CUDA device available (built without CUDA or no GPU)");

    const auto [nx, ny] = parseGrid(o->grid);
    req.tool = parseTool(o->tool);
    const std::vector<geometry::Posture> path = geometry::readPathFile(o->path).postures;
    const std::vector<zb::Posture> postures = toZbuffer(path);
    double xmin = DBL_MAX, ymin = DBL_MAX, xmax = -DBL_MAX, ymax = -DBL_MAX, ztop = -DBL_MAX;
    for (const auto& p : path) {
      xmin = std::min(xmin, p.tip_mm.x());
      xmax = std::max(xmax, p.tip_mm.x());
      ymin = std::min(ymin, p.tip_mm.y());
      ymax = std::max(ymax, p.tip_mm.y());
      ztop = std::max(ztop, p.tip_mm.z());
    }
    if (o->region.empty()) {
      const double margin = zb::toolReach(req.tool);
      req.grid =
          zb::Grid::fromRegion(xmin - margin, ymin - margin, xmax + margin, ymax + margin, nx, ny);
    } else {
      const auto r = parseNumbers(o->region, "--region", 4);
      try {
        req.grid = zb::Grid::fromRegion(r[0], r[1], r[2], r[3], nx, ny);
      } catch (const InputError& e) {
        throw InputError("--region '" + o->region + "': " + e.what());
      }
    }
    zb::checkGridFits(req.grid);  // before allocating anything grid-sized

    if (!o->part.empty()) {
      const geometry::TriangleMesh part = geometry::loadMesh(o->part);
      const zb::ToolMesh m = toZbuffer(part);
      req.initial_heights_mm = zb::stockFromPart(req.grid, m.vertices, m.triangles);
    } else {
      req.stock_mm = static_cast<float>(std::isnan(o->stock_mm) ? ztop : o->stock_mm);
    }
    req.progress = makeProgressLine(global.quiet);

    const zb::SimulationResult res = zb::simulate(req, postures);

    const std::filesystem::path out = o->out;
    zb::writeHeightsNpy(out / "heights.npy", req.grid, res.heights_mm);
    zb::writeHeightsJson(out / "heights.json", req.grid);
    const std::size_t stl_triangles =
        zb::writeSurfaceStl(out / "surface.stl", req.grid, res.heights_mm);
    zb::writeReliefPng(out / "heights.png", req.grid, res.heights_mm);

    const auto [lo, hi] = std::minmax_element(res.heights_mm.begin(), res.heights_mm.end());
    std::printf("postures        %zu (%zu culled: cannot lower any line)\n", res.postures,
                res.postures_culled);
    std::printf(
        "grid            %dx%d lines, spacing %.6g x %.6g mm, region %.6g,%.6g,%.6g,%.6g mm\n",
        req.grid.nx, req.grid.ny, req.grid.dx_mm, req.grid.dy_mm, req.grid.x0_mm, req.grid.y0_mm,
        req.grid.x0_mm + req.grid.nx * req.grid.dx_mm,
        req.grid.y0_mm + req.grid.ny * req.grid.dy_mm);
    std::printf("lines touched   %zu of %zu (%.1f%%)\n", res.lines_lowered, req.grid.lineCount(),
                100.0 * double(res.lines_lowered) / double(req.grid.lineCount()));
    std::printf("heights         %.6g .. %.6g mm\n", double(*lo) + 0.0, double(*hi) + 0.0);
    std::printf("time            %.3f s\n", res.seconds);
    std::printf("backend         %s\n", zb::backendName(res.backend));
    std::printf(
        "outputs         %s/{heights.npy, heights.json, surface.stl (%zu triangles), "
        "heights.png}\n",
        out.string().c_str(), stl_triangles);
  });
}

}  // namespace fieldpath::app
