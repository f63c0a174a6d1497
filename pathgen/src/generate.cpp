#include "fieldpath/pathgen/generate.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <functional>
#include <memory>
#include <mutex>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/phase_trace.h"
#include "fieldpath/dynamics/frame.h"
#include "fieldpath/dynamics/steering.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/region_field.h"
#include "fieldpath/field/sampling.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/cutter_part.h"
#include "fieldpath/pathgen/reach_box.h"
#include "open_sheets.h"
#include "pass_steering.h"
#include "path_check.h"

namespace fieldpath::pathgen {
namespace {

using common::InputError;
using Clock = std::chrono::steady_clock;

using geometry::kDegToRad;
/// Tool + holder nodes aimed at (seed 004: "le maillage outil comporte 500 nœuds").
constexpr double kTargetNodes = 500.0;
/// The share of the job's progress the balls' pre-check reports in (the field's from there on).
constexpr double kBallShare = 0.02;

double seconds(Clock::time_point since) {
  return std::chrono::duration<double>(Clock::now() - since).count();
}

using common::scaled;

/// Every pass station's ball must stay clear of the obstacles (whatever the axis): one that
/// touches is refused; one within `clearance_mm` of them is reported in `under` (the smallest of
/// each pass) and the job goes on. `progress` after each pass (10 000 passes took minutes
/// without a word).
void checkBallClearance(const ClearanceChecker& checker, const std::vector<Pass>& passes,
                        double ball_radius_mm, double clearance_mm,
                        const common::Progress& progress,
                        std::vector<GenerateResult::BallUnderClearance>& under) {
  for (std::size_t k = 0; k < passes.size(); ++k) {
    const Pass& pass = passes[k];
    common::report(progress, static_cast<double>(k) / passes.size(), "balls");
    std::vector<Vec3> centres;
    for (const PassSample& s : pass.samples) centres.push_back(s.centre_mm);
    // Exact under the clearance, and under 1 um at least: a station's 0 is then a touch, never a
    // lower bound.
    BallRequest request{ball_radius_mm, std::max(clearance_mm, 1e-3)};
    request.each = true;
    const BallResult balls = checker.ballClearance(centres, request);
    const std::vector<double>& each = balls.each_mm;
    size_t at = balls.at;
    int obstacle = balls.obstacle;
    if (balls.min_mm <= 0.0) {
      // Named where the ball first enters, not where it is deepest (a pass entering a wall at
      // line 37 was named at its line 42): the first station at 0, its obstacle asked again.
      const std::size_t first = static_cast<std::size_t>(
          std::find_if(each.begin(), each.end(), [](double e) { return e <= 0.0; }) - each.begin());
      if (first < at) {
        at = first;
        obstacle =
            checker.ballClearance(std::span(&centres[at], 1), BallRequest{ball_radius_mm}).obstacle;
      }
      std::ostringstream msg;
      const double s_mm = pass.samples[at].s_mm;
      msg << pass.label << ": at s = " << s_mm << " mm";
      // The input's line there (a pass's first line named an entry 40 lines on, a helper's).
      if (pass.whereAt) msg << " (" << pass.whereAt(s_mm) << ")";
      msg << " the ball touches or enters obstacle " << obstacle + 1
          << ": the passage is narrower than the ball there (a smaller tool.radius";
      // The parametric impeller's passes are placed by its passes_v, a nominal path's by its
      // file: no frame or unit to get wrong there.
      if (pass.whereAt)
        msg << "), or the pass runs through the obstacle (a nominal path in another frame or "
               "units?)";
      else
        msg << ", or the impeller's passes_v nearer the channel's middle, 0.5)";
      throw InputError(msg.str());
    }
    if (balls.min_mm < clearance_mm)
      under.push_back({pass.index, pass.label, pass.samples[at].s_mm, balls.min_mm, obstacle});
  }
}

}  // namespace

std::vector<geometry::TriangleMesh> bladeMeshes(const Impeller& impeller) {
  return {impeller.bladeMesh(0), impeller.bladeMesh(1)};
}

double defaultNodeSpacingMm(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder) {
  // Area of the revolved profile: ball/torus end ≈ hemisphere, shank, holder bands and end faces.
  const double r = tool.radius_mm;
  double area = 2 * std::numbers::pi * r * r + 2 * std::numbers::pi * r * (tool.length_mm - r);
  double prev_z = tool.length_mm, prev_r = r;
  for (const auto& station : holder) {
    const double slant = std::hypot(station.z_mm - prev_z, station.radius_mm - prev_r);
    area += std::numbers::pi * (station.radius_mm + prev_r) * slant;
    prev_z = station.z_mm;
    prev_r = station.radius_mm;
  }
  area += std::numbers::pi * prev_r * prev_r;  // top face
  return std::sqrt(area / kTargetNodes);
}

namespace {

/// A job's field and what it is made of (the voxels answer within the reach box, the exact sum
/// beyond it).
struct PathField {
  std::unique_ptr<field::DirectField> direct;
  std::shared_ptr<field::VoxelField> voxels;
  std::unique_ptr<field::BruteForceField> brute;
  std::unique_ptr<field::RegionField> voxels_in_reach;
  std::shared_ptr<const field::CellMask> refine_mask;  ///< refinement near the path
  const field::ForceField* force = nullptr;            ///< the one the passes are steered by
};
using NearPathMask = std::function<std::shared_ptr<const field::CellMask>(
    const field::DirectField& exact, const field::VoxelRequest& refined,
    const Eigen::AlignedBox3d& valid, std::optional<field::VoxelField>& level0)>;
/// The field the passes are steered by (request.mode: the exact sum, the brute force, or the
/// voxels), from the obstacles' samples (their open sheets turned to face the passes first);
/// none for a nominal job. `near_path`: the mask of the cells the path's nodes pass through, for
/// a refinement near the path (it steers the passes on the uniform grid it leaves in `level0`).
/// Fills the result's reach box, turned sheets, samples and voxel figures.
PathField buildPathField(const GenerateRequest& request, const std::vector<Vec3>& nodes,
                         const NearPathMask& near_path, GenerateResult& result) {
  PathField f;
  const std::vector<geometry::TriangleMesh>& obstacles = request.obstacles;
  const double h = request.field.voxel.voxel_size_mm;
  result.reach_box_mm = reachBox(result.passes, nodes, request.tool.radius_mm, request.dynamics,
                                 request.path.lead_deg * kDegToRad,
                                 request.mode == FieldMode::Voxel ? voxelRegionPadMm(h) : 0.0);
  if (!request.nominal) {
    // Open sheets turned to face the passes before they are sampled (their normals are the
    // field's direction): points along the nominal axis of every 4th station vote. The meshes
    // are copied only when a sheet is turned.
    std::vector<Vec3> points;
    {
      double reach_mm = request.tool.length_mm;
      for (const auto& station : request.holder) reach_mm = std::max(reach_mm, station.z_mm);
      for (const Pass& pass : result.passes)
        for (std::size_t i = 0; i < pass.samples.size(); i += 4)
          for (double t = 0.0; t <= reach_mm; t += std::max(request.tool.radius_mm, 1.0))
            points.push_back(pass.samples[i].centre_mm + t * pass.samples[i].normal);
    }
    const std::vector<OpenSheet> away =
        sheetsFacingAway(obstacles, points, request.field.r0_mm + request.tool.radius_mm);
    result.turned_sheets = away.size();
    std::vector<geometry::TriangleMesh> faced;
    if (!away.empty()) {
      faced = obstacles;
      turnSheets(faced, away);
    }
    field::ObstacleSamples samples = field::sampleObstacles(
        away.empty() ? obstacles : faced, request.field.sample_step_mm, request.field.weights);
    result.obstacle_points = samples.size();
    f.direct = std::make_unique<field::DirectField>(std::move(samples), request.field);
    f.force = f.direct.get();
    if (request.mode == FieldMode::BruteForce) {
      f.brute = std::make_unique<field::BruteForceField>(f.direct->samples(), request.field);
      f.force = f.brute.get();
    }
    if (request.mode == FieldMode::Voxel) {
      field::VoxelRequest voxel_request(request.field.voxel);
      voxel_request.region_mm = result.reach_box_mm;
      // The voxels hold values where every node of a point's stencil lies in the box (2 h in
      // from its faces); beyond, the exact sum answers (a voxel field is zero where it has no
      // nodes: a point the box missed would feel no wall).
      const Eigen::AlignedBox3d valid = field::RegionField::stencilBox(result.reach_box_mm, h);
      double built_share = kBallShare;
      std::optional<field::VoxelField> level0;
      if (voxel_request.refine_tolerance > 0.0 && voxel_request.refine_levels > 0 &&
          voxel_request.refine_region == field::RefineRegion::Path) {
        const auto near_start = Clock::now();
        f.refine_mask = near_path(*f.direct, voxel_request, valid, level0);
        result.times.near_path_s = seconds(near_start);
        voxel_request.refine_mask = f.refine_mask;
        built_share = 0.05;
      }
      voxel_request.progress = scaled(request.progress, built_share, 0.3, "field");
      f.voxels = f.refine_mask ? std::make_shared<field::VoxelField>(*f.direct, voxel_request,
                                                                     std::move(*level0))
                               : std::make_shared<field::VoxelField>(*f.direct, voxel_request);
      level0.reset();
      result.voxel_nodes = f.voxels->stats().active_nodes;
      result.voxel_memory_bytes = f.voxels->stats().memory_bytes;
      f.voxels_in_reach = std::make_unique<field::RegionField>(*f.voxels, *f.direct, valid,
                                                               voxel_request.refine_mask);
      f.force = f.voxels_in_reach.get();
    }
  }
  return f;
}

}  // namespace

GenerateResult generatePath(const GenerateRequest& request) {
  const auto start = Clock::now();
  GenerateResult result;
  const geometry::ToolSpec& tool = request.tool;
  if (tool.shape != geometry::ToolShape::Ball)
    throw InputError("tool.shape: the impeller passes are for a ball-end mill (shape: ball)");
  geometry::validateToolSpec(tool);
  geometry::validateHolderProfile(request.holder);
  if (!std::isfinite(request.clearance_mm) || request.clearance_mm < 0.0)
    throw InputError("clearance: must be a finite distance >= 0 mm");
  const double r = tool.radius_mm;
  const double lead_rad = request.path.lead_deg * kDegToRad;

  // ---- setup: passes, clearance hierarchies ---------------------------------------------------
  result.passes = request.passes;
  if (result.passes.empty()) throw InputError("path: no passes to machine");
  const std::vector<geometry::TriangleMesh>& obstacles = request.obstacles;
  if (obstacles.empty()) throw InputError("obstacles: none given (the surfaces that repel)");
  const double tol_mm = clearanceMeshTolMm(tool, request.holder);
  const geometry::TriangleMesh tool_mesh = geometry::toolMesh(tool, request.holder, tol_mm);
  result.tool_triangles = tool_mesh.triangles.size();
  const ClearanceChecker checker(tool_mesh, obstacles, tol_mm);
  checkBallClearance(checker, result.passes, r, request.clearance_mm,
                     scaled(request.progress, 0.0, kBallShare, "balls"),
                     result.balls_under_clearance);
  // The links' travel plane, checked before any work.
  double safe_z_mm = 0.0;
  if (!request.passes_only) {
    double top_mm = topOfMeshes(obstacles);
    if (request.part) top_mm = std::max(top_mm, topOfMeshes(std::span(&*request.part, 1)));
    safe_z_mm = resolveSafeZ(request.links.safe_z_mm, top_mm, request.clearance_mm);
    const double proven_mm =
        top_mm + request.clearance_mm + tol_mm + 2.0 * MotionRequest{}.resolution_mm;
    if (request.links.safe_z_mm && safe_z_mm < proven_mm) result.safe_z_proven_mm = proven_mm;
  }
  std::vector<Vec3> nodes;
  for (const auto& node :
       geometry::surfaceNodes(tool, request.holder, defaultNodeSpacingMm(tool, request.holder)))
    nodes.push_back(node.position_mm);
  result.tool_nodes = nodes.size();
  for (const Pass& pass : result.passes) result.path_length_mm += pass.length_mm;
  result.times.setup_s = seconds(start);

  // Where the progress stands at the end of each stage after the field (0.3): shares by what
  // each costs on 2 cores (a helper's sweep of 2k-195k postures: steering 0.15 ms a posture and
  // 12 ms a pass, the clearance 0.4 ms, the motions and the part 0.1 ms each). Fixed shares left
  // the clearance at 90-92 % for 60 % of a dense job.
  double stations = 0.0;
  for (const Pass& pass : result.passes) stations += static_cast<double>(pass.samples.size());
  const double steer_ms =
      request.nominal ? 0.01 * stations : 0.15 * stations + 12.0 * result.passes.size();
  const double clearance_ms = 0.4 * stations;
  const double motions_ms = request.passes_only ? 0.0 : 0.1 * stations;
  const double part_ms = request.part && !request.passes_only ? 0.1 * stations : 0.0;
  const double share = 0.7 / std::max(1e-9, steer_ms + clearance_ms + motions_ms + part_ms);
  const double steer_end = 0.3 + share * steer_ms;
  const double clearance_end = steer_end + share * clearance_ms;
  const double motions_end = clearance_end + share * motions_ms;

  // ---- steering: the passes are independent, steered on all cores (TBB), gathered in pass
  // order: the output is the serial run's bit for bit (each pass's solver sees the same inputs;
  // the field's evaluate is deterministic per point). Progress counts finished passes.
  const int pass_count = static_cast<int>(result.passes.size());
  // Which passes start from the axis settled at their start (dynamics.start): decided once, on
  // the nominal start posture's exact clearance, so that both steerings (near the path, final)
  // start the same passes settled. `auto` settles only under a field that pushes: with gain 0 the
  // axis at rest is the nominal one, and a note said the pass "started from the axis settled
  // under the field". The same at a pass's end for one steered from there (pass_steering.h),
  // decided only then: a clearance query for every pass's end went to the few that are.
  const bool may_settle =
      !request.nominal && request.dynamics.start != dynamics::StartPolicy::Nominal;
  const auto settles = [&](const PassSample& at) {
    return may_settle && (request.dynamics.start == dynamics::StartPolicy::Settled ||
                          (request.field.gain > 0.0 && checker.clearance(geometry::ballEndPosture(
                                                           at.centre_mm, nominalAxis(at, lead_rad),
                                                           r)) < request.clearance_mm));
  };
  std::vector<char> settle(result.passes.size(), 0);
  for (std::size_t p = 0; p < result.passes.size(); ++p)
    if (!result.passes[p].samples.empty()) settle[p] = settles(result.passes[p].samples.front());
  std::vector<char> started_settled(result.passes.size(), 0);
  std::vector<char> turned_start(result.passes.size(), 0);
  std::vector<char> corners_held(result.passes.size(), 0);
  std::vector<std::string> settle_failed(result.passes.size());  // why, where settling failed
  std::vector<std::string> loosened(result.passes.size());  // why, where the solver was loosened
  struct Steered {
    std::vector<GeneratedPosture> postures;
    dynamics::SolverStats stats;
    std::exception_ptr error;
  };
  std::mutex progress_mutex;
  // Pass p steered by `field` (pass_steering.h), from its start or its end.
  const auto steerPassOf = [&](std::size_t p, const field::ForceField* field,
                               const dynamics::DynamicsParams& params, bool from_end,
                               common::Progress progress) {
    const Pass& pass = result.passes[p];
    dynamics::Pass dyn_pass;
    dyn_pass.length_mm = pass.length_mm;
    dyn_pass.frameAt = [&pass, lead_rad](double s_mm) {
      const PassSample s = pass.at(s_mm);
      dynamics::PassFrame frame;
      frame.centre_mm = s.centre_mm;
      frame.feed = s.feed;
      frame.normal = s.normal;
      frame.lead0_rad = lead_rad;
      return frame;
    };
    dynamics::SteeringRequest steer;
    steer.field = field;
    steer.nodes_tool_frame_mm = nodes;
    steer.ball_radius_mm = r;
    steer.params = params;
    // The pass's own stations (even steps, or a nominal path's postures one for one); the solver
    // never steps over more than the longest gap between them.
    double gap_mm = 0.0;
    for (std::size_t i = 0; i < pass.samples.size(); ++i) {
      steer.output_s_mm.push_back(pass.samples[i].s_mm);
      if (i > 0) gap_mm = std::max(gap_mm, pass.samples[i].s_mm - pass.samples[i - 1].s_mm);
    }
    steer.step_mm = gap_mm > 0.0 ? gap_mm : pass.length_mm;
    steer.progress = std::move(progress);
    PassSteeringSetup setup;
    setup.label = pass.label;
    setup.checker = &checker;
    setup.ball_radius_mm = r;
    setup.required_mm = request.clearance_mm;
    setup.settle_start = settle[p] != 0;
    setup.settle_end = from_end && !pass.samples.empty() && settles(pass.samples.back());
    return steerOnePass(dyn_pass, steer, setup, from_end);
  };
  // Every pass steered by `field`; `report`: progress and interruption through request.progress.
  auto steerPasses = [&](const field::ForceField* field, bool report,
                         const dynamics::DynamicsParams& params) {
    std::vector<Steered> steered_passes(result.passes.size());
    std::fill(started_settled.begin(), started_settled.end(), 0);  // this steering's own
    std::fill(turned_start.begin(), turned_start.end(), 0);
    std::fill(corners_held.begin(), corners_held.end(), 0);
    std::fill(settle_failed.begin(), settle_failed.end(), std::string());
    std::fill(loosened.begin(), loosened.end(), std::string());
    int passes_done = 0;
    // Each pass's fraction done (its solver's intervals): the bar moves within a pass too (a
    // wide r0 makes one pass take minutes).
    std::vector<double> pass_done(result.passes.size(), 0.0);
    auto fractionDone = [&] {
      double sum = 0.0;
      for (const double f : pass_done) sum += f;
      return 0.3 + (steer_end - 0.3) * sum / std::max(1, pass_count);
    };
    auto steerOne = [&](std::size_t p) {
      const Pass& pass = result.passes[p];
      Steered& out = steered_passes[p];
      if (request.nominal) {
        const std::vector<geometry::Posture> nominal =
            nominalPostures(std::span(&pass, 1), lead_rad, r);
        for (std::size_t k = 0; k < nominal.size(); ++k) {
          GeneratedPosture g;
          g.pass = pass.index;
          g.s_mm = pass.samples[k].s_mm;
          g.lead_rad = lead_rad;
          g.posture = nominal[k];
          out.postures.push_back(g);
        }
        return;
      }
      common::Progress progress;
      if (request.progress && report)
        progress = [&, p](double fraction, std::string_view) {
          std::lock_guard<std::mutex> lock(progress_mutex);
          // Never back: a pass run again (loosened, or its corners held) reports from 0 anew.
          pass_done[p] = std::max(pass_done[p], std::clamp(fraction, 0.0, 1.0));
          return request.progress(fractionDone(), "passes");
        };
      PassSteering done = steerPassOf(p, field, params, false, std::move(progress));
      started_settled[p] = done.started_settled;
      turned_start[p] = done.turned_start;
      corners_held[p] = done.corners_held;
      settle_failed[p] = std::move(done.settle_failed);
      loosened[p] = std::move(done.loosened);
      const dynamics::SteeringResult& steered = done.run;
      if (steered.status != dynamics::Status::Ok) {
        std::ostringstream msg;
        msg << pass.label;
        if (pass.whereAt && !steered.samples.empty())  // the input line where it stopped
          msg << ", at " << pass.whereAt(steered.samples.back().s_mm);
        msg << ": " << dynamics::toString(steered.status) << ": " << steered.message;
        if (steered.status == dynamics::Status::SolverFailed)  // what to change, not CVODE's words
          msg << " (the spring-damper is too stiff for the integrator here: raise "
                 "dynamics.inertia or dynamics.damping, lower field.gain or dynamics.stiffness, "
                 "or relax dynamics.rtol; or the tool has no room there: the field pushes the "
                 "tool or holder from both sides, a passage narrower than they are, and "
                 "`generate --nominal` marks where the path collides)";
        throw InputError(msg.str());
      }
      out.postures = generatedPostures(pass.index, steered);
      out.stats = steered.stats;
    };
    auto runPass = [&](std::size_t p) {
      try {
        steerOne(p);
      } catch (...) {
        steered_passes[p].error = std::current_exception();
      }
      std::lock_guard<std::mutex> lock(progress_mutex);
      ++passes_done;
      pass_done[p] = 1.0;
      const std::string label =
          "pass " + std::to_string(passes_done) + "/" + std::to_string(pass_count);
      if (report && request.progress && !steered_passes[p].error &&
          !request.progress(fractionDone(), label))
        steered_passes[p].error = std::make_exception_ptr(common::Interrupted());
    };
    if (request.serial_passes)
      for (std::size_t p = 0; p < result.passes.size(); ++p) runPass(p);
    else
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, result.passes.size(), 1),
                        [&](const auto& range) {
                          for (std::size_t p = range.begin(); p != range.end(); ++p) runPass(p);
                        });
    return steered_passes;
  };

  // Refinement near the path (field.refine_region: path): the passes steered on the uniform
  // grid first; the cells their tool + holder nodes pass through are where the refined build
  // splits (1.5 h around them) and where the refined voxels answer (h / 2 around them; the exact
  // sum beyond). The refined path stays within hundredths of a degree of that first one (study:
  // the uniform 0.5 mm grid's tilt is 0.008 deg from the exact field's), so the refined build's
  // cells, not the whole reach box's, are those the path reads. Null where the first steering
  // fails (the refinement then splits everywhere, as with `reach`).
  // Returns the mask, and in `level0` the uniform grid (the refined build's level 0, refined
  // next rather than built again).
  auto nodesNearPath =
      [&](const field::DirectField& exact, const field::VoxelRequest& refined,
          const Eigen::AlignedBox3d& valid,
          std::optional<field::VoxelField>& level0) -> std::shared_ptr<const field::CellMask> {
    field::VoxelRequest uniform = field::levelZeroRequest(refined, request.field.r_min_mm);
    uniform.progress = scaled(request.progress, kBallShare, 0.05, "field");
    common::PhaseTrace trace("near path");
    level0.emplace(exact, uniform);
    trace.lap("uniform grid");
    const field::RegionField coarse_in_reach(*level0, exact, valid);
    // Where the nodes go, to well within the core (h/2): a looser solver suffices (rtol 1e-4
    // moves a node 90 mm up the holder by ~0.01 mm; impeller, 0.5 mm refined 1 %, one run
    // each on 2 cores: the near-path part 0.48 -> 0.44 s, the same mask and path).
    dynamics::DynamicsParams rough = request.dynamics;
    rough.rtol = std::max(rough.rtol, 1e-4);
    rough.atol = std::max(rough.atol, 1e-7);
    const std::vector<Steered> first = steerPasses(&coarse_in_reach, false, rough);
    std::vector<const GeneratedPosture*> postures;
    for (const Steered& s : first) {
      if (s.error) return nullptr;
      for (const GeneratedPosture& g : s.postures) postures.push_back(&g);
    }
    // Every node at every posture, placed in parallel.
    std::vector<Vec3> points(postures.size() * nodes.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, postures.size(), 64), [&](const auto& r) {
      for (std::size_t k = r.begin(); k != r.end(); ++k) {
        const Eigen::Isometry3d placed = geometry::toolToWorld(postures[k]->posture);
        for (std::size_t n = 0; n < nodes.size(); ++n)
          points[k * nodes.size() + n] = placed * nodes[n];
      }
    });
    trace.lap("steering on it");
    const double hc = refined.voxel_size_mm;
    // Only near the obstacles: beyond r0 of every sample nothing is refined and the voxels are
    // zero as the field is (the holder's nodes high above the part).
    Eigen::AlignedBox3d relevant;
    for (const Vec3& q : exact.samples().points_mm) relevant.extend(q);
    relevant.min().array() -= request.field.r0_mm + 2.0 * hc;
    relevant.max().array() += request.field.r0_mm + 2.0 * hc;
    auto mask =
        std::make_shared<const field::CellMask>(points, 0.5 * hc, 0.5 * hc, 1.5 * hc, relevant);
    trace.lap("mask");
    return mask;
  };

  // ---- field -----------------------------------------------------------------------------------
  const auto field_start = Clock::now();
  PathField path_field = buildPathField(request, nodes, nodesNearPath, result);
  const field::ForceField* force = path_field.force;
  result.times.field_s = seconds(field_start);

  // The cutter's test against the part runs last: its stamps are asked for now, so that a run
  // the test would refuse is refused before the steering (33 s of a run went before such a
  // refusal). Counted at the ball centres with the axis held: the centres follow the path
  // whatever the axis does, so the steered path's stamps are at least these (its turns and links
  // only add; the nominal axes would count turns the steering smooths away).
  if (request.part && !request.passes_only) {
    Eigen::AlignedBox3d part_box;
    for (const Vec3& v : request.part->vertices) part_box.extend(v);
    std::vector<std::vector<geometry::Posture>> centres(result.passes.size());
    for (std::size_t p = 0; p < result.passes.size(); ++p)
      for (const PassSample& sample : result.passes[p].samples)
        centres[p].push_back({sample.centre_mm, Vec3::UnitZ(), 0.0, false});
    requireCutterTestMemory(tool, part_box, centres);
  }

  const auto steer_start = Clock::now();
  std::vector<Steered> steered_passes = steerPasses(force, true, request.dynamics);
  // The first failure in pass order, as the serial loop would have thrown it.
  for (const Steered& s : steered_passes)
    if (s.error) std::rethrow_exception(s.error);
  for (std::size_t p = 0; p < result.passes.size(); ++p) {
    if (started_settled[p]) result.settled_starts.push_back(result.passes[p].index);
    if (turned_start[p]) result.turned_starts.push_back(result.passes[p].index);
    if (corners_held[p]) result.corners_held.push_back(result.passes[p].index);
    if (!settle_failed[p].empty())
      result.settle_failures.push_back({result.passes[p].index, settle_failed[p]});
    if (!loosened[p].empty()) result.loosened_solver.push_back(loosened[p]);
  }
  for (Steered& s : steered_passes) {
    for (GeneratedPosture& g : s.postures) {
      if (g.limited && result.first_limited == ClearanceResult::npos)
        result.first_limited = result.postures.size();
      result.limited_postures += g.limited;
      result.postures.push_back(g);
    }
    const dynamics::SolverStats& st = s.stats;
    result.solver_steps += st.steps;
    result.rhs_evals += st.rhs_evals;
    result.jacobian_evals += st.jacobian_evals;
    result.error_test_failures += st.error_test_failures;
    result.convergence_failures += st.convergence_failures;
  }
  result.times.steering_s = seconds(steer_start);
  if (path_field.voxels_in_reach)
    result.voxel_outside_points = path_field.voxels_in_reach->outsidePoints();

  // ---- links, then the exact clearance of every posture and motion ----------------------------
  const auto clearance_start = Clock::now();
  // A faulty pass steered again from its end (the repairs judge it): the final field's.
  const SteerFromEnd steer_from_end = [&](std::size_t p) -> std::optional<PassSteering> {
    PassSteering done = steerPassOf(p, force, request.dynamics, true, {});
    if (done.run.status != dynamics::Status::Ok) return std::nullopt;
    return done;
  };
  linkCheckAndRepair(request, checker, safe_z_mm, {steer_end, clearance_end, motions_end},
                     steer_from_end, result);
  result.times.clearance_s = seconds(clearance_start);
  result.times.total_s = seconds(start);
  if (request.keep_voxels) {
    result.voxels = std::move(path_field.voxels);
    if (result.voxels) result.refine_mask = path_field.refine_mask;
  }
  return result;
}

}  // namespace fieldpath::pathgen
