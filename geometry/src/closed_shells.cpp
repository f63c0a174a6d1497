#include "fieldpath/geometry/closed_shells.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <utility>

namespace fieldpath::geometry {
namespace {

using Vec2 = Eigen::Vector2d;

double orient(const Vec2& u, const Vec2& v, const Vec2& p) {
  return (v.x() - u.x()) * (p.y() - u.y()) - (v.y() - u.y()) * (p.x() - u.x());
}

/// The top-left rule for a counter-clockwise triangle's edge u → v: a point on the edge belongs
/// to the triangle if the edge is a top or a left one; of the two triangles sharing an edge
/// (traversed u → v by one, v → u by the other) exactly one owns it.
bool topLeft(const Vec2& u, const Vec2& v) {
  return (u.y() == v.y() && v.x() < u.x()) || v.y() < u.y();
}

bool owns(double w, const Vec2& u, const Vec2& v) { return w > 0.0 || (w == 0.0 && topLeft(u, v)); }

/// The point of triangle abc nearest p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3d closestOnTriangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                  const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = va + vb + vc;
  if (!(denom > 0)) return a;  // no area: its vertices are its points
  return a + (vb / denom) * ab + (vc / denom) * ac;
}

}  // namespace

ClosedShells::ClosedShells(const TriangleMesh& mesh)
    : vertices_(mesh.vertices), triangles_(mesh.triangles) {
  for (std::vector<int>& shell_triangles : closedShells(mesh)) {
    Shell shell;
    for (int t : shell_triangles)
      for (int e = 0; e < 3; ++e) shell.box.extend(vertices_[triangles_[t][e]]);
    // About 4 triangles a cell, at most 256 × 256 cells.
    const int n = std::clamp(static_cast<int>(std::sqrt(shell_triangles.size() / 4.0)), 1, 256);
    shell.nx = shell.ny = n;
    shell.cell_x = std::max(shell.box.sizes().x() / n, 1e-9);
    shell.cell_y = std::max(shell.box.sizes().y() / n, 1e-9);
    shell.cells.resize(static_cast<std::size_t>(n) * n);
    auto cellX = [&](double x) {
      return std::clamp(static_cast<int>((x - shell.box.min().x()) / shell.cell_x), 0, n - 1);
    };
    auto cellY = [&](double y) {
      return std::clamp(static_cast<int>((y - shell.box.min().y()) / shell.cell_y), 0, n - 1);
    };
    for (int t : shell_triangles) {
      Eigen::AlignedBox3d tb;
      for (int e = 0; e < 3; ++e) tb.extend(vertices_[triangles_[t][e]]);
      for (int ix = cellX(tb.min().x()); ix <= cellX(tb.max().x()); ++ix)
        for (int iy = cellY(tb.min().y()); iy <= cellY(tb.max().y()); ++iy)
          shell.cells[static_cast<std::size_t>(ix) * n + iy].push_back(t);
    }
    // The signed volume (divergence theorem, about a vertex of the shell: far from the origin
    // the products cancel): a shell wound inward is < 0.
    const Eigen::Vector3d origin = vertices_[triangles_[shell_triangles.front()][0]];
    for (int t : shell_triangles) {
      const Eigen::Vector3d a = vertices_[triangles_[t][0]] - origin;
      shell.volume_mm3 +=
          a.dot(
              (vertices_[triangles_[t][1]] - origin).cross(vertices_[triangles_[t][2]] - origin)) /
          6.0;
    }
    anchors_.push_back(origin);
    shell.triangles = std::move(shell_triangles);
    shells_.push_back(std::move(shell));
  }
  // Kinds from the outside in (a container encloses more than what it holds): a shell's parent
  // is the smallest shell that holds it wholly. A whole mesh flipped (a hollow box's outer shell
  // inward, its void outward) read its void as a solid: a tool in it "999.9 um" deep.
  std::vector<std::size_t> order(shells_.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  const auto size = [&](std::size_t s) { return std::abs(shells_[s].volume_mm3); };
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return size(a) > size(b); });
  // The boxes of the open shells that nearly close (a part left open: a void inside one has only
  // its winding to tell it), found once and only when a shell in no other is wound inward.
  std::optional<std::vector<Eigen::AlignedBox3d>> open_boxes;
  const auto inOpen = [&](const Eigen::AlignedBox3d& box) {
    if (!open_boxes) {
      open_boxes.emplace();
      for (const std::vector<int>& open : nearlyClosedOpenShells(mesh)) {
        Eigen::AlignedBox3d b;
        for (int t : open)
          for (int e = 0; e < 3; ++e) b.extend(vertices_[triangles_[t][e]]);
        open_boxes->push_back(b);
      }
    }
    return std::any_of(open_boxes->begin(), open_boxes->end(),
                       [&](const auto& b) { return b.contains(box); });
  };
  for (std::size_t k = 0; k < order.size(); ++k) {
    Shell& shell = shells_[order[k]];
    const Shell* parent = nullptr;
    for (std::size_t j = k; j-- > 0;) {  // the smallest first
      const Shell& other = shells_[order[j]];
      Eigen::AlignedBox3d reach = other.box;  // its surface's tolerance about it
      reach.min().array() -= surfaceTolMm(other);
      reach.max().array() += surfaceTolMm(other);
      if (reach.contains(shell.box) && within(shell, other)) {
        parent = &other;
        break;
      }
    }
    // A shell of no volume (a sheet closed on itself, both sides) has no winding to read: its
    // volume's sign is rounding's.
    const auto inward = [](const Shell& s) {
      const double size = s.box.diagonal().norm();
      return s.volume_mm3 < -1e-9 * size * size * size;
    };
    if (parent) {
      // In a void, an island whichever way it is wound (air in air is nothing: a helper's island
      // wound inward read as a void, a tool buried in it ok); in a solid, a void when wound the
      // other way, a body overlapping it when wound the same way.
      shell.sign = parent->sign < 0 || inward(shell) == inward(*parent) ? 1 : -1;
      shell.weight = shell.sign;
    } else if (inward(shell) && inOpen(shell.box)) {
      shell.sign = -1;  // a void of an open shell: air, whose inside counts for nothing
      shell.weight = 0;
    }
  }
}

const std::vector<int>& ClosedShells::cellAt(const Shell& shell, const Eigen::Vector3d& p) const {
  const int ix =
      std::clamp(static_cast<int>((p.x() - shell.box.min().x()) / shell.cell_x), 0, shell.nx - 1);
  const int iy =
      std::clamp(static_cast<int>((p.y() - shell.box.min().y()) / shell.cell_y), 0, shell.ny - 1);
  return shell.cells[static_cast<std::size_t>(ix) * shell.ny + iy];
}

bool ClosedShells::onSurface(const Shell& shell, const Eigen::Vector3d& p, double tol_mm) const {
  for (int t : cellAt(shell, p)) {
    const Eigen::Vector3d q = closestOnTriangle(
        p, vertices_[triangles_[t][0]], vertices_[triangles_[t][1]], vertices_[triangles_[t][2]]);
    if ((q - p).squaredNorm() <= tol_mm * tol_mm) return true;
  }
  return false;
}

double ClosedShells::surfaceTolMm(const Shell& shell) {
  // A millionth of the shell's size: a void that shares a face's plane with its solid (read in
  // floats, the same coordinates or a step apart) lies on it.
  return 1e-6 * std::max(1.0, shell.box.diagonal().norm());
}

bool ClosedShells::within(const Shell& inner, const Shell& outer) const {
  const double tol_mm = surfaceTolMm(outer);
  std::vector<int> ids;  // each vertex once
  ids.reserve(inner.triangles.size() * 3);
  for (int t : inner.triangles)
    for (int e = 0; e < 3; ++e) ids.push_back(triangles_[t][e]);
  std::sort(ids.begin(), ids.end());
  ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
  bool any_inside = false;  // strictly: a vertex off the surface, inside it
  for (int id : ids) {
    const Eigen::Vector3d& v = vertices_[id];
    if (onSurface(outer, v, tol_mm)) continue;
    if (crossings(outer, v) % 2 == 0) return false;
    any_inside = true;
  }
  return any_inside;
}

int ClosedShells::crossings(const Shell& shell, const Eigen::Vector3d& p) const {
  if (!shell.box.contains(p)) return 0;
  const Vec2 q(p.x(), p.y());
  int count = 0;
  for (int t : cellAt(shell, p)) {
    Eigen::Vector3d a = vertices_[triangles_[t][0]], b = vertices_[triangles_[t][1]],
                    c = vertices_[triangles_[t][2]];
    Vec2 a2(a.x(), a.y()), b2(b.x(), b.y()), c2(c.x(), c.y());
    const double area = orient(a2, b2, c2);
    if (area == 0.0) continue;  // seen edge-on: the ray grazes it
    if (area < 0.0) {           // counter-clockwise in projection
      std::swap(b, c);
      std::swap(b2, c2);
    }
    const double wa = orient(b2, c2, q), wb = orient(c2, a2, q), wc = orient(a2, b2, q);
    if (!owns(wa, b2, c2) || !owns(wb, c2, a2) || !owns(wc, a2, b2)) continue;
    const double z = (wa * a.z() + wb * b.z() + wc * c.z()) / (wa + wb + wc);
    count += z > p.z();
  }
  return count;
}

bool ClosedShells::contains(const Eigen::Vector3d& p) const {
  // The winding number: +1 inside each solid's shell, -1 inside each void's.
  int winding = 0;
  for (const Shell& shell : shells_)
    if (crossings(shell, p) % 2 == 1) winding += shell.weight;
  return winding > 0;
}

std::vector<std::vector<int>> nearlyClosedOpenShells(const TriangleMesh& mesh) {
  std::vector<std::vector<int>> out;
  for (std::vector<int>& shell : openShells(mesh)) {
    std::vector<std::pair<int, int>> edges;  // each triangle's edges, sorted: a lone one is open
    edges.reserve(shell.size() * 3);
    double area_mm2 = 0.0;
    for (const int k : shell) {
      const Eigen::Vector3i& t = mesh.triangles[static_cast<std::size_t>(k)];
      area_mm2 += 0.5 * (mesh.vertices[t[1]] - mesh.vertices[t[0]])
                            .cross(mesh.vertices[t[2]] - mesh.vertices[t[0]])
                            .norm();
      for (int e = 0; e < 3; ++e) edges.push_back(std::minmax(t[e], t[(e + 1) % 3]));
    }
    std::sort(edges.begin(), edges.end());
    double open_mm = 0.0;
    for (std::size_t i = 0; i < edges.size();) {
      std::size_t j = i + 1;
      while (j < edges.size() && edges[j] == edges[i]) ++j;
      if (j - i == 1)
        open_mm += (mesh.vertices[edges[i].second] - mesh.vertices[edges[i].first]).norm();
      i = j;
    }
    if (area_mm2 > 0.0 && open_mm < 3.0 * std::sqrt(area_mm2)) out.push_back(std::move(shell));
  }
  return out;
}

}  // namespace fieldpath::geometry
