#include "fieldpath/pathgen/clearance.h"

#include <algorithm>
#include <string>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/geometric_shape_to_BVH_model.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/distance.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "fieldpath/common/errors.h"

namespace fieldpath::pathgen {
namespace {

using Model = fcl::BVHModel<fcl::OBBRSSd>;

std::shared_ptr<Model> buildModel(const geometry::TriangleMesh& mesh, const std::string& what) {
  if (mesh.triangles.empty()) throw common::InputError(what + ": empty mesh, nothing to check");
  std::vector<fcl::Vector3d> points(mesh.vertices.begin(), mesh.vertices.end());
  std::vector<fcl::Triangle> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);
  auto model = std::make_shared<Model>();
  model->beginModel(static_cast<int>(triangles.size()), static_cast<int>(points.size()));
  model->addSubModel(points, triangles);
  model->endModel();
  model->computeLocalAABB();
  return model;
}

}  // namespace

struct ClearanceChecker::Impl {
  std::shared_ptr<Model> tool;
  std::vector<std::shared_ptr<Model>> obstacles;
};

ClearanceChecker::ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                                   std::span<const geometry::TriangleMesh> obstacles) {
  auto impl = std::make_shared<Impl>();
  impl->tool = buildModel(tool_mesh, "tool mesh");
  for (size_t i = 0; i < obstacles.size(); ++i)
    impl->obstacles.push_back(buildModel(obstacles[i], "obstacle " + std::to_string(i)));
  impl_ = std::move(impl);
}

std::size_t ClearanceChecker::obstacleCount() const { return impl_->obstacles.size(); }

namespace {

/// Nearest obstacle to `model` placed at `pose`: 0 if it touches or crosses one (collide()), else
/// the exact distance. The geometry overloads of FCL avoid CollisionObject, whose constructor
/// recomputes the model's bounding box on every query.
double nearestObstacle(const Model& model, const fcl::Transform3d& pose,
                       const std::vector<std::shared_ptr<Model>>& obstacles, int* obstacle) {
  const fcl::Transform3d identity = fcl::Transform3d::Identity();
  double best = std::numeric_limits<double>::infinity();
  int best_index = -1;
  for (size_t i = 0; i < obstacles.size(); ++i) {
    fcl::CollisionRequestd collision_request;
    fcl::CollisionResultd collision_result;
    double d;
    if (fcl::collide(&model, pose, obstacles[i].get(), identity, collision_request,
                     collision_result) > 0) {
      d = 0.0;
    } else {
      fcl::DistanceRequestd request;  // rel_err = abs_err = 0: exact triangle distances
      fcl::DistanceResultd result;
      d = std::max(0.0, fcl::distance(&model, pose, obstacles[i].get(), identity, request, result));
    }
    if (d < best) {
      best = d;
      best_index = static_cast<int>(i);
    }
  }
  if (obstacle) *obstacle = best_index;
  return best;
}

}  // namespace

double ClearanceChecker::clearance(const geometry::Posture& posture, int* obstacle) const {
  const Eigen::Isometry3d placed = geometry::toolToWorld(posture);
  return nearestObstacle(*impl_->tool, fcl::Transform3d(placed.matrix()), impl_->obstacles,
                         obstacle);
}

double ClearanceChecker::ballClearance(std::span<const Vec3> centres_mm, double radius_mm,
                                       std::size_t* at, int* obstacle) const {
  // A point-sized sphere model: the distance from the centre to the obstacles, less the radius.
  constexpr double kPointRadiusMm = 1e-4;
  auto ball = std::make_shared<Model>();
  fcl::generateBVHModel(*ball, fcl::Sphered(kPointRadiusMm), fcl::Transform3d::Identity(), 4u, 4u);
  std::vector<double> distance(centres_mm.size());
  std::vector<int> nearest(centres_mm.size());
  tbb::parallel_for(size_t{0}, centres_mm.size(), [&](size_t i) {
    fcl::Transform3d pose = fcl::Transform3d::Identity();
    pose.translation() = centres_mm[i];
    distance[i] = nearestObstacle(*ball, pose, impl_->obstacles, &nearest[i]);
  });
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < distance.size(); ++i) {
    if (distance[i] < best) {
      best = distance[i];
      if (at) *at = i;
      if (obstacle) *obstacle = nearest[i];
    }
  }
  return std::max(0.0, best - radius_mm);
}

ClearanceResult ClearanceChecker::check(std::span<const geometry::Posture> postures,
                                        const ClearanceRequest& request,
                                        const common::Progress& progress) const {
  ClearanceResult result;
  result.postures = postures.size();
  std::vector<double> distance(postures.size());
  std::vector<int> nearest(postures.size());
  const size_t batch = std::max<size_t>(1, request.batch);
  for (size_t begin = 0; begin < postures.size(); begin += batch) {
    const size_t end = std::min(postures.size(), begin + batch);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i)
        distance[i] = clearance(postures[i], &nearest[i]);
    });
    common::report(progress, static_cast<double>(end) / postures.size(), "clearance");
  }
  for (size_t i = 0; i < postures.size(); ++i) {
    if (distance[i] <= 0.0) {
      ++result.colliding;
      if (result.first_colliding == ClearanceResult::npos) result.first_colliding = i;
    }
    if (distance[i] < result.min_clearance_mm) {
      result.min_clearance_mm = distance[i];
      result.min_index = i;
      result.min_obstacle = nearest[i];
    }
  }
  if (request.per_posture) result.clearance_mm = std::move(distance);
  return result;
}

}  // namespace fieldpath::pathgen
