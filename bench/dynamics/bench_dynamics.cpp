/// bench_dynamics: the tool-axis dynamics on the seed's test case (seed 004 §2.3): 7 passes, ≈500
/// mm of path, ≈500 tool + holder nodes, two twisted walls of ≈5100 obstacle samples
/// (bench/field/walls.h). Prints markdown tables: per field and integrator, the median wall time of
/// the whole path over repeated runs, solver work (steps, RHS evaluations per mm, Jacobians), time
/// per RHS evaluation, the speed ratio against the direct field with BDF measured in the same run,
/// and the error of every variant's angles against the reference (direct field, BDF, tolerances /
/// 100).
///   bench_dynamics [--repeats N] [--quick] [--gain G] [--outer-y MM]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <tbb/info.h>

#include "../field/walls.h"
#include "fieldpath/common/stats.h"
#include "fieldpath/dynamics/steering.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/geometry/tool_model.h"

using namespace fieldpath;
using geometry::Vec3;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr int kPasses = 7;
constexpr double kPassHalfLength = 36.0;  ///< x ∈ [-36, 36]: 7 × 72 = 504 mm
constexpr double kBallRadius = 3.0;

using common::median;

/// Pass k of 7 along +x on the channel floor (z = 0), ball centre at y from -outer to +outer mm.
/// The walls lean in over x < 0: with outer = 8 the upright shank of the outer passes starts 0.4 mm
/// into the top of a wall (inside the voxel field's inner band) and is pushed out.
dynamics::Pass channelPass(int k, double outer_y_mm) {
  const double y = -outer_y_mm + 2.0 * outer_y_mm * k / (kPasses - 1);
  return dynamics::Pass{2.0 * kPassHalfLength, [y](double s_mm) {
                          dynamics::PassFrame f;
                          f.centre_mm = Vec3(-kPassHalfLength + s_mm, y, kBallRadius);
                          f.feed = Vec3::UnitX();
                          f.normal = Vec3::UnitZ();
                          return f;
                        }};
}

struct PathRun {
  std::vector<dynamics::SteeringResult> passes;
  double seconds = 0.0;
  long rhs_evals = 0, steps = 0, jacobians = 0, failures = 0;
  std::string status;
  double max_tilt_deg = 0.0;
};

PathRun runPath(const dynamics::SteeringRequest& request, double outer_y_mm) {
  PathRun run;
  const auto start = std::chrono::steady_clock::now();
  for (int k = 0; k < kPasses; ++k)
    run.passes.push_back(dynamics::steerPass(channelPass(k, outer_y_mm), request));
  run.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  run.status = "ok";
  for (const auto& r : run.passes) {
    run.rhs_evals += r.stats.rhs_evals;
    run.steps += r.stats.steps;
    run.jacobians += r.stats.jacobian_evals;
    run.failures += r.stats.error_test_failures + r.stats.convergence_failures;
    if (r.status != dynamics::Status::Ok) run.status = dynamics::toString(r.status);
    for (const auto& s : r.samples)
      run.max_tilt_deg = std::max(run.max_tilt_deg, std::abs(s.tilt_rad) / kDeg);
  }
  return run;
}

/// Angle error against the reference over the samples both runs have (lead and tilt), degrees.
struct AngleError {
  double max_deg = 0.0, rms_deg = 0.0;
  int worst_pass = 0;
  double worst_s_mm = 0.0;
};

AngleError angleError(const PathRun& a, const PathRun& reference) {
  AngleError e;
  double sum2 = 0.0;
  long count = 0;
  for (std::size_t p = 0; p < a.passes.size(); ++p) {
    const auto& x = a.passes[p].samples;
    const auto& y = reference.passes[p].samples;
    for (std::size_t i = 0; i < std::min(x.size(), y.size()); ++i) {
      for (double d : {x[i].lead_rad - y[i].lead_rad, x[i].tilt_rad - y[i].tilt_rad}) {
        sum2 += d * d;
        ++count;
        if (std::abs(d) / kDeg > e.max_deg) {
          e.max_deg = std::abs(d) / kDeg;
          e.worst_pass = static_cast<int>(p);
          e.worst_s_mm = x[i].s_mm;
        }
      }
    }
  }
  e.rms_deg = count ? std::sqrt(sum2 / count) / kDeg : 0.0;
  return e;
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  bool quick = false;
  double gain = 5e-3;       // max tilt ≈ 8° on this path with k = 1
  double outer_y_mm = 8.0;  // see channelPass
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc) {
      repeats = std::max(1, std::atoi(argv[++i]));
    } else if (!std::strcmp(argv[i], "--gain") && i + 1 < argc) {
      gain = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--outer-y") && i + 1 < argc) {
      outer_y_mm = std::atof(argv[++i]);
    } else if (!std::strcmp(argv[i], "--quick")) {
      quick = true;
    } else {
      std::fprintf(stderr,
                   "usage: bench_dynamics [--repeats N] [--quick] [--gain G] [--outer-y MM]\n");
      return 1;
    }
  }

  // ---- scene ------------------------------------------------------------------------------------
  field::FieldParams field_params;  // r0 5, r_min 0.25, area weights
  field_params.sample_step_mm = 2.0;
  field_params.gain = gain;
  const std::vector<geometry::TriangleMesh> walls = {bench::twistedWall(+1.0, 3.7),
                                                     bench::twistedWall(-1.0, 3.7)};
  const field::ObstacleSamples samples =
      field::sampleObstacles(walls, field_params.sample_step_mm, field_params.weights);
  const field::DirectField direct(samples, field_params);
  const field::BruteForceField brute(samples, field_params);

  geometry::ToolSpec tool;  // ball R 3, shank to 50 mm (the walls are 45 mm high)
  tool.radius_mm = kBallRadius;
  tool.length_mm = 50.0;
  const geometry::HolderProfile holder = {{50.0, 6.0}, {65.0, 6.0}, {65.0, 12.0}, {100.0, 12.0}};
  const double node_spacing_mm = 3.3;
  std::vector<Vec3> nodes;
  for (const auto& n : geometry::surfaceNodes(tool, holder, node_spacing_mm))
    nodes.push_back(n.position_mm);

  dynamics::SteeringRequest request;
  request.nodes_tool_frame_mm = nodes;
  request.ball_radius_mm = kBallRadius;
  request.step_mm = 0.5;
  request.params.on_limit = dynamics::LimitPolicy::Clamp;  // every variant runs the whole path

  std::printf(
      "# bench_dynamics: %d passes, %.0f mm of path, %zu tool+holder nodes (spacing %.1f mm), "
      "%zu obstacle samples, gain %.1e, passes at |y| <= %.1f mm, output every %.1f mm, feed %.0f "
      "mm/min, "
      "%d threads, medians of %d runs\n\n",
      kPasses, kPasses * 2.0 * kPassHalfLength, nodes.size(), node_spacing_mm, samples.size(), gain,
      outer_y_mm, request.step_mm, request.params.feed_mm_per_min, tbb::info::default_concurrency(),
      repeats);

  // ---- fields
  // -------------------------------------------------------------------------------------
  struct Variant {
    std::string name;
    const field::ForceField* field;
    dynamics::Integrator integrator;
    int repeats;
  };
  std::vector<std::unique_ptr<field::VoxelField>> voxels;
  std::vector<Variant> variants = {
      {"direct (PointIndexGrid)", &direct, dynamics::Integrator::Bdf, repeats}};
  std::printf("| voxel field | build (s) | active nodes | memory (MiB) |\n|---|---|---|---|\n");
  for (double h : quick ? std::vector<double>{0.5} : std::vector<double>{1.0, 0.5, 0.25}) {
    for (auto interpolation : {field::Interpolation::Trilinear, field::Interpolation::Quadratic}) {
      if (quick && interpolation == field::Interpolation::Quadratic) continue;
      field::VoxelRequest vr;
      vr.voxel_size_mm = h;
      vr.interpolation = interpolation;
      vr.region_mm = bench::wallsRegion();
      voxels.push_back(std::make_unique<field::VoxelField>(direct, vr));
      const auto& st = voxels.back()->stats();
      char name[64];
      std::snprintf(name, sizeof name, "voxel h %.2f %s", h,
                    interpolation == field::Interpolation::Trilinear ? "trilinear" : "quadratic");
      std::printf("| %s | %.2f | %zu | %.1f |\n", name, st.build_seconds, st.active_nodes,
                  st.memory_bytes / 1048576.0);
      variants.push_back({name, voxels.back().get(), dynamics::Integrator::Bdf, repeats});
    }
  }
  variants.push_back({"direct, ERK (explicit peer)", &direct, dynamics::Integrator::Erk, repeats});
  if (!quick)
    variants.push_back({"brute force (seed's method)", &brute, dynamics::Integrator::Bdf, 1});

  // ---- reference ------------------------------------------------------------------------------
  dynamics::SteeringRequest tight = request;
  tight.field = &direct;
  tight.params.rtol /= 100.0;
  tight.params.atol /= 100.0;
  const PathRun reference = runPath(tight, outer_y_mm);

  std::printf("\n## Whole path (BDF = CVODE, dense Newton, DQ Jacobian; rtol %.0e, atol %.0e)\n\n",
              request.params.rtol, request.params.atol);
  std::printf(
      "| field, integrator | path (s) | × direct BDF | steps | RHS evals | RHS / mm | Jacobians | "
      "µs / RHS | status | max tilt (°) | max error (°) | at pass, s (mm) | RMS error (°) |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|---|---|\n");
  double direct_seconds = 0.0;
  for (const Variant& v : variants) {
    dynamics::SteeringRequest r = request;
    r.field = v.field;
    r.params.integrator = v.integrator;
    std::vector<double> times;
    PathRun run;
    for (int i = 0; i < v.repeats; ++i) {
      run = runPath(r, outer_y_mm);
      times.push_back(run.seconds);
    }
    const double t = median(times);
    if (direct_seconds == 0.0) direct_seconds = t;
    const double length_mm = kPasses * 2.0 * kPassHalfLength;
    const AngleError e = angleError(run, reference);
    std::printf(
        "| %s%s | %.3f | %.2f | %ld | %ld | %.1f | %ld | %.1f | %s | %.2f | %.1e | %d, %.1f | %.1e "
        "|\n",
        v.name.c_str(), v.integrator == dynamics::Integrator::Bdf ? ", BDF" : "", t,
        direct_seconds / t, run.steps, run.rhs_evals, run.rhs_evals / length_mm, run.jacobians,
        1e6 * t / run.rhs_evals, run.status.c_str(), run.max_tilt_deg, e.max_deg, e.worst_pass,
        e.worst_s_mm, e.rms_deg);
    std::fflush(stdout);
  }
  std::printf(
      "\nreference: direct field, BDF, rtol %.0e, atol %.0e: %ld RHS evals, status %s, max tilt "
      "%.2f°\n",
      tight.params.rtol, tight.params.atol, reference.rhs_evals, reference.status.c_str(),
      reference.max_tilt_deg);
  return 0;
}
