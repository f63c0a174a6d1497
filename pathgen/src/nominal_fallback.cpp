#include "nominal_fallback.h"

#include <algorithm>
#include <cstdint>
#include <functional>
#include <iterator>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <tbb/parallel_for.h>

#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/cutter_part.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

/// Per pass, the postures of the checked path that collide there or on the move to the pass's
/// next posture, those that come under the required clearance there without colliding, and the
/// least clearance of its postures and in-pass motions (mm).
struct PassFaults {
  std::vector<std::size_t> colliding, under;
  std::vector<double> min_mm;
};
PassFaults faultsByPass(const GenerateResult& result, double required_mm,
                        const std::optional<PartContacts::Marks>& part_marks) {
  PassFaults out{
      std::vector<std::size_t>(result.passes.size(), 0),
      std::vector<std::size_t>(result.passes.size(), 0),
      std::vector<double>(result.passes.size(), std::numeric_limits<double>::infinity())};
  const auto& postures = result.postures;
  const auto& at = result.clearance.clearance_mm;
  const auto& moving = result.motions.clearance_mm;
  for (std::size_t k = 0; k < postures.size(); ++k) {
    const std::size_t i = postures[k].output;
    bool hit = i < at.size() && at[i] <= 0.0;
    bool under = i < at.size() && at[i] < required_mm;
    hit = hit || (part_marks && i < part_marks->posture.size() && part_marks->posture[i]);
    // The motion to the pass's next posture (a link's motions are the links').
    const auto p = static_cast<std::size_t>(postures[k].pass);
    if (i < at.size()) out.min_mm[p] = std::min(out.min_mm[p], at[i]);
    if (k + 1 < postures.size() && postures[k + 1].pass == postures[k].pass) {
      hit = hit || (i < moving.size() && moving[i] <= 0.0);
      under = under || (i < moving.size() && moving[i] < required_mm);
      hit = hit || (part_marks && i < part_marks->motion.size() && part_marks->motion[i]);
      if (i < moving.size()) out.min_mm[p] = std::min(out.min_mm[p], moving[i]);
    }
    out.colliding[p] += hit;
    out.under[p] += !hit && under;
  }
  return out;
}

/// A repair asks a pass's motions whether they keep a clearance (MotionRequest::enough_mm): this
/// over it, so that a bound reaching it is over it (the pass's own closest posture less 1 % took
/// a sixth of a reversed impeller's generate, a helper's profile).
constexpr double kEnoughOverMm = 1e-6;

/// Whether `postures` (one pass) clear the obstacles and the part (`part`: its model, prepared
/// once for every pass tried: a 1 M-triangle part takes seconds) at every posture and motion,
/// the obstacles by more than `above_mm` (0: clear; the steered pass's least clearance: nearer
/// to the required one than the steering came).
bool clearPass(const GenerateRequest& request, const ClearanceChecker& checker,
               const std::shared_ptr<const ObstacleModel>& part,
               const std::vector<geometry::Posture>& postures, double above_mm) {
  const ClearanceResult at_postures = checker.check(postures);
  if (at_postures.colliding > 0 || !(at_postures.min_clearance_mm > above_mm)) return false;
  MotionRequest motions;
  motions.required_mm = request.clearance_mm;
  motions.posture_clearance_mm = at_postures.clearance_mm;
  motions.enough_mm = above_mm + kEnoughOverMm;
  const MotionResult moved = checker.checkMotions(postures, motions);
  if (moved.colliding > 0 || !(moved.min_clearance_mm > above_mm)) return false;
  if (!part) return true;
  const std::optional<LinkPartResult> holder =
      checkHolderAgainstPart(request.tool, request.holder, part, postures);
  if (holder && holder->collides()) return false;
  return request.tool.shape == geometry::ToolShape::Flat ||
         !checkCutterAgainstPart(request.tool, part, postures).gouges();
}

/// How a pass's `postures` check alone, as pathFaults orders a path: its postures and motions
/// that collide with the obstacles, the holder's and the cutter's with the part (counted as
/// their checks count them: no fewer than faultsByPass's postures), then its least clearance of
/// the obstacles at the postures and motions, negated (the motions' a bound no tighter than
/// `enough_mm` where they keep that much).
std::pair<std::size_t, double> passFaults(const GenerateRequest& request,
                                          const ClearanceChecker& checker,
                                          const std::shared_ptr<const ObstacleModel>& part,
                                          const std::vector<geometry::Posture>& postures,
                                          double enough_mm) {
  const ClearanceResult at = checker.check(postures);
  MotionRequest motions;
  motions.required_mm = request.clearance_mm;
  motions.posture_clearance_mm = at.clearance_mm;
  motions.enough_mm = enough_mm;
  const MotionResult moved = checker.checkMotions(postures, motions);
  std::size_t hits = 0;
  for (std::size_t k = 0; k < postures.size(); ++k)
    hits += at.clearance_mm[k] <= 0.0 ||
            (k < moved.clearance_mm.size() && moved.clearance_mm[k] <= 0.0);
  if (part) {
    if (const auto holder = checkHolderAgainstPart(request.tool, request.holder, part, postures))
      hits += holder->colliding_postures + holder->colliding_motions;
    if (request.tool.shape != geometry::ToolShape::Flat) {
      const CutterPartResult cutter = checkCutterAgainstPart(request.tool, part, postures);
      hits += cutter.gouging_postures + cutter.gouging_motions;
    }
  }
  return {hits, -std::min(at.min_clearance_mm, moved.min_clearance_mm)};
}

/// Each pass's postures in `result.postures`: [begin, end), in pass order.
std::vector<std::pair<std::size_t, std::size_t>> postureRanges(const GenerateResult& result) {
  std::vector<std::pair<std::size_t, std::size_t>> out;
  std::size_t first = 0;
  for (const Pass& pass : result.passes) {
    std::size_t end = first;
    while (end < result.postures.size() && result.postures[end].pass == pass.index) ++end;
    out.emplace_back(first, end);
    first = end;
  }
  return out;
}

/// What the steering said of the passes `gone` (by Pass::index), and the ways up their links took,
/// forgotten: they are written otherwise (a reviewer: what it said of a pass written nominal was
/// not of the path written).
void forgetSteeringOf(GenerateResult& result, const std::function<bool(int)>& gone) {
  std::erase_if(result.settled_starts, gone);
  std::erase_if(result.turned_starts, gone);
  std::erase_if(result.corners_held, gone);
  std::erase_if(result.steered_from_end, gone);
  // (a link's way up taken for the axis the pass had)
  std::erase_if(result.routed_link_ends, [&](const auto& e) { return gone(e.pass); });
  std::erase_if(result.settle_failures, [&](const auto& f) { return gone(f.pass); });
  std::erase_if(result.loosened_solver, [&](const std::string& line) {
    for (const Pass& pass : result.passes)
      if (gone(pass.index) && line.rfind(pass.label + ": ", 0) == 0) return true;
    return false;
  });
}

/// The limits held: the written postures' (a pass replaced takes its own).
void recountLimited(GenerateResult& result) {
  result.limited_postures = 0;
  result.first_limited = ClearanceResult::npos;
  for (std::size_t k = 0; k < result.postures.size(); ++k)
    if (result.postures[k].limited) {
      if (result.first_limited == ClearanceResult::npos) result.first_limited = k;
      ++result.limited_postures;
    }
}

}  // namespace

bool hasFaultyPasses(const GenerateRequest& request, const GenerateResult& result,
                     const std::optional<PartContacts::Marks>& part_marks) {
  const PassFaults faults = faultsByPass(result, request.clearance_mm, part_marks);
  for (std::size_t p = 0; p < faults.colliding.size(); ++p)
    if (faults.colliding[p] + faults.under[p] > 0) return true;
  return false;
}

std::pair<std::size_t, double> pathFaults(const GenerateResult& result) {
  std::size_t collisions = result.clearance.colliding + result.motions.colliding;
  for (const auto* part : {&result.link_part, &result.holder_part})
    if (*part) collisions += (*part)->colliding_postures + (*part)->colliding_motions;
  return {collisions,
          -std::min(result.clearance.min_clearance_mm, result.motions.min_clearance_mm)};
}

bool keepClearNominalPasses(const GenerateRequest& request, const ClearanceChecker& checker,
                            const std::shared_ptr<const ObstacleModel>& part,
                            GenerateResult& result,
                            const std::optional<PartContacts::Marks>& part_marks) {
  const PassFaults faults = faultsByPass(result, request.clearance_mm, part_marks);
  const double lead_rad = request.path.lead_deg * geometry::kDegToRad;
  bool replaced = false;
  const auto ranges = postureRanges(result);
  for (std::size_t p = 0; p < result.passes.size(); ++p) {
    const Pass& pass = result.passes[p];
    const auto [begin, end] = ranges[p];
    const std::size_t colliding = faults.colliding[p], under = faults.under[p];
    if ((colliding == 0 && under == 0) || end - begin != pass.samples.size()) continue;
    const std::vector<geometry::Posture> nominal =
        nominalPostures(std::span(&pass, 1), lead_rad, request.tool.radius_mm);
    // A pass that collided steered takes axes that clear; one that only came under the required
    // clearance, axes that come less near (a helper's channel: the tilt away from one fin
    // brought the shank 0.45 mm from the other, leaning over it, where the nominal axes kept
    // 0.64 of 0.5; a vertical-arc engage's steered pass came to 0.065, its nominal one 0.375).
    if (!clearPass(request, checker, part, nominal, colliding == 0 ? faults.min_mm[p] : 0.0))
      continue;
    for (std::size_t k = begin; k < end; ++k) {
      GeneratedPosture& g = result.postures[k];
      g.posture = nominal[k - begin];
      g.lead_rad = lead_rad;
      g.tilt_rad = 0.0;
      g.moment = 0.0;
      g.limited = false;
    }
    result.kept_nominal.push_back({pass.index, pass.label, colliding, under});
    replaced = true;
  }
  if (replaced) {
    forgetSteeringOf(result, [&result](int pass) {
      for (const auto& k : result.kept_nominal)
        if (k.pass == pass) return true;
      return false;
    });
    recountLimited(result);
  }
  return replaced;
}

std::vector<FromEndPass> steerFaultyPassesFromEnd(
    const GenerateRequest& request, const ClearanceChecker& checker,
    const std::shared_ptr<const ObstacleModel>& part, const SteerFromEnd& steer_from_end,
    const GenerateResult& result, const std::optional<PartContacts::Marks>& part_marks,
    const common::Progress& progress) {
  const PassFaults faults = faultsByPass(result, request.clearance_mm, part_marks);
  const auto ranges = postureRanges(result);
  // The passes to try: those that collide, or come under the clearance where their ball does not
  // (no axis lifts a ball within the clearance: 50 such passes were steered again for changes of
  // 0.01 um, generate 2.6 times longer, a reviewer's).
  std::vector<std::size_t> tried;
  for (std::size_t p = 0; p < result.passes.size(); ++p) {
    const bool ball_under =
        std::any_of(result.balls_under_clearance.begin(), result.balls_under_clearance.end(),
                    [&](const auto& b) { return b.pass == result.passes[p].index; });
    if (faults.colliding[p] > 0 || (faults.under[p] > 0 && !ball_under)) tried.push_back(p);
  }
  // Each steered and judged alone, in parallel (as the passes were steered); kept in pass order.
  std::vector<std::optional<FromEndPass>> again(tried.size());
  std::mutex done_mutex;
  std::size_t done = 0;
  tbb::parallel_for(std::size_t{0}, tried.size(), [&](std::size_t t) {
    const std::size_t p = tried[t];
    const Pass& pass = result.passes[p];
    std::optional<PassSteering> run = steer_from_end(p);
    if (run && run->run.samples.size() == ranges[p].second - ranges[p].first) {
      std::vector<GeneratedPosture> postures = generatedPostures(pass.index, run->run);
      std::vector<geometry::Posture> placed;
      for (const GeneratedPosture& g : postures) placed.push_back(g.posture);
      // Fewer collisions, or as many and more clearance than rounding gives (1 um).
      const double better_mm = faults.min_mm[p] + 1e-3;
      const auto [collisions, minus_least] =
          passFaults(request, checker, part, placed, better_mm + kEnoughOverMm);
      if (collisions < faults.colliding[p] ||
          (collisions == faults.colliding[p] && -minus_least > better_mm)) {
        run->run = {};
        again[t] = FromEndPass{p, std::move(postures), std::move(*run)};
      }
    }
    std::lock_guard<std::mutex> lock(done_mutex);
    common::report(progress, double(++done) / double(tried.size()), "");
  });
  std::vector<FromEndPass> out;
  for (auto& a : again)
    if (a) out.push_back(std::move(*a));
  return out;
}

void useFromEnd(GenerateResult& result, const std::vector<FromEndPass>& passes) {
  if (passes.empty()) return;
  const auto ranges = postureRanges(result);
  for (const FromEndPass& f : passes)
    for (std::size_t k = ranges[f.pass].first; k < ranges[f.pass].second; ++k)
      result.postures[k] = f.postures[k - ranges[f.pass].first];
  const auto replaced = [&](int index) {
    return std::any_of(passes.begin(), passes.end(),
                       [&](const FromEndPass& f) { return result.passes[f.pass].index == index; });
  };
  forgetSteeringOf(result, replaced);
  for (const FromEndPass& f : passes) {
    const int pass = result.passes[f.pass].index;
    const PassSteering& said = f.said;
    result.steered_from_end.push_back(pass);
    if (said.started_settled) result.settled_starts.push_back(pass);
    if (said.turned_start) result.turned_starts.push_back(pass);
    if (said.corners_held) result.corners_held.push_back(pass);
    if (!said.settle_failed.empty()) result.settle_failures.push_back({pass, said.settle_failed});
    if (!said.loosened.empty()) result.loosened_solver.push_back(said.loosened);
  }
  for (auto* list : {&result.settled_starts, &result.turned_starts, &result.corners_held,
                     &result.steered_from_end})
    std::sort(list->begin(), list->end());
  std::stable_sort(result.settle_failures.begin(), result.settle_failures.end(),
                   [](const auto& a, const auto& b) { return a.pass < b.pass; });
  recountLimited(result);
}

std::pair<std::size_t, double> faultsAround(const GenerateResult& result,
                                            const std::optional<PartContacts::Marks>& part_marks,
                                            std::size_t p) {
  // The pass's postures (they lie in pass order: found by halving, not by a walk of them all,
  // once a pass judged).
  const int index = result.passes[p].index;
  const auto first =
      std::partition_point(result.postures.begin(), result.postures.end(),
                           [&](const GeneratedPosture& g) { return g.pass < index; });
  const auto last = std::partition_point(
      first, result.postures.end(), [&](const GeneratedPosture& g) { return g.pass == index; });
  const std::size_t n = result.path.postures.size();
  // Output postures [lo, hi): the link into the pass, the pass, the link out of it.
  const std::size_t lo = first != result.postures.begin() ? std::prev(first)->output + 1 : 0;
  const std::size_t hi = last != result.postures.end() ? last->output : n;
  const auto& at = result.clearance.clearance_mm;
  const auto& moving = result.motions.clearance_mm;
  const auto marked = [&](const std::vector<std::uint8_t> PartContacts::Marks::*which,
                          std::size_t i) {
    return part_marks && i < ((*part_marks).*which).size() && ((*part_marks).*which)[i];
  };
  std::size_t collisions = 0;
  double least_mm = std::numeric_limits<double>::infinity();
  for (std::size_t i = lo; i < hi && i < n; ++i) {
    if (i < at.size()) least_mm = std::min(least_mm, at[i]);
    collisions += (i < at.size() && at[i] <= 0.0) || marked(&PartContacts::Marks::posture, i);
  }
  // The motions into the window's first posture and out of its last (to the next pass's first).
  for (std::size_t i = lo > 0 ? lo - 1 : 0; i < hi && i + 1 < n; ++i) {
    if (i < moving.size()) least_mm = std::min(least_mm, moving[i]);
    collisions +=
        (i < moving.size() && moving[i] <= 0.0) || marked(&PartContacts::Marks::motion, i);
  }
  return {collisions, -least_mm};
}

}  // namespace fieldpath::pathgen
