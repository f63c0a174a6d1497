/// fieldpath study SCENE --voxels 2,1,0.5 --out DIR: speed against error of the voxel field
/// (seed 004 Tables 1–2, Figs. 5–6); the work is in study.h.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <sstream>
#include <string>

#include "commands.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/field/voxel_field.h"
#include "job.h"
#include "progress.h"
#include "scene.h"
#include "study.h"
#include "study_text.h"

namespace fieldpath::app {
namespace {

struct StudyOptions {
  std::string scene;
  std::string voxels = "2,1,0.5";
  std::string interpolations = "trilinear,quadratic";
  std::string stored = "force,plane_ratio";
  std::string refine;  ///< percent per voxel size; empty: no refined variants
  int refine_levels = 2;
  std::string refine_regions = "path";
  std::string backends;         ///< "": voxel nodes built once (auto), names unchanged
  double sample_step_mm = 0.0;  ///< > 0: overrides the scene's field.sample_step
  bool no_brute_force = false;
  double line_step_mm = 0.05;
  int repeats = 1;
  std::string out;
};

void run(const StudyOptions& o, const GlobalOptions& global, const std::string& command_line) {
  common::checkOutputDirectory(o.out, "--out");  // before the work, not after
  // The options' values first: one refused leaves the folder as it was, as the parser's
  // refusals do (a bad --voxels after a good study took its 7 files away: a study sweep's).
  StudyRequest request;
  request.voxel_sizes_mm = parseVoxelSizes(o.voxels, "--voxels");
  request.interpolations = parseInterpolations(o.interpolations, "--interp");
  request.stored = parseStored(o.stored, "--stored");
  if (!o.refine.empty())
    request.refine_tolerances =
        parseRefineTolerances(o.refine, request.voxel_sizes_mm.size(), "--refine");
  request.refine_levels = o.refine_levels;
  request.refine_regions = parseRefineRegions(o.refine_regions, "--refine-region");
  if (!o.backends.empty()) request.backends = parseBackends(o.backends, "--backend");
  // Said before the direct variants run, not after them.
  for (field::FieldBackend backend : request.backends)
    if (backend == field::FieldBackend::Cuda && !field::cudaFieldBackendAvailable())
      throw InputError(
          "--backend: cuda, but this program was built without CUDA or no GPU is present");
  request.brute_force = !o.no_brute_force;
  request.line_step_mm = o.line_step_mm;
  request.repeats = o.repeats;
  // A failed or interrupted study takes the earlier one's files away too (they stayed, read by a
  // script that did not look at the exit code as this run's), as generate, check and simulate do.
  common::claimOutputs(o.out,
                       {"study.csv", "lines.csv", "tilt.csv", "study.md", "speed_vs_error.png",
                        "force_error_lines.png", "tilt_along_path.png"},
                       {o.scene});  // never the scene (`study out/study.md --out out` removed it)
  common::removeEarlierOutputs();
  const Scene scene = loadScene(o.scene);
  if (!scene.impeller_model || !scene.guide_impeller)
    throw InputError(
        scene.file.string() +
        ": guide: study runs on the parametric impeller (`guide: { impeller: hub }` "
        "with `- impeller:` among the obstacles): its lines a and b cross its channel");
  request.job = sceneJob(scene);
  request.impeller = scene.impeller_model->params();
  if (o.sample_step_mm > 0.0) request.job.field.sample_step_mm = o.sample_step_mm;
  // What the options drive, estimated before any work (loadScene did the scene's own keys).
  if (o.sample_step_mm > 0.0)
    checkSampleStep(scene, o.sample_step_mm, "--sample-step", common::MemoryUse::kPassing);
  for (double h : request.voxel_sizes_mm)
    checkVoxelSize(scene, h, "--voxels " + study_detail::number(h));
  request.progress = makeProgressLine(global.quiet);
  const StudyResult result = runStudy(request);
  const std::filesystem::path dir = o.out;
  writeStudy(result, dir, command_line, "");
  // The plots are redrawn from this run's tables, or not at all (no matplotlib): never an earlier
  // run's beside them.
  common::removeStaleOutputs(
      dir, {"speed_vs_error.png", "force_error_lines.png", "tilt_along_path.png"});
  std::string message;
  if (!plotStudy(dir, &message)) {
    std::fprintf(stderr, "fieldpath study: %s\n", message.c_str());
    // study.md names the pictures: said there too that they are not (a study sweep's).
    std::ifstream in(dir / "study.md", std::ios::binary);
    std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    common::writeTextAtomically(dir / "study.md",
                                text + "\n**The pictures named above are not made:** " + message +
                                    " (the tables hold their data).\n");
  }
  common::commitOutputs();  // a summary lost from here takes none of them away

  std::printf("%-38s %10s %9s %9s %9s %9s %10s %9s\n", "variant", "nodes", "total_s", "x_direct",
              "lines_%", "nodes_%", "tilt_deg", "clear_mm");
  // An error over no counted point is "–", as in study.md (it read 0.000: a reviewer's).
  const auto percent = [](std::initializer_list<const field::FieldError*> errors) {
    double worst = -1.0;
    for (const field::FieldError* e : errors)
      if (e->count > 0) worst = std::max(worst, e->max_relative);
    char text[32];
    if (worst < 0.0) return std::string("–");
    std::snprintf(text, sizeof text, "%.3f", 100 * worst);
    return std::string(text);
  };
  bool under = false;
  for (const StudyRow& row : result.rows) {
    const bool this_under = underClearance(row, result.clearance_mm);
    under = under || this_under;
    std::printf("%-38s %10zu %9.3f %9.2f %9s %9s %10.4f %9.3f%s\n", row.variant.name().c_str(),
                row.active_nodes, row.total_s, row.speedup_vs_direct,
                percent({&row.line_a.relative, &row.line_b.relative}).c_str(),
                percent({&row.nodes.relative}).c_str(), row.tilt_max_deg, row.min_clearance_mm,
                this_under ? " *" : "");
  }
  if (under)
    std::printf("* its path went under the required clearance (%.3f mm) or collided\n",
                result.clearance_mm);
  std::printf("study: %s\n", (dir / "study.md").string().c_str());
}

}  // namespace

void addStudyCommand(CLI::App& app, const GlobalOptions& global) {
  auto options = std::make_shared<StudyOptions>();
  auto* cmd = app.add_subcommand(
      "study", "Speed against error of the voxel field on the impeller job (seed 004 Tables 1-2)");
  cmd->add_option("scene", options->scene, "Scene file (YAML) with the impeller")->required();
  cmd->add_option("--voxels", options->voxels, "Voxel sizes, mm, comma-separated")
      ->capture_default_str();
  cmd->add_option("--interp", options->interpolations,
                  "Interpolations: trilinear, quadratic or both, comma-separated")
      ->capture_default_str();
  cmd->add_option("--stored", options->stored,
                  "What voxel nodes store: force, plane_ratio or both, comma-separated")
      ->capture_default_str();
  cmd->add_option("--refine", options->refine,
                  "Refinement tolerances, %, one per voxel size (0: none): adds a refined "
                  "trilinear variant of that size per stored quantity (a size listed twice, "
                  "e.g. --voxels 0.5,0.5 --refine 0.5,1, is refined to both, its uniform "
                  "variants made once)");
  cmd->add_option("--refine-levels", options->refine_levels,
                  "Levels below the voxel size the refined variants may go")
      ->capture_default_str();
  cmd->add_option("--refine-region", options->refine_regions,
                  "Where the refined variants split cells: path (near the path steered on the "
                  "uniform grid first, as generate does), reach (everywhere tool + holder can "
                  "reach) or both, comma-separated")
      ->capture_default_str();
  cmd->add_option("--backend", options->backends,
                  "Voxel node builds, comma-separated (auto, cpu, cuda, reference): each voxel "
                  "variant runs once per build, e.g. reference,cpu puts the old per-node build "
                  "beside the block build (default: once, auto)");
  cmd->add_option("--sample-step", options->sample_step_mm,
                  "Obstacle sampling step, mm, instead of the scene's field.sample_step")
      ->check(positiveFinite("mm"));
  cmd->add_flag("--no-brute-force", options->no_brute_force,
                "Skip the every-point direct sum (slow on large scenes)");
  // Bounded: 1e-8 sampled each line with 2 points unsaid, 1e-5 ran for minutes unestimated, and
  // a billion repeats ran until killed (a helper's).
  cmd->add_option("--line-step", options->line_step_mm, "Sampling of the study lines, mm")
      ->check(numberFromTo(0.001, 10.0, "mm"))
      ->capture_default_str();
  cmd->add_option("--repeat", options->repeats, "Runs per variant; times are their medians")
      ->check(numberFromTo(1, 100, ""))
      ->capture_default_str();
  cmd->add_option("--out", options->out, "Output folder")->required();
  cmd->callback([options, &global] {
    std::ostringstream line_step, sample_step;
    line_step << options->line_step_mm;
    sample_step << options->sample_step_mm;
    std::string command_line =
        "fieldpath study " + options->scene + " --voxels " + options->voxels + " --interp " +
        options->interpolations + " --stored " + options->stored +
        (options->refine.empty() ? std::string()
                                 : " --refine " + options->refine + " --refine-levels " +
                                       std::to_string(options->refine_levels) +
                                       " --refine-region " + options->refine_regions) +
        (options->sample_step_mm > 0.0 ? " --sample-step " + sample_step.str() : std::string()) +
        (options->backends.empty() ? std::string() : " --backend " + options->backends) +
        (options->no_brute_force ? " --no-brute-force" : "") + " --repeat " +
        std::to_string(options->repeats) + " --line-step " + line_step.str() + " --out " +
        options->out;
    run(*options, global, command_line);
  });
}

}  // namespace fieldpath::app
