#include "generate_report.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "fieldpath/common/csv.h"
#include "fieldpath/geometry/units.h"
#include "generate_repairs.h"
#include "json_text.h"
#include "path_report.h"

namespace fieldpath::app {
namespace {

using geometry::kRadToDeg;

const char* startPolicyName(dynamics::StartPolicy start) {
  switch (start) {
    case dynamics::StartPolicy::Auto:
      return "auto";
    case dynamics::StartPolicy::Nominal:
      return "nominal";
    case dynamics::StartPolicy::Settled:
      return "settled";
  }
  return "?";
}

}  // namespace

nlohmann::json reportJson(const Scene& scene, const pathgen::GenerateRequest& job,
                          const pathgen::GenerateResult& r, const pathgen::AxisTurn& axis_turn,
                          const JobNotes& notes) {
  using nlohmann::json;
  json passes = json::array();
  json settled = json::array();  // 1-based, as per_pass
  for (const int p : r.settled_starts) settled.push_back(p + 1);
  json balls_under = json::array();
  for (const auto& b : r.balls_under_clearance)
    balls_under.push_back({{"pass", b.pass + 1},
                           {"at", b.label},
                           {"s_mm", b.s_mm},
                           {"ball_clearance_mm", b.clearance_mm},
                           {"obstacle", b.obstacle + 1},
                           {"obstacle_name", obstacleName(scene, b.obstacle)}});
  json settle_failures = json::array();
  for (const auto& f : r.settle_failures)
    settle_failures.push_back({{"pass", f.pass + 1}, {"why", f.why}});
  for (const pathgen::Pass& pass : r.passes) {
    double min_clearance = INFINITY, max_tilt = 0;
    int postures = 0, colliding = 0;
    for (const auto& g : r.postures) {
      if (g.pass != pass.index) continue;
      ++postures;
      min_clearance = std::min(min_clearance, g.clearance_mm);
      max_tilt = std::max(max_tilt, std::abs(g.tilt_rad) * kRadToDeg);
      colliding += g.clearance_mm <= 0.0;
    }
    passes.push_back(
        {{"pass", pass.index + 1},
         {"source", pass.label},
         {"v", jsonNumber(pass.v)},
         {"length_mm", pass.length_mm},
         {"postures", postures},
         {"min_clearance_mm", jsonNumber(min_clearance)},
         {"max_tilt_deg", max_tilt},
         {"colliding_postures", colliding},
         {"settled_start", std::find(r.settled_starts.begin(), r.settled_starts.end(),
                                     pass.index) != r.settled_starts.end()},
         {"turned_start", std::find(r.turned_starts.begin(), r.turned_starts.end(), pass.index) !=
                              r.turned_starts.end()},
         {"corners_held", std::find(r.corners_held.begin(), r.corners_held.end(), pass.index) !=
                              r.corners_held.end()},
         {"steered_from_end", std::find(r.steered_from_end.begin(), r.steered_from_end.end(),
                                        pass.index) != r.steered_from_end.end()}});
    if (std::isnan(pass.v))  // a null beside its reason (DESIGN.md)
      passes.back()["v_skipped"] = "a pass of a nominal path has no channel coordinate v";
  }
  const auto& box = r.reach_box_mm;
  const std::vector<std::string> unsafe =
      unsafeReasons(r.path, r.clearance, r.motions, r.link_part, r.holder_part, kLinkHint);
  return {
      {"scene", scene.file.string()},
      {"field_mode", job.nominal ? "nominal" : pathgen::fieldModeNames(job.mode).id},
      {"voxel_size_mm", job.mode == pathgen::FieldMode::Voxel && !job.nominal
                            ? json(job.field.voxel.voxel_size_mm)
                            : json(nullptr)},
      {"nominal", job.nominal},
      {"postures", r.path.postures.size()},
      {"pass_postures", r.postures.size()},
      {"passes", r.passes.size()},
      {"path_length_mm", r.path_length_mm},
      {"times_s",
       {{"setup", r.times.setup_s},
        {"field", r.times.field_s},
        {"field_near_path", r.times.near_path_s},
        {"steering", r.times.steering_s},
        {"clearance", r.times.clearance_s},
        {"total", r.times.total_s}}},
      {"counts",
       {{"obstacle_points", r.obstacle_points},
        {"tool_nodes", r.tool_nodes},
        {"tool_triangles", r.tool_triangles},
        {"voxel_nodes", r.voxel_nodes},
        {"voxel_memory_bytes", r.voxel_memory_bytes},
        {"voxel_outside_points", r.voxel_outside_points},
        {"turned_open_sheets", r.turned_sheets}}},
      {"reach_box_mm",
       {{"min", {box.min().x(), box.min().y(), box.min().z()}},
        {"max", {box.max().x(), box.max().y(), box.max().z()}},
        {"volume_cm3", box.volume() / 1000.0}}},
      {"clearance",
       clearanceJson(
           r.clearance, job.clearance_mm, pathgen::clearanceMeshTolMm(job.tool, job.holder),
           r.clearance.min_obstacle < 0 ? "" : obstacleName(scene, r.clearance.min_obstacle))},
      {"motions", motionsJson(r.motions, job.clearance_mm, pathgen::MotionRequest{}.resolution_mm)},
      {"link_part", linkPartJson(r.link_part)},
      {"holder_part", holderPartJson(r.holder_part)},
      {"cutter_part", cutterPartJson(r.cutter_part)},
      // The passes' balls' least distance to the part (a ball end mill and a part), exact up to
      // `far_mm`: at or past it the passes never finish the part.
      {"ball_part", r.ball_part_mm
                        ? json{{"min_mm", *r.ball_part_mm},  // a lower bound at or past far_mm
                               {"far_mm", pathgen::farFromPartMm(job.tool.radius_mm)},
                               {"reaches", *r.ball_part_mm <= pathgen::kReachesPartMm},
                               // the path's passes (from 1) whose ball stays past far_mm
                               {"far_passes", r.far_from_part.passes},
                               {"far_postures", r.far_from_part.postures}}
                        : json(nullptr)},
      {"cutter_part_skipped",
       r.cutter_part ? json(nullptr) : json("no `part` in the scene, or a flat end")},
      {"link_part_skipped",
       r.link_part ? json(nullptr) : json("no `part` in the scene, or no links")},
      {"holder_part_skipped",
       r.holder_part ? json(nullptr) : json("no `part` or no `holder` in the scene")},
      {"safe", unsafe.empty()},
      {"tool_notes", notes.tool},
      {"obstacle_notes", notes.obstacle},
      {"link_notes", notes.link},
      {"unsafe", unsafe},
      {"links",
       {{"links", r.path.count(geometry::PathBlock::Kind::Link)},
        {"link_postures", r.link_postures},
        {"retract_mm", job.links.retract_mm},
        {"safe_z_mm", r.safe_z_mm},
        {"safe_z", job.links.safe_z_mm ? "given" : "auto: highest mesh point + clearance + 2 mm"},
        {"max_turn_deg", pathgen::kMaxLinkTurnDeg},
        {"routed_off_axis", routedLinkEndsJson(r)},
        {"routed_off_axis_undone", r.routed_link_ends_undone},
        {"unfreed", r.unfreed_link_ends}}},
      {"limits",
       {{"on_limit", job.dynamics.on_limit == dynamics::LimitPolicy::Clamp ? "clamp" : "fail"},
        {"max_tilt_deg", job.dynamics.max_tilt_deg},
        {"max_lead_deg", job.dynamics.max_lead_deg},
        {"limited_postures", r.limited_postures},
        {"limited_colliding", r.limited_colliding},
        {"first_limited", r.first_limited == pathgen::ClearanceResult::npos
                              ? json(nullptr)
                              : json({{"posture", r.postures[r.first_limited].output},
                                      {"pass", r.postures[r.first_limited].pass + 1},
                                      {"s_mm", r.postures[r.first_limited].s_mm}})}}},
      {"max_tilt_deg", r.max_tilt_deg},
      {"max_lead_deg", r.max_lead_deg},
      // The balls themselves within `clearance` (no axis clears them): what marks such a path.
      {"balls_under_clearance", balls_under},
      {"kept_nominal", keptNominalJson(r)},
      {"kept_nominal_undone", r.kept_nominal_undone},
      {"steered_from_end_undone", r.steered_from_end_undone},
      {"axis_turn", axisTurnJson(axis_turn)},
      {"start",
       {{"policy", startPolicyName(job.dynamics.start)},
        {"settled_passes", settled},
        {"settle_failures", settle_failures}}},
      {"solver",
       {{"steps", r.solver_steps},
        {"rhs_evals", r.rhs_evals},
        {"jacobian_evals", r.jacobian_evals},
        {"error_test_failures", r.error_test_failures},
        {"convergence_failures", r.convergence_failures},
        {"loosened", r.loosened_solver},
        {"response_mm", job.dynamics.responseLengthMm()}}},
      {"per_pass", passes},
  };
}

std::string anglesCsv(const pathgen::GenerateResult& r) {
  std::ostringstream csv;
  csv << "s_mm,pass,lead_deg,tilt_deg,moment,nearest_mm,posture,limited\n";
  csv.precision(9);
  for (const auto& g : r.postures)
    csv << common::csvNumber(g.s_mm) << ',' << g.pass + 1 << ','
        << common::csvNumber(g.lead_rad * kRadToDeg) << ','
        << common::csvNumber(g.tilt_rad * kRadToDeg) << ',' << common::csvNumber(g.moment) << ','
        << common::csvNumber(g.clearance_mm) << ',' << g.output << ',' << (g.limited ? 1 : 0)
        << '\n';
  return csv.str();
}

}  // namespace fieldpath::app
