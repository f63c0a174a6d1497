#include "cli_parse.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <cmath>
#include <limits>

#include "errors.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/geometry/tool_model.h"
#include "scene_mesh.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

namespace zb = zbuffer;

bool isAnalyticToolText(const std::string& text) {
  return text.rfind("ball:", 0) == 0 || text.rfind("torus:", 0) == 0 || text.rfind("flat:", 0) == 0;
}

/// `ball`, `torus` or `flat` alone (no such file): a shape whose sizes were left out, not a mesh.
bool isBareShapeName(const std::string& text) {
  return (text == "ball" || text == "torus" || text == "flat") && !std::filesystem::exists(text);
}

}  // namespace

zb::Tool parseTool(const std::string& text) {
  if (isBareShapeName(text))
    throw InputError("--tool " + text + ": the shape needs its sizes: " +
                     (text == "torus" ? "torus:R:r[:L]" : text + ":R[:L]") + " (mm)");
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
  geometry::TriangleMesh mesh = geometry::loadMesh(text);
  mendExportDefects(mesh, text);  // as the scene's solids: slivers, facets wound against the rest
  // The Z-buffer cuts with the tool's downward-facing surface from its tip up: an open mesh
  // (a cylinder without its bottom cap) cut nothing, one below its tip cut 13 mm too deep.
  geometry::MeshReport report = geometry::validateMesh(mesh);
  if (report.open_edges > 0 || report.non_manifold_edges > 0) {
    // Triangles of no area cut nothing, but their edges read as non-manifold (a helper's tool
    // with 286 such edges was refused where the same file as an obstacle was mended): left out
    // where that closes the tool.
    geometry::TriangleMesh kept{mesh.vertices, {}};
    for (const Eigen::Vector3i& t : mesh.triangles)
      if (!geometry::hasNoArea(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]))
        kept.triangles.push_back(t);
    const geometry::MeshReport without = geometry::validateMesh(kept);
    if (without.open_edges == 0 && without.non_manifold_edges == 0 && !kept.triangles.empty()) {
      std::fprintf(stderr, "note: --tool %s: %zu triangles of no area left out\n", text.c_str(),
                   mesh.triangles.size() - kept.triangles.size());
      mesh = std::move(kept);
      report = without;
    }
  }
  if (report.open_edges > 0 || report.non_manifold_edges > 0)
    throw InputError("--tool " + text + ": the tool mesh is not closed (" +
                     std::to_string(report.open_edges) + " open, " +
                     std::to_string(report.non_manifold_edges) +
                     " non-manifold edges): a tool is a closed solid, tip at the origin, along +z");
  double lowest = 0.0, size = 0.0;
  for (const auto& v : mesh.vertices) {
    lowest = std::min(lowest, v.z());
    size = std::max(size, v.cwiseAbs().maxCoeff());
  }
  if (lowest < -1e-6 * std::max(size, 1.0))
    throw InputError("--tool " + text + ": the tool mesh reaches z = " + std::to_string(lowest) +
                     " mm, below its tip: the tip is the origin and the tool lies along +z");
  // Wound inward (every triangle the other way round), its "downward" faces were its top: it cut
  // nothing, or 6 mm too high with a tilted axis. Turned outward, as the scene's solids are.
  if (geometry::orientClosedShells(mesh) > 0)
    std::fprintf(stderr, "note: --tool %s: the tool mesh was wound inward: turned outward\n",
                 text.c_str());
  try {
    return zb::Tool::fromMesh(toZbuffer(mesh));
  } catch (const InputError& e) {
    throw InputError("--tool " + text + ": " + e.what());
  }
}

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

}  // namespace fieldpath::app
