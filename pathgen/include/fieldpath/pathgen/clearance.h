#pragma once
/// Exact clearance of tool + holder against the obstacle meshes (FCL, which stays inside the .cpp):
/// triangle-exact distances between bounding-volume hierarchies (OBBRSS) built once.
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::pathgen {

using geometry::Vec3;

struct ClearanceRequest {
  bool per_posture = true;  ///< fill ClearanceResult::clearance_mm
  /// Postures per progress report (and per parallel batch).
  std::size_t batch = 256;
};

struct ClearanceResult {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t postures = 0;
  /// Smallest distance tool + holder ↔ obstacles over all postures, mm; 0 when any collides.
  double min_clearance_mm = std::numeric_limits<double>::infinity();
  std::size_t min_index = npos;  ///< posture of the minimum (the first colliding one if any)
  int min_obstacle = -1;         ///< obstacle index of the minimum
  std::size_t colliding = 0;  ///< postures that touch or cross an obstacle (collide() or d ≤ 0)
  std::size_t first_colliding = npos;
  std::vector<double> clearance_mm;  ///< per posture, mm; 0 for colliding ones (if per_posture)
};

/// Tool + holder mesh (tool frame: tip at the origin, axis +z) against fixed obstacle meshes.
/// Copies share the built hierarchies; queries are const and thread-safe.
class ClearanceChecker {
 public:
  /// Builds the hierarchies once. Throws common::InputError for an empty mesh.
  ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                   std::span<const geometry::TriangleMesh> obstacles);

  /// Distance (mm) from the placed tool to the nearest obstacle, 0 if they touch or intersect;
  /// `obstacle` (optional) receives its index.
  double clearance(const geometry::Posture& posture, int* obstacle = nullptr) const;

  /// Every posture, in parallel (TBB); progress is reported between batches.
  ClearanceResult check(std::span<const geometry::Posture> postures,
                        const ClearanceRequest& request = {},
                        const common::Progress& progress = {}) const;

  /// Smallest distance (mm) from a ball of `radius_mm` at each centre (world frame) to the
  /// obstacles, 0 if one touches; `at` and `obstacle` receive where. The ball of a ball-end mill
  /// must clear the obstacles whatever the axis: exact (centre-to-mesh distance less the radius).
  double ballClearance(std::span<const Vec3> centres_mm, double radius_mm,
                       std::size_t* at = nullptr, int* obstacle = nullptr) const;

  std::size_t obstacleCount() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace fieldpath::pathgen
