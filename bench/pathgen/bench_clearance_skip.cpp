/// bench_clearance_skip: the two checks of a dense job that report a minimum and contacts, not
/// each posture's figure, with their exhaustive peers measured in the same run:
///   - the balls (generate's first check: every pass station's ball clear of the obstacles):
///     ballClearance over every station against ballClearance exact below the scene's clearance;
///   - the holder against the part: check() of every posture against exact_min_only.
/// The impeller example's passes resampled every --step mm (0.01: ~70k stations), nominal axes.
/// Reports medians over --repeats runs, the ratio to the exhaustive run, and the differences
/// (minimum, its station or posture, colliding count): all must be zero.
/// Usage: bench_clearance_skip [--scene FILE] [--step MM] [--repeats N]
/// Results of record: bench/results/pathgen.md ("Checks of dense jobs").
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "fieldpath/common/stats.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/passes.h"
#include "job.h"
#include "scene.h"

using namespace fieldpath;

using common::medianSeconds;

int main(int argc, char** argv) {
  std::string scene_file = std::string(FIELDPATH_SOURCE_DIR) + "/examples/impeller/scene.yaml";
  double step_mm = 0.01;
  int repeats = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scene" && i + 1 < argc)
      scene_file = argv[++i];
    else if (a == "--step" && i + 1 < argc)
      step_mm = std::atof(argv[++i]);
    else if (a == "--repeats" && i + 1 < argc)
      repeats = std::max(1, std::atoi(argv[++i]));
    else {
      std::fprintf(stderr,
                   "usage: bench_clearance_skip [--scene FILE] [--step MM] [--repeats N]\n");
      return 1;
    }
  }
  app::Scene scene = app::loadScene(scene_file);
  scene.path.step_mm = step_mm;
  scene.path.step_given = true;
  const pathgen::GenerateRequest job = app::sceneJob(scene);
  if (!job.part) {
    std::fprintf(stderr, "bench_clearance_skip: the scene has no part\n");
    return 1;
  }
  const double r = job.tool.radius_mm;
  std::vector<geometry::Vec3> centres;
  for (const pathgen::Pass& pass : job.passes)
    for (const pathgen::PassSample& s : pass.samples) centres.push_back(s.centre_mm);
  const std::vector<geometry::Posture> postures =
      pathgen::nominalPostures(job.passes, job.path.lead_deg * M_PI / 180.0, r);

  // The balls: every station's centre against the obstacles.
  const pathgen::ClearanceChecker obstacles(
      geometry::toolMesh(job.tool, job.holder, pathgen::clearanceMeshTolMm(job.tool, job.holder)),
      job.obstacles, pathgen::clearanceMeshTolMm(job.tool, job.holder));
  pathgen::BallResult all, skip;
  const double balls_all_s = medianSeconds(
      repeats, [&] { all = obstacles.ballClearance(centres, pathgen::BallRequest{r}); });
  const double balls_skip_s = medianSeconds(repeats, [&] {
    skip = obstacles.ballClearance(centres, pathgen::BallRequest{r, job.clearance_mm});
  });

  // The holder against the part at every posture.
  const pathgen::ClearanceChecker holder(
      geometry::holderMesh(job.tool, job.holder, pathgen::clearanceMeshTolMm(job.tool, job.holder)),
      std::span(&*job.part, 1), pathgen::clearanceMeshTolMm(job.tool, job.holder));
  pathgen::ClearanceRequest only_min;
  only_min.exact_min_only = true;
  pathgen::ClearanceResult every, some;
  const double holder_all_s = medianSeconds(repeats, [&] { every = holder.check(postures); });
  const double holder_skip_s =
      medianSeconds(repeats, [&] { some = holder.check(postures, only_min); });

  std::printf(
      "%s, passes every %g mm: %zu stations on %zu passes; %d repeats (median), %u "
      "hardware threads\n\n",
      scene_file.c_str(), step_mm, centres.size(), job.passes.size(), repeats,
      std::max(1u, std::thread::hardware_concurrency()));
  std::printf(
      "| check | every posture s | skipping s | ratio | min, every / skipping (mm) | "
      "at, every / skipping | colliding, every / skipping |\n");
  std::printf("|---|---:|---:|---:|---|---|---|\n");
  // The balls' minimum is exact only under the clearance: above it the skipping run says so.
  std::printf(
      "| balls (exact under %g mm) | %.3f | %.3f | %.1f | %.6f / %.6f%s | %zu / %zu | - |\n",
      job.clearance_mm, balls_all_s, balls_skip_s, balls_all_s / balls_skip_s, all.min_mm,
      skip.min_mm, all.min_mm < job.clearance_mm ? "" : " (above: a bound)", all.at, skip.at);
  std::printf("| holder vs part | %.3f | %.3f | %.1f | %.6f / %.6f | %zu / %zu | %zu / %zu |\n",
              holder_all_s, holder_skip_s, holder_all_s / holder_skip_s, every.min_clearance_mm,
              some.min_clearance_mm, every.min_index, some.min_index, every.colliding,
              some.colliding);
  const bool same =
      (all.min_mm >= job.clearance_mm ? skip.min_mm >= job.clearance_mm && skip.min_mm <= all.min_mm
                                      : skip.min_mm == all.min_mm && skip.at == all.at) &&
      every.min_clearance_mm == some.min_clearance_mm && every.min_index == some.min_index &&
      every.colliding == some.colliding && every.first_colliding == some.first_colliding;
  std::printf("\nsame answers: %s\n", same ? "yes" : "NO");
  return same ? 0 : 2;
}
