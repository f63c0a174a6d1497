#include "fieldpath/geometry/mesh.h"

#include "fieldpath/geometry/closed_shells.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <utility>
#include <vector>

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

  // Every edge use as (lo << 32 | hi) << 1 | direction (0: lo→hi), sorted: an undirected edge's
  // uses are one run (vertex indices < 2^31; a std::map took 1 s at a million triangles).
  std::vector<std::uint64_t> edges;
  edges.reserve(3 * mesh.triangles.size());
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
      const std::uint64_t lo = std::uint32_t(std::min(u, v)), hi = std::uint32_t(std::max(u, v));
      edges.push_back((lo << 32 | hi) << 1 | (u < v ? 0u : 1u));
    }
  }
  std::sort(edges.begin(), edges.end());
  for (std::size_t first = 0; first < edges.size();) {
    std::array<int, 2> uses{0, 0};
    std::size_t last = first;
    for (; last < edges.size() && (edges[last] >> 1) == (edges[first] >> 1); ++last)
      ++uses[edges[last] & 1u];
    first = last;
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

bool hasNoArea(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const double longest2 =
      std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()});
  return !((b - a).cross(c - a).norm() > 1e-6 * longest2);
}

double meshVolume(const TriangleMesh& mesh) {
  double six_volume_mm3 = 0.0;
  for (const auto& t : mesh.triangles)
    six_volume_mm3 += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]]));
  return six_volume_mm3 / 6.0;
}

namespace {
/// The shells of a mesh (triangles joined through their vertices) and whether each is closed.
struct Shell {
  std::vector<int> triangles;
  bool closed;
};
std::vector<Shell> shellsOf(const TriangleMesh& mesh) {
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
  // A triangle written again (the same three vertices the same way round, as some exports do) is
  // the same surface once: its repeats are left out of the shells.
  std::vector<std::pair<std::array<int, 3>, int>> cycles(mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    const int first = t[0] <= t[1] && t[0] <= t[2] ? 0 : t[1] <= t[2] ? 1 : 2;
    cycles[i] = {{t[first], t[(first + 1) % 3], t[(first + 2) % 3]}, static_cast<int>(i)};
  }
  std::sort(cycles.begin(), cycles.end());
  std::vector<char> repeat(mesh.triangles.size(), 0);
  for (std::size_t i = 1; i < cycles.size(); ++i)
    if (cycles[i].first == cycles[i - 1].first)
      repeat[static_cast<std::size_t>(cycles[i].second)] = 1;
  // Closed: every edge used as many times each way (once each way on a manifold; bodies that
  // share a face or an edge, as a multi-body export writes them, use it twice each way: the
  // vertical-ray parity of ClosedShells still tells inside from outside). The directed edges as
  // sorted keys (u << 32 | v): a count is the length of a key's run (a std::map of pairs took 1 s
  // at a million triangles). Counted three ways, the first that closes a shell kept: without the
  // repeats; also without triangles of no area (a needle or cap touching a solid at a vertex
  // opened it: a tool inside read 20 mm clear, a review's; they are surface for the distances,
  // not for the inside); with every triangle (two bodies sharing a face, each writing it the same
  // way round, need both copies).
  const auto key = [](int u, int v) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(v);
  };
  std::vector<char> flat(mesh.triangles.size(), 0);
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    flat[i] = hasNoArea(mesh.vertices[t[0]], mesh.vertices[t[1]], mesh.vertices[t[2]]);
  }
  const auto counted = [&](int way, std::size_t i) {
    return way == 2 || (!repeat[i] && (way == 0 || !flat[i]));
  };
  // Per shell (its union-find root): the way that closed it, -1 while none has.
  std::vector<int> closed_by(static_cast<std::size_t>(n), -1);
  for (int way = 0; way < 3; ++way) {
    std::vector<std::uint64_t> directed;
    directed.reserve(3 * mesh.triangles.size());
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      if (!counted(way, i) || closed_by[std::size_t(root(mesh.triangles[i][0]))] >= 0) continue;
      const auto& t = mesh.triangles[i];
      for (int e = 0; e < 3; ++e) directed.push_back(key(t[e], t[(e + 1) % 3]));
    }
    if (directed.empty()) break;
    std::sort(directed.begin(), directed.end());
    const auto uses = [&](std::uint64_t k) {
      const auto [first, last] = std::equal_range(directed.begin(), directed.end(), k);
      return last - first;
    };
    // Per shell not closed yet (its union-find root): closed this way unless an edge says not.
    std::vector<char> ok(static_cast<std::size_t>(n), 1), any(static_cast<std::size_t>(n), 0);
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      const std::size_t shell = std::size_t(root(t[0]));
      if (closed_by[shell] >= 0 || !counted(way, i) || !ok[shell]) continue;
      any[shell] = 1;
      for (int e = 0; e < 3; ++e) {
        const int u = t[e], v = t[(e + 1) % 3];
        if (u == v || uses(key(u, v)) != uses(key(v, u))) {
          ok[shell] = 0;
          break;
        }
      }
    }
    for (std::size_t shell = 0; shell < std::size_t(n); ++shell)
      if (closed_by[shell] < 0 && any[shell] && ok[shell]) closed_by[shell] = way;
  }
  // Each shell's triangles as the way that closed it counts them; an open one's but the repeats.
  std::vector<std::vector<int>> triangles_of(static_cast<std::size_t>(n));
  std::vector<char> closed(static_cast<std::size_t>(n), 0);
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const std::size_t shell = std::size_t(root(mesh.triangles[i][0]));
    const int way = closed_by[shell];
    closed[shell] = way >= 0;
    if (way >= 0 ? counted(way, i) : !repeat[i]) triangles_of[shell].push_back(static_cast<int>(i));
  }
  std::vector<Shell> out;
  for (std::size_t shell = 0; shell < triangles_of.size(); ++shell)
    if (!triangles_of[shell].empty())
      out.push_back({std::move(triangles_of[shell]), closed[shell] != 0});
  return out;
}
}  // namespace

std::vector<std::vector<int>> closedShells(const TriangleMesh& mesh) {
  std::vector<std::vector<int>> out;
  for (Shell& shell : shellsOf(mesh))
    if (shell.closed) out.push_back(std::move(shell.triangles));
  return out;
}

std::vector<std::vector<int>> openShells(const TriangleMesh& mesh) {
  std::vector<std::vector<int>> out;
  for (Shell& shell : shellsOf(mesh))
    if (!shell.closed) out.push_back(std::move(shell.triangles));
  return out;
}

std::size_t orientClosedShells(TriangleMesh& mesh) {
  const ClosedShells shells(mesh);
  std::size_t turned = 0;
  for (std::size_t s = 0; s < shells.size(); ++s) {
    // A solid's shell faces out of it, a void's into the void (out of the solid around it).
    if ((shells.volumeMm3(s) < 0.0) == (shells.sign(s) < 0)) continue;
    ++turned;
    for (int i : shells.triangles(s)) std::swap(mesh.triangles[i][1], mesh.triangles[i][2]);
  }
  return turned;
}

}  // namespace fieldpath::geometry
