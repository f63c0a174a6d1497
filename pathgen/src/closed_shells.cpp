#include "closed_shells.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace fieldpath::pathgen {
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

}  // namespace

ClosedShells::ClosedShells(const geometry::TriangleMesh& mesh)
    : vertices_(mesh.vertices), triangles_(mesh.triangles) {
  const std::vector<std::vector<int>> shell_list = geometry::closedShells(mesh);
  for (const std::vector<int>& shell_triangles : shell_list) {
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
    // the products cancel): a cavity's shell, wound into the void, is < 0.
    const Eigen::Vector3d origin = vertices_[triangles_[shell_triangles.front()][0]];
    for (int t : shell_triangles) {
      const Eigen::Vector3d a = vertices_[triangles_[t][0]] - origin;
      shell.volume_mm3 +=
          a.dot(
              (vertices_[triangles_[t][1]] - origin).cross(vertices_[triangles_[t][2]] - origin)) /
          6.0;
    }
    anchors_.push_back(vertices_[triangles_[shell_triangles.front()][0]]);
    shells_.push_back(std::move(shell));
  }
  // A shell wound inward inside another one is a void of it: its inside is not the part's (a
  // tool in a 200 mm box's void read as buried, "2999.9 um"). Wound inward and inside none, it is
  // a solid exported inside out, its inside the part's all the same.
  // Wholly inside: every vertex (one inside, the rest out, is a body overlapping it, wound
  // inward: a reviewer's case).
  for (std::size_t i = 0; i < shells_.size(); ++i) {
    if (shells_[i].volume_mm3 >= 0.0) continue;
    for (std::size_t j = 0; j < shells_.size() && shells_[i].sign > 0; ++j) {
      if (j == i || !(shells_[j].volume_mm3 > 0.0)) continue;
      bool inside = true;
      for (std::size_t k = 0; inside && k < shell_list[i].size(); ++k)
        for (int e = 0; inside && e < 3; ++e)
          inside = crossings(shells_[j], vertices_[triangles_[shell_list[i][k]][e]]) % 2 == 1;
      if (inside) shells_[i].sign = -1;
    }
  }
}

int ClosedShells::crossings(const Shell& shell, const Eigen::Vector3d& p) const {
  if (!shell.box.contains(p)) return 0;
  const Vec2 q(p.x(), p.y());
  const int ix =
      std::clamp(static_cast<int>((p.x() - shell.box.min().x()) / shell.cell_x), 0, shell.nx - 1);
  const int iy =
      std::clamp(static_cast<int>((p.y() - shell.box.min().y()) / shell.cell_y), 0, shell.ny - 1);
  int count = 0;
  for (int t : shell.cells[static_cast<std::size_t>(ix) * shell.ny + iy]) {
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
    if (crossings(shell, p) % 2 == 1) winding += shell.sign;
  return winding > 0;
}

}  // namespace fieldpath::pathgen
