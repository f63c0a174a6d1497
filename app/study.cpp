#include "study.h"
#include "study_text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iomanip>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/memory.h"
#include "fieldpath/common/stats.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/law.h"
#include "fieldpath/field/region_field.h"
#include "fieldpath/field/sampling.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/reach_box.h"

namespace fieldpath::app {
using namespace study_detail;
namespace {

using common::InputError;
using geometry::kRadToDeg;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
/// A study-line point as a tiny ball for the exact (FCL) wall distance, mm.
constexpr double kPointRadiusMm = 1e-6;

/// Study lines sit at mid blade height (ruling parameter t); line a runs along the part of the
/// channel the passes cover (impeller u_range), line b crosses it in the middle of that part.
constexpr double kLineBladeT = 0.5;

using common::scaled;

/// A study line's points: t along the polyline, wall distances from FCL.
StudyLine makeLine(std::string name, std::string description, std::vector<Vec3> points,
                   const pathgen::ClearanceChecker& checker) {
  StudyLine line;
  line.name = std::move(name);
  line.description = std::move(description);
  double t = 0.0;
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (i) t += (points[i] - points[i - 1]).norm();
    line.t_mm.push_back(t);
    line.wall_distance_mm.push_back(
        checker.ballClearance(std::span<const Vec3>(&points[i], 1), kPointRadiusMm));
  }
  line.points_mm = std::move(points);
  return line;
}

/// Line a: along the channel at mid blade height, r0/2 off the left blade (mid-channel is beyond
/// r0 of both blades on a channel wider than 2 r0: no field there to compare).
std::vector<Vec3> lineAPoints(const pathgen::Impeller& impeller, double offset_mm, double step_mm) {
  const double u0 = impeller.params().u_range[0], u1 = impeller.params().u_range[1];
  auto at = [&](double u) {
    return Vec3(impeller.blade(0, u, kLineBladeT) +
                offset_mm * impeller.bladeNormal(0, u, kLineBladeT));
  };
  // Arc length of the offset curve, then even steps along it.
  const int dense = 4000;
  std::vector<double> s(dense + 1, 0.0);
  for (int i = 1; i <= dense; ++i)
    s[i] =
        s[i - 1] + (at(u0 + (u1 - u0) * i / dense) - at(u0 + (u1 - u0) * (i - 1) / dense)).norm();
  const int count = std::max(2, static_cast<int>(std::ceil(s.back() / step_mm)) + 1);
  std::vector<Vec3> points;
  int k = 0;
  for (int i = 0; i < count; ++i) {
    const double target = s.back() * i / (count - 1);
    while (k < dense - 1 && s[k + 1] < target) ++k;
    const double w = s[k + 1] > s[k] ? (target - s[k]) / (s[k + 1] - s[k]) : 0.0;
    points.push_back(at(u0 + (u1 - u0) * (k + w) / dense));
  }
  return points;
}

/// Line b: straight across the channel, wall to wall, mid blade height, at `u`.
std::vector<Vec3> lineBPoints(const pathgen::Impeller& impeller, double u, double step_mm) {
  const Vec3 a = impeller.blade(0, u, kLineBladeT), b = impeller.blade(1, u, kLineBladeT);
  const int count = std::max(2, static_cast<int>(std::ceil((b - a).norm() / step_mm)) + 1);
  std::vector<Vec3> points;
  for (int i = 0; i < count; ++i) points.push_back(a + (b - a) * (double(i) / (count - 1)));
  return points;
}

/// Force error of `approx` against `exact` over the points with `counted[i]` (see study.h).
ForceError forceError(std::span<const Vec3> approx, std::span<const Vec3> exact,
                      const std::vector<char>& counted, std::vector<double>* per_point) {
  double max_ref = 0.0;
  for (std::size_t i = 0; i < exact.size(); ++i)
    if (counted[i]) max_ref = std::max(max_ref, exact[i].norm());
  std::vector<Vec3> a, r;
  ForceError e;
  double sum_sq = 0.0;
  std::size_t n = 0;
  if (per_point) per_point->assign(exact.size(), kNaN);
  for (std::size_t i = 0; i < exact.size(); ++i) {
    if (!counted[i] || max_ref == 0.0) continue;
    const double diff = (approx[i] - exact[i]).norm() / max_ref;
    e.max_scaled = std::max(e.max_scaled, diff);
    sum_sq += diff * diff;
    ++n;
    if (exact[i].norm() >= kErrorFloorFraction * max_ref) {
      a.push_back(approx[i]);
      r.push_back(exact[i]);
      if (per_point) (*per_point)[i] = (approx[i] - exact[i]).norm() / exact[i].norm();
    }
  }
  if (n) e.rms_scaled = std::sqrt(sum_sq / static_cast<double>(n));
  e.relative = field::relativeError(a, r, kErrorFloorFraction * max_ref);
  return e;
}

/// Stage by stage median of repeated runs.
pathgen::StageTimes medianTimes(const std::vector<pathgen::StageTimes>& runs) {
  auto of = [&](double pathgen::StageTimes::*stage) {
    std::vector<double> values;
    for (const auto& t : runs) values.push_back(t.*stage);
    return common::median(values);
  };
  pathgen::StageTimes t;
  t.setup_s = of(&pathgen::StageTimes::setup_s);
  t.field_s = of(&pathgen::StageTimes::field_s);
  t.steering_s = of(&pathgen::StageTimes::steering_s);
  t.clearance_s = of(&pathgen::StageTimes::clearance_s);
  t.near_path_s = of(&pathgen::StageTimes::near_path_s);
  t.total_s = of(&pathgen::StageTimes::total_s);
  return t;
}

std::vector<Vec3> evaluate(const field::ForceField& field, std::span<const Vec3> points) {
  std::vector<Vec3> forces(points.size());
  field.evaluate(points, forces);
  return forces;
}

/// What the errors of one variant are measured on, built once.
struct ErrorSets {
  std::vector<Vec3> nodes_mm;    ///< tool + holder nodes at every posture of the direct path
  std::vector<Vec3> centres_mm;  ///< ball centre of each posture
  std::size_t nodes_per_posture = 0;
  std::vector<Vec3> moments_direct;
  std::vector<char> moments_counted;

  /// τ = Σ (x_i - C) × F(x_i) per posture (DESIGN.md "The dynamics"): what steers the axis.
  std::vector<Vec3> moments(const std::vector<Vec3>& node_forces) const {
    std::vector<Vec3> result(centres_mm.size(), Vec3::Zero());
    for (std::size_t p = 0; p < centres_mm.size(); ++p)
      for (std::size_t k = p * nodes_per_posture; k < (p + 1) * nodes_per_posture; ++k)
        result[p] += (nodes_mm[k] - centres_mm[p]).cross(node_forces[k]);
    return result;
  }
  std::vector<Vec3> nodes_direct, line_a_direct, line_b_direct;
  std::vector<char> nodes_counted, line_a_counted, line_b_counted;
};

}  // namespace

StudyResult runStudy(const StudyRequest& request) {
  if (request.voxel_sizes_mm.empty()) throw InputError("--voxels: give at least one voxel size");
  for (double h : request.voxel_sizes_mm)
    if (!std::isfinite(h) || h <= 0.0) throw InputError("--voxels: voxel sizes must be > 0 mm");
  if (request.interpolations.empty()) throw InputError("--interp: give at least one interpolation");
  if (request.stored.empty()) throw InputError("--stored: give force, plane_ratio or both");
  if (request.repeats < 1) throw InputError("--repeat: must be >= 1");
  if (!std::isfinite(request.line_step_mm) || request.line_step_mm <= 0.0)
    throw InputError("--line-step: the study lines need a step > 0 mm");

  std::vector<StudyVariant> variants;
  if (request.brute_force) variants.push_back({pathgen::FieldMode::BruteForce});
  variants.push_back({pathgen::FieldMode::Direct});
  if (!request.refine_tolerances.empty() &&
      request.refine_tolerances.size() != request.voxel_sizes_mm.size())
    throw InputError("--refine: give one tolerance per voxel size");
  if (request.refine_levels < 1 || request.refine_levels > 6)
    throw InputError("--refine-levels: must be in [1, 6]");
  const std::size_t first_voxel = variants.size();
  // A size listed twice (to be refined to two tolerances) gets its uniform variants once.
  auto listed = [&](const StudyVariant& v) {
    return std::any_of(variants.begin(), variants.end(),
                       [&](const StudyVariant& w) { return w.name() == v.name(); });
  };
  for (std::size_t k = 0; k < request.voxel_sizes_mm.size(); ++k) {
    const double h = request.voxel_sizes_mm[k];
    for (field::StoredQuantity stored : request.stored)
      for (field::Interpolation interp : request.interpolations) {
        const StudyVariant uniform{pathgen::FieldMode::Voxel, {h, interp, stored, 0.0, 0}};
        if (!listed(uniform)) variants.push_back(uniform);
      }
    const double tolerance = request.refine_tolerances.empty() ? 0.0 : request.refine_tolerances[k];
    if (tolerance > 0.0)
      for (field::StoredQuantity stored : request.stored)
        for (field::RefineRegion where : request.refine_regions) {
          StudyVariant refined{
              pathgen::FieldMode::Voxel,
              {h, field::Interpolation::Trilinear, stored, tolerance, request.refine_levels}};
          refined.voxel.refine_region = where;
          if (!listed(refined)) variants.push_back(refined);
        }
  }
  if (!request.backends.empty()) {  // each voxel variant once per build, side by side
    std::vector<StudyVariant> built(variants.begin(), variants.begin() + long(first_voxel));
    for (std::size_t v = first_voxel; v < variants.size(); ++v)
      for (field::FieldBackend backend : request.backends) {
        StudyVariant variant = variants[v];
        variant.voxel.backend = backend;
        variant.named_backend = true;
        built.push_back(variant);
      }
    variants = std::move(built);
  }

  // The study lines' points (a and b): made once, counted below, evaluated in prepareErrors.
  const pathgen::Impeller impeller(request.impeller);
  const auto& u_range = request.impeller.u_range;
  const double u_mid = 0.5 * (u_range[0] + u_range[1]);
  std::vector<Vec3> line_a_points =
      lineAPoints(impeller, 0.5 * request.job.field.r0_mm, request.line_step_mm);
  std::vector<Vec3> line_b_points = lineBPoints(impeller, u_mid, request.line_step_mm);

  // What the study holds to its end, asked before any variant runs (study swept: an accepted
  // --max-memory 57M ran to 106 MiB, 3.2 times a limit with --line-step 0.001: none of it was
  // estimated). Measured on the impeller example (2 variants): the tool nodes at every posture of
  // the direct path with their exact and one variant's forces, ~75 B a node (1035 postures x 529
  // nodes: 40 MB; 90 counted); the lines, ~800 B a point with their exact values, wall distances,
  // per-variant magnitudes and errors and lines.csv's text (100 k points: 79 MB); every
  // variant's postures.
  {
    const pathgen::GenerateRequest& job = request.job;
    std::size_t stations = 0;
    for (const pathgen::Pass& pass : job.passes) stations += pass.samples.size();
    const double nodes =
        double(geometry::surfaceNodes(job.tool, job.holder,
                                      pathgen::defaultNodeSpacingMm(job.tool, job.holder))
                   .size());
    const double line_points = double(line_a_points.size() + line_b_points.size());
    const double variant_count = double(variants.size());
    const double bytes = double(stations) * nodes * 90.0 +
                         line_points * (600.0 + 150.0 * variant_count) +
                         double(stations) * variant_count * sizeof(pathgen::GeneratedPosture);
    common::requireMemory(
        "study", bytes,
        std::to_string(stations) + " postures x " + std::to_string(std::llround(nodes)) +
            " tool nodes, " + std::to_string(std::llround(line_points)) +
            " line points (--line-step) and " + std::to_string(variants.size()) + " variants",
        common::MemoryUse::kKept);
  }

  // Shares of the progress bar: each variant's path run and its error evaluation.
  const auto share = [&](std::size_t i) { return double(i) / double(variants.size()); };
  const std::size_t direct_row = request.brute_force ? 1 : 0;

  StudyResult result;
  result.field = request.job.field;
  result.clearance_mm = request.job.clearance_mm;
  result.repeats = request.repeats;
  const pathgen::GenerateRequest& job = request.job;

  // ---- force errors: the exact field, the lines, the nodes along the direct path ------------
  // Set up once the direct path exists (it precedes every voxel variant); each voxel variant is
  // then measured right after its run, with the field its path was steered by (built once, and
  // freed before the next variant's).
  std::unique_ptr<field::DirectField> direct;
  ErrorSets sets;
  auto prepareErrors = [&](const pathgen::GenerateResult& direct_run) {
    const std::vector<geometry::TriangleMesh>& obstacles = job.obstacles;
    const pathgen::ClearanceChecker checker(
        geometry::toolMesh(job.tool, job.holder, pathgen::clearanceMeshTolMm(job.tool, job.holder)),
        obstacles);
    direct = std::make_unique<field::DirectField>(
        field::sampleObstacles(obstacles, job.field.sample_step_mm, job.field.weights), job.field);

    result.line_a =
        makeLine("a",
                 "along the channel (u " + number(u_range[0]) + " to " + number(u_range[1]) +
                     ", the passes' range), mid blade height, r0/2 off the left blade",
                 std::move(line_a_points), checker);
    result.line_b = makeLine(
        "b", "across the channel at u = " + number(u_mid) + ", mid blade height, wall to wall",
        std::move(line_b_points), checker);

    std::vector<Vec3> tool_nodes;
    for (const auto& node : geometry::surfaceNodes(
             job.tool, job.holder, pathgen::defaultNodeSpacingMm(job.tool, job.holder)))
      tool_nodes.push_back(node.position_mm);
    for (const pathgen::GeneratedPosture& g : direct_run.postures) {
      const Eigen::Isometry3d placed = geometry::toolToWorld(g.posture);
      for (const Vec3& n : tool_nodes) sets.nodes_mm.push_back(placed * n);
      sets.centres_mm.push_back(geometry::ballCentre(g.posture, job.tool.radius_mm));
    }
    sets.nodes_per_posture = tool_nodes.size();
    result.node_points = sets.nodes_mm.size();
    sets.nodes_direct = evaluate(*direct, sets.nodes_mm);
    sets.nodes_counted.assign(sets.nodes_mm.size(), 1);
    sets.moments_direct = sets.moments(sets.nodes_direct);
    sets.moments_counted.assign(sets.moments_direct.size(), 1);
    for (StudyLine* line : {&result.line_a, &result.line_b}) {
      auto& counted = line == &result.line_a ? sets.line_a_counted : sets.line_b_counted;
      auto& exact = line == &result.line_a ? sets.line_a_direct : sets.line_b_direct;
      exact = evaluate(*direct, line->points_mm);
      counted.clear();
      for (std::size_t i = 0; i < exact.size(); ++i) {
        line->direct_magnitude.push_back(exact[i].norm());
        counted.push_back(line->wall_distance_mm[i] >= job.clearance_mm &&
                          direct_run.reach_box_mm.contains(line->points_mm[i]));
      }
    }
  };
  // Row i's errors, rows in order (the lines keep one entry per row). `voxels`: the field of
  // its path, or null (a failed run: built here over the region generate would have used).
  auto measureErrors = [&](StudyRow& row, const pathgen::GenerateResult& run,
                           const Eigen::AlignedBox3d& direct_reach_mm,
                           std::shared_ptr<const field::VoxelField> voxels) {
    std::unique_ptr<field::ForceField> brute;
    if (row.variant.isVoxel() && !voxels) {
      field::VoxelRequest voxel_request(row.variant.voxel);
      Eigen::AlignedBox3d region = direct_reach_mm;  // padded as generate pads it
      const double pad_mm = pathgen::voxelRegionPadMm(row.variant.voxel.voxel_size_mm);
      region.min().array() -= pad_mm;
      region.max().array() += pad_mm;
      voxel_request.region_mm = row.failure.empty() ? run.reach_box_mm : region;
      voxels = std::make_shared<field::VoxelField>(*direct, voxel_request);
    }
    if (voxels) {
      row.active_nodes = voxels->stats().active_nodes;
      row.dense_box_nodes = voxels->stats().dense_box_nodes;
      row.voxel_memory_bytes = voxels->stats().memory_bytes;
      row.refined_nodes = voxels->stats().refined_nodes;
      row.levels = voxels->stats().levels;
    } else if (row.variant.mode == pathgen::FieldMode::BruteForce) {
      brute = std::make_unique<field::BruteForceField>(direct->samples(), job.field);
    }
    // Refined near its path: the field the job read, the voxels in the mask's core and the
    // exact sum beyond (generate's RegionField).
    std::unique_ptr<field::RegionField> near_path;
    if (voxels && run.refine_mask) {
      near_path = std::make_unique<field::RegionField>(
          *voxels, *direct,
          field::RegionField::stencilBox(run.reach_box_mm, row.variant.voxel.voxel_size_mm),
          run.refine_mask);
    }
    const field::ForceField* approx = near_path ? near_path.get()
                                      : voxels  ? voxels.get()
                                                : brute.get();
    const field::ForceField& f = approx ? *approx : *direct;
    for (StudyLine* line : {&result.line_a, &result.line_b}) {
      const bool is_a = line == &result.line_a;
      const std::vector<Vec3> forces = evaluate(f, line->points_mm);
      std::vector<double> magnitude, per_point;
      for (const Vec3& v : forces) magnitude.push_back(v.norm());
      (is_a ? row.line_a : row.line_b) =
          forceError(forces, is_a ? sets.line_a_direct : sets.line_b_direct,
                     is_a ? sets.line_a_counted : sets.line_b_counted, &per_point);
      line->magnitude.push_back(std::move(magnitude));
      line->relative_error.push_back(std::move(per_point));
    }
    const std::vector<Vec3> node_forces = approx ? evaluate(f, sets.nodes_mm) : sets.nodes_direct;
    row.nodes = forceError(node_forces, sets.nodes_direct, sets.nodes_counted, nullptr);
    row.moment =
        forceError(sets.moments(node_forces), sets.moments_direct, sets.moments_counted, nullptr);
  };

  std::vector<pathgen::GenerateResult> runs;
  for (std::size_t i = 0; i < variants.size(); ++i) {
    pathgen::GenerateRequest variant_job = job;
    variant_job.mode = variants[i].mode;
    variant_job.nominal = false;
    variant_job.passes_only = true;  // the variants are compared on the passes' postures
    variant_job.keep_voxels = variants[i].isVoxel();
    if (variants[i].isVoxel()) variant_job.field.voxel = variants[i].voxel;
    const double run_end = share(i) + 0.8 * (share(i + 1) - share(i));
    variant_job.progress = scaled(request.progress, share(i), run_end, variants[i].name());
    StudyRow row;
    row.variant = variants[i];
    try {
      runs.push_back(pathgen::generatePath(variant_job));
      // Timings: the median of `repeats` runs (the machine may be shared); the path is the first.
      std::vector<pathgen::StageTimes> times = {runs.back().times};
      variant_job.progress = {};
      variant_job.keep_voxels = false;
      for (int k = 1; k < request.repeats; ++k)
        times.push_back(pathgen::generatePath(variant_job).times);
      runs.back().times = medianTimes(times);
      row.times = runs.back().times;
      row.total_s = row.times.field_s + row.times.steering_s;
      row.min_clearance_mm = runs.back().clearance.min_clearance_mm;
      row.colliding = runs.back().clearance.colliding;
      row.max_tilt_deg = runs.back().max_tilt_deg;
      row.solver_steps = runs.back().solver_steps;
      row.rhs_evals = runs.back().rhs_evals;
    } catch (const InputError& e) {
      // An approximate field may steer the axis out of the scene's limits: that is a result.
      if (variants[i].mode == pathgen::FieldMode::Direct) throw;
      row.failure = e.what();
      row.times = {kNaN, kNaN, kNaN, kNaN, kNaN};
      row.total_s = row.speedup_vs_brute = row.speedup_vs_direct = kNaN;
      row.path_speedup_vs_direct = kNaN;
      row.tilt_max_deg = row.tilt_rms_deg = row.tilt_middle_max_deg = kNaN;
      row.min_clearance_mm = row.max_tilt_deg = kNaN;
      runs.emplace_back();
    }
    result.rows.push_back(row);
    if (i < direct_row) continue;  // the brute-force row is measured with the direct one
    common::report(request.progress, run_end, "errors");
    if (i == direct_row) prepareErrors(runs[i]);
    for (std::size_t k = i == direct_row ? 0 : i; k <= i; ++k)
      measureErrors(result.rows[k], runs[k], runs[direct_row].reach_box_mm,
                    std::move(runs[k].voxels));
  }
  const pathgen::GenerateResult& direct_run = runs[direct_row];
  result.postures = direct_run.postures.size();
  result.tool_nodes = direct_run.tool_nodes;
  result.obstacle_points = direct_run.obstacle_points;
  result.path_length_mm = direct_run.path_length_mm;
  result.reach_box_cm3 = direct_run.reach_box_mm.volume() / 1000.0;

  // ---- speed-ups and tilt differences --------------------------------------------------------
  const double brute_total = request.brute_force ? result.rows[0].total_s : kNaN;
  const double direct_total = result.rows[direct_row].total_s;
  const double direct_path = result.rows[direct_row].times.steering_s;
  result.middle_pass = static_cast<int>(direct_run.passes.size()) / 2;
  for (const pathgen::GeneratedPosture& g : direct_run.postures)
    if (g.pass == result.middle_pass) result.tilt_s_mm.push_back(g.s_mm);
  for (std::size_t i = 0; i < result.rows.size(); ++i) {
    StudyRow& row = result.rows[i];
    if (!row.failure.empty()) {
      result.tilt_deg.emplace_back();
      continue;
    }
    row.speedup_vs_brute = brute_total / row.total_s;
    row.speedup_vs_direct = direct_total / row.total_s;
    row.path_speedup_vs_direct = direct_path / row.times.steering_s;
    const auto& postures = runs[i].postures;
    if (postures.size() != direct_run.postures.size())
      throw std::logic_error("study: " + row.variant.name() + " has " +
                             std::to_string(postures.size()) + " postures, direct " +
                             std::to_string(direct_run.postures.size()));
    double sum_sq = 0.0;
    std::vector<double> tilt;
    for (std::size_t k = 0; k < postures.size(); ++k) {
      const double d = std::abs(postures[k].tilt_rad - direct_run.postures[k].tilt_rad) * kRadToDeg;
      row.tilt_max_deg = std::max(row.tilt_max_deg, d);
      sum_sq += d * d;
      if (postures[k].pass != result.middle_pass) continue;
      tilt.push_back(postures[k].tilt_rad * kRadToDeg);
      row.tilt_middle_max_deg = std::max(row.tilt_middle_max_deg, d);
    }
    row.tilt_rms_deg = postures.empty() ? 0.0 : std::sqrt(sum_sq / double(postures.size()));
    result.tilt_deg.push_back(std::move(tilt));
  }
  common::report(request.progress, 1.0, "done");
  return result;
}

// ---- outputs ------------------------------------------------------------------------------------

}  // namespace fieldpath::app
