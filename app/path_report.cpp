/// app/path_report.h: the JSON blocks and messages about a checked path.
#include "path_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <utility>

#include "fieldpath/common/file_digest.h"
#include "fieldpath/geometry/units.h"

namespace fieldpath::app {
nlohmann::json jsonIndex(std::size_t i) {
  return i == pathgen::ClearanceResult::npos ? nlohmann::json(nullptr) : nlohmann::json(i);
}

nlohmann::json jsonNumber(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

nlohmann::json clearanceJson(const pathgen::ClearanceResult& c, double required_mm,
                             double chord_tol_mm, const std::string& min_obstacle_name) {
  return {{"required_mm", required_mm},
          {"min_mm", jsonNumber(c.min_clearance_mm)},
          {"min_posture", jsonIndex(c.min_index)},
          {"min_obstacle", c.min_obstacle + 1},
          {"min_obstacle_name",
           min_obstacle_name.empty() ? nlohmann::json(nullptr) : nlohmann::json(min_obstacle_name)},
          {"colliding_postures", c.colliding},
          {"first_colliding_posture", jsonIndex(c.first_colliding)},
          {"tool_mesh_chord_tol_mm", chord_tol_mm},
          {"distances",
           "exact mesh distances (FCL) less the tool mesh's chordal tolerance: never optimistic; "
           "a posture within it of an obstacle counts as colliding"},
          {"ok", c.colliding == 0 && c.min_clearance_mm >= required_mm}};
}

nlohmann::json motionsJson(const pathgen::MotionResult& m, double required_mm,
                           double resolution_mm) {
  nlohmann::json out = {
      {"motions", m.motions},
      {"method",
       "tip and axis interpolated linearly; adaptive sampling with a certified lower bound "
       "(tool + holder move at most |dtip| + reach * dangle between samples; the distance "
       "is 1-Lipschitz in that): the lowest-bound piece halved first, until the bound reaches "
       "max(required_mm, closest posture - max(0.01 mm, 1 % of it)), a sample touches, or "
       "the lowest piece moves <= 2 * resolution_mm (the motion's bound then)"},
      {"resolution_mm", resolution_mm},
      {"min_mm", jsonNumber(m.min_clearance_mm)},
      {"min_is",
       "a lower bound, within max(0.01 mm, 1 % of the closest posture's clearance) of the "
       "true minimum when that is above required_mm"},
      {"min_motion", jsonIndex(m.min_index)},
      {"colliding_motions", m.colliding},
      {"first_colliding_motion", jsonIndex(m.first_colliding)},
      {"motions_under_required", m.under_required},
      {"first_motion_under_required", jsonIndex(m.first_under_required)},
      {"samples", m.samples},
      {"ok", m.colliding == 0 && m.under_required == 0 && !(m.min_clearance_mm < required_mm)}};
  // A null beside its reason (DESIGN.md): a path of one posture has no motion.
  if (m.motions == 0) out["min_skipped"] = "no motion: the path has one posture";
  return out;
}

nlohmann::json partContactsJson(const pathgen::LinkPartResult& r, const char* postures_key,
                                const char* motions_key, const char* method) {
  return {{postures_key, r.postures},
          {motions_key, r.motions},
          {"colliding_postures", r.colliding_postures},
          {"first_colliding_posture", jsonIndex(r.first_colliding_posture)},
          {"colliding_motions", r.colliding_motions},
          {"first_colliding_motion", jsonIndex(r.first_colliding_motion)},
          {"min_mm", jsonNumber(r.min_clearance_mm)},
          {"method", method},
          {"ok", !r.collides()}};
}

nlohmann::json linkPartJson(const std::optional<pathgen::LinkPartResult>& l) {
  if (!l) return nullptr;
  return partContactsJson(
      *l, "link_postures", "link_motions",
      "every link posture and every motion between two link postures against the part mesh "
      "(as `motions`, required 0: rapid moves must not touch it), and the moves out of and "
      "into a pass with the tool and holder 0.1 mm smaller all round (they start or end where "
      "the ball cuts and may slide along a wall it finishes; counted, not in min_mm); min_mm "
      "a lower bound within 10 % of the links' least clearance to the part");
}

nlohmann::json holderPartJson(const std::optional<pathgen::LinkPartResult>& h) {
  if (!h) return nullptr;
  return partContactsJson(
      *h, "postures", "motions",
      "the holder (its stations, and the shank above the tool's length up to them: they never "
      "cut) against the part mesh at every "
      "posture and motion, passes and links (as `motions`, required 0)");
}

nlohmann::json cutterPartJson(const std::optional<pathgen::CutterPartResult>& c) {
  if (!c) return nullptr;
  return {
      {"stamps", c->stamps},
      {"tolerance_um", 1e3 * c->tolerance_mm},
      {"step_mm", c->step_mm},
      {"between_stamps_um", 1e3 * c->between_stamps_mm},
      {"tested",
       "the corner (a ball's sphere, a torus's ring and the slab inside it) and the "
       "shank"},
      {"gouging_postures", c->gouging_postures},
      {"gouging_motions", c->gouging_motions},
      {"first_gouging_posture", jsonIndex(c->first_gouging_posture)},
      {"first_gouging_motion", jsonIndex(c->first_gouging_motion)},
      {"max_depth_um", 1e3 * c->max_depth_mm},
      {"deepest_posture", c->deepest_on_motion ? nlohmann::json(nullptr) : jsonIndex(c->deepest)},
      {"deepest_motion", c->deepest_on_motion ? jsonIndex(c->deepest) : nlohmann::json(nullptr)},
      {"method",
       "the cutter shrunk all round by tolerance_um (FCL's sphere and cylinder: exact "
       "surfaces; a torus's ring: the part's triangles near it each measured from its disc, "
       "GJK to ~1e-7 mm) against the part's triangles and inside, at every posture and at stamps "
       "step_mm apart along the motions near the part; between two stamps an entry may be "
       "up to between_stamps_um deeper (at the shank's top rim up to half a step: the holder "
       "above it is tested on its own); max_depth_um to 0.1 um, at most the tool radius; not "
       "part of `unsafe`: a concave part meshed with a chordal error reads a path on its true "
       "surface as entering it by up to that error"},
      {"ok", !c->gouges()}};
}

std::string sceneDigest(const Scene& scene) {
  std::string out = common::fileDigest(scene.file);
  if (scene.part_file) out += ",part:" + common::fileDigest(*scene.part_file);
  for (const std::filesystem::path& f : scene.obstacle_files) out += "," + common::fileDigest(f);
  return out;
}

nlohmann::json axisTurnJson(const pathgen::AxisTurn& t) {
  return {{"max_deg", t.deg},
          {"posture", jsonIndex(t.at)},
          {"step_mm", t.step_mm},
          {"note_above_deg", pathgen::kNoteAxisTurnDeg}};
}

std::string axisTurnWarning(const geometry::PathFile& path, const pathgen::AxisTurn& t) {
  if (t.at == pathgen::AxisTurn{}.at || !(t.deg > pathgen::kNoteAxisTurnDeg)) return {};
  auto name = [&](std::size_t i) {
    return std::to_string(i) + (i < path.lines.size() ? " (" + path.where(i) + ")" : "");
  };
  // The numbers alone through snprintf: the names hold file paths of any length.
  char deg[32], step[32], limit[32];
  std::snprintf(deg, sizeof deg, "%.1f", t.deg);
  std::snprintf(step, sizeof step, "%.2f", t.step_mm);
  std::snprintf(limit, sizeof limit, "%g", pathgen::kNoteAxisTurnDeg);
  return std::string("the tool axis turns ") + deg + " deg between postures " + name(t.at) +
         " and " + name(t.at + 1) + ", " + step +
         " mm apart: more than a machine's rotary axes follow at feed (over " + limit +
         " deg between two postures of a pass)";
}

std::string blockOf(const geometry::PathFile& path, std::size_t i) {
  std::size_t passes_before = 0;
  for (const geometry::PathBlock& b : path.blocks) {
    const bool pass = b.kind == geometry::PathBlock::Kind::Pass;
    if (i >= b.begin && i < b.end)
      return pass ? "pass " + std::to_string(passes_before + 1)
             : path.count(geometry::PathBlock::Kind::Pass) == 0 ? std::string("a link")
             : passes_before == path.count(geometry::PathBlock::Kind::Pass)
                 ? std::string("the link after the last pass")
                 : "the link into pass " + std::to_string(passes_before + 1);
    passes_before += pass;
  }
  return {};
}

std::string postureWhere(const geometry::PathFile& path, std::size_t i, std::size_t block_of) {
  const std::string block = blockOf(path, block_of);
  const std::string line = i < path.lines.size() ? path.where(i) : std::string();
  const std::string sep = !block.empty() && !line.empty() ? ", " : "";
  return "posture " + std::to_string(i) +
         (block.empty() && line.empty() ? "" : " (" + block + sep + line + ")");
}
std::string postureWhere(const geometry::PathFile& path, std::size_t i) {
  return postureWhere(path, i, i);
}

bool inLink(const geometry::PathFile& path, std::size_t i) {
  for (const geometry::PathBlock& b : path.blocks)
    if (i >= b.begin && i < b.end) return b.kind == geometry::PathBlock::Kind::Link;
  return false;
}

std::vector<bool> linkMask(const geometry::PathFile& path) {
  std::vector<bool> link(path.postures.size(), false);
  for (const geometry::PathBlock& b : path.blocks)
    if (b.kind == geometry::PathBlock::Kind::Link)
      for (std::size_t i = b.begin; i < b.end && i < link.size(); ++i) link[i] = true;
  return link;
}

std::string motionWhere(const geometry::PathFile& path, std::size_t i) {
  const bool into_link = !inLink(path, i) && i + 1 < path.postures.size() && inLink(path, i + 1);
  const std::string where = postureWhere(path, i, into_link ? i + 1 : i);
  const std::size_t open = where.find(" (");
  return "posture " + std::to_string(i) + " to the next" +
         (open == std::string::npos ? "" : where.substr(open));
}

std::string collidingPasses(const geometry::PathFile& path, const std::vector<double>& posture_mm) {
  std::vector<std::size_t> passes;
  bool links = false;
  std::size_t passes_before = 0;
  for (const geometry::PathBlock& b : path.blocks) {
    const bool pass = b.kind == geometry::PathBlock::Kind::Pass;
    passes_before += pass;
    for (std::size_t i = b.begin; i < b.end && i < posture_mm.size(); ++i)
      if (posture_mm[i] <= 0.0) {
        if (pass)
          passes.push_back(passes_before);
        else
          links = true;
        break;
      }
  }
  if (passes.empty() && !links) return {};
  constexpr std::size_t kNamed = 8;
  std::vector<std::string> names;
  for (std::size_t k = 0; k < passes.size() && k < kNamed; ++k)
    names.push_back(std::to_string(passes[k]));
  if (passes.size() > kNamed) names.push_back(std::to_string(passes.size() - kNamed) + " more");
  std::string text = passes.empty() ? "" : passes.size() == 1 ? "pass " : "passes ";
  for (std::size_t k = 0; k < names.size(); ++k)
    text += (k == 0 ? "" : k + 1 == names.size() ? " and " : ", ") + names[k];
  if (links) text += passes.empty() ? "links" : " and links";
  return " in " + text;
}

/// "1 posture touches", "2 postures touch": a count, its noun and verb agreed ("1 postures
/// touch" read as a typo to a user); the verb given in both forms, so no verb is special-cased.
std::string counted(std::size_t n, const std::string& noun, const std::string& verb_one,
                    const std::string& verb_many) {
  return std::to_string(n) + " " + noun + (n == 1 ? " " + verb_one : "s " + verb_many);
}

namespace {

/// Where link posture i lies on the axis line of the pass posture its link block joins (the next
/// pass's first, or the last pass's last), above it: that posture and how far up (mm); none
/// where it lies elsewhere (the travel plane, a way off the axis).
std::optional<std::pair<std::size_t, double>> onPassAxis(const geometry::PathFile& path,
                                                         std::size_t i) {
  for (const geometry::PathBlock& b : path.blocks) {
    if (i < b.begin || i >= b.end || b.kind != geometry::PathBlock::Kind::Link) continue;
    for (const std::size_t j : {b.end, b.begin - 1}) {  // (b.begin 0: j wraps past the end)
      if (j >= path.postures.size() || inLink(path, j)) continue;
      const geometry::Posture &p = path.postures[i], &end = path.postures[j];
      const geometry::Vec3 up = p.tip_mm - end.tip_mm;
      const double along_mm = up.dot(end.axis);
      if (geometry::axisAngle(p.axis, end.axis) < 1e-6 && along_mm > 1e-6 &&
          (up - along_mm * end.axis).norm() <= 1e-6 * std::max(1.0, along_mm))
        return std::pair(j, along_mm);
    }
  }
  return std::nullopt;
}

}  // namespace

std::vector<std::string> unsafeReasons(const geometry::PathFile& path,
                                       const pathgen::ClearanceResult& c,
                                       const pathgen::MotionResult& m,
                                       const std::optional<pathgen::LinkPartResult>& l,
                                       const std::optional<pathgen::LinkPartResult>& h,
                                       const std::string& link_hint) {
  std::vector<std::string> out;
  // A pass posture that touches itself: a link's plunge into it (or retract out of it) touches
  // because the pass does, and the link's keys are not the cure (a CAM engineer's mould: the
  // holder met a pin at pass 1's start, and the hint named links.retract and links.safe_z).
  auto passTouches = [&](std::size_t k) {
    return k < c.clearance_mm.size() && !inLink(path, k) && c.clearance_mm[k] <= 0.0;
  };
  auto posture = [&](std::size_t i) {
    if (!inLink(path, i)) return postureWhere(path, i);
    // A link posture up a pass end's axis: the axis meets the obstacle there, which the travel
    // plane's keys do not move (an oracle's mould: a link coming down pass 12's start axis into
    // a rib was hinted with links.retract and links.safe_z).
    if (const auto on = onPassAxis(path, i)) {
      const auto [j, along_mm] = *on;
      char up[32];
      std::snprintf(up, sizeof up, "%.3g", along_mm);
      const bool start = j > i;
      return postureWhere(path, i) + ": " + up + " mm up the axis of the " +
             (start ? "first" : "last") + " posture of its pass (" + postureWhere(path, j) +
             "), which meets the obstacle there" +
             (passTouches(j) ? "; that posture touches too (the pass collides there)"
              : link_hint.empty()
                  ? ""
                  : " (generate's links run along a pass end's axis: not "
                    "moved by the links' keys; a pass " +
                        std::string(start ? "starting" : "ending") + " on another axis avoids it)");
    }
    return postureWhere(path, i) + (link_hint.empty() ? "" : ": " + link_hint);
  };
  auto motion = [&](std::size_t i) {
    const bool link = inLink(path, i) || inLink(path, i + 1);
    if (link && !link_hint.empty() && (passTouches(i) || passTouches(i + 1)))
      return motionWhere(path, i) + ": its end in the pass touches too (the pass collides there)";
    return motionWhere(path, i) + (link && !link_hint.empty() ? ": " + link_hint : "");
  };
  if (c.colliding) {
    const std::string in = collidingPasses(path, c.clearance_mm);
    out.push_back(counted(c.colliding, "posture", "touches", "touch") + " an obstacle (first: " +
                  posture(c.first_colliding) + (in.empty() ? "" : ";" + in) + ")");
  }
  if (m.colliding)
    out.push_back(counted(m.colliding, "motion", "touches", "touch") +
                  " an obstacle (first: " + motion(m.first_colliding) + ")");
  if (l && l->colliding_postures)
    out.push_back(counted(l->colliding_postures, "link posture", "touches", "touch") +
                  " the part (first: " + posture(l->first_colliding_posture) + ")");
  if (l && l->colliding_motions)
    out.push_back(counted(l->colliding_motions, "link motion", "touches", "touch") +
                  " the part (first: " + motion(l->first_colliding_motion) + ")");
  if (h && h->colliding_postures)
    out.push_back(counted(h->colliding_postures, "posture", "puts", "put") +
                  " the holder into the part (first: " + posture(h->first_colliding_posture) + ")");
  if (h && h->colliding_motions)
    out.push_back(counted(h->colliding_motions, "motion", "puts", "put") +
                  " the holder into the part (first: " + motion(h->first_colliding_motion) + ")");
  return out;
}

std::string cutterGougeReason(const geometry::PathFile& path,
                              const std::optional<pathgen::CutterPartResult>& cut) {
  if (!cut || !cut->gouges()) return {};
  char depth[32], tolerance[32];
  std::snprintf(depth, sizeof depth, "%.1f", 1e3 * cut->max_depth_mm);
  std::snprintf(tolerance, sizeof tolerance, "%g", 1e3 * cut->tolerance_mm);
  // (the first of the two is always one: gouges() holds)
  const std::string first = cut->first_gouging_posture <= cut->first_gouging_motion
                                ? postureWhere(path, cut->first_gouging_posture)
                                : "the motion from " + motionWhere(path, cut->first_gouging_motion);
  return "the cutter enters the part deeper than the gouge tolerance (" + std::string(tolerance) +
         " um) at " + std::to_string(cut->gouging_postures) + " postures and " +
         std::to_string(cut->gouging_motions) + " motions (max " + depth + " um; first: " + first +
         ")";
}

nlohmann::json rotaryJson(const pathgen::RotaryStray& s, double reach_mm) {
  return {{"assumes",
           "a post that writes (tilt >= 0 from z, C about z) angles, each interpolated linearly "
           "(A/C, B/C machines), against the tool vector on the great circle at an even pace "
           "(Fanuc G43.5, Siemens ORIVECT, Heidenhain LN): how far the tool moves from the "
           "checked one at the same instant, at the tool's reach (no point of the tool moves "
           "more), sampled along each motion (within about a micrometre of its largest)"},
          {"reach_mm", reach_mm},
          {"max_stray_mm", s.max_offset_mm},
          {"max_stray_motion", jsonIndex(s.max_at)},
          {"motions_stray_past_clearance", s.beyond_clearance},
          {"first_stray_past_clearance", jsonIndex(s.first_beyond)},
          {"motions_stray_under_required", s.under_required},
          {"c_turn_deg", s.c_deg},
          {"axis_turn_deg", s.turn_deg}};
}

std::string rotaryWarning(const geometry::PathFile& path, const pathgen::RotaryStray& s,
                          const pathgen::MotionResult& m) {
  if (s.beyond_clearance == 0) return {};
  const std::size_t i = s.first_beyond;
  char numbers[160];
  std::snprintf(numbers, sizeof numbers,
                "C turns %.1f deg for %.2f deg of the axis, the tool strays %.2f mm where the "
                "motion is %.3f mm clear",
                s.c_deg, s.turn_deg, s.offset_mm[i], m.clearance_mm[i]);
  const bool many = s.beyond_clearance > 1;
  return std::to_string(s.beyond_clearance) + (many ? " motions" : " motion") +
         " may stray past the clearance " + (many ? "they have" : "it has") +
         " if posted as rotary angles (first: " + motionWhere(path, i) + ": " + numbers +
         "): post the tool vector (G43.5 / ORIVECT / LN), not interpolated A/B/C";
}

nlohmann::json dogLegJson(const pathgen::DogLegRapids& d) {
  return {{"assumes",
           "rapids (the motions into link postures, RAPID in APT) run axis by axis, in any order "
           "and pace: the tip in the box its ends span, the axis between theirs; proven clear of "
           "the obstacles (not of the part) where the motion's clearance less that box's reach "
           "(corner off the segment + tool reach x turn) keeps the required clearance; a bound: "
           "an unproven rapid is not shown to collide; rapids under the required clearance as "
           "checked are the check's findings, not counted here"},
          {"rapids", d.rapids},
          {"unproven", d.unproven},
          {"checked_under_required", d.checked_under},
          {"lowest_motion", jsonIndex(d.lowest)},
          {"lowest_bound_mm", d.unproven ? nlohmann::json(d.lowest_bound_mm) : nlohmann::json()},
          {"lowest_box_mm", d.unproven ? nlohmann::json(d.lowest_box_mm) : nlohmann::json()}};
}

std::string farPassesWarning(const geometry::PathFile& path, const pathgen::FarFromPart& c,
                             double far_mm) {
  const std::size_t passes = path.count(geometry::PathBlock::Kind::Pass);
  if (c.passes.empty() || c.passes.size() >= passes) return {};
  char far[32];
  std::snprintf(far, sizeof far, "%.3g", far_mm);
  return std::to_string(c.passes.size()) + " of the " + std::to_string(passes) +
         " passes keep the ball more than " + far +
         " mm from the part at every posture (first: " + postureWhere(path, c.first_posture) +
         "): they cut nothing there. Passes beside the part: is it turned or offset from the "
         "path's frame, or in other units?";
}

std::string dogLegNote(const geometry::PathFile& path, const pathgen::DogLegRapids& d,
                       const pathgen::MotionResult& m, bool has_part) {
  const std::size_t clear = d.rapids - d.checked_under;  // as checked: the proof's rapids
  if (d.unproven == 0 && !(has_part && clear > 0)) return {};
  // Those under the clearance as checked are the check's own findings, in no proof.
  const auto moves = [](std::size_t n) {
    return std::to_string(n) + (n == 1 ? " rapid move" : " rapid moves");
  };
  const std::string of = d.checked_under == 0 ? moves(d.rapids)
                                              : moves(clear) + " clear as checked (of " +
                                                    std::to_string(d.rapids) + ")";
  const char* are = (d.checked_under == 0 ? d.rapids : clear) == 1 ? " is" : " are";
  std::string note;
  if (d.unproven > 0) {
    char numbers[96];
    std::snprintf(numbers, sizeof numbers, "%.3f mm clear as checked, up to %.2f mm off it",
                  m.clearance_mm[d.lowest], d.lowest_box_mm);
    note = std::to_string(d.unproven) + " of the " + of + (d.unproven == 1 ? " is" : " are") +
           " proven clear of the obstacles only when run straight (lowest: " +
           motionWhere(path, d.lowest) + ", " + numbers + " run axis by axis)";
  } else {
    note = "the " + of + are + " proven clear of the obstacles run axis by axis";
  }
  if (has_part)
    note += (d.unproven > 0 ? "; " : ", ") +
            std::string(
                "the part is not in that proof: a retract out of a pass run axis by axis "
                "can cut into the finished surface");
  return note + ": run rapids as linear moves, or post them as feed moves";
}

std::string limitsAtCollisionsNote(const pathgen::GenerateResult& r, double max_lead_deg,
                                   double max_tilt_deg) {
  // At a limit: within a thousandth of a degree (the clamp holds the angle on it).
  constexpr double kAtLimitDeg = 1e-3;
  std::size_t colliding = 0, limited = 0, at_lead = 0, at_tilt = 0;
  const pathgen::GeneratedPosture* first = nullptr;
  for (const pathgen::GeneratedPosture& g : r.postures) {
    if (!(g.clearance_mm <= 0.0)) continue;
    ++colliding;
    const bool lead = std::abs(g.lead_rad) * geometry::kRadToDeg >= max_lead_deg - kAtLimitDeg;
    const bool tilt = std::abs(g.tilt_rad) * geometry::kRadToDeg >= max_tilt_deg - kAtLimitDeg;
    if (!g.limited && !lead && !tilt) continue;
    ++limited;
    at_lead += lead;
    at_tilt += tilt;
    if (!first) first = &g;
  }
  if (limited == 0) return {};
  char text[160];
  std::snprintf(text, sizeof text,
                "lead at %g deg (dynamics.max_lead_deg): %zu; tilt at %g deg "
                "(dynamics.max_tilt_deg): %zu",
                max_lead_deg, at_lead, max_tilt_deg, at_tilt);
  const std::string which =
      limited < colliding ? std::to_string(limited) + " of the " + std::to_string(colliding) +
                                " colliding postures have"
      : colliding == 1 ? std::string("the colliding posture has")
      : colliding == 2 ? std::string("both colliding postures have")
                       : "all " + std::to_string(colliding) + " colliding postures have";
  return which + " an angle held at its limit (" + text +
         "; first: " + postureWhere(r.path, first->output) +
         "): the field pushes the axis past the limits there; wider limits where the machine "
         "and the holder allow, or a nominal path with more room there";
}

}  // namespace fieldpath::app
