/// Mends the export defects that make a solid's shell read as open (mesh.h, repairShells): slivers
/// of no area, T-junctions, facets wound against their neighbours. A solid with any of them had
/// no inside for the checks: a tool wholly inside it read as clear (a helper's finding).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <queue>
#include <utility>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::geometry {
namespace {

/// Relative height under which a triangle is a sliver, and a vertex lies on an edge: the height
/// over the edge against the edge's length plus the coordinates' size (a float STL's points sit
/// off their edge by ~1e-7 of their size).
constexpr double kFlatRelative = 1e-6;
/// The T-junction search gives up past this many (edge, vertex) tests: a triangle soup's every
/// edge is open, and its repair is no mend of a solid.
constexpr std::size_t kMaxTests = 50'000'000;

std::uint64_t edgeKey(int u, int v) {
  const auto lo = std::uint32_t(std::min(u, v)), hi = std::uint32_t(std::max(u, v));
  return std::uint64_t(lo) << 32 | hi;
}

/// Per undirected edge (sorted key, uses) over the triangles.
std::vector<std::pair<std::uint64_t, int>> edgeUses(const std::vector<Eigen::Vector3i>& triangles) {
  std::vector<std::uint64_t> keys;
  keys.reserve(3 * triangles.size());
  for (const auto& t : triangles)
    for (int e = 0; e < 3; ++e) keys.push_back(edgeKey(t[e], t[(e + 1) % 3]));
  std::sort(keys.begin(), keys.end());
  std::vector<std::pair<std::uint64_t, int>> out;
  for (std::size_t i = 0; i < keys.size();) {
    std::size_t j = i;
    while (j < keys.size() && keys[j] == keys[i]) ++j;
    out.emplace_back(keys[i], static_cast<int>(j - i));
    i = j;
  }
  return out;
}

int usesOf(const std::vector<std::pair<std::uint64_t, int>>& uses, std::uint64_t key) {
  const auto it = std::lower_bound(uses.begin(), uses.end(), std::make_pair(key, 0));
  return it != uses.end() && it->first == key ? it->second : 0;
}

/// The vertices lying on edge u-v strictly between its ends, ordered from u, from `by_x` (sorted
/// on `axis`); `budget` counts the tests made.
std::vector<int> pointsOnEdge(const TriangleMesh& mesh, int u, int v, int axis,
                              const std::vector<std::pair<double, int>>& by_x,
                              std::size_t& budget) {
  const Eigen::Vector3d& a = mesh.vertices[u];
  const Eigen::Vector3d& b = mesh.vertices[v];
  const Eigen::Vector3d d = b - a;
  const double length = d.norm();
  if (!(length > 0.0)) return {};
  const double tol = kFlatRelative * (length + a.cwiseAbs().maxCoeff() + b.cwiseAbs().maxCoeff());
  const double x0 = std::min(a[axis], b[axis]) - tol, x1 = std::max(a[axis], b[axis]) + tol;
  std::vector<std::pair<double, int>> found;
  for (auto it = std::lower_bound(by_x.begin(), by_x.end(), std::make_pair(x0, -1));
       it != by_x.end() && it->first <= x1; ++it) {
    if (++budget > kMaxTests) return {};
    const int w = it->second;
    if (w == u || w == v) continue;
    const Eigen::Vector3d p = mesh.vertices[w] - a;
    const double along = p.dot(d) / length;
    if (along <= tol || along >= length - tol) continue;
    if ((p - along / length * d).norm() <= tol) found.emplace_back(along, w);
  }
  std::sort(found.begin(), found.end());
  std::vector<int> out;
  for (const auto& f : found)
    if (out.empty() || out.back() != f.second) out.push_back(f.second);
  return out;
}

/// A triangle of no area whose apex stands strictly inside its longest edge (the edge's
/// neighbours then meet the apex: a T-junction, mended below). A needle (two corners nearly one:
/// an edge too short to weld here) is no sliver: left out, it would leave a hole.
bool isSliver(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c) {
  const Eigen::Vector3d* p[3] = {&a, &b, &c};
  int longest = 0;
  double longest2 = 0.0;
  for (int e = 0; e < 3; ++e) {
    const double l2 = (*p[(e + 1) % 3] - *p[e]).squaredNorm();
    if (l2 > longest2) longest2 = l2, longest = e;
  }
  if (!hasNoArea(a, b, c)) return false;
  const Eigen::Vector3d& u = *p[longest];
  const Eigen::Vector3d& v = *p[(longest + 1) % 3];
  const Eigen::Vector3d& apex = *p[(longest + 2) % 3];
  const double t = (apex - u).dot(v - u) / longest2;
  const double margin = kFlatRelative * (1.0 + (u.cwiseAbs().maxCoeff() + v.cwiseAbs().maxCoeff()) /
                                                   std::sqrt(longest2));
  return t > margin && t < 1.0 - margin;
}

/// Splits every open edge at the open-edge vertices that lie on it (a T-junction: one side's edge
/// is two of the other side's), one edge a triangle a round, until none is left. Returns the
/// splits made, or 0 with the mesh unchanged and `gave_up` set where the search gives up.
std::size_t splitTJunctions(TriangleMesh& mesh, bool& gave_up) {
  std::size_t splits = 0, budget = 0;
  std::vector<Eigen::Vector3i> triangles = mesh.triangles;
  for (int round = 0; round < 8; ++round) {
    const auto uses = edgeUses(triangles);
    // The open edges' vertices, sorted along the axis they spread most on (a sheet in a plane
    // x = const along x was one run of every vertex).
    std::vector<int> open_vertices;
    Eigen::AlignedBox3d spread;
    for (const auto& [key, count] : uses)
      if (count == 1)
        for (const int w : {int(key >> 32), int(key & 0xffffffffu)}) {
          open_vertices.push_back(w);
          spread.extend(mesh.vertices[w]);
        }
    if (open_vertices.empty()) break;
    Eigen::Index axis = 0;
    spread.sizes().maxCoeff(&axis);
    std::vector<std::pair<double, int>> by_x;  // (coordinate on that axis, vertex)
    for (const int w : open_vertices) by_x.emplace_back(mesh.vertices[w][axis], w);
    std::sort(by_x.begin(), by_x.end());
    by_x.erase(std::unique(by_x.begin(), by_x.end()), by_x.end());
    if (by_x.empty()) break;
    std::vector<Eigen::Vector3i> next;
    next.reserve(triangles.size());
    std::size_t made = 0;
    for (const auto& t : triangles) {
      bool split = false;
      for (int e = 0; e < 3 && !split; ++e) {
        const int a = t[e], b = t[(e + 1) % 3], c = t[(e + 2) % 3];
        if (usesOf(uses, edgeKey(a, b)) != 1) continue;
        const std::vector<int> on = pointsOnEdge(mesh, a, b, int(axis), by_x, budget);
        if (budget > kMaxTests) {
          gave_up = true;
          return 0;
        }
        if (on.empty()) continue;
        // (a, b, c) → (a, p1, c), (p1, p2, c), ..., (pk, b, c): the same winding, the same surface.
        int from = a;
        for (const int p : on) {
          next.emplace_back(from, p, c);
          from = p;
        }
        next.emplace_back(from, b, c);
        made += on.size();
        split = true;
      }
      if (!split) next.push_back(t);
    }
    if (made == 0) break;
    splits += made;
    triangles = std::move(next);
  }
  mesh.triangles = std::move(triangles);
  return splits;
}

/// Turns the facets of each closed, manifold shell (every edge used by two triangles) that are
/// wound against their neighbours: the larger part of the shell's facets keeps its winding.
/// Returns the facets turned.
std::size_t agreeWindings(TriangleMesh& mesh) {
  const auto uses = edgeUses(mesh.triangles);
  // Each undirected edge's two triangles (only where every edge of a shell has two).
  std::vector<std::pair<std::uint64_t, int>> edge_triangle;
  edge_triangle.reserve(3 * mesh.triangles.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const auto& t = mesh.triangles[i];
    for (int e = 0; e < 3; ++e)
      edge_triangle.emplace_back(edgeKey(t[e], t[(e + 1) % 3]), static_cast<int>(i));
  }
  std::sort(edge_triangle.begin(), edge_triangle.end());
  const auto other = [&](std::uint64_t key, int self) {
    const auto it =
        std::lower_bound(edge_triangle.begin(), edge_triangle.end(), std::make_pair(key, -1));
    for (auto j = it; j != edge_triangle.end() && j->first == key; ++j)
      if (j->second != self) return j->second;
    return -1;
  };
  const auto sameWay = [&](int i, int j, int u, int v) {  // j traverses u → v as i does
    const auto& s = mesh.triangles[j];
    for (int e = 0; e < 3; ++e)
      if (s[e] == u && s[(e + 1) % 3] == v) return true;
    return false;
  };
  std::vector<int> component(mesh.triangles.size(), -1);
  std::vector<char> flip(mesh.triangles.size(), 0);
  std::size_t turned = 0;
  for (std::size_t seed = 0; seed < mesh.triangles.size(); ++seed) {
    if (component[seed] >= 0) continue;
    std::vector<int> members{static_cast<int>(seed)};
    component[seed] = static_cast<int>(seed);
    bool manifold = true;
    std::size_t flipped = 0;
    for (std::size_t k = 0; k < members.size(); ++k) {
      const int i = members[k];
      const auto& t = mesh.triangles[i];
      for (int e = 0; e < 3; ++e) {
        // i's edge as i will be wound (flipped or not).
        int u = t[e], v = t[(e + 1) % 3];
        if (flip[i]) std::swap(u, v);
        const std::uint64_t key = edgeKey(u, v);
        if (usesOf(uses, key) != 2) {
          manifold = false;
          continue;
        }
        const int j = other(key, i);
        if (j < 0 || component[j] >= 0) continue;
        component[j] = static_cast<int>(seed);
        flip[j] = sameWay(i, j, u, v) ? 1 : 0;  // a neighbour traverses a shared edge the other way
        flipped += flip[j];
        members.push_back(j);
      }
    }
    if (!manifold || flipped == 0) continue;
    const bool turn_flipped = 2 * flipped <= members.size();
    for (const int i : members)
      if ((flip[i] != 0) == turn_flipped) {
        std::swap(mesh.triangles[i][1], mesh.triangles[i][2]);
        ++turned;
      }
  }
  return turned;
}

}  // namespace

std::vector<char> repeatedFacets(const TriangleMesh& mesh) {
  using Key = std::array<double, 9>;
  const auto& v = mesh.vertices;
  // A triangle's points from its least one (lexicographically) on, in its own cyclic order.
  auto keyOf = [&v](const Eigen::Vector3i& t) {
    int first = 0;
    for (int e = 1; e < 3; ++e) {
      const Eigen::Vector3d &a = v[std::size_t(t[e])], &b = v[std::size_t(t[first])];
      if (std::lexicographical_compare(a.data(), a.data() + 3, b.data(), b.data() + 3)) first = e;
    }
    Key key;
    for (int e = 0; e < 3; ++e)
      for (int a = 0; a < 3; ++a)
        key[std::size_t(3 * e + a)] = v[std::size_t(t[(first + e) % 3])][a];
    return key;
  };
  std::vector<std::pair<Key, std::size_t>> keys;
  keys.reserve(mesh.triangles.size());
  const int nv = static_cast<int>(v.size());
  for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
    const Eigen::Vector3i& t = mesh.triangles[i];
    if (t.minCoeff() >= 0 && t.maxCoeff() < nv) keys.emplace_back(keyOf(t), i);  // (others: not)
  }
  std::sort(keys.begin(), keys.end());
  std::vector<char> repeated(mesh.triangles.size(), 0);
  for (std::size_t k = 1; k < keys.size(); ++k)
    if (keys[k].first == keys[k - 1].first) repeated[keys[k].second] = 1;
  return repeated;
}

ShellRepair repairShells(TriangleMesh& mesh) {
  ShellRepair out;
  const MeshReport before = validateMesh(mesh);
  if (before.non_finite_vertices > 0 || (before.open_edges == 0 && before.inconsistent_edges == 0))
    return out;  // closed already (or not a mesh to mend)
  // Slivers: no surface to sample or to machine, but edges that leave their neighbours open.
  std::vector<Eigen::Vector3i> kept;
  kept.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) {
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    const Eigen::Vector3d& b = mesh.vertices[t[1]];
    const Eigen::Vector3d& c = mesh.vertices[t[2]];
    const bool sliver = t[0] == t[1] || t[1] == t[2] || t[2] == t[0] || isSliver(a, b, c);
    if (sliver)
      ++out.slivers_removed;
    else
      kept.push_back(t);
  }
  if (kept.empty()) return {};  // all slivers: left for the caller's "no surface"
  TriangleMesh mended{mesh.vertices, std::move(kept)};
  bool gave_up = false;
  out.edges_split = splitTJunctions(mended, gave_up);
  if (gave_up) {  // no mend at all rather than a part of one, and said
    ShellRepair said;
    said.search_given_up = true;
    said.open_edges_before = said.open_edges_after = before.open_edges;
    return said;
  }
  out.facets_turned = agreeWindings(mended);
  // Kept only where it closes something and nothing gets worse: no count up, no closed shell
  // opened (a multi-body file's closed body opened by a mend of another lost its inside).
  const MeshReport after = validateMesh(mended);
  const bool better =
      after.open_edges < before.open_edges || after.inconsistent_edges < before.inconsistent_edges;
  const bool worse = after.open_edges > before.open_edges ||
                     after.inconsistent_edges > before.inconsistent_edges ||
                     after.non_manifold_edges > before.non_manifold_edges ||
                     closedShells(mended).size() < closedShells(mesh).size();
  if (!better || worse) return {};
  out.open_edges_before = before.open_edges;
  out.open_edges_after = after.open_edges;
  // A sliver none of whose edges the mended shells use closed nothing (a lone needle or cap, 100
  // mm long: left out, a tool through it read 200 mm clear): it is surface, and stays (the
  // clearance tree pads it, pathgen/clearance.cpp).
  std::vector<std::uint64_t> used;
  used.reserve(3 * mended.triangles.size());
  for (const auto& t : mended.triangles)
    for (int e = 0; e < 3; ++e) used.push_back(edgeKey(t[e], t[(e + 1) % 3]));
  std::sort(used.begin(), used.end());
  for (const auto& t : mesh.triangles) {
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0]) continue;
    const Eigen::Vector3d& a = mesh.vertices[t[0]];
    if (!isSliver(a, mesh.vertices[t[1]], mesh.vertices[t[2]])) continue;
    bool touches = false;
    for (int e = 0; e < 3 && !touches; ++e)
      touches = std::binary_search(used.begin(), used.end(), edgeKey(t[e], t[(e + 1) % 3]));
    if (!touches) {
      mended.triangles.push_back(t);
      --out.slivers_removed;
    }
  }
  if (!out.any()) return {};
  out.open_edges_after = validateMesh(mended).open_edges;
  mesh = std::move(mended);
  return out;
}

}  // namespace fieldpath::geometry
