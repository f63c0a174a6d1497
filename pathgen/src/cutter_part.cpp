/// pathgen/cutter_part.h: the cutter against the part, exactly.
#include "fieldpath/pathgen/cutter_part.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cmath>
#include <memory>
#include <optional>
#include <span>
#include <unordered_map>

#include <fcl/geometry/bvh/BVH_model.h>
#include <fcl/geometry/shape/cylinder.h>
#include <fcl/geometry/shape/sphere.h>
#include <fcl/narrowphase/collision.h>
#include <fcl/narrowphase/detail/gjk_solver_libccd.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "clearance_memo.h"  // memo_detail: keys of bits
#include "fieldpath/common/limits.h"
#include "fieldpath/common/short_number.h"
#include "obstacle_model.h"

namespace fieldpath::pathgen {
namespace {

using geometry::Posture;
using geometry::Vec3;

/// Whether triangle (a, b, c) meets the ball of radius `reach_mm` about `centre` cut by the plane
/// (x - centre)·axis <= cap_mm: the triangle clipped to the half-space, then its distance from the
/// centre (inside its plane's projection: the plane's; else the nearest edge's).
bool triangleMeetsCappedBall(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& centre,
                             const Vec3& axis, double reach_mm, double cap_mm) {
  // Sutherland-Hodgman against one plane: at most 4 vertices.
  Vec3 poly[4];
  int n = 0;
  const Vec3 in[3] = {a, b, c};
  for (int i = 0; i < 3; ++i) {
    const Vec3 &p = in[i], &q = in[(i + 1) % 3];
    const double hp = (p - centre).dot(axis) - cap_mm, hq = (q - centre).dot(axis) - cap_mm;
    if (hp <= 0.0) poly[n++] = p;
    if ((hp < 0.0 && hq > 0.0) || (hp > 0.0 && hq < 0.0))
      poly[n++] = p + (hp / (hp - hq)) * (q - p);
  }
  if (n == 0) return false;
  const double reach_sq = reach_mm * reach_mm;
  auto segmentSq = [&](const Vec3& p, const Vec3& q) {
    const Vec3 d = q - p;
    const double len_sq = d.squaredNorm();
    const double t = len_sq > 0.0 ? std::clamp((centre - p).dot(d) / len_sq, 0.0, 1.0) : 0.0;
    return (p + t * d - centre).squaredNorm();
  };
  double nearest_sq = HUGE_VAL;
  for (int i = 0; i < n; ++i)
    nearest_sq = std::min(nearest_sq, segmentSq(poly[i], poly[(i + 1) % n]));
  if (nearest_sq <= reach_sq) return true;
  // The centre's foot inside the clipped polygon (convex, in the triangle's plane): the plane's
  // distance.
  const Vec3 normal = (b - a).cross(c - a);
  const double area_sq = normal.squaredNorm();
  if (!(area_sq > 0.0) || n < 3) return false;
  const double height = (centre - a).dot(normal);
  const Vec3 foot = centre - (height / area_sq) * normal;
  for (int i = 0; i < n; ++i)
    if ((poly[(i + 1) % n] - poly[i]).cross(foot - poly[i]).dot(normal) < 0.0) return false;
  return height * height / area_sq <= reach_sq;
}

/// One stamp: a pose of the tool, at posture `index` (on_motion false) or on the motion from
/// posture `index` to the next.
struct Stamp {
  Posture pose;
  std::size_t index;
  bool on_motion;
};

/// The part (its shared ObstacleModel) as the cutter meets it.
class Part {
 public:
  explicit Part(const ObstacleModel& model) : model_(model) {}

  const Eigen::AlignedBox3d& box() const { return model_.box; }

  /// Whether the cutter shrunk by `shrink_mm` meets the part at `pose`: a ball, radius R − s
  /// about its centre, under its top L − s (a ball shorter than its diameter: a necked tool
  /// written with L = R has no material above L; the whole sphere read the neck's side of a
  /// step in the part 0.16 mm deep, a helper's); a torus's corner, the points within r − s of
  /// its disc (radius R − r, at height r, square to the axis: the corner eroded by s is exactly
  /// that; one shorter than 2 r is tested whole, which can only say more); the shank, radius
  /// R − s from the corner's top to L − s.
  bool touches(const geometry::ToolSpec& tool, const Posture& pose, double shrink_mm) const {
    const double corner = geometry::cornerRadius(tool);
    const double radius = tool.radius_mm - shrink_mm;
    if (!(radius > 0.0)) return false;
    const Eigen::Matrix3d turn = geometry::rotationFromZ(pose.axis);
    const Vec3 axis = turn.col(2);
    const double reach_mm = corner - shrink_mm, disc_mm = tool.radius_mm - corner;
    const double cap_mm = tool.length_mm - shrink_mm - corner;  // the top over the corner's centre
    if (reach_mm > 0.0) {
      const Vec3 centre = pose.tip_mm + corner * axis;
      if (!(disc_mm > 1e-9) && cap_mm < reach_mm) {
        if (cappedBallMeets(centre, turn, reach_mm, cap_mm)) return true;
      } else if (cornerMeets(centre, turn, disc_mm, reach_mm)) {
        return true;
      }
    }
    // Shrunk past its corner radius, a torus's bottom rises with the shrink (its flat end).
    const double bottom = std::max(corner, shrink_mm), top = tool.length_mm - shrink_mm;
    if (top > bottom) {
      const Vec3 middle = pose.tip_mm + 0.5 * (bottom + top) * axis;
      if (meets(fcl::Cylinderd(radius, top - bottom), placed(turn, middle))) return true;
      if (model_.solids.contains(middle)) return true;
    }
    return false;
  }

 private:
  static fcl::Transform3d placed(const Eigen::Matrix3d& turn, const Vec3& centre) {
    fcl::Transform3d at = fcl::Transform3d::Identity();
    at.linear() = turn;
    at.translation() = centre;
    return at;
  }

  bool meets(const fcl::CollisionGeometryd& shape, const fcl::Transform3d& at) const {
    fcl::CollisionRequestd request;
    fcl::CollisionResultd result;
    return fcl::collide(&shape, at, model_.tree.get(), fcl::Transform3d::Identity(), request,
                        result) > 0;
  }

  /// Whether a triangle of the part that meets `bound` (placed `at`) passes `exact(a, b, c)`:
  /// FCL lists the triangles in the bound, each then tested exactly. A list cut short at
  /// kMaxContacts says yes (not cleared).
  template <class Exact>
  bool anyTriangleIn(const fcl::CollisionGeometryd& bound, const fcl::Transform3d& at,
                     Exact&& exact) const {
    constexpr std::size_t kMaxContacts = std::size_t{1} << 22;
    fcl::CollisionRequestd request(kMaxContacts);
    fcl::CollisionResultd result;
    if (fcl::collide(&bound, at, model_.tree.get(), fcl::Transform3d::Identity(), request,
                     result) == 0)
      return false;
    if (result.numContacts() >= kMaxContacts) return true;
    const auto& tree = *model_.tree;
    for (std::size_t i = 0; i < result.numContacts(); ++i) {
      // FCL meets a shape with a mesh as the mesh with the shape: the triangle is the side whose
      // object is the tree (b1 here, not b2).
      const fcl::Contactd& contact = result.getContact(i);
      const fcl::Triangle& t = tree.tri_indices[contact.o1 == &tree ? contact.b1 : contact.b2];
      if (exact(tree.vertices[t[0]], tree.vertices[t[1]], tree.vertices[t[2]])) return true;
    }
    return false;
  }

  /// Whether the part meets the ball of radius `reach_mm` about `centre` under the plane `cap_mm`
  /// over it along the axis (turn's third column): the triangles in the ball, each clipped.
  bool cappedBallMeets(const Vec3& centre, const Eigen::Matrix3d& turn, double reach_mm,
                       double cap_mm) const {
    if (!(cap_mm > -reach_mm)) return false;  // nothing of the ball under its top
    const Vec3 axis = turn.col(2);
    // A point of the cut ball: wholly inside a closed part, it meets it.
    if (model_.solids.contains(centre + 0.5 * (std::min(cap_mm, reach_mm) - reach_mm) * axis))
      return true;
    return anyTriangleIn(fcl::Sphered(reach_mm), placed(turn, centre),
                         [&](const Vec3& a, const Vec3& b, const Vec3& c) {
                           return triangleMeetsCappedBall(a, b, c, centre, axis, reach_mm, cap_mm);
                         });
  }

  /// Whether the part comes within `reach_mm` of the disc of radius `disc_mm` about `centre`,
  /// square to the axis (a ball's corner: a disc of no radius, the sphere; a torus's: the ring).
  bool cornerMeets(const Vec3& centre, const Eigen::Matrix3d& turn, double disc_mm,
                   double reach_mm) const {
    if (model_.solids.contains(centre)) return true;  // wholly inside a closed part
    const fcl::Transform3d at = placed(turn, centre);
    if (!(disc_mm > 1e-9)) return meets(fcl::Sphered(reach_mm), at);
    // Over the disc the eroded corner is a slab: FCL's cylinder, exactly.
    if (meets(fcl::Cylinderd(disc_mm, 2.0 * reach_mm), at)) return true;
    // Around it a ring (a torus: no FCL shape). The triangles in the cylinder that bounds it are
    // each measured from the disc (GJK, ~1e-7 mm): within reach, they enter the ring.
    const fcl::Cylinderd disc(disc_mm, 0.0);
    const fcl::detail::GJKSolver_libccd<double> solver;
    return anyTriangleIn(fcl::Cylinderd(disc_mm + reach_mm, 2.0 * reach_mm), at,
                         [&](const Vec3& a, const Vec3& b, const Vec3& c) {
                           double distance = 0.0;
                           return !solver.shapeTriangleDistance(disc, at, a, b, c, &distance) ||
                                  distance <= reach_mm;
                         });
  }

 private:
  const ObstacleModel& model_;
};

/// The deepest shrink at which the cutter still meets the part at `pose`, given that it meets it
/// at `known_mm`: bisection to kGougeDepthResolutionMm (the cutter shrunk more lies inside the
/// cutter shrunk less, so meeting is monotone in the shrink).
double entryDepthMm(const Part& part, const geometry::ToolSpec& tool, const Posture& pose,
                    double known_mm) {
  double inside = known_mm, clear = tool.radius_mm;
  while (clear - inside > kGougeDepthResolutionMm) {
    const double mid = 0.5 * (inside + clear);
    (part.touches(tool, pose, mid) ? inside : clear) = mid;
  }
  return inside;
}

/// How far apart the stamps stand along a motion, and how far from its tip the cutter reaches.
struct StampSpacing {
  double step_mm = 0;   ///< no point of the cutter moves farther between two stamps
  double reach_mm = 0;  ///< the farthest point of the cutter from its tip
};

/// A cutting surface whose tightest curvature radius is ρ (a ball's R, a torus's corner r; the
/// shank's R is no tighter) swept between two stamps s apart stands at most s² / (8 ρ) beyond
/// both: s = √(2 ρ tolerance) keeps that to a quarter of the tolerance. The reach: the top rim's
/// distance (or the ball's far side, for a ball shorter than its diameter).
StampSpacing stampSpacing(const geometry::ToolSpec& tool, double tolerance_mm) {
  const double tightest = geometry::cornerRadius(tool);
  return {std::sqrt(2.0 * tightest * tolerance_mm),
          std::max(std::hypot(tool.length_mm, tool.radius_mm), 2.0 * tightest)};
}

/// `part_box` grown by the cutter's reach: a motion whose tips' box misses it cannot meet the part.
Eigen::AlignedBox3d nearPart(Eigen::AlignedBox3d part_box, double reach_mm) {
  part_box.min().array() -= reach_mm;
  part_box.max().array() += reach_mm;
  return part_box;
}

bool motionNear(const Posture& a, const Posture& b, const Eigen::AlignedBox3d& near) {
  Eigen::AlignedBox3d motion(a.tip_mm);
  motion.extend(b.tip_mm);
  return motion.intersects(near);
}

/// The stamps along the motions of `postures` near the part.
double motionStamps(std::span<const Posture> postures, const Eigen::AlignedBox3d& near,
                    const StampSpacing& spacing) {
  double count = 0;
  for (std::size_t i = 0; i + 1 < postures.size(); ++i)
    if (motionNear(postures[i], postures[i + 1], near))
      count +=
          geometry::motionSteps(postures[i], postures[i + 1], spacing.reach_mm, spacing.step_mm);
  return count;
}

/// `count` stamps along the motions, and `postures` stamps at the postures, asked for (passing).
void requireStamps(double count, std::size_t postures, const StampSpacing& spacing) {
  // Each stamp also has its verdict (one byte) beside it while the test runs.
  common::requireMemory("the cutter's test against the part",
                        (count + double(postures)) * double(sizeof(Stamp) + 1),
                        common::shortNumber(count) + " stamps along the motions, " +
                            common::shortNumber(spacing.step_mm) + " mm apart",
                        common::MemoryUse::kPassing);
}

/// The stamps' bytes said before they are taken (a tolerance of 1e-8 mm made 25.8 M stamps,
/// 2.6 GB): the postures and the stamps of every motion near the part. Returns how many at most.
std::size_t requireStampMemory(std::span<const Posture> postures, const Eigen::AlignedBox3d& near,
                               const StampSpacing& spacing) {
  const double count = motionStamps(postures, near, spacing);
  requireStamps(count, postures.size(), spacing);
  return static_cast<std::size_t>(count) + postures.size();
}

/// The postures and the stamps along the motions that come within the tool's length of the
/// part's box, `step_mm` apart at most for any point of the tool (geometry::forEachPoseBetween).
std::vector<Stamp> stampsNearPart(std::span<const Posture> postures, const Part& part,
                                  const StampSpacing& spacing) {
  const Eigen::AlignedBox3d near = nearPart(part.box(), spacing.reach_mm);
  const std::size_t most = requireStampMemory(postures, near, spacing);
  const double reach_mm = spacing.reach_mm, step_mm = spacing.step_mm;
  std::vector<Stamp> out;
  out.reserve(most);  // once: growing by doubling held up to twice the bytes said
  for (std::size_t i = 0; i < postures.size(); ++i) {
    if (near.contains(postures[i].tip_mm)) out.push_back({postures[i], i, false});
    if (i + 1 == postures.size()) break;
    const Posture& a = postures[i];
    const Posture& b = postures[i + 1];
    if (!motionNear(a, b, near)) continue;
    geometry::forEachPoseBetween(a, b, reach_mm, step_mm, [&](const Posture& pose) {
      out.push_back({pose, i, true});
    });
  }
  return out;
}

/// Calls visit(begin, end) for each run of stamps of one posture or of one motion (stampsNearPart
/// makes them in runs).
template <class Visit>
void forEachOwner(const std::vector<Stamp>& stamps, Visit&& visit) {
  for (std::size_t begin = 0; begin < stamps.size();) {
    std::size_t end = begin + 1;
    while (end < stamps.size() && stamps[end].index == stamps[begin].index &&
           stamps[end].on_motion == stamps[begin].on_motion)
      ++end;
    visit(begin, end);
    begin = end;
  }
}

}  // namespace

struct CutterMemo::Impl {
  using PostureKey = std::array<std::uint64_t, 6>;
  using MotionKey = std::array<std::uint64_t, 12>;
  /// The tool's shape, R, r and L, and the tolerance.
  using Context = std::array<std::uint64_t, 5>;
  std::optional<Context> context;
  std::shared_ptr<const ObstacleModel> part;  ///< held: another model at its address is another
  /// The owners clear at every stamp, each with the generation that last put or gave it back.
  std::unordered_map<PostureKey, std::uint32_t, memo_detail::BitsHash<6>> clear_postures;
  std::unordered_map<MotionKey, std::uint32_t, memo_detail::BitsHash<12>> clear_motions;
  std::size_t reused = 0;
  std::uint32_t generation = 0;

  /// Emptied where the part, the tool or the tolerance is not the one it was filled for.
  void useFor(const std::shared_ptr<const ObstacleModel>& model, const geometry::ToolSpec& tool,
              double tolerance_mm) {
    const Context now{
        static_cast<std::uint64_t>(tool.shape), std::bit_cast<std::uint64_t>(tool.radius_mm),
        std::bit_cast<std::uint64_t>(tool.corner_radius_mm),
        std::bit_cast<std::uint64_t>(tool.length_mm), std::bit_cast<std::uint64_t>(tolerance_mm)};
    if (context == now && part == model) return;
    clear_postures.clear();
    clear_motions.clear();
    context = now;
    part = model;
  }
  /// Whether the posture or the motion (from posture `index` on) that `stamp` belongs to is held
  /// clear (and marked used); with `put`, it is put in instead.
  bool clear(std::span<const Posture> postures, const Stamp& stamp, bool put) {
    const auto ask = [&](auto& owners, const auto& key) {
      if (put) return owners.insert_or_assign(key, generation).second;
      const auto hit = owners.find(key);
      if (hit == owners.end()) return false;
      hit->second = generation;
      return true;
    };
    if (stamp.on_motion) {
      MotionKey key;
      memo_detail::putBits(key.data(), postures[stamp.index]);
      memo_detail::putBits(key.data() + 6, postures[stamp.index + 1]);
      return ask(clear_motions, key);
    }
    PostureKey key;
    memo_detail::putBits(key.data(), postures[stamp.index]);
    return ask(clear_postures, key);
  }
};

CutterMemo::CutterMemo() : impl_(std::make_unique<Impl>()) {}
CutterMemo::~CutterMemo() = default;
std::size_t CutterMemo::reused() const { return impl_->reused; }

void CutterMemo::forgetUnused() {
  const std::uint32_t now = impl_->generation;
  std::erase_if(impl_->clear_postures, [now](const auto& entry) { return entry.second != now; });
  std::erase_if(impl_->clear_motions, [now](const auto& entry) { return entry.second != now; });
  ++impl_->generation;
}

void requireCutterTestMemory(const geometry::ToolSpec& tool, const Eigen::AlignedBox3d& part_box,
                             std::span<const std::vector<Posture>> passes, double tolerance_mm) {
  if (tool.shape == geometry::ToolShape::Flat || part_box.isEmpty() || !(tolerance_mm > 0.0) ||
      !(tolerance_mm < tool.radius_mm))
    return;  // nothing the test would stamp
  const StampSpacing spacing = stampSpacing(tool, tolerance_mm);
  const Eigen::AlignedBox3d near = nearPart(part_box, spacing.reach_mm);
  // Each pass's own motions: the move from one pass to the next is a link, whose way (up, over,
  // down) is not known yet (a jump straight across counted 5.2 M stamps where the test made 2.3).
  double count = 0;
  std::size_t postures = 0;
  for (const std::vector<Posture>& pass : passes) {
    count += motionStamps(pass, near, spacing);
    postures += pass.size();
  }
  requireStamps(count, postures, spacing);
}

CutterPartResult checkCutterAgainstPart(const geometry::ToolSpec& tool,
                                        const geometry::TriangleMesh& part_mesh,
                                        std::span<const Posture> postures, double tolerance_mm,
                                        const common::Progress& progress) {
  if (tool.shape == geometry::ToolShape::Flat || part_mesh.triangles.empty()) {
    CutterPartResult result;
    result.tolerance_mm = tolerance_mm;
    return result;
  }
  return checkCutterAgainstPart(tool, prepareObstacle(part_mesh, "part"), postures, tolerance_mm,
                                progress);
}

CutterPartResult checkCutterAgainstPart(const geometry::ToolSpec& tool,
                                        const std::shared_ptr<const ObstacleModel>& part_model,
                                        std::span<const Posture> postures, double tolerance_mm,
                                        const common::Progress& progress, CutterMemo* memo) {
  CutterPartResult result;
  result.tolerance_mm = tolerance_mm;
  if (tool.shape == geometry::ToolShape::Flat || !part_model || !(tolerance_mm > 0.0) ||
      !(tolerance_mm < tool.radius_mm))
    return result;
  const Part part(*part_model);
  const StampSpacing spacing = stampSpacing(tool, tolerance_mm);
  result.step_mm = spacing.step_mm;
  const double tightest = geometry::cornerRadius(tool);
  result.between_stamps_mm = result.step_mm * result.step_mm / (8.0 * tightest);
  const std::vector<Stamp> stamps = stampsNearPart(postures, part, spacing);
  result.stamps = stamps.size();
  std::vector<char> gouging(stamps.size(), 0);
  // The stamps of the postures and motions that the memo holds clear: not tested again.
  CutterMemo::Impl* const kept = memo ? &memo->impl() : nullptr;
  std::vector<char> known(kept ? stamps.size() : 0, 0);
  if (kept) {
    kept->useFor(part_model, tool, tolerance_mm);
    forEachOwner(stamps, [&](std::size_t begin, std::size_t end) {
      if (!kept->clear(postures, stamps[begin], false)) return;
      std::fill(known.begin() + begin, known.begin() + end, 1);
      ++kept->reused;
    });
  }
  constexpr std::size_t kBatch = 4096;
  for (std::size_t begin = 0; begin < stamps.size(); begin += kBatch) {
    const std::size_t end = std::min(stamps.size(), begin + kBatch);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end), [&](const auto& range) {
      for (std::size_t i = range.begin(); i != range.end(); ++i)
        if (!kept || !known[i]) gouging[i] = part.touches(tool, stamps[i].pose, tolerance_mm);
    });
    common::report(progress, double(end) / double(stamps.size()), "cutter vs part");
  }
  if (kept)
    forEachOwner(stamps, [&](std::size_t begin, std::size_t end) {
      if (!known[begin] && std::none_of(gouging.begin() + begin, gouging.begin() + end,
                                        [](char g) { return g != 0; }))
        kept->clear(postures, stamps[begin], true);
    });
  // The depth of the deepest: each gouging stamp bisected only where it goes deeper than the
  // deepest so far (few stamps gouge in a path worth running).
  for (std::size_t i = 0; i < stamps.size(); ++i) {
    if (!gouging[i]) continue;
    const Stamp& s = stamps[i];
    (s.on_motion ? result.motion_contacts : result.posture_contacts).push_back(s.index);
    const double known = std::max(tolerance_mm, result.max_depth_mm);
    if (result.max_depth_mm > 0.0 && !part.touches(tool, s.pose, known + kGougeDepthResolutionMm))
      continue;
    result.max_depth_mm = entryDepthMm(part, tool, s.pose, known);
    result.deepest = s.index;
    result.deepest_on_motion = s.on_motion;
  }
  for (std::vector<std::size_t>* list : {&result.posture_contacts, &result.motion_contacts})
    list->erase(std::unique(list->begin(), list->end()), list->end());
  result.gouging_postures = result.posture_contacts.size();
  result.gouging_motions = result.motion_contacts.size();
  if (!result.posture_contacts.empty()) result.first_gouging_posture = result.posture_contacts[0];
  if (!result.motion_contacts.empty()) result.first_gouging_motion = result.motion_contacts[0];
  return result;
}

}  // namespace fieldpath::pathgen
