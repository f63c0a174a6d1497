#pragma once
/// Internal to pathgen/: a mesh as the exact checks test it (ClearanceChecker, the cutter against
/// the part): FCL's tree of its triangles, its closed shells (FCL meets surfaces only: a tool
/// wholly inside a closed mesh touches no triangle) and a vertex of each open shell (a sheet
/// wholly inside the tool meets none of its triangles either). Built once a mesh and shared:
/// `check` tested a part four ways (links, the moves into passes, the holder, the cutter) and
/// built each its own (a 1 M-triangle part: four trees of ~8 s and ~300 B a triangle each).
#include <memory>
#include <string>
#include <vector>

#include <fcl/geometry/bvh/BVH_model.h>
#include <Eigen/Core>

#include "fieldpath/geometry/closed_shells.h"
#include "fieldpath/geometry/mesh.h"

namespace fieldpath::pathgen {

using BvhModel = fcl::BVHModel<fcl::OBBRSSd>;

/// FCL's tree of `mesh`. Throws common::InputError naming `what` for an empty mesh.
std::shared_ptr<BvhModel> buildBvhModel(const geometry::TriangleMesh& mesh,
                                        const std::string& what);

struct ObstacleModel {
  ObstacleModel(const geometry::TriangleMesh& mesh, const std::string& what);
  std::shared_ptr<BvhModel> tree;
  geometry::ClosedShells solids;
  /// A vertex of each open shell, sorted by x.
  std::vector<Eigen::Vector3d> sheet_anchors;
  Eigen::AlignedBox3d box;  ///< of the vertices
};

}  // namespace fieldpath::pathgen
