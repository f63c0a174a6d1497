#include "link_reroute.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <utility>
#include <vector>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"

namespace fieldpath::pathgen {
namespace {

using geometry::Posture;
using geometry::Vec3;

/// Fractions of the turn from the axis to the vertical tried for a way up (past 1: on past the
/// vertical, leaning the other way), in order: the first that clears is taken, the least turn.
constexpr double kWayFractions[] = {0.25, 0.5, 0.75, 1.0, 1.25, 1.5};
/// A way up must rise at least this much (its z component): sin 5°, as the links' own climb.
constexpr double kMinWayRise = 0.0872;

/// How a way up from a pass's end posture checks: collisions, then the least clearance of the
/// obstacles (mm), the pass's own posture not counted (every way starts there).
struct WayCheck {
  std::size_t collisions = 0;
  double min_mm = std::numeric_limits<double>::infinity();
  /// Fewer collisions; among clear ways, more clearance. Among colliding ones the clearance
  /// does not choose (a ball written into the part collides every way: a way 90 deg off a
  /// 60 deg axis was taken for 0.26 mm more of the obstacles).
  bool betterThan(const WayCheck& o) const {
    return collisions != o.collisions ? collisions < o.collisions
                                      : collisions == 0 && min_mm > o.min_mm;
  }
};

/// Checks a pass's end posture `p` left (or entered) by `way` with its axis held (along the axis
/// where `way` is), as linkPasses writes it.
class WayChecker {
 public:
  WayChecker(const GenerateRequest& request, const ClearanceChecker& obstacles, double safe_z_mm)
      : request_(request), obstacles_(obstacles), safe_z_mm_(safe_z_mm) {
    if (request.part) {
      const auto model = prepareObstacle(*request.part, "part");
      whole_.emplace(geometry::toolMesh(request.tool, request.holder, kClearanceMeshTolMm),
                     std::span(&model, 1), kClearanceMeshTolMm);
      grazing_.emplace(grazingPartChecker(request.tool, request.holder, model));
    }
  }

  WayCheck check(const Posture& p, const LinkEndWay& way, bool into) const {
    const double z_mm = safe_z_mm_ - lowestPointBelowTip(request_.tool, request_.holder, p.axis);
    const Vec3 climb = way.alongAxis() ? p.axis : way.climb;
    Posture retracted = p, travel = p;
    retracted.tip_mm =
        p.tip_mm + request_.links.retract_mm * (way.alongAxis() ? p.axis : way.retract_dir);
    travel.tip_mm = retracted.tip_mm;
    if (climb.z() >= kMinWayRise)
      travel.tip_mm += std::max(0.0, (z_mm - retracted.tip_mm.z()) / climb.z()) * climb;
    else  // an axis near horizontal: its link goes straight up from the retract (linkPasses)
      travel.tip_mm.z() = std::max(travel.tip_mm.z(), z_mm);
    const std::vector<Posture> up = {p, retracted, travel};
    WayCheck out;
    const ClearanceResult at = obstacles_.check(up);
    MotionRequest motions;
    motions.required_mm = request_.clearance_mm;
    motions.posture_clearance_mm = at.clearance_mm;
    // Told to within 10 % (a lower bound), as the links are against the part: a way is chosen
    // here, the path taken is checked in full after.
    motions.tighten_fraction = 0.1;
    // Told to within 10 % (a lower bound), as the links are against the part: a way is chosen
    // here, the path taken is checked in full after.
    motions.tighten_fraction = 0.1;
    const MotionResult moved = obstacles_.checkMotions(up, motions);
    for (std::size_t k = 1; k < up.size(); ++k) {
      out.collisions += at.clearance_mm[k] <= 0.0;
      out.min_mm = std::min(out.min_mm, at.clearance_mm[k]);
    }
    out.collisions += moved.colliding;
    // The move from the pass's posture is no clearer than that posture: counted only where the
    // posture keeps the clearance (a pass under it would make every way as bad).
    out.min_mm = std::min(out.min_mm, moved.clearance_mm[1]);
    if (at.clearance_mm[0] >= request_.clearance_mm)
      out.min_mm = std::min(out.min_mm, moved.clearance_mm[0]);
    if (whole_) {
      // As the path holds it: the pass's posture, then the link (the move between them grazes).
      geometry::PathFile path;
      path.postures = into ? std::vector<Posture>{travel, retracted, p} : up;
      using Kind = geometry::PathBlock::Kind;
      path.blocks = into ? std::vector<geometry::PathBlock>{{Kind::Link, 0, 2}, {Kind::Pass, 2, 3}}
                         : std::vector<geometry::PathBlock>{{Kind::Pass, 0, 1}, {Kind::Link, 1, 3}};
      const LinkPartResult part = checkLinksAgainstPart(*whole_, *grazing_, path);
      out.collisions += part.colliding_postures + part.colliding_motions;
    }
    return out;
  }

 private:
  const GenerateRequest& request_;
  const ClearanceChecker& obstacles_;
  double safe_z_mm_;
  std::optional<ClearanceChecker> whole_;  // tool + holder against the part
  std::optional<GrazingChecker> grazing_;
};

/// The ways up tried after the axis, climbing on the great circle from `axis` through +z (none
/// for an axis within 0.5 deg of vertical, whose way is already straight up): at each angle,
/// first after the retract along the axis (DESIGN's), then with the retract along the climb too
/// (where the retract's end is in the way: a pass settled in a channel). An axis near horizontal
/// climbs straight up from its retract (linkPasses), but one 5.7 deg up climbed along itself,
/// 460 mm sideways through a block (a helper's), where the retract then straight up was clear.
std::vector<LinkEndWay> waysUp(const Vec3& axis) {
  std::vector<LinkEndWay> out;
  const double angle = std::acos(std::clamp(axis.z(), -1.0, 1.0));
  Vec3 side = axis - axis.z() * Vec3::UnitZ();  // the horizontal the axis leans to
  if (angle < 0.5 * geometry::kDegToRad || side.norm() < 1e-9) return out;
  side.normalize();
  for (const double t : kWayFractions) {
    const double from_vertical = (1.0 - t) * angle;  // negative: past the vertical
    const Vec3 way = std::cos(from_vertical) * Vec3::UnitZ() + std::sin(from_vertical) * side;
    if (way.z() < kMinWayRise) continue;
    out.push_back({axis, way});
    out.push_back({way, way});
  }
  return out;
}

/// Whether the link's postures and motions at the pass's end posture `i` (output index) on the
/// side `into` (before it) or out (after it) collide or come under `required_mm`.
bool faultyEnd(const GenerateResult& result, const std::optional<PartContacts::Marks>& marks,
               std::size_t i, bool into, double required_mm) {
  const auto& at = result.clearance.clearance_mm;
  const auto& moving = result.motions.clearance_mm;
  // Into: postures i-2, i-1 and the motions from them; out: postures i+1, i+2, motions from i, i+1.
  // The move from the pass's posture is no clearer than that posture: it counts under the
  // required clearance only where the posture is not.
  const bool end_under = i < at.size() && at[i] < required_mm;
  for (int d = 1; d <= 2; ++d) {
    const std::ptrdiff_t posture = into ? static_cast<std::ptrdiff_t>(i) - d : i + d;
    const std::ptrdiff_t motion = into ? static_cast<std::ptrdiff_t>(i) - d : i + d - 1;
    if (posture >= 0 && static_cast<std::size_t>(posture) < at.size()) {
      const auto k = static_cast<std::size_t>(posture);
      if (at[k] < required_mm || (marks && k < marks->posture.size() && marks->posture[k]))
        return true;
    }
    if (motion >= 0 && static_cast<std::size_t>(motion) < moving.size()) {
      const auto k = static_cast<std::size_t>(motion);
      const bool from_end = d == 1;  // the move touching the pass's posture
      if (moving[k] <= 0.0 || (moving[k] < required_mm && !(from_end && end_under)) ||
          (marks && k < marks->motion.size() && marks->motion[k]))
        return true;
    }
  }
  return false;
}

}  // namespace

std::vector<GenerateResult::RoutedLinkEnd> rerouteLinkEnds(
    const GenerateRequest& request, const ClearanceChecker& checker, double safe_z_mm,
    const GenerateResult& result, const std::optional<PartContacts::Marks>& part_marks) {
  std::vector<GenerateResult::RoutedLinkEnd> routed;
  // Each pass's first and last posture in result.postures.
  std::vector<std::pair<std::size_t, std::size_t>> ends(result.passes.size(), {std::size_t(-1), 0});
  for (std::size_t k = 0; k < result.postures.size(); ++k) {
    auto& [first, last] = ends[static_cast<std::size_t>(result.postures[k].pass)];
    first = std::min(first, k);
    last = std::max(last, k);
  }
  std::optional<WayChecker> ways;  // the part's model built only where a link end is faulty
  for (std::size_t p = 0; p < ends.size(); ++p) {
    if (ends[p].first == std::size_t(-1)) continue;
    for (const bool into : {true, false}) {
      const GeneratedPosture& g = result.postures[into ? ends[p].first : ends[p].second];
      if (!faultyEnd(result, part_marks, g.output, into, request.clearance_mm)) continue;
      if (!ways) ways.emplace(request, checker, safe_z_mm);
      const Posture& posture = g.posture;
      const WayCheck along = ways->check(posture, LinkEndWay{}, into);
      std::optional<std::pair<LinkEndWay, WayCheck>> best;
      for (const LinkEndWay& way : waysUp(posture.axis)) {
        const WayCheck c = ways->check(posture, way, into);
        if (!best || c.betterThan(best->second)) best.emplace(way, c);
        if (c.collisions == 0 && c.min_mm >= request.clearance_mm)
          break;  // the least turn that clears
      }
      if (!best || !best->second.betterThan(along)) continue;
      GenerateResult::RoutedLinkEnd end;
      end.pass = result.passes[p].index;
      end.label = result.passes[p].label;
      end.into = into;
      end.way = best->first.climb;
      end.retract_along_axis = best->first.retract_dir == posture.axis;
      end.off_axis_deg =
          std::acos(std::clamp(end.way.dot(posture.axis), -1.0, 1.0)) / geometry::kDegToRad;
      end.axis_collisions = along.collisions;
      end.axis_min_mm = along.min_mm;
      end.taken_collisions = best->second.collisions;
      end.taken_min_mm = best->second.min_mm;
      routed.push_back(end);
    }
  }
  return routed;
}

void linkWays(const GenerateResult& result, LinkRequest& links) {
  links.in_ways.assign(result.passes.size(), LinkEndWay{});
  links.out_ways.assign(result.passes.size(), LinkEndWay{});
  // Each pass's end postures, for the retract along the axis.
  std::vector<const geometry::Posture*> first(result.passes.size()), last(result.passes.size());
  for (const GeneratedPosture& g : result.postures) {
    const auto p = static_cast<std::size_t>(g.pass);
    if (!first[p]) first[p] = &g.posture;
    last[p] = &g.posture;
  }
  for (const auto& end : result.routed_link_ends)
    for (std::size_t p = 0; p < result.passes.size(); ++p)
      if (result.passes[p].index == end.pass && first[p]) {
        const Vec3& axis = (end.into ? first[p] : last[p])->axis;
        (end.into ? links.in_ways : links.out_ways)[p] =
            LinkEndWay{end.retract_along_axis ? axis : end.way, end.way};
      }
}

}  // namespace fieldpath::pathgen
