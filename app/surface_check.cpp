#include "surface_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>

#include <tbb/parallel_for.h>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/memory.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/passes.h"
#include "fieldpath/zbuffer/outputs.h"
#include "machined_band.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

using geometry::Vec3;
using Vec2 = Eigen::Vector2d;

/// The centre of line `i` of `grid` (row-major), mm.
Vec2 lineAt(const zbuffer::Grid& grid, std::size_t i) {
  return Vec2(grid.x0_mm + (double(i % grid.nx) + 0.5) * grid.dx_mm,
              grid.y0_mm + (double(i / grid.nx) + 0.5) * grid.dy_mm);
}

/// How far a line's deviation `scallop_um` may lie under a cusp's within spacing/√2 of it
/// (µm), for lines `spacing_mm` apart, a cutting edge of curvature radius `edge_mm` and the
/// part's upward normal `n` there (SurfaceResult::scallop_grid_error_um). A cusp of height h
/// between two arcs of radius ρ meets them at α = asin(√(2ρh − h²)/ρ) from the part's normal;
/// the deviation (vertical, machined − part) climbs at tan(θ + α) − tan(θ) a mm there, θ the
/// part's slope; h is the cusp's own, found from the line's by a few rounds. Infinite where θ
/// + α reaches 85°: a cusp against a wall that steep is not bounded by vertical lines. The
/// deviations here are vertical (`scallop_um` and the bound); h, along the normal, is their
/// cos θ.
double scallopGridErrorUm(double scallop_um, double spacing_mm, double edge_mm, const Vec3& n) {
  if (!(scallop_um > 0.0) || !(edge_mm > 0.0)) return 0.0;
  const double reach_mm = spacing_mm / std::sqrt(2.0);
  const double theta = std::acos(std::clamp(n.z(), 0.0, 1.0));
  const double steepest = 85.0 * geometry::kDegToRad;
  double error_mm = 0.0;
  for (int round = 0; round < 4; ++round) {
    const double h = std::min(edge_mm, (1e-3 * scallop_um + error_mm) * std::cos(theta));
    const double alpha =
        std::asin(std::min(1.0, std::sqrt(std::max(0.0, 2 * edge_mm * h - h * h)) / edge_mm));
    if (theta + alpha >= steepest) return std::numeric_limits<double>::infinity();
    error_mm = (std::tan(theta + alpha) - std::tan(theta)) * reach_mm;
  }
  return 1e3 * error_mm;
}

/// The path's postures with the motions between them swept: where a motion can reach below
/// `stock_top_mm` (its lower tip less the tool's reach), postures along it as `check`'s motions
/// are (geometry::alongMotion) so that no point of the tool moves more than `step_mm` between two
/// of them (geometry::forEachPoseBetween, as cutter_part's stamps), up to `extent_mm` from the
/// tip (zbuffer::toolExtent: the shank's top turns L / R times faster than the ball; stepped by
/// the ball's reach, a 10° swing of a 40 mm tool cut 68 of a 100 um gouge between its stamps).
std::vector<geometry::Posture> sweptPostures(const std::vector<geometry::Posture>& postures,
                                             double reach_mm, double extent_mm, double step_mm,
                                             double stock_top_mm) {
  std::vector<geometry::Posture> out;
  out.reserve(postures.size());
  for (std::size_t i = 0; i < postures.size(); ++i) {
    out.push_back(postures[i]);
    if (i + 1 == postures.size()) break;
    const geometry::Posture& a = postures[i];
    const geometry::Posture& b = postures[i + 1];
    if (std::min(a.tip_mm.z(), b.tip_mm.z()) - reach_mm > stock_top_mm) continue;  // above it all
    geometry::forEachPoseBetween(a, b, extent_mm, step_mm,
                                 [&out](const geometry::Posture& p) { out.push_back(p); });
  }
  return out;
}

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
    case '>':
      return "100010001010100";
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

/// Deviation above the colour bar's top (the band's largest scallop): the page's purple.
constexpr std::array<std::uint8_t, 3> kAboveScale = {107, 61, 153};

std::string microns(double um) {
  char text[32];
  std::snprintf(text, sizeof text, "%.0fum", um);
  return text;
}

}  // namespace

void writeDeviationPng(const std::filesystem::path& file, const SurfaceResult& stats) {
  const zbuffer::Grid& grid = stats.grid;
  const std::vector<float>& dev_um = stats.deviation_um;
  const int max_side = 1200;
  const int k =
      std::max(1, static_cast<int>(std::ceil(std::max(grid.nx, grid.ny) / double(max_side))));
  const int map_w = grid.nx / k, map_h = grid.ny / k;
  // Gouges scaled to the tolerance at least: a mesh's chordal error of -1 um read full blue, as
  // a gouge, where the page shows it pale (a helper's finding). Above the band's largest scallop
  // (stock left on the outer passes' flanks) a colour of its own, as the page's: it read as the
  // worst scallop.
  const double gouge_scale = std::max({1.0, stats.gouge_tolerance_um, stats.max_gouge_um});
  double scallop_scale = std::max(1.0, stats.max_scallop_um);
  if (stats.band_lines == 0)  // no band (one pass): the scale is the cut lines' largest
    for (std::size_t i = 0; i < dev_um.size(); ++i)
      if (std::isfinite(dev_um[i]) && (stats.lowered.empty() || stats.lowered[i]))
        scallop_scale = std::max(scallop_scale, double(dev_um[i]));
  const std::array<std::string, 3> labels = {microns(scallop_scale), "0um", microns(-gouge_scale)};
  std::size_t label_chars = 0;
  for (const std::string& l : labels) label_chars = std::max(label_chars, l.size());
  const int scale = std::max(2, map_h / 120), bar_w = 12 * scale;
  const int legend_w = bar_w + 8 * scale + 4 * scale * static_cast<int>(label_chars);
  Image img{map_w + legend_w, std::max(map_h, 60 * scale), {}};
  img.rgb.assign(static_cast<std::size_t>(img.width) * img.height * 3, 255);
  bool above = false;  // some line shown above the bar's top (its swatch and '>' then drawn)
  for (int py = 0; py < map_h; ++py) {
    for (int px = 0; px < map_w; ++px) {
      const int ix = px * k, iy = (map_h - 1 - py) * k;
      const std::size_t line = static_cast<std::size_t>(iy) * grid.nx + ix;
      const float d = dev_um[line];
      const bool stock = !stats.lowered.empty() && !stats.lowered[line];
      const bool over = !std::isnan(d) && !stock && d > scallop_scale + 0.5;
      above = above || over;
      img.set(px, py,
              std::isnan(d) ? std::array<std::uint8_t, 3>{200, 200, 200}
              : stock       ? std::array<std::uint8_t, 3>{235, 222, 179}  // never cut: the stock
              : over        ? kAboveScale
                            : deviationColour(d, gouge_scale, scallop_scale));
    }
  }
  // Colour bar: top = max scallop, middle = 0, bottom = max gouge; above it, the swatch of what
  // lies above its top, labelled '>'.
  const int bar_x = map_w + 4 * scale, bar_top = 7 * scale, bar_h = img.height - 11 * scale;
  for (int y = 0; y < bar_h; ++y) {
    const double t = 1.0 - 2.0 * y / (bar_h - 1);  // +1 top, -1 bottom
    const double dev = t >= 0 ? t * scallop_scale : t * gouge_scale;
    for (int x = 0; x < bar_w; ++x)
      img.set(bar_x + x, bar_top + y, deviationColour(dev, gouge_scale, scallop_scale));
  }
  const int label_x = bar_x + bar_w + 2 * scale;
  if (above) {
    for (int y = 0; y < 5 * scale; ++y)
      for (int x = 0; x < bar_w; ++x) img.set(bar_x + x, y, kAboveScale);
    img.text(label_x, 0, ">", scale);
  }
  img.text(label_x, bar_top, labels[0], scale);
  img.text(label_x, bar_top + bar_h / 2 - 3 * scale, labels[1], scale);
  img.text(label_x, bar_top + bar_h - 5 * scale, labels[2], scale);
  const std::string png = zbuffer::encodePng(img.width, img.height, img.rgb);
  common::writeTextAtomically(file, png);
}

namespace {

/// Deviations below the part (`deviation_um`, µm: the vertical times the facet's |n_z|) made no
/// deeper than the cut point's horizontal distance to air: the part is a height field (its top
/// over each line), so a point cut to height h is at most as deep as the distance to the centre
/// of the nearest line whose top is at or below h, or that lies off the part (a surface lies
/// between them; the centre's distance, where the wall stands between the two is not known: up
/// to a spacing more than the depth, never less). The vertical holds where the facet above is
/// the nearest surface; beside a wall it does not: a shank 0.03 mm into a wall lowered the lines
/// on the wall's top by its height, 7.4 mm read. Only lines deeper than half the tolerance are
/// searched, ring by ring (a ring's border only) up to their vertical depth and at most
/// kMaxRings lines away (deeper, the vertical stands: it errs deep). Off the part means a line
/// whose ray missed the part joined to the grid's border through such lines: one inside the
/// part is a crack between its patches, not air.
void gougeDepthsToAir(const zbuffer::Grid& grid, const std::vector<float>& top_mm,
                      const std::vector<float>& cut_mm, double tolerance_um,
                      std::vector<float>& deviation_um) {
  constexpr int kMaxRings = 32;
  const int nx = grid.nx, ny = grid.ny;
  // Lines off the part: no part under them, joined to the border (a flood fill, 4 neighbours).
  std::vector<std::uint8_t> off(top_mm.size(), 0);
  std::vector<std::size_t> queue;
  const auto seed = [&](int x, int y) {
    const std::size_t j = std::size_t(y) * nx + x;
    if (!off[j] && std::isnan(top_mm[j])) {
      off[j] = 1;
      queue.push_back(j);
    }
  };
  for (int x = 0; x < nx; ++x) seed(x, 0), seed(x, ny - 1);
  for (int y = 0; y < ny; ++y) seed(0, y), seed(nx - 1, y);
  for (std::size_t k = 0; k < queue.size(); ++k) {
    const int x = int(queue[k] % nx), y = int(queue[k] / nx);
    if (x > 0) seed(x - 1, y);
    if (x + 1 < nx) seed(x + 1, y);
    if (y > 0) seed(x, y - 1);
    if (y + 1 < ny) seed(x, y + 1);
  }
  const double dx = grid.dx_mm, dy = grid.dy_mm;
  tbb::parallel_for(std::size_t{0}, deviation_um.size(), [&](std::size_t i) {
    if (!(deviation_um[i] < -0.5 * tolerance_um)) return;
    const int ix = static_cast<int>(i % nx), iy = static_cast<int>(i / nx);
    double best_mm = -1e-3 * deviation_um[i];
    const float h = cut_mm[i];
    const auto visit = [&](int jx, int jy) {
      // Past the grid the part is not known (it may go on): no air is taken from there.
      if (jx < 0 || jy < 0 || jx >= nx || jy >= ny) return;
      const std::size_t j = std::size_t(jy) * nx + jx;
      if (!(off[j] || top_mm[j] <= h)) return;  // material there at h (or a crack)
      best_mm = std::min(best_mm, std::hypot((jx - ix) * dx, (jy - iy) * dy));
    };
    for (int ring = 1; ring <= kMaxRings; ++ring) {
      if (ring * std::min(dx, dy) >= best_mm) break;  // no line of this ring is nearer
      for (int k = -ring; k <= ring; ++k) {
        visit(ix + k, iy - ring);
        visit(ix + k, iy + ring);
      }
      for (int k = -ring + 1; k <= ring - 1; ++k) {
        visit(ix - ring, iy + k);
        visit(ix + ring, iy + k);
      }
    }
    deviation_um[i] = static_cast<float>(-1e3 * best_mm);
  });
}

}  // namespace

std::optional<SurfaceGrid> surfaceGrid(const SurfaceRequest& request) {
  const geometry::TriangleMesh& part = *request.part;
  const geometry::PathFile& path = *request.path;
  const double radius = request.tool.radius_mm;
  // The region: in plan, what the passes' tool bodies reach of the part (the ball centre and the
  // shank's axis up to the part's highest point), padded by the tool radius, within the part. A
  // tilted shank cuts beside the ball's footprint: a flank driven into a wall reads as a gouge.
  Eigen::AlignedBox2d passes_box, part_box;
  double part_top_mm = -std::numeric_limits<double>::infinity();
  for (const Vec3& v : part.vertices) {
    part_box.extend(Vec2(v.x(), v.y()));
    part_top_mm = std::max(part_top_mm, v.z());
  }
  const double shank_mm = std::max(0.0, request.tool.length_mm - radius);  // centre to the top
  for (const auto& [begin, end] : pathgen::passRanges(path, 0.0, radius))
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 c = geometry::ballCentre(path.postures[i], radius);
      const Vec3& a = path.postures[i].axis;
      passes_box.extend(Vec2(c.x(), c.y()));
      double up_mm = shank_mm;  // along the axis while the shank is below the part's top
      if (a.z() > 0.0) up_mm = std::min(up_mm, std::max(0.0, (part_top_mm - c.z()) / a.z()));
      const Vec3 reach = c + up_mm * a;
      passes_box.extend(Vec2(reach.x(), reach.y()));
    }
  passes_box.min().array() -= radius;
  passes_box.max().array() += radius;
  Eigen::AlignedBox2d region = passes_box.intersection(part_box);
  if (region.isEmpty() || !(region.sizes().minCoeff() > 0.0)) return std::nullopt;
  SurfaceGrid result;
  double spacing = request.spacing_mm;
  if (!(spacing <= region.sizes().maxCoeff())) {
    char text[320];
    // A part under 1 mm beside passes many times larger is most often one in metres (a helper's
    // was told only to give a finer spacing).
    const bool speck = part_box.diagonal().norm() < 1.0 &&
                       passes_box.diagonal().norm() > 100.0 * part_box.diagonal().norm();
    std::snprintf(text, sizeof text,
                  "--spacing: %g mm is wider than the surface checked (%.3g x %.3g mm in plan): "
                  "give less (default 0.05 mm)%s",
                  spacing, region.sizes().x(), region.sizes().y(),
                  speck ? "; the part spans under 1 mm in plan beside passes 100 times larger: "
                          "is it in metres? every length is read in millimetres"
                        : "");
    throw common::InputError(text);
  }
  const double area = region.sizes().x() * region.sizes().y();
  if (area / (spacing * spacing) > static_cast<double>(kMaxSurfaceLines)) {
    spacing = std::sqrt(area / static_cast<double>(kMaxSurfaceLines));
    result.coarsened = true;
  }
  // Two lines past the part's edge, where the passes reach there: off the part is air, so a cut
  // into a side of the part at the region's edge is told by its distance to that air
  // (gougeDepthsToAir), not by the side's height (a shank 0.05 mm into a 29 mm wall read 29 mm
  // where the grid stopped at the wall).
  Eigen::AlignedBox2d part_margin = part_box;
  part_margin.min().array() -= 2.0 * spacing;
  part_margin.max().array() += 2.0 * spacing;
  region = passes_box.intersection(part_margin);
  const int nx = std::max(2, static_cast<int>(std::ceil(region.sizes().x() / spacing)));
  const int ny = std::max(2, static_cast<int>(std::ceil(region.sizes().y() / spacing)));
  result.grid =
      zbuffer::Grid::fromRegion(region.min().x(), region.min().y(), region.min().x() + nx * spacing,
                                region.min().y() + ny * spacing, nx, ny);
  result.spacing_mm = spacing;
  // The GPU's context first (held once), then the grid with check's own arrays beside the
  // Z-buffer's: the part's top and slope, the stock, the heights cut, the deviation, the band and
  // the reference under overhangs, about 34 B a line measured (simulate's 20 let an accepted
  // limit run to 1.3 times it: a diff review's), 48 taken.
  if (request.backend != zbuffer::Backend::Cpu && zbuffer::cudaAvailable())
    common::requireCudaContext();
  const double lines = double(nx) * double(ny);
  char detail[96];
  std::snprintf(detail, sizeof detail, "%.3g lines %.3g mm apart (--spacing)", lines, spacing);
  common::requireMemory("check's surface grid " + std::to_string(nx) + "x" + std::to_string(ny),
                        48.0 * lines + 16.0 * 1024 * 1024, detail, common::MemoryUse::kPassing);
  zbuffer::checkGridFits(result.grid);  // the 2^31 lines
  return result;
}

namespace {

/// SurfaceResult::unreachable_band_lines and max_reachable_scallop_um: the band's lines from the
/// highest down, in chunks (doubling from 256: on a part without walls beside the band the first
/// line answers), the ball set on the part at each (centre R along the part's normal, `top`
/// in the frame `z0_mm` below the world's), until one clears the obstacles. A chunk is queried
/// in the grid's order, each centre told only touching or clear: one measured d from the
/// obstacles tells its neighbours within min(d, R - d) touching, within d - R clear, unmeasured
/// (ballClearance's walk; one query a line took 13 s over 732 000 lines beside a rib).
void tellUnreachable(SurfaceResult& result, const pathgen::ClearanceChecker& obstacles,
                     double radius_mm, const zbuffer::Grid& grid, const std::vector<float>& top,
                     double z0_mm) {
  std::vector<std::size_t> order;
  order.reserve(result.band_lines);
  for (std::size_t i = 0; i < result.in_band.size(); ++i)
    if (result.in_band[i] && !std::isnan(top[i])) order.push_back(i);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return result.deviation_um[a] > result.deviation_um[b] ||
           (result.deviation_um[a] == result.deviation_um[b] && a < b);
  });
  // Shrunk a little: a ball that only grazes a wall (a fillet of radius R) reaches the part.
  const double ball_mm = radius_mm - std::min(0.01, 0.01 * radius_mm);
  std::vector<std::size_t> lines;
  std::vector<Vec3> centres;
  std::vector<double> clear_mm;
  for (std::size_t begin = 0, chunk = 256; begin < order.size(); begin += chunk, chunk *= 2) {
    const std::size_t end = std::min(order.size(), begin + chunk);
    lines.assign(order.begin() + std::ptrdiff_t(begin), order.begin() + std::ptrdiff_t(end));
    std::sort(lines.begin(), lines.end());  // the grid's order: neighbours follow each other
    centres.clear();
    for (const std::size_t i : lines) {
      const Vec2 at = lineAt(grid, i);
      const Vec3 on_part(at.x(), at.y(), double(top[i]) + z0_mm);
      centres.push_back(on_part + radius_mm * partNormal(grid, top, at));
    }
    // Exact below -R (none) and split at 0: each centre told touching (0) or clear (> 0).
    clear_mm = obstacles.ballClearance(centres, {ball_mm, -ball_mm, 0.0, true}).each_mm;
    for (std::size_t k = begin; k < end; ++k) {
      const std::size_t at =
          std::size_t(std::lower_bound(lines.begin(), lines.end(), order[k]) - lines.begin());
      if (clear_mm[at] > 0.0) {
        result.max_reachable_scallop_um = result.deviation_um[order[k]];
        return;
      }
      ++result.unreachable_band_lines;
    }
  }
}

}  // namespace

std::optional<SurfaceResult> checkSurface(const SurfaceRequest& request, const SurfaceGrid& plan) {
  const geometry::TriangleMesh& part = *request.part;
  const geometry::PathFile& path = *request.path;
  const double radius = request.tool.radius_mm;
  SurfaceResult result;
  result.coarsened = plan.coarsened;
  const double spacing = plan.spacing_mm;
  zbuffer::SimulationRequest sim;
  sim.grid = plan.grid;
  sim.tool =
      request.tool.shape == geometry::ToolShape::Ball
          ? zbuffer::Tool::ball(radius, request.tool.length_mm)
      : request.tool.shape == geometry::ToolShape::Torus
          ? zbuffer::Tool::torus(radius, request.tool.corner_radius_mm, request.tool.length_mm)
          : zbuffer::Tool::flat(radius, request.tool.length_mm);
  sim.backend = request.backend;
  // The Z-buffer in a frame at the grid's corner and the part's lowest point: its coordinates
  // are floats, which 1e5 mm from the origin hold to 8 µm only (a clean job read 7.8 µm of
  // gouge 1e5 mm up, 62 µm at 9e5 mm; a reviewer's at x = 5e5 mm, 20.6 µm); the deviation is a
  // difference, the same in either frame. What is reported is in the part's frame (world_grid).
  const zbuffer::Grid world_grid = sim.grid;
  const Vec3 origin(world_grid.x0_mm, world_grid.y0_mm,
                    std::min_element(part.vertices.begin(), part.vertices.end(),
                                     [](const Vec3& a, const Vec3& b) { return a.z() < b.z(); })
                        ->z());
  sim.grid.x0_mm = sim.grid.y0_mm = 0.0;
  geometry::TriangleMesh part_local = part;
  for (Vec3& v : part_local.vertices) v -= origin;
  std::vector<geometry::Posture> postures_local = path.postures;
  for (geometry::Posture& p : postures_local) p.tip_mm -= origin;
  const zbuffer::ToolMesh part_mesh = toZbuffer(part_local);
  // Each line's facet slope: deviations are told along the part's normal, as a profile
  // tolerance is; vertical ones read 1/cos(slope) deeper (a 3 um overcut of a 60 deg wall: 6 um).
  std::vector<float> facet_nz;
  const std::vector<float> nominal =
      zbuffer::partTop(sim.grid, part_mesh.vertices, part_mesh.triangles, &facet_nz);
  float top = -std::numeric_limits<float>::infinity();
  for (float h : nominal)
    if (!std::isnan(h)) top = std::max(top, h);
  if (!std::isfinite(top)) return std::nullopt;  // no line of the region falls on the part
  sim.initial_heights_mm = nominal;
  for (float& h : sim.initial_heights_mm) h = (std::isnan(h) ? top : h) + kStockAllowanceMm;
  sim.progress = request.progress;
  // Sweep the motions: a straight move between two cutting postures over a concave part, or a
  // link that dips into it, cuts between them. Stamps `step` apart leave a cutting edge of
  // radius of curvature ρ at most step² / (8 ρ) shallower than the swept one: a quarter of the
  // gouge tolerance. ρ: the ball's R, a torus's corner r (check refuses a flat end: its sharp
  // rim, tilted, leaves step · tan(tilt), which this spacing does not bound).
  const double tol_mm = 1e-3 * request.gouge_tolerance_um;
  const double edge_mm =
      request.tool.shape == geometry::ToolShape::Torus ? request.tool.corner_radius_mm : radius;
  result.sweep_step_mm = std::max(0.5 * spacing, std::sqrt(2.0 * edge_mm * tol_mm));
  result.sweep_error_um = 1e3 * result.sweep_step_mm * result.sweep_step_mm / (8.0 * edge_mm);
  const std::vector<geometry::Posture> swept =
      sweptPostures(postures_local, zbuffer::toolReach(sim.tool), zbuffer::toolExtent(sim.tool),
                    result.sweep_step_mm, top + kStockAllowanceMm);
  result.simulated_postures = swept.size();
  sim.expected_postures = swept.size();
  const zbuffer::SimulationResult simulated = zbuffer::simulate(sim, toZbuffer(swept));
  result.grid = world_grid;
  result.gouge_tolerance_um = request.gouge_tolerance_um;
  result.backend = simulated.backend;
  result.simulation_s = simulated.seconds;
  result.cut_lines = simulated.lines_lowered;
  result.in_band = machinedBand(world_grid, path, radius, edge_mm, nominal);
  result.deviation_um.assign(sim.grid.lineCount(), std::numeric_limits<float>::quiet_NaN());
  result.lowered.assign(sim.grid.lineCount(), 0);
  for (std::size_t i = 0; i < result.lowered.size(); ++i)
    result.lowered[i] = simulated.heights_mm[i] < sim.initial_heights_mm[i];
  // The surface each line is measured against: the part's top, or, where the tool passed
  // beneath the top's layer (under an overhang), the top of what lies under it (the Z-buffer
  // keeps a line's lowest tool point only: under an overhang it is no cut of the overhang,
  // which read 14.5 mm of gouge for a clear tool; the overhang's underside is the cutter's exact
  // test's). A line with nothing under the layer is not measured.
  std::vector<float> reference = nominal, reference_nz = facet_nz;
  zbuffer::PartUnderCut under;
  // Only a line cut under its top by more than the tolerance can be beneath a layer (none on a
  // clean path: the four rasterisations and the shells are skipped).
  const float layer_mm = static_cast<float>(tol_mm);
  if (zbuffer::anyCutUnderTop(nominal, simulated.heights_mm, layer_mm)) {
    std::vector<std::uint8_t> open(part_local.triangles.size(), 0);
    for (const std::vector<int>& shell : geometry::openShells(part_local))
      for (const int k : shell) open[static_cast<std::size_t>(k)] = 1;
    under = zbuffer::partUnderCut(sim.grid, part_mesh.vertices, part_mesh.triangles, nominal,
                                  simulated.heights_mm, open, layer_mm);
  }
  for (std::size_t i = 0; i < under.beneath.size(); ++i)
    if (under.beneath[i]) {
      ++result.beneath_lines;
      result.beneath_unmeasured += std::isnan(under.surface_mm[i]);
      reference[i] = under.surface_mm[i];
      reference_nz[i] = under.normal_z[i];
    }
  for (std::size_t i = 0; i < reference.size(); ++i)
    if (!std::isnan(reference[i]))
      result.deviation_um[i] =
          static_cast<float>(1000.0 * (double(simulated.heights_mm[i]) - double(reference[i])) *
                             double(reference_nz[i]));
  gougeDepthsToAir(sim.grid, reference, simulated.heights_mm, request.gouge_tolerance_um,
                   result.deviation_um);
  double sum = 0, sum2 = 0, min_dev = 0, max_dev = 0;
  double highest_cusp = 0;  // the highest any line's cusp may stand (scallopGridErrorUm)
  const double spacing_mm = std::max(sim.grid.dx_mm, sim.grid.dy_mm);
  for (std::size_t i = 0; i < reference.size(); ++i) {
    if (std::isnan(reference[i])) {
      result.in_band[i] = 0;
      continue;
    }
    const double vertical_um = 1000.0 * (double(simulated.heights_mm[i]) - double(reference[i]));
    const double cos_slope = double(reference_nz[i]);
    const double d = result.deviation_um[i];
    ++result.part_lines;
    result.part_cut_lines += result.lowered[i] != 0;
    min_dev = std::min(min_dev, d);
    result.gouged_lines += d < -request.gouge_tolerance_um;
    if (!result.in_band[i]) continue;
    if (!result.lowered[i]) {
      ++result.uncut_band_lines;
      result.in_band[i] = 0;
      continue;
    }
    ++result.band_lines;
    sum += d;
    sum2 += d * d;
    max_dev = std::max(max_dev, d);
    const Vec2 at = lineAt(world_grid, i);
    const double bound_um =
        scallopGridErrorUm(vertical_um, spacing_mm, edge_mm, partNormal(world_grid, reference, at));
    highest_cusp = std::max(highest_cusp, (vertical_um + bound_um) * cos_slope);
  }
  if (result.band_lines > 0) {
    result.mean_um = sum / result.band_lines;
    result.rms_um = std::sqrt(sum2 / result.band_lines);
    result.scallop_grid_error_um = highest_cusp - max_dev;
  }
  result.max_gouge_um = std::max(0.0, -min_dev);
  result.max_scallop_um = max_dev;
  if (request.obstacles && request.tool.shape == geometry::ToolShape::Ball && result.band_lines > 0)
    tellUnreachable(result, *request.obstacles, radius, world_grid, reference, origin.z());
  return result;
}

}  // namespace fieldpath::app
