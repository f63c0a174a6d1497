/// app/generate_messages.h: what generate says of a finished job.
#include "generate_messages.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/Geometry>

#include "cutter_note.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/field/params.h"
#include "generate_repairs.h"
#include "path_report.h"

namespace fieldpath::app {
namespace {

/// A nominal path whose axes lean along the feed by more than this (deg) gets a note: the
/// steering starts from path.lead_deg, not from the file's lead.
constexpr double kNoteLeanDeg = 1.0;

}  // namespace

/// Where a link's climb along a tilted axis to the travel plane takes the tool farthest outside
/// the scene's meshes in x-y (DESIGN's links climb along the axis: at 78 deg from vertical a
/// 33 mm climb ran 230 mm sideways, 223 mm past the part, unsaid: a helper's finding). Fixtures
/// and the machine's travel are not in the scene: said in a note when a link leaves the meshes'
/// x-y box by more than a quarter of its size. Empty when none does. The advice is the way's: a
/// steeper axis shortens a climb along the axis, not one taken off it (rerouteLinkEnds).
std::string farLinkNote(const Scene& scene, const pathgen::GenerateResult& result) {
  const geometry::PathFile& path = result.path;
  Eigen::AlignedBox2d box;
  const auto extend = [&box](const geometry::TriangleMesh& mesh) {
    for (const geometry::Vec3& v : mesh.vertices) box.extend(Eigen::Vector2d(v.x(), v.y()));
  };
  for (const geometry::TriangleMesh& mesh : scene.obstacles) extend(mesh);
  if (scene.part) extend(*scene.part);
  if (box.isEmpty()) return {};
  double farthest_mm = 0.0;
  std::size_t at = 0;
  for (const geometry::PathBlock& block : path.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Link) continue;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      const geometry::Vec3& tip = path.postures[i].tip_mm;
      const double out_mm = box.exteriorDistance(Eigen::Vector2d(tip.x(), tip.y()));
      if (out_mm > farthest_mm) farthest_mm = out_mm, at = i;
    }
  }
  if (!(farthest_mm > 0.25 * box.sizes().maxCoeff())) return {};
  // The passes on either side of that link posture, and whether their ends there climb off the
  // axis.
  int before = -1, after = -1;  // Pass::index (GeneratedPosture::pass is the position)
  for (const pathgen::GeneratedPosture& g : result.postures) {
    const int index = result.passes[static_cast<std::size_t>(g.pass)].index;
    if (g.output < at) before = index;
    if (g.output > at && after < 0) after = index;
  }
  // The farthest posture tops one of the link's two climbs (the travel between them is straight
  // in x-y): the way out of the pass before up to the first posture at the travel plane, or the
  // way into the one after from the last. Only that end's way is named (a diff review's: a
  // climb along the next pass's own axis was blamed on the way out of the last, rerouted).
  bool out_of_before = true;
  for (const geometry::PathBlock& block : path.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Link || at < block.begin || at >= block.end)
      continue;
    double top_mm = -std::numeric_limits<double>::infinity();
    for (std::size_t i = block.begin; i < block.end; ++i)
      top_mm = std::max(top_mm, path.postures[i].tip_mm.z());
    std::size_t first_top = block.end;
    for (std::size_t i = block.begin; i < block.end && first_top == block.end; ++i)
      if (path.postures[i].tip_mm.z() >= top_mm - 1e-6) first_top = i;
    // The link before the first pass has no way out of one, the one after the last no way in.
    out_of_before = before >= 0 && (after < 0 || at <= first_top);
  }
  const pathgen::GenerateResult::RoutedLinkEnd* routed = nullptr;
  for (const auto& end : result.routed_link_ends)
    if (out_of_before ? (!end.into && end.pass == before) : (end.into && end.pass == after))
      routed = &end;
  std::ostringstream note;
  note << std::fixed;
  note.precision(0);
  if (routed)
    note << "the links climb to the travel plane (the way " << (routed->into ? "into " : "out of ")
         << routed->label << " off its axis, the note above): ";
  else
    note << "the links climb along the tool axis to the travel plane: ";
  note << postureWhere(path, at) << " lies " << farthest_mm
       << " mm outside the meshes' x-y box; fixtures and the machine's travel are not in the "
          "scene, so check that room on the machine ("
       << (routed ? "a lower links.safe_z shortens the climb"
                  : "a lower links.safe_z or a steeper axis at the pass ends shortens the climb")
       << ")";
  return note.str();
}

void printJobMessages(const Scene& scene, const pathgen::GenerateRequest& job,
                      const pathgen::GenerateResult& result, const JobMessages& said) {
  const auto& c = result.clearance;
  const auto& m = result.motions;
  const bool under_required = said.under_required;
  const pathgen::AxisTurn& axis_turn = said.axis_turn;
  const pathgen::RotaryStray& rotary = said.rotary;
  const pathgen::DogLegRapids& dog_leg = said.dog_leg;
  const JobNotes& notes = said.notes;
  if (const std::string gouge = cutterGougeReason(result.path, result.cutter_part); !gouge.empty())
    std::fprintf(stderr,
                 "warning: %s: a gouge, or the part's chordal error where it is concave "
                 "(report.json cutter_part; `check --gouge-tol` sets the tolerance)\n",
                 gouge.c_str());
  // Steered passes under the clearance: the axis may answer too late. The feed is the
  // dynamics' time scale, unsaid (a helper's feed 10 000 mm/min: 127 postures in the blades).
  // Said where the response is longer than twice the defaults' (16.7 mm): else the feed is
  // not why (a fat holder's collisions read "a lower feed turns it sooner", which it did not).
  const dynamics::DynamicsParams defaults;
  if (!job.nominal && job.dynamics.responseLengthMm() > 2.0 * defaults.responseLengthMm()) {
    std::size_t under = 0;
    for (const pathgen::GeneratedPosture& g : result.postures)
      under += g.clearance_mm < job.clearance_mm;
    if (under > 0)
      std::fprintf(stderr,
                   "note: %zu pass postures under `clearance` (colliding ones included): the "
                   "steered axis answers the "
                   "field over about %.3g mm of path (dynamics.feed, %.3g mm/s, times "
                   "sqrt(inertia / stiffness), %.3g s): a lower feed or inertia turns it sooner "
                   "(the same steering at n times the feed with inertia / n^2 and a given "
                   "damping / n; dynamics.feed is "
                   "also path.apt's FEDRAT; report.json solver.response_mm)\n",
                   under, job.dynamics.responseLengthMm(), job.dynamics.feed_mm_per_min / 60.0,
                   std::sqrt(job.dynamics.inertia / job.dynamics.stiffness));
  }
  // Passes that never come near the part: a path in other units or another frame (an inch
  // CAM file over a part in mm read "min clearance 28.378 mm", max tilt 0, no word; check
  // refuses it, but only if run).
  if (const double far_mm = pathgen::farFromPartMm(job.tool.radius_mm);
      result.ball_part_mm && *result.ball_part_mm >= far_mm)
    std::fprintf(stderr,
                 "warning: the passes' ball stays more than %.3g mm from the part (`part`) "
                 "everywhere: they do not finish it. A path in other units or another frame "
                 "(an inch file over a part in mm?), or for another part (report.json "
                 "ball_part)\n",
                 far_mm);
  if (const std::string far = farPassesWarning(result.path, result.far_from_part,
                                               pathgen::farFromPartMm(job.tool.radius_mm));
      !far.empty())
    std::fprintf(stderr, "warning: %s (report.json ball_part.far_passes)\n", far.c_str());
  if (under_required)
    std::fprintf(stderr,
                 "warning: the path comes closer to the obstacles than `clearance` (%.3f mm): "
                 "postures min %.3f mm (%s), motions min >= %.3f mm (%zu under it; "
                 "report.json)\n",
                 job.clearance_mm, c.min_clearance_mm,
                 postureWhere(result.path, c.min_index).c_str(), m.min_clearance_mm,
                 m.under_required);
  // (the jumps of a field pushing a tool that has no room: 30 deg in 0.5 mm in a pocket
  // narrower than the holder; unsafe there too, but the turn is its own warning)
  if (const std::string turn = axisTurnWarning(result.path, axis_turn); !turn.empty())
    std::fprintf(stderr, "warning: %s (report.json axis_turn)\n", turn.c_str());
  // The nominal's own feeds are not carried: path.apt is fed at dynamics.feed (a reviewer's
  // nominal at FEDRAT/MMPM,150 came out at 1000 without a word).
  if (scene.nominal)
    for (const geometry::PathFile::Feed& f : scene.nominal->feeds)
      if (!(f.mm_per_min == job.dynamics.feed_mm_per_min)) {
        std::fprintf(stderr,
                     "note: %s's FEDRAT records (line %zu: %s) are not carried: path.apt is "
                     "fed at dynamics.feed, %s mm/min\n",
                     scene.nominal->file.string().c_str(), f.line,
                     std::isfinite(f.mm_per_min)
                         ? (common::shortNumber(f.mm_per_min) + " mm/min").c_str()
                         : f.text.c_str(),
                     common::shortNumber(job.dynamics.feed_mm_per_min).c_str());
        break;
      }
  if (const std::string stray = rotaryWarning(result.path, rotary, result.motions); !stray.empty())
    std::fprintf(stderr, "warning: %s (report.json rotary_angles)\n", stray.c_str());
  if (const std::string rapids =
          dogLegNote(result.path, dog_leg, result.motions, scene.part.has_value());
      !rapids.empty())
    std::fprintf(stderr, "note: %s (report.json dog_leg_rapids)\n", rapids.c_str());
  printRepairs(result, job.links.retract_mm);
  if (!result.balls_under_clearance.empty()) {
    const auto& b = result.balls_under_clearance.front();
    std::fprintf(stderr,
                 "warning: %zu pass%s the ball itself within `clearance` of an obstacle "
                 "(first: %s at s = %.3f mm, %.6g mm from %s): its centre is held, no "
                 "axis clears it (report.json balls_under_clearance)\n",
                 result.balls_under_clearance.size(),
                 result.balls_under_clearance.size() == 1 ? " runs" : "es run", b.label.c_str(),
                 b.s_mm, b.clearance_mm, obstacleName(scene, b.obstacle).c_str());
  }
  for (const std::string& why : result.loosened_solver)
    std::fprintf(stderr, "warning: %s (report.json solver.loosened)\n", why.c_str());
  if (!result.settle_failures.empty())
    std::fprintf(stderr,
                 "warning: %zu pass%s (first: pass %d) could not start from the axis settled "
                 "under the field and started from the nominal axis (or the clear one nearest "
                 "it) instead: %s "
                 "(report.json start.settle_failures)\n",
                 result.settle_failures.size(), result.settle_failures.size() == 1 ? "" : "es",
                 result.settle_failures.front().pass + 1,
                 result.settle_failures.front().why.c_str());
  for (const auto* list : {&notes.tool, &notes.obstacle, &notes.link})
    for (const std::string& note : *list) std::fprintf(stderr, "note: %s\n", note.c_str());
  // A lead in the file is not kept: n is ⊥ the feed, steered (the field) or written as it is
  // (--nominal: the written axes were up to 5.6 deg off the file's, unsaid: a helper's finding).
  if (scene.nominal) {
    const pathgen::Pass* leanest = nullptr;
    for (const pathgen::Pass& p : job.passes)
      if (!leanest || p.nominal_lean_deg > leanest->nominal_lean_deg) leanest = &p;
    if (leanest && leanest->nominal_lean_deg > kNoteLeanDeg)
      std::fprintf(stderr,
                   "note: %s: the nominal axes lean along the feed by up to %.1f deg: %s from "
                   "the axis made square to the feed and path.lead_deg (%g deg), not from the "
                   "file's lead\n",
                   leanest->nominal_lean_at.c_str(), leanest->nominal_lean_deg,
                   job.nominal ? "the path is written" : "the steering starts", job.path.lead_deg);
  }
  if (!result.settled_starts.empty() && job.dynamics.start == dynamics::StartPolicy::Auto)
    std::fprintf(stderr,
                 "note: %zu pass%s (first: pass %d) started from the axis settled under the field "
                 "at %s start: %s nominal start posture was within `clearance` of an obstacle "
                 "(dynamics.start: auto; `nominal` starts there and collides)\n",
                 result.settled_starts.size(), result.settled_starts.size() == 1 ? "" : "es",
                 result.settled_starts.front() + 1,
                 result.settled_starts.size() == 1 ? "its" : "their",
                 result.settled_starts.size() == 1 ? "its" : "each one's");
  if (!result.turned_starts.empty())
    std::fprintf(stderr,
                 "note: %zu pass%s (first: pass %d) started from the clear axis nearest the "
                 "nominal one (itself where clear; else %g deg steps within the angle limits): "
                 "%s start, settled under the field (or nominal where settling failed), was "
                 "within `clearance` (a holder through a wall thinner than its reach is pushed "
                 "on, not back) (report.json passes turned_start)\n",
                 result.turned_starts.size(), result.turned_starts.size() == 1 ? "" : "es",
                 result.turned_starts.front() + 1, pathgen::kClearStartStepDeg,
                 result.turned_starts.size() == 1 ? "its" : "each one's");
  if (!result.corners_held.empty())
    std::fprintf(stderr,
                 "note: %zu pass%s (first: pass %d) steered with the axis held through %s "
                 "corners: turning with the feed (DESIGN's frame) it came under `clearance` "
                 "there, or swung the axis over %g deg in a step (report.json passes "
                 "corners_held)\n",
                 result.corners_held.size(), result.corners_held.size() == 1 ? "" : "es",
                 result.corners_held.front() + 1, result.corners_held.size() == 1 ? "its" : "their",
                 pathgen::kNoteAxisTurnDeg);
  if (result.safe_z_proven_mm > 0.0)
    std::fprintf(stderr,
                 "note: links.safe_z %g mm leaves the links within the checks' margin of "
                 "`clearance` (the tool mesh's chordal tolerance, the motions' resolution): they "
                 "may read as under it though clear; %.3f mm or more is proven clear\n",
                 result.safe_z_mm, result.safe_z_proven_mm);
  if (result.turned_sheets > 0)
    std::fprintf(
        stderr,
        "note: %zu open obstacle surface%s faced away from the passes: turned to face them "
        "(the field pushes along the normals)\n",
        result.turned_sheets, result.turned_sheets == 1 ? "" : "s");
  if (result.voxel_outside_points > 0) {
    // What to do about it (a blisk helper read the note as a fault): nothing for accuracy, the
    // exact field is the voxels' reference; only the time, and which key widens the voxels.
    const bool near_path = job.field.voxel.refine_tolerance > 0.0 &&
                           job.field.voxel.refine_region == field::RefineRegion::Path;
    std::fprintf(stderr,
                 "note: %zu node positions fell outside where the voxels answer (%s) and were "
                 "given the exact field: as accurate there, only slower to evaluate%s\n",
                 result.voxel_outside_points,
                 near_path ? "the refined cells lie near the path steered on the uniform grid "
                             "first; the steered path went farther"
                           : "the reach box, taken at stations of each pass: a pass turned "
                             "sharply between them",
                 near_path ? "; field.refine_region: reach refines everywhere the tool "
                             "reaches (a longer build)"
                           : "");
  }
}

}  // namespace fieldpath::app
