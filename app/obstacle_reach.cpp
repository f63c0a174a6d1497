/// Obstacles out of the field's reach over a path (obstacle_reach.h).
#include "obstacle_reach.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>

#include <Eigen/Geometry>

namespace fieldpath::app {
namespace {

/// Distance between two boxes (0 where they overlap), mm.
double boxDistance(const Eigen::AlignedBox3d& a, const Eigen::AlignedBox3d& b) {
  const Eigen::Vector3d gap =
      (a.min() - b.max()).cwiseMax(b.min() - a.max()).cwiseMax(Eigen::Vector3d::Zero());
  return gap.norm();
}

/// A piece of tool + holder: a cylinder about the axis from `from_mm` to `to_mm` above the tip,
/// of `radius_mm`, holding that part of the solid.
struct AxisPiece {
  double from_mm, to_mm, radius_mm;
};

/// The tool's cutting body and shank (to its length, of its radius), the gap up to the holder
/// if any, and each span between two holder stations (of the larger radius): one capsule of the
/// largest radius over the whole length kept a wall 8 mm from the ball 5 mm "near" (the holder's
/// 12 mm radius taken down to the tip).
std::vector<AxisPiece> axisPieces(const Scene& scene) {
  // (a ball's sphere lies in its cylinder from the tip to 2R)
  std::vector<AxisPiece> pieces{
      {0.0, std::max(scene.tool.length_mm, 2.0 * scene.tool.radius_mm), scene.tool.radius_mm}};
  const std::vector<geometry::HolderStation>& holder = scene.holder;
  if (!holder.empty() && holder.front().z_mm > scene.tool.length_mm)
    pieces.push_back({scene.tool.length_mm, holder.front().z_mm,
                      std::max(scene.tool.radius_mm, holder.front().radius_mm)});
  for (std::size_t i = 0; i < holder.size(); ++i) {
    const geometry::HolderStation& next = holder[i + 1 < holder.size() ? i + 1 : i];
    pieces.push_back({holder[i].z_mm, next.z_mm, std::max(holder[i].radius_mm, next.radius_mm)});
  }
  return pieces;
}

/// The boxes of groups of nearby triangles of a mesh (sorted along the Morton curve of their
/// centroids, at most ~256 groups): one box round a curved blade or an L-shaped wall lies far
/// nearer the tool than the mesh does.
std::vector<Eigen::AlignedBox3d> clusterBoxes(const geometry::TriangleMesh& mesh) {
  Eigen::AlignedBox3d all;
  for (const Eigen::Vector3d& v : mesh.vertices) all.extend(v);
  const std::size_t n = mesh.triangles.size();
  if (all.isEmpty()) return {};
  if (n == 0) return {all};
  const Eigen::Vector3d size = all.sizes().cwiseMax(1e-9);
  // 10 bits an axis, interleaved.
  auto spread = [](std::uint64_t x) {
    std::uint64_t r = 0;
    for (int b = 0; b < 10; ++b) r |= ((x >> b) & 1u) << (3 * b);
    return r;
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> order(n);
  for (std::size_t t = 0; t < n; ++t) {
    const Eigen::Vector3i& tri = mesh.triangles[t];
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) c += mesh.vertices[std::size_t(tri[k])];
    const Eigen::Vector3d u =
        ((c / 3.0 - all.min()).cwiseQuotient(size) * 1023.0).cwiseMax(0.0).cwiseMin(1023.0);
    order[t] = {spread(std::uint64_t(u.x())) | spread(std::uint64_t(u.y())) << 1 |
                    spread(std::uint64_t(u.z())) << 2,
                t};
  }
  std::sort(order.begin(), order.end());
  const std::size_t group = std::max<std::size_t>(16, (n + 255) / 256);
  std::vector<Eigen::AlignedBox3d> boxes;
  for (std::size_t first = 0; first < n; first += group) {
    Eigen::AlignedBox3d box;
    for (std::size_t k = first; k < std::min(n, first + group); ++k)
      for (int j = 0; j < 3; ++j)
        box.extend(mesh.vertices[std::size_t(mesh.triangles[order[k].second][j])]);
    boxes.push_back(box);
  }
  return boxes;
}

}  // namespace

std::vector<ObstacleOutOfReach> obstaclesOutOfReach(const Scene& scene,
                                                    const geometry::PathFile& path,
                                                    double reach_mm) {
  const std::vector<AxisPiece> pieces = axisPieces(scene);
  std::vector<ObstacleOutOfReach> out;
  if (path.postures.empty()) return out;
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    const std::vector<Eigen::AlignedBox3d> boxes = clusterBoxes(scene.obstacles[i]);
    if (boxes.empty()) continue;
    Eigen::AlignedBox3d whole;
    for (const Eigen::AlignedBox3d& cluster : boxes) whole.extend(cluster);
    // Every box of every piece at every posture: a lower bound of the distance (each box holds
    // its piece of the solid, each cluster box its triangles); done once within reach.
    double nearest = std::numeric_limits<double>::infinity();
    for (const geometry::Posture& p : path.postures) {
      for (const AxisPiece& piece : pieces) {
        Eigen::AlignedBox3d box(p.tip_mm + piece.from_mm * p.axis);
        box.extend(p.tip_mm + piece.to_mm * p.axis);
        // A cylinder's disc of radius r about unit axis a spans r sqrt(1 - a_k²) along axis k
        // (a box padded by r all round kept a holder above a wall's top 4 mm "near" it).
        const Eigen::Vector3d pad =
            piece.radius_mm * (1.0 - p.axis.array().square()).max(0.0).sqrt().matrix();
        box.min() -= pad;
        box.max() += pad;
        if (boxDistance(box, whole) >= nearest) continue;  // no cluster nearer than the whole
        for (const Eigen::AlignedBox3d& cluster : boxes)
          nearest = std::min(nearest, boxDistance(box, cluster));
        if (nearest <= reach_mm) break;
      }
      if (nearest <= reach_mm) break;
    }
    if (nearest > reach_mm) out.push_back({i, nearest});
  }
  return out;
}

std::string obstaclesOutOfReachNote(const Scene& scene,
                                    const std::vector<ObstacleOutOfReach>& out_of_reach,
                                    double reach_mm) {
  if (out_of_reach.empty()) return {};
  const auto mm = [](double v) {
    char text[32];
    std::snprintf(text, sizeof text, "%.3g", v);
    return std::string(text);
  };
  std::string named;
  for (std::size_t k = 0; k < out_of_reach.size(); ++k) {
    const std::size_t i = out_of_reach[k].obstacle;
    if (k == 3) {
      named += " and " + std::to_string(out_of_reach.size() - 3) + " more";
      break;
    }
    named += k == 0 ? "" : k + 1 == out_of_reach.size() ? " and " : ", ";
    named +=
        (i < scene.obstacle_files.size() && i < scene.obstacle_keys.size()
             ? scene.obstacle_keys[i] + " (" + scene.obstacle_files[i].filename().string() + ", "
             : "the impeller's blade " + std::to_string(i + 1 - scene.obstacle_files.size()) +
                   " (") +
        "at least " + mm(out_of_reach[k].at_least_mm) + " mm away)";
  }
  const bool one = out_of_reach.size() == 1;
  const bool all = out_of_reach.size() == scene.obstacles.size();
  return named + (one ? " stays" : " stay") + " farther than field.r0 (" + mm(reach_mm) +
         " mm) from the tool and holder at every posture: " +
         (all ? "no obstacle steered the path (its axes are the nominal ones)"
              : std::string(one ? "it" : "they") + " steered nothing") +
         (one ? " and it is" : " and they are") + " only checked for clearance; if " +
         (one ? "it" : "they") + " should steer, " + (one ? "is it" : "are they") +
         " in the path's frame and units?";
}

}  // namespace fieldpath::app
