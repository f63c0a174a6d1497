#include "machined_band.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <tuple>
#include <unordered_map>
#include <utility>

#include <tbb/parallel_for.h>

#include "fieldpath/pathgen/passes.h"

namespace fieldpath::app {
namespace {

using geometry::Vec3;
using Vec2 = Eigen::Vector2d;
using Line = std::vector<Vec2>;

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

/// Marks the lines inside triangle (a, b, c) (plan view, mm).
void markTriangle(const zbuffer::Grid& grid, const Vec2& a, const Vec2& b, const Vec2& c,
                  std::vector<char>& mask) {
  const double area = cross(b - a, c - a);
  if (std::abs(area) < 1e-12) return;
  const Vec2 lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
  const int ix0 =
      std::max(0, static_cast<int>(std::floor((lo.x() - grid.x0_mm) / grid.dx_mm - 0.5)));
  const int ix1 =
      std::min(grid.nx - 1, static_cast<int>(std::ceil((hi.x() - grid.x0_mm) / grid.dx_mm - 0.5)));
  const int iy0 =
      std::max(0, static_cast<int>(std::floor((lo.y() - grid.y0_mm) / grid.dy_mm - 0.5)));
  const int iy1 =
      std::min(grid.ny - 1, static_cast<int>(std::ceil((hi.y() - grid.y0_mm) / grid.dy_mm - 0.5)));
  for (int iy = iy0; iy <= iy1; ++iy)
    for (int ix = ix0; ix <= ix1; ++ix) {
      const Vec2 x(grid.x0_mm + (ix + 0.5) * grid.dx_mm, grid.y0_mm + (iy + 0.5) * grid.dy_mm);
      const double e0 = cross(b - a, x - a), e1 = cross(c - b, x - b), e2 = cross(a - c, x - c);
      if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))
        mask[static_cast<std::size_t>(iy) * grid.nx + ix] = 1;
    }
}

/// Where a posture's tool touches the part, in plan: the support point, in the direction -n of
/// the part's normal n there, of its cutting end (a ring of radius R - r, r above the tip, swept
/// by a ball of radius r; a ball: r = R, its centre less R n). A fixed point from under the tip:
/// the contact moves with the normal where it lands (a few rounds; a plane's in one). Contacts,
/// not ball centres: on a slope those lie R sin(slope) off the contact, and a band of centres
/// took in the tool's flank beyond the first pass (a tilted plane's 76 um scallop read as 233 um).
Vec2 contactInPlan(const geometry::Posture& p, double radius_mm, double corner_mm,
                   const zbuffer::Grid& grid, const std::vector<float>& top) {
  const Vec3& a = p.axis;
  const Vec3 ring_centre = p.tip_mm + corner_mm * a;
  Vec2 q(p.tip_mm.x(), p.tip_mm.y());
  for (int round = 0; round < 4; ++round) {
    const Vec3 n = partNormal(grid, top, q);
    const Vec3 u = n - n.dot(a) * a;  // -n's direction in the ring's plane is -u
    Vec3 point = ring_centre - corner_mm * n;
    if (u.norm() > 1e-9) point -= (radius_mm - corner_mm) / u.norm() * u;
    q = Vec2(point.x(), point.y());
  }
  return q;
}

/// An end of a contact line: its point and the direction the line leaves it by (outward).
struct LineEnd {
  std::size_t line;
  bool at_start;
  Vec2 point, outward;
  double last_step_mm;  ///< the line's step next to this end
};

LineEnd endOf(const std::vector<Line>& lines, std::size_t k, bool at_start) {
  const Line& l = lines[k];
  const Vec2 e = at_start ? l.front() : l.back();
  const Vec2 inner = at_start ? l[1] : l[l.size() - 2];
  return {k, at_start, e, (e - inner).normalized(), (e - inner).norm()};
}

/// The hash of cell (ix, iy): keys may collide, which only costs a few more candidates.
std::int64_t cellHash(std::int64_t ix, std::int64_t iy) { return ix * 73856093 ^ iy * 19349663; }

/// The integer cell index of coordinate `x` (mm) in cells `cell_mm` wide.
std::int64_t cellIndex(double x, double cell_mm) {
  return static_cast<std::int64_t>(std::floor(x / cell_mm));
}

/// The hash of the cell `dx`, `dy` cells from the one holding plan point p.
std::int64_t cellKey(const Vec2& p, double cell_mm, int dx = 0, int dy = 0) {
  return cellHash(cellIndex(p.x(), cell_mm) + dx, cellIndex(p.y(), cell_mm) + dy);
}

/// The contact lines with pieces that continue one another joined into one line: an end of one
/// meets an end of another within twice the larger of their steps there (and within 2 R),
/// heading on within 30° and along the gap (a pass written in pieces, in any order or direction:
/// each piece alone has no neighbour at its ends, and a band of pieces leaves the gaps out).
std::vector<Line> joined(std::vector<Line> lines, double radius_mm) {
  const double cell = 2.0 * radius_mm, cos30 = std::cos(M_PI / 6);
  std::vector<LineEnd> ends;
  for (std::size_t k = 0; k < lines.size(); ++k)
    for (const bool at_start : {true, false}) ends.push_back(endOf(lines, k, at_start));
  std::unordered_multimap<std::int64_t, std::size_t> by_cell;
  for (std::size_t e = 0; e < ends.size(); ++e) by_cell.emplace(cellKey(ends[e].point, cell), e);
  struct Join {
    double gap_mm;
    std::size_t a, b;
  };
  std::vector<Join> joins;
  for (std::size_t e = 0; e < ends.size(); ++e)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
        const auto [first, last] = by_cell.equal_range(cellKey(ends[e].point, cell, dx, dy));
        for (auto it = first; it != last; ++it) {
          const std::size_t f = it->second;
          if (f <= e || ends[f].line == ends[e].line) continue;
          const LineEnd &a = ends[e], &b = ends[f];
          const Vec2 gap = b.point - a.point;
          const double g = gap.norm();
          if (g > std::min(2.0 * radius_mm, 2.0 * std::max(a.last_step_mm, b.last_step_mm)))
            continue;
          if (a.outward.dot(b.outward) > -cos30) continue;
          if (g > 1e-9 && (gap.dot(a.outward) < cos30 * g || -gap.dot(b.outward) < cos30 * g))
            continue;
          joins.push_back({g, e, f});
        }
      }
  std::sort(joins.begin(), joins.end(), [](const Join& x, const Join& y) {
    return std::tie(x.gap_mm, x.a, x.b) < std::tie(y.gap_mm, y.a, y.b);
  });
  constexpr std::size_t kFree = std::numeric_limits<std::size_t>::max();
  std::vector<std::size_t> partner(ends.size(), kFree);
  for (const Join& j : joins)
    if (partner[j.a] == kFree && partner[j.b] == kFree) {
      partner[j.a] = j.b;
      partner[j.b] = j.a;
    }
  // Walk the chains from a free end; what is left are rings of pieces (started anywhere).
  std::vector<char> used(lines.size(), 0);
  std::vector<Line> out;
  const auto walk = [&](std::size_t end) {
    Line chain;
    while (end != kFree && !used[ends[end].line]) {
      const LineEnd& e = ends[end];
      used[e.line] = 1;
      Line& l = lines[e.line];
      if (!e.at_start) std::reverse(l.begin(), l.end());
      chain.insert(chain.end(), l.begin(), l.end());
      const std::size_t other = e.at_start ? end + 1 : end - 1;  // ends are (start, end) per line
      end = partner[other];
    }
    out.push_back(std::move(chain));
  };
  for (std::size_t e = 0; e < ends.size(); ++e)
    if (partner[e] == kFree && !used[ends[e].line]) walk(e);
  for (std::size_t e = 0; e < ends.size(); e += 2)
    if (!used[ends[e].line]) walk(e);
  return out;
}

/// The line resampled every `step_mm` along it, its ends kept: a path's own postures may be far
/// denser than the band needs (the casts cost by points), or far apart (a long straight pass of
/// two postures, whose neighbour covers only its middle).
Line resampledEvery(const Line& line, double step_mm) {
  Line out{line.front()};
  double next_mm = step_mm;  // along the current segment, to the next point
  for (std::size_t i = 1; i < line.size(); ++i) {
    const Vec2 d = line[i] - line[i - 1];
    const double length_mm = d.norm();
    for (; next_mm <= length_mm; next_mm += step_mm)
      out.push_back(line[i - 1] + (next_mm / length_mm) * d);
    next_mm -= length_mm;
  }
  if ((out.back() - line.back()).norm() > 1e-9) out.push_back(line.back());
  return out;
}

/// The contact lines' segments, hashed by cell, for casting sideways from them.
class SegmentIndex {
 public:
  SegmentIndex(const std::vector<Line>& lines, double cell_mm) : lines_(lines), cell_(cell_mm) {
    arc_.resize(lines.size());
    for (std::size_t k = 0; k < lines.size(); ++k) {
      arc_[k].assign(lines[k].size(), 0.0);
      for (std::size_t i = 1; i < lines[k].size(); ++i) {
        arc_[k][i] = arc_[k][i - 1] + (lines[k][i] - lines[k][i - 1]).norm();
        const Vec2 lo = lines[k][i - 1].cwiseMin(lines[k][i]);
        const Vec2 hi = lines[k][i - 1].cwiseMax(lines[k][i]);
        forCells(lo, hi, [&](std::int64_t key) { cells_.emplace(key, std::make_pair(k, i)); });
      }
    }
  }

  /// What a cast sideways met: the distance (NaN: nothing within reach) and the line.
  struct Hit {
    double distance_mm = std::numeric_limits<double>::quiet_NaN();
    std::size_t line = 0;
  };

  /// The nearest other contact line along unit `dir` from point `i` of line `k`, at most
  /// `reach_mm` away. A line's own segments count where they lie more than twice that distance
  /// away along it (a spiral's next turn; not its own segments at the point).
  Hit castFrom(std::size_t k, std::size_t i, const Vec2& dir, double reach_mm) const {
    const Vec2& p = lines_[k][i];
    const double min_t = 1e-6 * reach_mm;
    Hit best;
    // The cells the cast crosses, in its order (Amanatides and Woo), until one ends beyond the
    // nearest meeting: a segment met at t lies in the cell holding that point.
    std::int64_t ix = cellIndex(p.x(), cell_), iy = cellIndex(p.y(), cell_);
    const int step_x = dir.x() > 0 ? 1 : -1, step_y = dir.y() > 0 ? 1 : -1;
    const auto exitAt = [this](std::int64_t cell, int step, double from, double along) {
      if (along == 0.0) return std::numeric_limits<double>::infinity();
      return (double(cell + (step > 0 ? 1 : 0)) * cell_ - from) / along;
    };
    double exit_x = exitAt(ix, step_x, p.x(), dir.x());
    double exit_y = exitAt(iy, step_y, p.y(), dir.y());
    const double across_x = cell_ / std::abs(dir.x()), across_y = cell_ / std::abs(dir.y());
    for (;;) {
      const auto [first, last] = cells_.equal_range(cellHash(ix, iy));
      for (auto it = first; it != last; ++it) {
        const auto [m, j] = it->second;
        const Vec2 &a = lines_[m][j - 1], &b = lines_[m][j];
        const double denom = cross(dir, b - a);
        if (std::abs(denom) < 1e-12) continue;
        const double t = cross(a - p, b - a) / denom, u = cross(a - p, dir) / denom;
        if (u < 0 || u > 1 || t <= min_t || t > reach_mm || t >= best.distance_mm) continue;
        if (m == k) {
          const double along = arc_[m][j - 1] + u * (arc_[m][j] - arc_[m][j - 1]);
          if (std::abs(along - arc_[k][i]) <= 2.0 * t) continue;
        }
        best = {t, m};
      }
      const double exit = std::min(exit_x, exit_y);
      if (!(exit <= reach_mm) || exit >= best.distance_mm) return best;
      if (exit_x < exit_y) {
        ix += step_x;
        exit_x += across_x;
      } else {
        iy += step_y;
        exit_y += across_y;
      }
    }
  }

 private:
  template <class F>
  void forCells(const Vec2& lo, const Vec2& hi, F&& f) const {
    const std::int64_t x0 = cellIndex(lo.x(), cell_), x1 = cellIndex(hi.x(), cell_);
    const std::int64_t y0 = cellIndex(lo.y(), cell_), y1 = cellIndex(hi.y(), cell_);
    for (auto iy = y0; iy <= y1; ++iy)
      for (auto ix = x0; ix <= x1; ++ix) f(cellHash(ix, iy));
  }

  const std::vector<Line>& lines_;
  double cell_;
  std::vector<std::vector<double>> arc_;
  // Keys may collide: a segment met through another cell is only one more candidate.
  std::unordered_multimap<std::int64_t, std::pair<std::size_t, std::size_t>> cells_;
};

}  // namespace

Vec3 partNormal(const zbuffer::Grid& grid, const std::vector<float>& top, const Vec2& p) {
  if (grid.nx < 3 || grid.ny < 3) return Vec3::UnitZ();
  const double fx = (p.x() - grid.x0_mm) / grid.dx_mm - 0.5,
               fy = (p.y() - grid.y0_mm) / grid.dy_mm - 0.5;
  if (!std::isfinite(fx) || !std::isfinite(fy)) return Vec3::UnitZ();
  const int ix = static_cast<int>(std::clamp(std::round(fx), 1.0, grid.nx - 2.0));
  const int iy = static_cast<int>(std::clamp(std::round(fy), 1.0, grid.ny - 2.0));
  auto h = [&](int i, int j) { return double(top[static_cast<std::size_t>(j) * grid.nx + i]); };
  const double gx = (h(ix + 1, iy) - h(ix - 1, iy)) / (2.0 * grid.dx_mm);
  const double gy = (h(ix, iy + 1) - h(ix, iy - 1)) / (2.0 * grid.dy_mm);
  if (!std::isfinite(gx) || !std::isfinite(gy)) return Vec3::UnitZ();
  return Vec3(-gx, -gy, 1.0).normalized();
}

std::vector<char> machinedBand(const zbuffer::Grid& grid, const geometry::PathFile& path,
                               double radius_mm, double corner_mm, const std::vector<float>& top) {
  std::vector<Line> pieces;
  double length_mm = 0;
  for (const auto& [begin, end] : pathgen::passRanges(path, 0.0, radius_mm)) {
    Line line;
    for (std::size_t i = begin; i < end; ++i) {
      const Vec2 c = contactInPlan(path.postures[i], radius_mm, corner_mm, grid, top);
      if (line.empty() || (c - line.back()).norm() > 1e-9) line.push_back(c);
    }
    for (std::size_t i = 1; i < line.size(); ++i) length_mm += (line[i] - line[i - 1]).norm();
    if (line.size() >= 2) pieces.push_back(std::move(line));
  }
  // Points a quarter of R apart along the lines (about 4 million at most in all): a neighbour's
  // side is followed to within (R/4)² / 8ρ of its curvature radius ρ.
  const double step_mm =
      std::max({0.25 * radius_mm, std::max(grid.dx_mm, grid.dy_mm), length_mm / 4e6});
  std::vector<Line> lines;
  for (const Line& l : joined(std::move(pieces), radius_mm))
    lines.push_back(resampledEvery(l, step_mm));
  const double reach_mm = 4.0 * radius_mm;  // passes farther apart leave no scallop between them
  // Cells a few points wide: a cast stops at the cell past its nearest meeting (the passes'
  // step-over), not after all of its reach.
  const SegmentIndex index(lines, std::max(step_mm, reach_mm / 8));
  // Per point of every line: the distance to the nearest line on its left and on its right.
  std::vector<std::size_t> first(lines.size() + 1, 0);
  for (std::size_t k = 0; k < lines.size(); ++k) first[k + 1] = first[k] + lines[k].size();
  std::vector<std::array<SegmentIndex::Hit, 2>> hit(first.back());
  const auto sideways = [&](std::size_t k, std::size_t i) {
    const Line& l = lines[k];
    const Vec2 t = (l[std::min(i + 1, l.size() - 1)] - l[i == 0 ? 0 : i - 1]).normalized();
    return Vec2(-t.y(), t.x());
  };
  tbb::parallel_for(std::size_t{0}, lines.size(), [&](std::size_t k) {
    for (std::size_t i = 0; i < lines[k].size(); ++i) {
      const Vec2 left = sideways(k, i);
      hit[first[k] + i] = {index.castFrom(k, i, left, reach_mm),
                           index.castFrom(k, i, -left, reach_mm)};
    }
  });
  // Each step of a line with its neighbour seen from both ends, the same line: the
  // quadrilateral between them. (Where the two casts meet different lines, the strip would
  // span what lies between them: casts from the first points of staggered passes run past the
  // starts of the next ones, and a triangle 8.6 mm long took in the stock before them, 181 um.)
  std::vector<char> mask(grid.lineCount(), 0);
  for (std::size_t k = 0; k < lines.size(); ++k)
    for (std::size_t i = 0; i + 1 < lines[k].size(); ++i)
      for (const int side : {0, 1}) {
        const SegmentIndex::Hit &h0 = hit[first[k] + i][side], &h1 = hit[first[k] + i + 1][side];
        if (std::isnan(h0.distance_mm) || std::isnan(h1.distance_mm) || h0.line != h1.line)
          continue;
        const double t0 = h0.distance_mm, t1 = h1.distance_mm;
        const double sign = side == 0 ? 1.0 : -1.0;
        const Vec2 &a = lines[k][i], &b = lines[k][i + 1];
        const Vec2 a_hit = a + sign * t0 * sideways(k, i);
        const Vec2 b_hit = b + sign * t1 * sideways(k, i + 1);
        markTriangle(grid, a, b, b_hit, mask);
        markTriangle(grid, a, b_hit, a_hit, mask);
      }
  return mask;
}

}  // namespace fieldpath::app
