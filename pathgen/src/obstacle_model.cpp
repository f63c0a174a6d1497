#include "obstacle_model.h"

#include <new>
#include <stdexcept>
#include <string>
#include <vector>

#include <fcl/geometry/bvh/BVH_model.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/closed_shells.h"
#include "fieldpath/pathgen/clearance.h"

namespace fieldpath::pathgen {

std::shared_ptr<BvhModel> buildBvhModel(const geometry::TriangleMesh& mesh,
                                        const std::string& what) {
  if (mesh.triangles.empty()) throw common::InputError(what + ": empty mesh, nothing to check");
  std::vector<fcl::Vector3d> points(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  // Triangles of no area (geometry::hasNoArea: a sliver closing a T-junction, a needle): FCL's
  // sphere-triangle test takes a zero normal for "inside the triangle" and met a ball 0.54 mm
  // clear of such a sliver (a reviewer's case: 841 um of false gouge). Left out, a lone needle
  // 100 mm long and 1e-5 mm wide vanished and a ball through it read 199 mm clear (a later
  // review's): each is its longest edge, padded sideways by kSliverPad of that edge's length (at
  // most 1 um) to a triangle FCL measures. The edge is measured whole; the sliver's apex stands
  // within its own height (under 1e-6 of the edge) of it. The shells (inside tests) keep the
  // sliver as it is.
  constexpr double kSliverPad = 1e-4, kSliverPadMaxMm = 1e-3;
  for (const auto& t : mesh.triangles) {
    if (!geometry::hasNoArea(mesh.vertices[std::size_t(t[0])], mesh.vertices[std::size_t(t[1])],
                             mesh.vertices[std::size_t(t[2])])) {
      triangles.emplace_back(t[0], t[1], t[2]);
      continue;
    }
    int longest = 0;  // the edge from corner `longest` to the next
    double length = -1.0;
    for (int e = 0; e < 3; ++e) {
      const double l =
          (mesh.vertices[std::size_t(t[(e + 1) % 3])] - mesh.vertices[std::size_t(t[e])]).norm();
      if (l > length) {
        length = l;
        longest = e;
      }
    }
    if (!(length > 0.0)) continue;  // a point: no surface
    const Eigen::Vector3d p = mesh.vertices[std::size_t(t[longest])];
    const Eigen::Vector3d q = mesh.vertices[std::size_t(t[(longest + 1) % 3])];
    const Eigen::Vector3d r = mesh.vertices[std::size_t(t[(longest + 2) % 3])];
    const Eigen::Vector3d u = (q - p) / length;
    Eigen::Vector3d side = (r - p) - (r - p).dot(u) * u;  // the apex's side, else any
    if (!(side.norm() > 1e-12 * length)) side = u.unitOrthogonal();
    const Eigen::Vector3d apex =
        0.5 * (p + q) + std::min(kSliverPad * length, kSliverPadMaxMm) * side.normalized();
    points.emplace_back(apex);
    triangles.emplace_back(t[longest], t[(longest + 1) % 3], static_cast<int>(points.size() - 1));
  }
  if (triangles.empty())
    throw common::InputError(what + ": every triangle has zero area, nothing to check");
  auto model = std::make_shared<BvhModel>();
  // FCL reports a failed allocation as a code (and a line on stderr) and leaves the tree
  // unusable: under `ulimit -v` the next query crashed. As the allocation it is: std::bad_alloc.
  for (const int code :
       {model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size())),
        model->addSubModel(points, triangles), model->endModel()})
    if (code == fcl::BVH_ERR_MODEL_OUT_OF_MEMORY)
      throw std::bad_alloc();
    else if (code != fcl::BVH_OK)
      throw std::runtime_error(what + ": FCL could not build its tree (code " +
                               std::to_string(code) + ")");
  model->computeLocalAABB();
  return model;
}

ObstacleModel::ObstacleModel(const geometry::TriangleMesh& mesh, const std::string& what)
    : tree(buildBvhModel(mesh, what)), solids(mesh) {
  for (const std::vector<int>& shell : geometry::openShells(mesh))
    sheet_anchors.push_back(mesh.vertices[static_cast<std::size_t>(
        mesh.triangles[static_cast<std::size_t>(shell.front())][0])]);
  std::sort(sheet_anchors.begin(), sheet_anchors.end(),
            [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.x() < b.x(); });
  for (const Eigen::Vector3d& v : mesh.vertices) box.extend(v);
}

std::shared_ptr<const ObstacleModel> prepareObstacle(const geometry::TriangleMesh& mesh,
                                                     const std::string& what) {
  return std::make_shared<const ObstacleModel>(mesh, what);
}

}  // namespace fieldpath::pathgen
