#pragma once
/// Obstacles the field never brought to bear: one farther than `field.r0` from the tool and holder
/// at every posture of a path exerts no force anywhere on it (eq. 1 ends at r0), so it steered
/// nothing. An obstacle in other units or another frame than the path (blades in inches floating
/// in the hub's bore) read `safe`, and only this tells it.
#include <cstddef>
#include <string>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "scene.h"

namespace fieldpath::app {

struct ObstacleOutOfReach {
  std::size_t obstacle = 0;  ///< 0-based, as scene.obstacles
  double at_least_mm = 0.0;  ///< a lower bound of its distance to tool + holder over the path
};

/// The obstacles farther than `reach_mm` from the tool and holder (the cutter, and each span of
/// the holder, in a box of its own about the axis) at every posture of `path`, told by boxes
/// (of groups of nearby triangles of the obstacle): each
/// distance is a lower bound, so an obstacle listed is surely out of reach (one within it by the
/// boxes alone is not listed).
std::vector<ObstacleOutOfReach> obstaclesOutOfReach(const Scene& scene,
                                                    const geometry::PathFile& path,
                                                    double reach_mm);

/// The note of them (empty where none): named by their scene entries, "none steered" where all.
std::string obstaclesOutOfReachNote(const Scene& scene,
                                    const std::vector<ObstacleOutOfReach>& out_of_reach,
                                    double reach_mm);

}  // namespace fieldpath::app
