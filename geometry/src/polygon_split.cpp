/// geometry/src/polygon_split.h: polygon faces of mesh files split into triangles.
#include "polygon_split.h"

#include <cmath>

#include <Eigen/Geometry>

namespace fieldpath::geometry {
namespace {

/// Twice the signed area of the 2-D triangle (a, b, c): positive when counter-clockwise.
double cross2(const Eigen::Vector2d& a, const Eigen::Vector2d& b, const Eigen::Vector2d& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

}  // namespace

std::optional<std::vector<Eigen::Vector3i>> splitPolygon(
    const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3i> fan;
  for (std::size_t k = 1; k + 1 < points.size(); ++k) fan.emplace_back(0, int(k), int(k + 1));
  if (points.size() <= 3) return fan;
  // A corner at the position of the one before it (a vertex listed twice, or two records of one
  // point) has no edge to it: left out. A zero-length edge at a reflex corner split its turn into
  // two of none, and an L-shaped face read convex and was fanned over its notch (a reviewer's).
  std::vector<int> corner;
  for (std::size_t k = 0; k < points.size(); ++k)
    if (points[k] != points[(k + points.size() - 1) % points.size()]) corner.push_back(int(k));
  const std::size_t n = corner.size();
  if (n < 3) return fan;  // no area
  fan.clear();
  for (std::size_t k = 1; k + 1 < n; ++k) fan.emplace_back(corner[0], corner[k], corner[k + 1]);
  if (n == 3) return fan;
  // The polygon's plane: Newell's normal follows the winding, so the corners run counter-clockwise
  // about it; its length is twice the polygon's area.
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < n; ++k)
    normal += points[std::size_t(corner[k])].cross(points[std::size_t(corner[(k + 1) % n])]);
  if (!(normal.norm() > 0.0)) return fan;  // no area: the fan's triangles have none either
  normal.normalize();
  const Eigen::Vector3d u = normal.unitOrthogonal(), v = normal.cross(u);
  std::vector<Eigen::Vector2d> flat(points.size());  // by the points' own index
  double size = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const Eigen::Vector3d d = points[k] - points[0];
    flat[k] = {d.dot(u), d.dot(v)};
    size = std::max(size, flat[k].cwiseAbs().maxCoeff());
  }
  // Convex (no corner turning clockwise beyond rounding): the fan, as every face was split before.
  const double tol = 1e-12 * size * size;
  bool convex = true;
  for (std::size_t k = 0; k < n && convex; ++k)
    convex =
        cross2(flat[corner[(k + n - 1) % n]], flat[corner[k]], flat[corner[(k + 1) % n]]) >= -tol;
  if (convex) return fan;
  if (n > kMaxClippedCorners) return std::nullopt;

  // Ear clipping: a corner turning counter-clockwise whose triangle holds no other corner left.
  std::vector<int> left = corner;
  std::vector<Eigen::Vector3i> out;
  const auto inside = [&](int p, int a, int b, int c) {  // on or within the triangle (a, b, c)
    const Eigen::Vector2d& q = flat[std::size_t(p)];
    return cross2(flat[a], flat[b], q) >= -tol && cross2(flat[b], flat[c], q) >= -tol &&
           cross2(flat[c], flat[a], q) >= -tol;
  };
  // The search goes on from the last ear (quadratic for the polygons exporters write); a full
  // round without an ear means the polygon crosses itself.
  std::size_t k = 0, tried = 0;
  while (left.size() > 3) {
    const std::size_t m = left.size();
    if (tried++ == m) return std::nullopt;
    k %= m;
    const int a = left[(k + m - 1) % m], b = left[k], c = left[(k + 1) % m];
    bool ear = cross2(flat[a], flat[b], flat[c]) > tol;  // not reflex nor straight
    for (std::size_t j = 0; ear && j < m; ++j) {
      const int p = left[j];
      ear = p == a || p == b || p == c || flat[p] == flat[a] || flat[p] == flat[b] ||
            flat[p] == flat[c] || !inside(p, a, b, c);
    }
    if (!ear) {
      ++k;
      continue;
    }
    out.emplace_back(a, b, c);
    left.erase(left.begin() + std::ptrdiff_t(k));
    k = k == 0 ? 0 : k - 1;
    tried = 0;
  }
  out.emplace_back(left[0], left[1], left[2]);
  return out;
}

}  // namespace fieldpath::geometry
