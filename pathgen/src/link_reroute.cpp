#include "link_reroute.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <string>
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
/// The leans from the vertical (deg) and the directions of the climbs tried round the vertical.
constexpr double kSideClimbDeg[] = {30.0, 60.0};
constexpr int kSideClimbAzimuths = 8;
/// The moves sideways before a climb straight up, in widest radii of the tool and holder.
constexpr double kAsideReaches[] = {2.0, 4.0, 8.0};
/// The first shorter retract tried before a move sideways, a part of links.retract: a pass just
/// under a shelf, whose full retract runs into it (a helper's 90 mm holder 5 mm under one).
constexpr double kAsideRetractPart = 0.25;
/// The ways tried, family by family (waysUp).
enum class WayFamily { Circle, Around, Aside };
/// The motions' resolution in the ways' checks (mm; MotionRequest's is 0.005).
constexpr double kWayResolutionMm = 0.05;
/// A way up must rise at least this much (its z component): sin 5°, as the links' own climb.
constexpr double kMinWayRise = 0.0872;

/// How a way up from a pass's end posture checks: its collisions, and the least clearance of the
/// obstacles (mm), the pass's own posture not counted (every way starts there).
struct WayCheck {
  std::size_t collisions = 0;
  double min_mm = std::numeric_limits<double>::infinity();
};

/// Checks a pass's end posture `p` left (or entered) by `way` with its axis held (along the axis
/// where `way` is), as linkPasses writes it.
class WayChecker {
 public:
  WayChecker(const GenerateRequest& request, const ClearanceChecker& obstacles,
             const std::shared_ptr<const ObstacleModel>& model, double safe_z_mm)
      : request_(request), obstacles_(obstacles), safe_z_mm_(safe_z_mm) {
    if (model) {
      const double tol_mm = clearanceMeshTolMm(request.tool, request.holder);
      whole_.emplace(geometry::toolMesh(request.tool, request.holder, tol_mm), std::span(&model, 1),
                     tol_mm);
      grazing_.emplace(grazingPartChecker(request.tool, request.holder, model));
    }
  }

  /// Stops counting at `give_up_at` collisions.
  WayCheck check(const Posture& p, const LinkEndWay& way, bool into,
                 std::size_t give_up_at = std::numeric_limits<std::size_t>::max()) const {
    const double z_mm = safe_z_mm_ - lowestPointBelowTip(request_.tool, request_.holder, p.axis);
    std::vector<Posture> up = {p};
    const auto pass = [&](const Vec3& tip) {
      up.push_back(p);
      up.back().tip_mm = tip;
    };
    if (!way.alongAxis()) {
      for (const Vec3& tip : wayTips(p.tip_mm, z_mm, request_.links.retract_mm, way)) pass(tip);
    } else {  // as linkPasses: along the axis, or for one near horizontal, retract then up
      const Vec3 retracted = p.tip_mm + request_.links.retract_mm * p.axis;
      pass(retracted);
      Vec3 travel = retracted;
      if (p.axis.z() >= kMinWayRise)
        travel += std::max(0.0, (z_mm - retracted.z()) / p.axis.z()) * p.axis;
      else
        travel.z() = std::max(travel.z(), z_mm);
      pass(travel);
    }
    WayCheck out;
    const ClearanceResult at = obstacles_.check(up);
    for (std::size_t k = 1; k < up.size(); ++k) {
      out.collisions += at.clearance_mm[k] <= 0.0;
      out.min_mm = std::min(out.min_mm, at.clearance_mm[k]);
    }
    if (out.collisions >= give_up_at) return out;
    // Bounded as the path's own motions are (a bound within the slack keptMm allows), one
    // motion at a time from the climb down: the climb is where a way runs into what is over the
    // pass, and a motion kept under the clearance is sampled finely (a shelf over every way: 13 s
    // an end with the moves under it certified first, a links adversary's).
    for (std::size_t k = up.size() - 1; k-- > 0;) {
      MotionRequest motions;
      motions.required_mm = request_.clearance_mm;
      // Coarser than the path's own check (0.005 mm): a way's motion kept just under the
      // clearance is halved down to the resolution to tell touching from not, and a 24 mm move
      // 0.48 mm under a shelf cost ~8 s a link end (a regression hunt's). Coarser can only call
      // a way colliding that is not (never the reverse), and the path taken is checked again
      // at the full resolution.
      motions.resolution_mm = kWayResolutionMm;
      motions.posture_clearance_mm = std::span(at.clearance_mm).subspan(k, 2);
      const MotionResult moved = obstacles_.checkMotions(std::span(up).subspan(k, 2), motions);
      out.collisions += moved.colliding;
      out.min_mm = std::min(out.min_mm, moved.min_clearance_mm);
      if (out.collisions >= give_up_at) return out;
    }
    if (whole_) {
      // As the path holds it: the pass's posture, then the link (the move between them grazes).
      geometry::PathFile path;
      path.postures = up;
      if (into) std::reverse(path.postures.begin(), path.postures.end());
      const std::size_t n = up.size();
      using Kind = geometry::PathBlock::Kind;
      path.blocks =
          into ? std::vector<geometry::PathBlock>{{Kind::Link, 0, n - 1}, {Kind::Pass, n - 1, n}}
               : std::vector<geometry::PathBlock>{{Kind::Pass, 0, 1}, {Kind::Link, 1, n}};
      const LinkPartResult part = checkLinksAgainstPart(*whole_, *grazing_, path, {}, true);
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
/// Then (Around), where none of those does better than the axis (an upright axis has none: a
/// pass under a shelf climbed into it, a helper's), climbs leaning kSideClimbDeg from the
/// vertical toward kSideClimbAzimuths directions, the nearest the axis's lean first. Then
/// (Aside), where no straight climb frees it (a pass 10 mm under a shelf, a 90 mm holder below
/// it: a helper's), the retract along the axis, a move sideways of kAsideReaches times the tool
/// and holder's widest radius `reach_mm` toward those directions, then straight up; then the
/// same after shorter retracts (`retract_mm` links.retract: kAsideRetractPart of it, 1 mm, twice
/// the clearance `clearance_mm` within 0.2-1 mm, 0.2 mm), where the full one runs into what is
/// over the pass.
std::vector<LinkEndWay> waysUp(const Vec3& axis, WayFamily family, double reach_mm,
                               double retract_mm, double clearance_mm) {
  std::vector<LinkEndWay> out;
  const auto add = [&](const Vec3& way) {
    if (way.z() < kMinWayRise) return;
    out.push_back({axis, way});
    out.push_back({way, way});
  };
  const double angle = std::acos(std::clamp(axis.z(), -1.0, 1.0));
  Vec3 side = axis - axis.z() * Vec3::UnitZ();  // the horizontal the axis leans to
  const bool leans = angle >= 0.5 * geometry::kDegToRad && side.norm() > 1e-9;
  side = leans ? side.normalized() : Vec3::UnitX();
  if (family == WayFamily::Circle) {
    if (leans)
      for (const double t : kWayFractions) {
        const double from_vertical = (1.0 - t) * angle;  // negative: past the vertical
        add(std::cos(from_vertical) * Vec3::UnitZ() + std::sin(from_vertical) * side);
      }
    return out;
  }
  const Vec3 across = Vec3::UnitZ().cross(side);
  const auto horizontal = [&](int k) {  // azimuths 0, +1, -1, +2, ... steps from the lean
    const int step = (k + 1) / 2 * (k % 2 ? 1 : -1);
    const double azimuth = 2.0 * M_PI * step / kSideClimbAzimuths;
    return Vec3(std::cos(azimuth) * side + std::sin(azimuth) * across);
  };
  if (family == WayFamily::Around) {
    for (const double lean_deg : kSideClimbDeg)
      for (int k = 0; k < kSideClimbAzimuths; ++k) {
        const double lean = lean_deg * geometry::kDegToRad;
        add(std::cos(lean) * Vec3::UnitZ() + std::sin(lean) * horizontal(k));
      }
    return out;
  }
  // The full retract first; then shorter ones (a quarter of it, 1 mm, twice the clearance up to
  // 1 mm, 0.2 mm), the longest that frees the end taken: the move sideways runs over the surface
  // the pass has just cut, checked against the part for contacts only (twice a clearance of 2 mm
  // left a 1 mm retract under a shelf untried; with clearance 0, 0.2 mm over the part where
  // 0.7 mm was free: a regression hunt's).
  // Longest first, each once: a quarter of a 2 mm retract (0.5) comes after 1 mm (it was
  // tried before it, and 1 mm never: a diff review's).
  std::vector<double> retracts = {kAsideRetractPart * retract_mm, 1.0,
                                  std::clamp(2.0 * clearance_mm, 0.2, 1.0), 0.2};
  std::erase_if(retracts, [&](double length) { return length >= retract_mm || length < 0.2; });
  std::sort(retracts.begin(), retracts.end(), std::greater<>());
  retracts.erase(std::unique(retracts.begin(), retracts.end()), retracts.end());
  retracts.insert(retracts.begin(), retract_mm);
  for (std::size_t i = 0; i < retracts.size(); ++i) {
    for (const double reaches : kAsideReaches)
      for (int k = 0; k < kSideClimbAzimuths; ++k) {
        LinkEndWay way{axis, Vec3::UnitZ(), reaches * reach_mm * horizontal(k)};
        if (i > 0) way.retract_mm = retracts[i];
        out.push_back(way);
      }
  }
  return out;
}

/// The clearance a link end must keep (mm): the required one, or the pass's end posture's own
/// where that is less (every way starts there: a link no nearer than its pass does not make the
/// path nearer), less the motions' bound's slack (max(0.01 mm, 1 %), clearance.h): a link 0.0004
/// mm under its pass's 0.955 was taken 60 deg off its axis for 0.045 mm more (a regression
/// hunt's; 2 s to 8 s).
double keptMm(double required_mm, double end_mm) {
  const double target = std::min(required_mm, end_mm);
  return target - std::max(0.01, 0.01 * target);
}

/// Whether the link's postures and motions at the pass's end posture `i` (output index) on the
/// side `into` (before it) or out (after it) collide or come under keptMm.
bool faultyEnd(const GenerateResult& result, const std::optional<PartContacts::Marks>& marks,
               std::size_t i, bool into, double required_mm) {
  const auto& at = result.clearance.clearance_mm;
  const auto& moving = result.motions.clearance_mm;
  const double kept_mm = keptMm(required_mm, i < at.size() ? at[i] : required_mm);
  // Into: postures i-2, i-1 and the motions from them; out: postures i+1, i+2, motions from i, i+1.
  for (int d = 1; d <= 2; ++d) {
    const std::ptrdiff_t posture = into ? static_cast<std::ptrdiff_t>(i) - d : i + d;
    const std::ptrdiff_t motion = into ? static_cast<std::ptrdiff_t>(i) - d : i + d - 1;
    if (posture >= 0 && static_cast<std::size_t>(posture) < at.size()) {
      const auto k = static_cast<std::size_t>(posture);
      if (at[k] <= 0.0 || at[k] < kept_mm ||
          (marks && k < marks->posture.size() && marks->posture[k]))
        return true;
    }
    if (motion >= 0 && static_cast<std::size_t>(motion) < moving.size()) {
      const auto k = static_cast<std::size_t>(motion);
      if (moving[k] <= 0.0 || moving[k] < kept_mm ||
          (marks && k < marks->motion.size() && marks->motion[k]))
        return true;
    }
  }
  return false;
}

/// The pass as a message about its end names it: a nominal pass's way out at its last line (its
/// label names the first: "the way out of pass 1 (nominal.cl:2)" for a link leaving from line
/// 32, a links adversary's).
std::string endLabel(const Pass& pass, bool into) {
  if (into || !pass.whereAt) return pass.label;
  return "pass " + std::to_string(pass.index + 1) + " (" + pass.whereAt(pass.length_mm) + ")";
}

}  // namespace

std::vector<GenerateResult::RoutedLinkEnd> rerouteLinkEnds(
    const GenerateRequest& request, const ClearanceChecker& checker,
    const std::shared_ptr<const ObstacleModel>& part, double safe_z_mm,
    const GenerateResult& result, const std::optional<PartContacts::Marks>& part_marks,
    std::vector<std::string>* unfreed) {
  std::vector<GenerateResult::RoutedLinkEnd> routed;
  // Each pass's first and last posture in result.postures.
  std::vector<std::pair<std::size_t, std::size_t>> ends(result.passes.size(), {std::size_t(-1), 0});
  for (std::size_t k = 0; k < result.postures.size(); ++k) {
    auto& [first, last] = ends[static_cast<std::size_t>(result.postures[k].pass)];
    first = std::min(first, k);
    last = std::max(last, k);
  }
  std::optional<WayChecker> ways;  // built only where a link end is faulty
  // The tool and holder's widest radius: the moves sideways are in it.
  double reach_mm = request.tool.radius_mm;
  for (const auto& station : request.holder) reach_mm = std::max(reach_mm, station.radius_mm);
  for (std::size_t p = 0; p < ends.size(); ++p) {
    if (ends[p].first == std::size_t(-1)) continue;
    for (const bool into : {true, false}) {
      const GeneratedPosture& g = result.postures[into ? ends[p].first : ends[p].second];
      if (!faultyEnd(result, part_marks, g.output, into, request.clearance_mm)) continue;
      // A pass whose end posture collides itself: every way from it does (the impeller's
      // nominal path), and no link of its can be freed.
      const auto& at = result.clearance.clearance_mm;
      if ((g.output < at.size() && at[g.output] <= 0.0) ||
          (part_marks && g.output < part_marks->posture.size() && part_marks->posture[g.output]))
        continue;
      if (!ways) ways.emplace(request, checker, part, safe_z_mm);
      const Posture& posture = g.posture;
      const double kept_mm = keptMm(request.clearance_mm, result.clearance.clearance_mm[g.output]);
      const auto keeps = [&](const WayCheck& c) {
        return c.collisions == 0 && c.min_mm >= kept_mm;
      };
      const WayCheck along = ways->check(posture, LinkEndWay{}, into);
      std::optional<std::pair<LinkEndWay, WayCheck>> best;
      // Off the axis only to keep the clearance, or clear of everything where the axis's way
      // collides: not for a little more clearance where nothing keeps it, nor for fewer
      // collisions (still unsafe: a detour that frees nothing).
      const auto taken = [&] { return best && (keeps(best->second) || along.collisions > 0); };
      for (const WayFamily family : {WayFamily::Circle, WayFamily::Around, WayFamily::Aside}) {
        // Each family only where none before it keeps the clearance: a clear way under it is
        // kept only if no later family keeps it (a 60 deg climb 0.169 mm from a wall was taken
        // where a move sideways kept 5.9 mm, a links adversary's).
        if (best && keeps(best->second)) break;
        for (const LinkEndWay& way : waysUp(posture.axis, family, reach_mm,
                                            request.links.retract_mm, request.clearance_mm)) {
          const WayCheck c = ways->check(posture, way, into, 1);  // a collision rules it out
          // Only a way clear of everything is taken (fewer collisions is still unsafe): the
          // clearest of those.
          if (c.collisions == 0 && (!best || c.min_mm > best->second.min_mm)) best.emplace(way, c);
          if (keeps(c)) break;  // the least turn that keeps it
        }
      }
      if (!taken()) {
        if (unfreed)
          unfreed->push_back(std::string(into ? "the way into " : "the way out of ") +
                             endLabel(result.passes[p], into));
        continue;
      }
      // A leaning climb stops where it is out from under what the axis's way ran into, then
      // rises straight up: the shortest of 1/8, 1/4, 1/2 of it that checks as well (a pass
      // under a shelf left at 60 deg to the plane: 177 mm sideways in a 130 mm scene).
      if (best->first.climb.z() < 1.0 - 1e-9) {
        const double z_mm =
            safe_z_mm - lowestPointBelowTip(request.tool, request.holder, posture.axis);
        const std::vector<Vec3> tips =
            wayTips(posture.tip_mm, z_mm, request.links.retract_mm, best->first);
        const double full_mm = (tips.back() - tips[tips.size() - 2]).norm();
        const bool kept = keeps(best->second);
        for (const double fraction : {0.125, 0.25, 0.5}) {
          LinkEndWay shorter = best->first;
          shorter.climb_mm = fraction * full_mm;
          const WayCheck c = ways->check(posture, shorter, into, 1);
          if (kept ? keeps(c) : c.collisions == 0) {
            best.emplace(shorter, c);
            break;
          }
        }
      }
      GenerateResult::RoutedLinkEnd end;
      end.pass = result.passes[p].index;
      end.label = endLabel(result.passes[p], into);
      end.into = into;
      end.way = best->first.climb;
      end.retract_along_axis = best->first.retract_dir == posture.axis;
      end.retract_mm = best->first.retractMm(request.links.retract_mm);
      end.sideways_mm = best->first.sideways_mm;
      end.climb_mm = best->first.climb_mm;
      end.off_axis_deg =
          std::acos(std::clamp(end.way.dot(posture.axis), -1.0, 1.0)) / geometry::kDegToRad;
      end.axis_collisions = along.collisions;
      end.axis_min_mm = along.min_mm;
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
            LinkEndWay{end.retract_along_axis ? axis : end.way, end.way, end.sideways_mm,
                       end.climb_mm, end.retract_mm};
      }
}

}  // namespace fieldpath::pathgen
