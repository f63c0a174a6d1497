#include "fieldpath/pathgen/clearance.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <queue>
#include <string>
#include <tuple>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/geometric_shape_to_BVH_model.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/detail/primitive_shape_algorithm/triangle_distance.h>
#include <fcl/narrowphase/distance.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "clearance_memo.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/closed_shells.h"
#include "obstacle_model.h"

namespace fieldpath::pathgen {

namespace {

using Model = BvhModel;

/// The closest pair of triangles (tool, obstacle) of a distance query, handed to the next query
/// of a nearby pose (the next posture of a run, the next sample of a motion): their distance
/// there bounds the new one from above, and FCL's branch and bound, started under that bound,
/// skips every pair of boxes farther apart. The value is the same (FCL returns the least
/// triangle distance under its start); only the boxes visited change.
struct Witness {
  int obstacle = -1, tool_triangle = -1, obstacle_triangle = -1;
};

/// A lower bound of the distance between a ball (`centre`, `radius_mm`) and anything in `box`,
/// a micrometre short of it (for the rounding of coordinates far from the origin); 0 or less
/// where they may meet.
double boxGapMm(const fcl::Vector3d& centre, double radius_mm, const fcl::AABBd& box) {
  const fcl::Vector3d outside =
      (box.min_ - centre).cwiseMax(centre - box.max_).cwiseMax(fcl::Vector3d::Zero());
  return outside.norm() - radius_mm - 1e-3;
}

}  // namespace

struct ClearanceChecker::Impl {
  std::shared_ptr<Model> tool;
  std::vector<std::shared_ptr<const ObstacleModel>> obstacles;
  double chord_tol_mm = 0.0;
  /// √3 float steps at the obstacles' farthest coordinate past common::kFloatExactMm, taken off
  /// every distance: mesh files are read in single precision (each coordinate off by up to a
  /// step, allowing the text reader's last digit), and a face written at x = 900000.03 read 0.03
  /// mm farther, a path 0.490 mm clear read 0.508 (a review's); a slanted face moves by up to √3
  /// times what one coordinate does (half a step each read a face 0.022 mm too far: a later one).
  double read_margin_mm = 0.0;
  double reach_mm = 0.0;
  /// ClearanceChecker::clearance, `witness` as nearestObstacle's.
  double clearance(const geometry::Posture& posture, int* obstacle, Witness* witness) const;
  /// The closed shells of the tool (tool frame): an obstacle wholly inside the tool touches no
  /// triangle (FCL: clear). The obstacles' own are in their ObstacleModel.
  std::optional<geometry::ClosedShells> tool_solid;

  /// A point of the tool mesh's surface (tool frame): a vertex of its first triangle (the tip for
  /// a whole tool; a point of the holder for geometry::holderMesh, whose tip is not its own).
  Eigen::Vector3d tool_anchor = Eigen::Vector3d::Zero();

  /// Whether the tool placed at `placed` lies inside obstacle i or holds it, given that their
  /// surfaces do not meet: a point of its surface inside the obstacle, or an obstacle shell's
  /// vertex inside it. (The tip was taken for the point: for the holder alone, a tip resting on
  /// the part's top read as the holder inside the part.)
  bool enclosed(const Eigen::Isometry3d& placed, std::size_t i) const {
    // Apart from the obstacle's box, neither can hold the other.
    if (boxGapMm(placed * tool->aabb_center, tool->aabb_radius, obstacles[i]->tree->aabb_local) >
        0.0)
      return false;
    const geometry::ClosedShells& solid = obstacles[i]->solids;
    if (!solid.empty() && solid.contains(placed * tool_anchor)) return true;
    if (!tool_solid || tool_solid->empty()) return false;
    const Eigen::Isometry3d to_tool = placed.inverse();
    for (const Eigen::Vector3d& anchor : solid.anchors())
      if (tool_solid->contains(to_tool * anchor)) return true;
    // Sheets: only those within the tool's reach of its tip (a soup of unjoined triangles has
    // an anchor each).
    const std::vector<Eigen::Vector3d>& sheets = obstacles[i]->sheet_anchors;
    const Eigen::Vector3d tip = placed.translation();
    const auto byX = [](const Eigen::Vector3d& p, double x) { return p.x() < x; };
    for (auto it = std::lower_bound(sheets.begin(), sheets.end(), tip.x() - reach_mm, byX);
         it != sheets.end() && it->x() <= tip.x() + reach_mm; ++it)
      if ((*it - tip).squaredNorm() <= reach_mm * reach_mm && tool_solid->contains(to_tool * *it))
        return true;
    return false;
  }
};

namespace {

std::vector<std::shared_ptr<const ObstacleModel>> prepareAll(
    std::span<const geometry::TriangleMesh> obstacles) {
  std::vector<std::shared_ptr<const ObstacleModel>> out;
  for (std::size_t i = 0; i < obstacles.size(); ++i)
    out.push_back(prepareObstacle(obstacles[i], "obstacle " + std::to_string(i + 1)));
  return out;
}

}  // namespace

ClearanceChecker::ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                                   std::span<const geometry::TriangleMesh> obstacles,
                                   double tool_chord_tol_mm)
    : ClearanceChecker(tool_mesh, prepareAll(obstacles), tool_chord_tol_mm) {}

ClearanceChecker::ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                                   std::span<const std::shared_ptr<const ObstacleModel>> obstacles,
                                   double tool_chord_tol_mm) {
  if (!std::isfinite(tool_chord_tol_mm) || tool_chord_tol_mm < 0.0)
    throw common::InputError("tool mesh chordal tolerance: must be finite and >= 0");
  auto impl = std::make_shared<Impl>();
  impl->tool = buildBvhModel(tool_mesh, "tool mesh");
  impl->tool_solid.emplace(tool_mesh);
  if (!tool_mesh.triangles.empty())
    impl->tool_anchor = tool_mesh.vertices[static_cast<std::size_t>(tool_mesh.triangles[0][0])];
  impl->obstacles.assign(obstacles.begin(), obstacles.end());
  impl->chord_tol_mm = tool_chord_tol_mm;
  for (const auto& obstacle : impl->obstacles) {
    if (obstacle->box.isEmpty()) continue;
    const double far_mm = std::max(obstacle->box.min().cwiseAbs().maxCoeff(),
                                   obstacle->box.max().cwiseAbs().maxCoeff());
    if (far_mm > common::kFloatExactMm)
      impl->read_margin_mm =
          std::max(impl->read_margin_mm, std::sqrt(3.0) * common::floatStepMm(far_mm));
  }
  for (const auto& v : tool_mesh.vertices) impl->reach_mm = std::max(impl->reach_mm, v.norm());
  impl_ = std::move(impl);
}

namespace {

/// The distance between triangle `tool_triangle` of `model` placed at `pose` and triangle
/// `obstacle_triangle` of `tree`: an upper bound of their meshes' distance.
double pairDistance(const Model& model, const fcl::Transform3d& pose, const Model& tree,
                    int tool_triangle, int obstacle_triangle) {
  fcl::Vector3d a[3], b[3], p, q;
  const fcl::Triangle& ta = model.tri_indices[tool_triangle];
  const fcl::Triangle& tb = tree.tri_indices[obstacle_triangle];
  for (int k = 0; k < 3; ++k) {
    a[k] = pose * model.vertices[ta[k]];
    b[k] = tree.vertices[tb[k]];
  }
  return fcl::detail::TriangleDistance<double>::triDistance(a, b, p, q);
}

/// Nearest obstacle to `model` placed at `pose`: 0 if it touches or crosses one (FCL's triangle
/// distance of meeting triangles is 0), else the exact distance. A collide() asked first (an
/// early way out where they meet) cost 13 % of a clear CAM job's check, a helper's profile, and
/// saved 11 % of a nominal path's that collides at 184 motions: the paths written and checked
/// are mostly clear (clearance.csv of both the same with and without it). The geometry overloads of
/// FCL avoid CollisionObject, whose constructor recomputes the model's bounding box on every query.
/// `witness` (optional): in, a nearby pose's closest pair (Witness); out, this pose's.
double nearestObstacle(const Model& model, const fcl::Transform3d& pose,
                       const std::vector<std::shared_ptr<const ObstacleModel>>& obstacles,
                       int* obstacle, Witness* witness = nullptr) {
  const fcl::Transform3d identity = fcl::Transform3d::Identity();
  // Each query starts under the least found so far and under the witness pair's distance here
  // (a hair above it: that pair is then found again by FCL's own arithmetic). A query that
  // finds nothing under its start is no nearer than it: not the nearest (ties keep the first,
  // as the plain loop: a later obstacle at the same distance finds nothing under it).
  double start = std::numeric_limits<double>::infinity();
  if (witness && witness->obstacle >= 0 &&
      static_cast<std::size_t>(witness->obstacle) < obstacles.size()) {
    const double bound = pairDistance(model, pose, *obstacles[witness->obstacle]->tree,
                                      witness->tool_triangle, witness->obstacle_triangle);
    if (std::isfinite(bound)) start = bound + 1e-9 * (1.0 + bound);
  }
  double best = std::numeric_limits<double>::infinity();
  int best_index = -1;
  Witness found;
  // The model's bounding sphere as placed: an obstacle whose box lies farther from it than the
  // query's start cannot come nearer (a fixture of 96 bodies took 21x one body's time when each
  // was asked in full, a helper's scale sweep).
  const fcl::Vector3d centre = pose * model.aabb_center;
  for (size_t i = 0; i < obstacles.size(); ++i) {
    const double under = std::min(best, start);
    if (boxGapMm(centre, model.aabb_radius, obstacles[i]->tree->aabb_local) >= under) continue;
    fcl::DistanceRequestd request;  // rel_err = abs_err = 0: exact triangle distances
    fcl::DistanceResultd result;
    result.min_distance = under;
    const double d =
        fcl::distance(&model, pose, obstacles[i]->tree.get(), identity, request, result);
    if (d < under) {
      best = std::max(0.0, d);
      best_index = static_cast<int>(i);
      found = {best_index, static_cast<int>(result.b1), static_cast<int>(result.b2)};
    }
  }
  if (best_index < 0 && std::isfinite(start))  // (never: the witness pair lies under its start)
    return nearestObstacle(model, pose, obstacles, obstacle, nullptr);
  if (obstacle) *obstacle = best_index;
  if (witness) *witness = found;
  return best;
}

}  // namespace

double ClearanceChecker::Impl::clearance(const geometry::Posture& posture, int* obstacle,
                                         Witness* witness) const {
  const Eigen::Isometry3d placed = geometry::toolToWorld(posture);
  const double d =
      nearestObstacle(*tool, fcl::Transform3d(placed.matrix()), obstacles, obstacle, witness);
  if (d > 0.0)  // no surfaces meet: inside one another is the one way left to collide
    for (std::size_t i = 0; i < obstacles.size(); ++i)
      if (enclosed(placed, i)) {
        if (obstacle) *obstacle = static_cast<int>(i);
        return 0.0;
      }
  return std::max(0.0, d - chord_tol_mm - read_margin_mm);
}

double ClearanceChecker::clearance(const geometry::Posture& posture, int* obstacle) const {
  return impl_->clearance(posture, obstacle, nullptr);
}

BallResult ClearanceChecker::ballClearance(std::span<const Vec3> centres_mm,
                                           const BallRequest& request) const {
  const double radius_mm = request.radius_mm, exact_below_mm = request.exact_below_mm,
               split_mm = request.split_mm;
  // A point-sized sphere model: the distance from the centre to the obstacles, less the radius.
  constexpr double kPointRadiusMm = 1e-4;
  auto ball = std::make_shared<Model>();
  fcl::generateBVHModel(*ball, fcl::Sphered(kPointRadiusMm), fcl::Transform3d::Identity(), 4u, 4u);
  std::vector<double> distance(centres_mm.size());
  std::vector<int> nearest(centres_mm.size());
  const auto measure = [&](size_t i, Witness& witness) {
    fcl::Transform3d pose = fcl::Transform3d::Identity();
    pose.translation() = centres_mm[i];
    distance[i] = nearestObstacle(*ball, pose, impl_->obstacles, &nearest[i], &witness);
    for (std::size_t k = 0; k < impl_->obstacles.size() && distance[i] > 0.0; ++k)
      if (!impl_->obstacles[k]->solids.empty() &&
          impl_->obstacles[k]->solids.contains(centres_mm[i])) {
        distance[i] = 0.0;  // the centre inside an obstacle: the ball is in it
        nearest[i] = static_cast<int>(k);
      }
  };
  // Runs of stations, each walked in order from its last measured centre: a centre that cannot
  // come under the exact range (its lower bound d - |c - c_measured|) keeps that bound. The
  // runs in parallel; the bounds, the minimum and its first index as every station measured.
  constexpr size_t kRun = 64;  // (256 left a pass of fewer stations on one core)
  const bool split = std::isfinite(split_mm) && split_mm > exact_below_mm;
  // In the result's terms (less the radius and the read margin: a bound skipped at exactly
  // `exact_below` read under it by the margin far from the origin: a pass 17 mm from a wall at
  // x = 6e5 was refused as the ball entering it, a helper's).
  const double from_mm = radius_mm + impl_->read_margin_mm;
  const double skip_from_mm = from_mm + (split ? split_mm : exact_below_mm);
  const double nearer_from_mm = from_mm + exact_below_mm, nearer_than_mm = from_mm + split_mm;
  tbb::parallel_for(size_t{0}, (centres_mm.size() + kRun - 1) / kRun, [&](size_t run) {
    const size_t end = std::min(centres_mm.size(), (run + 1) * kRun);
    size_t measured = run * kRun;
    Witness witness;  // the last measured centre's closest pair
    measure(measured, witness);
    for (size_t i = measured + 1; i < end; ++i) {
      const double moved = (centres_mm[i] - centres_mm[measured]).norm();
      const double bound = distance[measured] - moved;
      if ((std::isfinite(skip_from_mm) && bound >= skip_from_mm) ||
          (split && bound >= nearer_from_mm && distance[measured] + moved < nearer_than_mm)) {
        distance[i] = bound;
        nearest[i] = nearest[measured];
        continue;
      }
      measure(i, witness);
      measured = i;
    }
  });
  BallResult result;
  double best = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < distance.size(); ++i) {
    if (distance[i] < best) {
      best = distance[i];
      result.at = i;
      result.obstacle = nearest[i];
    }
  }
  if (request.each) {
    result.each_mm.resize(distance.size());
    for (size_t i = 0; i < distance.size(); ++i)
      result.each_mm[i] = std::max(0.0, distance[i] - radius_mm - impl_->read_margin_mm);
  }
  result.min_mm = std::max(0.0, best - radius_mm - impl_->read_margin_mm);
  return result;
}

ClearanceResult ClearanceChecker::check(std::span<const geometry::Posture> postures,
                                        const ClearanceRequest& request,
                                        const common::Progress& progress) const {
  ClearanceResult result;
  result.postures = postures.size();
  std::vector<double> distance(postures.size());
  std::vector<int> nearest(postures.size());
  const size_t batch = std::max<size_t>(1, request.batch);
  constexpr size_t kEvery = 8;  // exact_min_only: the postures measured first
  const auto measured = [&](size_t i) { return i % kEvery == 0 || i + 1 == postures.size(); };
  double least_measured = std::numeric_limits<double>::infinity();
  if (request.exact_min_only) {
    const size_t firsts = (postures.size() + kEvery - 1) / kEvery;
    tbb::parallel_for(tbb::blocked_range<size_t>(0, firsts), [&](const auto& range) {
      Witness witness;  // the posture measured before's closest pair
      for (size_t j = range.begin(); j != range.end(); ++j)
        distance[j * kEvery] =
            impl_->clearance(postures[j * kEvery], &nearest[j * kEvery], &witness);
    });
    if (!postures.empty()) distance.back() = clearance(postures.back(), &nearest.back());
    for (size_t i = 0; i < postures.size(); i += kEvery)
      least_measured = std::min(least_measured, distance[i]);
    if (!postures.empty()) least_measured = std::min(least_measured, distance.back());
  }
  // The lower bound of posture i's clearance from measured posture k's: the tool MESH as placed
  // (each posture by its own minimal rotation from +z, so a turn of the axis's azimuth twists
  // it about the axis too) moves no point farther than |Δtip| + reach · the angle of R_i R_k^T
  // (the axes' angle alone missed the twist: 0.36 um at 60 deg of tilt, a reviewer's case). The
  // mesh distance changes no faster, and the surfaces never meet on the way (the same inside).
  const auto boundFrom = [&](size_t k, size_t i) {
    const Eigen::Matrix3d turn = geometry::rotationFromZ(postures[i].axis) *
                                 geometry::rotationFromZ(postures[k].axis).transpose();
    const double angle = std::acos(std::clamp(0.5 * (turn.trace() - 1.0), -1.0, 1.0));
    // acos loses digits near 0: never below the axes' angle, plus a rounding margin.
    const double turned = std::max(angle, geometry::axisAngle(postures[i].axis, postures[k].axis));
    return distance[k] - (postures[i].tip_mm - postures[k].tip_mm).norm() -
           impl_->reach_mm * (turned + 1e-7);
  };
  // Postures checked before (the memo): given back, not measured.
  ClearanceMemo::Impl* const memo =
      request.memo && !request.exact_min_only ? request.memo->impl_.get() : nullptr;
  std::vector<char> known(memo ? postures.size() : 0, 0);
  if (memo)
    for (size_t i = 0; i < postures.size(); ++i)
      if (const auto hit = memo->postures.find(ClearanceMemo::Impl::key(postures[i]));
          hit != memo->postures.end()) {
        distance[i] = hit->second.distance_mm;
        nearest[i] = hit->second.obstacle;
        hit->second.used = memo->generation;
        known[i] = 1;
        ++memo->reused;
      }
  for (size_t begin = 0; begin < postures.size(); begin += batch) {
    const size_t end = std::min(postures.size(), begin + batch);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      Witness witness;  // the previous posture's closest pair (the values do not depend on it)
      for (size_t i = range.begin(); i != range.end(); ++i) {
        if (memo && known[i]) continue;
        if (request.exact_min_only) {
          if (measured(i)) continue;
          const size_t before = i - i % kEvery;
          const size_t after = std::min(before + kEvery, postures.size() - 1);
          const double from_before = boundFrom(before, i), from_after = boundFrom(after, i);
          const double bound = std::max(from_before, from_after);
          // Strictly above the least measured: it can be neither the minimum nor tie with it.
          if (bound > 0.0 && bound > least_measured) {
            distance[i] = bound;
            nearest[i] = nearest[from_after > from_before ? after : before];
            continue;
          }
        }
        distance[i] = impl_->clearance(postures[i], &nearest[i], &witness);
      }
    });
    common::report(progress, static_cast<double>(end) / postures.size(), "clearance");
  }
  if (memo)
    for (size_t i = 0; i < postures.size(); ++i)
      if (!known[i])
        memo->postures.emplace(
            ClearanceMemo::Impl::key(postures[i]),
            ClearanceMemo::Impl::Posture{distance[i], nearest[i], memo->generation});
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

namespace fieldpath::pathgen {

MotionResult ClearanceChecker::checkMotions(std::span<const geometry::Posture> postures,
                                            const MotionRequest& request,
                                            const common::Progress& progress) const {
  MotionResult result;
  result.motions = postures.empty() ? 0 : postures.size() - 1;
  result.tool_reach_mm = impl_->reach_mm;
  std::vector<double> ends(postures.size());
  // The ends' closest pairs, where they are measured here (each motion's first sample starts
  // from its first end's).
  const bool ends_given = request.posture_clearance_mm.size() == postures.size();
  std::vector<Witness> end_pairs(ends_given ? 0 : postures.size());
  std::vector<double> bound(result.motions);
  std::vector<char> touched(result.motions, 0);
  std::vector<std::size_t> samples(result.motions, 0);
  const double reach = impl_->reach_mm;
  const double resolution = std::max(1e-6, request.resolution_mm);
  double stop_mm = request.required_mm;
  auto motion = [&](std::size_t i) {
    const geometry::Posture& a = postures[i];
    const geometry::Posture& b = postures[i + 1];
    struct Piece {
      double t0, t1, d0, d1;
      geometry::Posture p0, p1;
      double reach_mm, certain;  ///< its sweep D, and its lower bound
    };
    const auto piece = [&](double t0, double t1, double d0, double d1, const geometry::Posture& p0,
                           const geometry::Posture& p1) {
      const double reach_mm = geometry::motionSweepMm(p0, p1, reach);
      return Piece{t0, t1, d0,       d1,
                   p0, p1, reach_mm, std::min({d0, d1, 0.5 * (d0 + d1 - reach_mm)})};
    };
    // Lowest bound first (branch and bound): the samples near the motion's minimum come early,
    // and a piece whose bound is within the slack of the lowest sample cannot hold a lower
    // minimum worth telling. Halving every piece under `stop_mm` to the resolution instead took a
    // 460 mm motion over a rib 68 s of the holder's samples (180 s on a helper's machine).
    const auto later = [](const Piece& x, const Piece& y) { return x.certain > y.certain; };
    std::priority_queue<Piece, std::vector<Piece>, decltype(later)> queue(later);
    queue.push(piece(0.0, 1.0, ends[i], ends[i + 1], a, b));
    double best = std::min(ends[i], ends[i + 1]);  // the lowest distance sampled on the motion
    double lowest = std::numeric_limits<double>::infinity();
    Witness witness = ends_given ? Witness{} : end_pairs[i];  // the last sample's closest pair
    while (!queue.empty()) {
      const Piece p = queue.top();
      queue.pop();
      // A piece resolved already bounds the motion at `lowest`, and no piece left bounds lower:
      // they leave lowest first, and a half's bound is no lower than its piece's (the distance
      // moves by at most half the sweep from either end: dm >= max(d0, d1) - D/2, and a half
      // sweeps D/2). Refining on changed nothing but the time (a motion under the clearance was
      // resolved along its whole length: 17 000 queries on a reversed impeller's first check,
      // a third of its generate, a helper's profile).
      if (p.certain >= lowest) break;
      const double slack =
          std::max(request.tighten_mm, request.tighten_fraction * std::max(best, 0.0));
      // Every piece left bounds no lower than this one: certified (clear of contact and of the
      // required clearance), the motion's bound is this one's.
      if (p.certain >= stop_mm ||
          (p.certain > 0.0 && p.certain >= request.required_mm && p.certain >= best - slack)) {
        lowest = std::min(lowest, p.certain);
        break;
      }
      // A piece of a billionth of its motion that still sweeps farther than the resolution
      // (an axis reversed between two postures jumps at one t: no halving shrinks it) is not
      // resolved further: its lower bound stands, 0 where it may touch (was an endless halving).
      const bool unresolved = !(p.t1 - p.t0 > 1e-9) || !std::isfinite(p.reach_mm);
      if (p.reach_mm <= 2 * resolution || unresolved) {
        lowest = std::min(lowest, std::max(0.0, std::isfinite(p.certain) ? p.certain : 0.0));
        continue;
      }
      const double tm = 0.5 * (p.t0 + p.t1);
      const geometry::Posture pm = geometry::alongMotion(a, b, tm);
      const double raw =
          nearestObstacle(*impl_->tool, fcl::Transform3d(geometry::toolToWorld(pm).matrix()),
                          impl_->obstacles, nullptr, &witness);
      ++samples[i];
      if (raw <= 0.0) {  // the meshes touch: so do the true solids (the mesh is inside the tool)
        touched[i] = 1;
        lowest = 0.0;
        break;
      }
      const double dm = std::max(0.0, raw - impl_->chord_tol_mm - impl_->read_margin_mm);
      best = std::min(best, dm);
      queue.push(piece(p.t0, tm, p.d0, dm, p.p0, pm));
      queue.push(piece(tm, p.t1, dm, p.d1, pm, p.p1));
    }
    bound[i] = lowest;  // infinite: no obstacle at all
  };
  // The postures' own clearances first (the ends of every motion), unless given.
  const size_t batch = std::max<size_t>(1, request.batch);
  if (ends_given)
    std::copy(request.posture_clearance_mm.begin(), request.posture_clearance_mm.end(),
              ends.begin());
  else
  for (size_t begin = 0; begin < postures.size(); begin += batch) {
    const size_t end = std::min(postures.size(), begin + batch);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      Witness witness;
      for (size_t i = range.begin(); i != range.end(); ++i) {
        ends[i] = impl_->clearance(postures[i], nullptr, &witness);
        end_pairs[i] = witness;
      }
    });
    common::report(progress, 0.3 * end / postures.size(), "motions");
  }
  // Refine each motion until its bound reaches the required clearance or, where the path comes
  // closer, within the slack of the closest posture: the reported minimum is then tight too.
  double closest_mm = std::numeric_limits<double>::infinity();
  for (double d : ends) closest_mm = std::min(closest_mm, d);
  stop_mm =
      std::max(request.required_mm,
               std::min(request.enough_mm,
                        closest_mm - std::max(request.tighten_mm, request.tighten_fraction *
                                                                      std::max(closest_mm, 0.0))));
  // Motions refined before under the same request (the memo): given back, not refined.
  ClearanceMemo::Impl* const memo = request.memo ? request.memo->impl_.get() : nullptr;
  const std::array<double, 6> asked = {stop_mm,
                                       request.required_mm,
                                       resolution,
                                       request.tighten_mm,
                                       request.tighten_fraction,
                                       request.enough_mm};
  std::vector<char> known(memo ? result.motions : 0, 0);
  if (memo)
    for (size_t i = 0; i < result.motions; ++i)
      if (const auto hit = memo->motions.find(
              ClearanceMemo::Impl::key(postures[i], postures[i + 1], ends[i], ends[i + 1], asked));
          hit != memo->motions.end()) {
        bound[i] = hit->second.bound_mm;
        touched[i] = hit->second.touched;
        samples[i] = hit->second.samples;
        hit->second.used = memo->generation;
        known[i] = 1;
        ++memo->reused;
      }
  for (size_t begin = 0; begin < result.motions; begin += batch) {
    const size_t end = std::min(result.motions, begin + batch);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i)
        if (!memo || !known[i]) motion(i);
    });
    common::report(progress, 0.3 + 0.7 * end / result.motions, "motions");
  }
  if (memo)
    for (size_t i = 0; i < result.motions; ++i)
      if (!known[i])
        memo->motions.emplace(
            ClearanceMemo::Impl::key(postures[i], postures[i + 1], ends[i], ends[i + 1], asked),
            ClearanceMemo::Impl::Motion{bound[i], touched[i] != 0, samples[i], memo->generation});
  for (size_t i = 0; i < result.motions; ++i) {
    result.samples += samples[i];
    if (touched[i] || bound[i] <= 0.0) {
      ++result.colliding;
      if (result.first_colliding == MotionResult::npos) result.first_colliding = i;
    }
    if (bound[i] < request.required_mm) {
      ++result.under_required;
      if (result.first_under_required == MotionResult::npos) result.first_under_required = i;
    }
    if (bound[i] < result.min_clearance_mm) {
      result.min_clearance_mm = bound[i];
      result.min_index = i;
    }
  }
  result.clearance_mm = std::move(bound);
  return result;
}

}  // namespace fieldpath::pathgen
