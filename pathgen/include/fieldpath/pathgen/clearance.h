#pragma once
/// Exact clearance of tool + holder against the obstacle meshes (FCL, which stays inside the .cpp):
/// triangle-exact distances between bounding-volume hierarchies (OBBRSS) built once.
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::pathgen {

using geometry::Vec3;

/// Exact results kept from one check for the next (a repair checks again the path it changed:
/// most of its postures and motions are those checked before, bit for bit). A posture's
/// clearance is its own, whatever the postures around it, and a motion's bound is its two
/// postures' under one request: the same key, the same result. One check at a time uses it, and
/// one checker (its keys do not name the tool or the obstacles).
class ClearanceMemo {
 public:
  ClearanceMemo();
  ~ClearanceMemo();
  ClearanceMemo(const ClearanceMemo&) = delete;
  ClearanceMemo& operator=(const ClearanceMemo&) = delete;
  /// Postures and motions given back from it so far, not measured again.
  std::size_t reused() const;
  /// Drops what the checks since the last call did not use: called before each check of a whole
  /// path, the memo holds at most two checks' postures and motions (a repair job's checks grew it
  /// by the path's changes each, for nothing: a motion keyed by bounds that a shifted posture
  /// changed is never asked again).
  void forgetUnused();
  /// Drops everything (another checker's results are not these).
  void clear();

 private:
  friend class ClearanceChecker;
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

struct ClearanceRequest {
  bool per_posture = true;  ///< fill ClearanceResult::clearance_mm
  /// Where set, the postures found in it are not measured again, and those measured are kept in
  /// it (not with exact_min_only, whose bounds are not the postures' own).
  ClearanceMemo* memo = nullptr;
  /// Postures per progress report (and per parallel batch).
  std::size_t batch = 256;
  /// Only the minimum (value and posture) and the colliding postures exact: every 8th posture is
  /// measured, then a posture whose lower bound from its measured neighbours (their clearance
  /// less |Δtip| + ρ_max times the angle between the two placements' rotations, twist included)
  /// is above 0 and above the least measured keeps that bound (never above what a query would
  /// give) instead of a query. For checks that
  /// report a minimum and contacts, not each posture's figure: the holder against the part took
  /// half of a 97k-posture job.
  bool exact_min_only = false;
};

/// Every motion between consecutive postures (tip and axis interpolated linearly, the axis
/// renormalised), checked by adaptive sampling with a certified bound: tool + holder are a solid
/// of revolution about the axis, so between two poses every point of it moves at most
/// D = |Δtip| + ρ_max Δθ (ρ_max: the farthest point from the tip, Δθ: the angle between the
/// axes), and the distance to the obstacles is 1-Lipschitz in that motion. Over a sub-motion
/// whose ends are d0 and d1 away the distance is at least (d0 + d1 - D) / 2. Sub-motions are
/// halved, the lowest bound first, until that bound reaches max(required_mm, min(enough_mm,
/// closest − slack)),
/// slack = max(tighten_mm, tighten_fraction × closest), closest: the closest posture, or (above
/// 0 and required_mm) the lowest distance sampled on the motion less its slack; or a sample
/// touches, or D ≤ 2 `resolution_mm` (the lowest piece resolved: no piece left bounds lower,
/// and the motion's bound is its). The smallest bound is then within `slack` of the true
/// minimum wherever that is above required_mm. The slack is relative far from the obstacles: a
/// fixed 0.01 mm refined a job 10× the size (tool, path, clearances) into 27 s of samples, and 100×
/// into minutes.
struct MotionRequest {
  double required_mm = 0.0;     ///< stop refining a motion once certified at this clearance
  double resolution_mm = 0.005;  ///< halve sub-motions no shorter (in D) than 2 × this
  double tighten_mm = 0.01;      ///< see above
  double tighten_fraction = 0.01;  ///< see above
  /// Where the caller asks only whether the motions keep this much (mm): a motion is certified
  /// once its bound reaches it, if that comes before the rule above (its bound then may lie
  /// further under its true minimum). The repairs judging one pass against its steering ask so.
  double enough_mm = std::numeric_limits<double>::infinity();
  /// Postures per progress report (and per parallel batch).
  std::size_t batch = 256;
  /// The postures' clearances if known (ClearanceResult::clearance_mm), else computed here.
  std::span<const double> posture_clearance_mm;
  /// Where set, the motions found in it (the same two postures under the same request) are not
  /// refined again, and those refined are kept in it.
  ClearanceMemo* memo = nullptr;
};

struct MotionResult {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t motions = 0;
  /// Lower bound of the clearance over all motions, mm (0 when one touches).
  double min_clearance_mm = std::numeric_limits<double>::infinity();
  std::size_t min_index = npos;  ///< motion i: posture i → i + 1
  /// Motions where a sample touches or the bound cannot exclude contact at the resolution.
  std::size_t colliding = 0;
  std::size_t first_colliding = npos;
  /// Motions whose bound stays below `required_mm` (colliding ones included).
  std::size_t under_required = 0;
  std::size_t first_under_required = npos;
  std::size_t samples = 0;           ///< distance queries between the postures
  std::vector<double> clearance_mm;  ///< per motion: its lower bound, mm
  double tool_reach_mm = 0.0;        ///< the farthest point of tool + holder from the tip, mm
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
  /// Per posture, mm; 0 for colliding ones (if per_posture); lower bounds where
  /// ClearanceRequest::exact_min_only spared the query.
  std::vector<double> clearance_mm;
};

/// An obstacle mesh as the exact checks test it (FCL's tree, its closed shells, its sheets), built
/// once and shared by the checkers that test against the same mesh (a part is tested for its
/// links, the moves into passes, the holder and the cutter). Opaque outside pathgen.
struct ObstacleModel;
std::shared_ptr<const ObstacleModel> prepareObstacle(const geometry::TriangleMesh& mesh,
                                                     const std::string& what);

/// What ClearanceChecker::ballClearance is asked.
struct BallRequest {
  double radius_mm = 0.0;
  /// Finite: only a smallest clearance under it is exact (and its `at`): a centre within
  /// d - exact_below - R of one measured d from the obstacles is not measured (the distance to a
  /// surface changes no faster than the point moves, and the point stays on the same side of it),
  /// so a dense path far from the walls costs a few queries, not one a station (97k stations took
  /// 17 s); a result of exact_below_mm or more is a lower bound.
  double exact_below_mm = std::numeric_limits<double>::infinity();
  /// Finite (over exact_below_mm): each centre told exactly nearer or farther than it, its value
  /// a lower bound between the two (a centre proven nearer by its walk, d + |c - c_measured| - R
  /// under split_mm, is not measured: a path hovering 1.5 mm over a part, told against 6 mm,
  /// checked as fast as one on it). With exact_below_mm = -radius_mm and split_mm = 0 a centre is
  /// told only touching (0) or clear (> 0), each measured one telling its neighbours within
  /// min(d, R - d) and beyond d - R (check's stock beside obstacles).
  double split_mm = std::numeric_limits<double>::quiet_NaN();
  bool each = false;  ///< fill BallResult::each_mm
};
struct BallResult {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  double min_mm = std::numeric_limits<double>::infinity();  ///< the least clearance (none: inf)
  std::size_t at = npos;                                    ///< its centre (first of equals)
  int obstacle = -1;                                        ///< its obstacle (0-based)
  /// With BallRequest::each: every centre's clearance, exact under exact_below_mm (a lower bound
  /// at or above it).
  std::vector<double> each_mm;
};

/// Tool + holder mesh (tool frame: tip at the origin, axis +z) against fixed obstacle meshes.
/// Copies share the built hierarchies; queries are const and thread-safe.
class ClearanceChecker {
 public:
  /// Builds the hierarchies once. Throws common::InputError for an empty mesh. Reported
  /// clearances are the mesh distances less `tool_chord_tol_mm`: a faceted tool whose vertices
  /// lie on the true surface is inside it by up to its chordal error, so they are never
  /// optimistic (DESIGN.md "Links and motion").
  ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                   std::span<const geometry::TriangleMesh> obstacles,
                   double tool_chord_tol_mm = 0.0);
  /// The same against obstacles prepared once (prepareObstacle), shared with other checkers.
  ClearanceChecker(const geometry::TriangleMesh& tool_mesh,
                   std::span<const std::shared_ptr<const ObstacleModel>> obstacles,
                   double tool_chord_tol_mm = 0.0);

  /// Distance (mm) from the placed tool to the nearest obstacle less the chordal tolerance, 0 if
  /// they touch or intersect; `obstacle` (optional) receives its index.
  double clearance(const geometry::Posture& posture, int* obstacle = nullptr) const;

  /// Every posture, in parallel (TBB); progress is reported between batches.
  ClearanceResult check(std::span<const geometry::Posture> postures,
                        const ClearanceRequest& request = {},
                        const common::Progress& progress = {}) const;

  /// Every motion between consecutive postures (see MotionRequest), in parallel (TBB).
  MotionResult checkMotions(std::span<const geometry::Posture> postures,
                            const MotionRequest& request = {},
                            const common::Progress& progress = {}) const;

  /// Smallest distance (mm) from balls of `request.radius_mm` at `centres_mm` (world frame) to
  /// the obstacles, 0 if one touches, where and from which obstacle (BallRequest: how exact).
  /// The ball of a ball-end mill must clear the obstacles whatever the axis: exact (centre-to-mesh
  /// distance less the radius).
  BallResult ballClearance(std::span<const Vec3> centres_mm, const BallRequest& request) const;
  /// The smallest alone, exact.
  double ballClearance(std::span<const Vec3> centres_mm, double radius_mm) const {
    return ballClearance(centres_mm, BallRequest{radius_mm}).min_mm;
  }

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace fieldpath::pathgen
