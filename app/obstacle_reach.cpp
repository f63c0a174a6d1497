/// Obstacles out of the field's reach over a path (obstacle_reach.h).
#include "obstacle_reach.h"

#include <algorithm>
#include <cmath>
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

}  // namespace

std::vector<ObstacleOutOfReach> obstaclesOutOfReach(const Scene& scene,
                                                    const geometry::PathFile& path,
                                                    double reach_mm) {
  // The tool and holder as a capsule: the axis from the tip to the top of the holder (or of the
  // tool), their largest radius around it.
  double top_mm = scene.tool.length_mm, radius_mm = scene.tool.radius_mm;
  for (const geometry::HolderStation& station : scene.holder) {
    top_mm = std::max(top_mm, station.z_mm);
    radius_mm = std::max(radius_mm, station.radius_mm);
  }
  std::vector<Eigen::AlignedBox3d> boxes;
  for (const geometry::TriangleMesh& mesh : scene.obstacles) {
    Eigen::AlignedBox3d box;
    for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
    boxes.push_back(box);
  }
  std::vector<double> nearest(boxes.size(), std::numeric_limits<double>::infinity());
  for (const geometry::Posture& p : path.postures) {
    Eigen::AlignedBox3d capsule(p.tip_mm);
    capsule.extend(p.tip_mm + top_mm * p.axis);
    capsule.min().array() -= radius_mm;
    capsule.max().array() += radius_mm;
    for (std::size_t i = 0; i < boxes.size(); ++i)
      nearest[i] = std::min(nearest[i], boxDistance(capsule, boxes[i]));
  }
  std::vector<ObstacleOutOfReach> out;
  for (std::size_t i = 0; i < boxes.size(); ++i)
    if (!boxes[i].isEmpty() && !path.postures.empty() && nearest[i] > reach_mm)
      out.push_back({i, nearest[i]});
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
