/// Open obstacle sheets turned to face the tool (open_sheets.h).
#include "open_sheets.h"

#include <algorithm>
#include <array>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace fieldpath::pathgen {

using geometry::Vec3;

std::vector<OpenSheet> sheetsFacingAway(std::span<const geometry::TriangleMesh> meshes,
                                        std::span<const Vec3> points, double near_mm) {
  // Every open shell's triangles, up to kMaxProbes of them in all (evenly strided): each point
  // votes for the side of the nearest one's centre. Bounded whatever the count of shells (a
  // triangle soup is a shell a triangle).
  constexpr std::size_t kMaxProbes = 20000;
  struct Probe {
    Vec3 centre, normal;
    std::size_t mesh, shell;
  };
  std::vector<std::vector<std::vector<int>>> shells(meshes.size());
  std::size_t open_triangles = 0;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    shells[m] = geometry::openShells(meshes[m]);
    for (const auto& shell : shells[m]) open_triangles += shell.size();
  }
  if (open_triangles == 0 || points.empty()) return {};
  const std::size_t stride = std::max<std::size_t>(1, open_triangles / kMaxProbes);
  std::vector<Probe> probes;
  std::size_t counter = 0;
  for (std::size_t m = 0; m < meshes.size(); ++m)
    for (std::size_t s = 0; s < shells[m].size(); ++s)
      for (const int t : shells[m][s]) {
        if (counter++ % stride != 0) continue;
        const auto& tri = meshes[m].triangles[static_cast<std::size_t>(t)];
        const Vec3& a = meshes[m].vertices[tri[0]];
        const Vec3& b = meshes[m].vertices[tri[1]];
        const Vec3& c = meshes[m].vertices[tri[2]];
        const Vec3 normal = (b - a).cross(c - a);
        if (!(normal.norm() > 0.0)) continue;
        probes.push_back({(a + b + c) / 3.0, normal.normalized(), m, s});
      }
  // Votes per shell: points in front of it, behind it.
  std::vector<std::vector<std::array<std::size_t, 2>>> votes(meshes.size());
  for (std::size_t m = 0; m < meshes.size(); ++m) votes[m].assign(shells[m].size(), {0, 0});
  // Each point's nearest probe (on all cores: points × probes reaches 1e8 on a mesh job), then
  // the votes in point order.
  const double near_sq = near_mm * near_mm;
  std::vector<const Probe*> nearest(points.size(), nullptr);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, points.size(), 64), [&](const auto& range) {
    for (std::size_t i = range.begin(); i != range.end(); ++i) {
      double best = near_sq;
      for (const Probe& probe : probes) {
        const double d = (points[i] - probe.centre).squaredNorm();
        if (d <= best) {
          best = d;
          nearest[i] = &probe;
        }
      }
    }
  });
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (nearest[i] == nullptr) continue;
    const double side = (points[i] - nearest[i]->centre).dot(nearest[i]->normal);
    if (side != 0.0) ++votes[nearest[i]->mesh][nearest[i]->shell][side > 0.0 ? 0 : 1];
  }
  std::vector<OpenSheet> away;
  for (std::size_t m = 0; m < meshes.size(); ++m)
    for (std::size_t s = 0; s < shells[m].size(); ++s)
      if (votes[m][s][1] > votes[m][s][0]) away.push_back({m, std::move(shells[m][s])});
  return away;
}

void turnSheets(std::vector<geometry::TriangleMesh>& meshes, std::span<const OpenSheet> sheets) {
  for (const OpenSheet& sheet : sheets)
    for (const int t : sheet.triangles) {
      auto& triangle = meshes[sheet.mesh].triangles[static_cast<std::size_t>(t)];
      std::swap(triangle[1], triangle[2]);
    }
}

}  // namespace fieldpath::pathgen
