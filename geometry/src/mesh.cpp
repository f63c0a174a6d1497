#include "fieldpath/geometry/mesh.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <utility>

#include <Eigen/Geometry>

namespace fieldpath::geometry {

bool MeshReport::closed() const {
  return triangles > 0 && non_finite_vertices == 0 && degenerate_triangles == 0 &&
         open_edges == 0 && non_manifold_edges == 0 && inconsistent_edges == 0;
}

std::string MeshReport::summary() const {
  std::string s =
      std::to_string(vertices) + " vertices, " + std::to_string(triangles) + " triangles";
  if (closed()) return s + ", closed";
  const std::pair<std::size_t, const char*> problems[] = {
      {non_finite_vertices, "non-finite vertices"},
      {degenerate_triangles, "degenerate triangles"},
      {open_edges, "open edges"},
      {non_manifold_edges, "non-manifold edges"},
      {inconsistent_edges, "inconsistently oriented edges"}};
  if (triangles == 0) s += ", empty";
  for (const auto& [count, what] : problems)
    if (count > 0) s += ", " + std::to_string(count) + " " + what;
  return s + ", not closed";
}

MeshReport validateMesh(const TriangleMesh& mesh) {
  MeshReport r;
  r.vertices = mesh.vertices.size();
  r.triangles = mesh.triangles.size();
  for (const auto& v : mesh.vertices)
    if (!v.allFinite()) ++r.non_finite_vertices;

  // Undirected edge (lo, hi) → uses in direction lo→hi and hi→lo.
  std::map<std::pair<int, int>, std::array<int, 2>> edges;
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& t : mesh.triangles) {
    const bool in_range = (t.array() >= 0).all() && (t.array() < n).all();
    if (!in_range || t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) {
      ++r.degenerate_triangles;
      if (!in_range) continue;
    } else {
      const auto& a = mesh.vertices[t[0]];
      const auto& b = mesh.vertices[t[1]];
      const auto& c = mesh.vertices[t[2]];
      if (!((b - a).cross(c - a).norm() > 0.0)) ++r.degenerate_triangles;
    }
    for (int e = 0; e < 3; ++e) {
      const int u = t[e], v = t[(e + 1) % 3];
      if (u == v) continue;
      auto& uses = edges[{std::min(u, v), std::max(u, v)}];
      ++uses[u < v ? 0 : 1];
    }
  }
  for (const auto& [edge, uses] : edges) {
    const int total = uses[0] + uses[1];
    if (total == 1)
      ++r.open_edges;
    else if (total > 2)
      ++r.non_manifold_edges;
    else if (uses[0] != 1)
      ++r.inconsistent_edges;
  }
  return r;
}

double meshArea(const TriangleMesh& mesh) {
  double area_mm2 = 0.0;
  for (const auto& t : mesh.triangles) {
    const auto& a = mesh.vertices[t[0]];
    area_mm2 += 0.5 * (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a).norm();
  }
  return area_mm2;
}

double meshVolume(const TriangleMesh& mesh) {
  double six_volume_mm3 = 0.0;
  for (const auto& t : mesh.triangles)
    six_volume_mm3 += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return six_volume_mm3 / 6.0;
}

std::vector<std::vector<int>> closedShells(const TriangleMesh& mesh) {
  const int n = static_cast<int>(mesh.vertices.size());
  for (const auto& t : mesh.triangles)
    if (!((t.array() >= 0).all() && (t.array() < n).all())) return {};  // validateMesh's job
  // Shells: triangles joined through their vertices (union-find on the vertices).
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  const auto root = [&](int v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  for (const auto& t : mesh.triangles)
    for (int e = 1; e < 3; ++e) parent[root(t[e])] = root(t[0]);
  // Closed: every edge used once each way.
  std::map<std::pair<int, int>, int> directed;  // (u, v) → uses
  for (const auto& t : mesh.triangles)
    for (int e = 0; e < 3; ++e) ++directed[{t[e], t[(e + 1) % 3]}];
  std::map<int, std::vector<int>> triangles_of;
  std::map<int, bool> closed;
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    const int shell = root(t[0]);
    triangles_of[shell].push_back(static_cast<int>(i));
    closed.try_emplace(shell, true);
    for (int e = 0; e < 3; ++e) {
      const int u = t[e], v = t[(e + 1) % 3];
      const auto back = directed.find({v, u});
      if (u == v || directed[{u, v}] != 1 || back == directed.end() || back->second != 1)
        closed[shell] = false;
    }
  }
  std::vector<std::vector<int>> out;
  for (auto& [shell, triangles] : triangles_of)
    if (closed[shell]) out.push_back(std::move(triangles));
  return out;
}

std::size_t orientClosedShells(TriangleMesh& mesh) {
  const std::vector<std::vector<int>> shells = closedShells(mesh);
  std::vector<double> volume(shells.size(), 0.0);
  std::vector<Eigen::AlignedBox3d> box(shells.size());
  for (std::size_t s = 0; s < shells.size(); ++s)
    for (int i : shells[s]) {
      const auto& t = mesh.triangles[i];
      const auto& a = mesh.vertices[t[0]];
      volume[s] += a.dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
      for (int e = 0; e < 3; ++e) box[s].extend(mesh.vertices[t[e]]);
    }
  // A shell inside another one's box may be a cavity, rightly wound inward: left alone.
  const auto inAnother = [&](std::size_t s) {
    for (std::size_t o = 0; o < shells.size(); ++o)
      if (o != s && box[o].contains(box[s])) return true;
    return false;
  };
  std::size_t turned = 0;
  for (std::size_t s = 0; s < shells.size(); ++s) {
    if (!(volume[s] < 0.0) || inAnother(s)) continue;
    ++turned;
    for (int i : shells[s]) std::swap(mesh.triangles[i][1], mesh.triangles[i][2]);
  }
  return turned;
}

}  // namespace fieldpath::geometry
