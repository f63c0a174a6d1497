/// `fieldpath generate SCENE [--direct | --voxel H] [--nominal] --out DIR`: the path of a scene,
/// passes joined by links (path.cl, path.apt, angles.csv, report.json), written only once the
/// whole job has succeeded.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <span>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "commands.h"
#include "cutter_note.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/geometry/cl_file.h"
#include "generate_messages.h"
#include "generate_report.h"
#include "job.h"
#include "json_text.h"
#include "obstacle_reach.h"
#include "path_report.h"
#include "progress.h"
#include "scene.h"

namespace fieldpath::app {
namespace {

/// The files `check --out` and `simulate --out` write, by the report that names their path.
struct ResultsOfAPath {
  const char* report;  ///< holds path_digest: the path file they are of
  std::span<const char* const> files;
  const char* what;
};
constexpr const char* kCheckFiles[] = {"check.json", "clearance.csv", "deviation.npy",
                                       "deviation.json", "deviation.png"};
constexpr const char* kSimulateFiles[] = {"simulate.json", "heights.npy", "heights.json",
                                          "surface.stl", "heights.png"};
constexpr ResultsOfAPath kResultsOfAPath[] = {{"check.json", kCheckFiles, "check"},
                                              {"simulate.json", kSimulateFiles, "simulation"}};

/// The results in `out` that are of the path.cl or path.apt this run replaces (their report's
/// path_digest is the file's): check.json's `"ok": true`, deviation.png and clearance.csv stayed
/// beside a new path nobody had checked, heights.npy beside one nobody had simulated (helpers'
/// findings). Results of another path, or ones that cannot be read, are not listed. Decided
/// before the earlier path is removed; removed by forgetResults once the scene is read.
struct StaleResults {
  struct Group {
    const ResultsOfAPath* kind;
    std::filesystem::path of;  ///< the path file they are of (out/path.cl or out/path.apt)
  };
  std::vector<Group> groups;
};
StaleResults resultsOfReplacedPath(const std::filesystem::path& out) {
  namespace fs = std::filesystem;
  StaleResults stale;
  for (const ResultsOfAPath& kind : kResultsOfAPath) {
    std::error_code ec;
    const fs::path report = out / kind.report;
    if (!fs::is_regular_file(report, ec)) continue;
    try {
      std::ifstream in(report);
      const std::string digest = nlohmann::json::parse(in).value("path_digest", std::string());
      for (const char* name : {"path.cl", "path.apt"})
        if (!digest.empty() && fs::is_regular_file(out / name, ec) &&
            digest == common::fileDigest(out / name)) {
          stale.groups.push_back({&kind, out / name});
          break;
        }
    } catch (const std::exception&) {
      // not theirs, or a path that cannot be read: left as it is
    }
  }
  return stale;
}

/// Removes `stale` (never a file the run reads: removeStaleOutputs) once the scene is read and
/// the run may write its folder: a scene whose part was the earlier simulation's surface.stl lost
/// it before it was read, and a run refused for replacing its own input had taken 10 result
/// files of the path it kept (a reviewer's). `failed`: the run failed before writing its path;
/// the results go only where the path they are of went (taken away as the run's claimed output).
void forgetResults(const std::filesystem::path& out, const StaleResults& stale, bool failed) {
  for (const StaleResults::Group& group : stale.groups) {
    std::error_code ec;
    if (failed && std::filesystem::exists(group.of, ec)) continue;
    common::removeStaleOutputs(out, group.kind->files);
    std::fprintf(stderr, "note: %s: the %s of the path this run replaces is removed with it\n",
                 out.string().c_str(), group.kind->what);
  }
}

/// forgetResults(failed) where the run leaves its scope by an exception, until disarmed.
struct ForgetResultsOnFailure {
  const std::filesystem::path out;
  const StaleResults& stale;
  bool armed = true;
  const int uncaught = std::uncaught_exceptions();
  ~ForgetResultsOnFailure() {
    if (!armed || std::uncaught_exceptions() <= uncaught) return;
    try {
      forgetResults(out, stale, /*failed=*/true);
    } catch (const std::exception&) {  // (a file that cannot be removed: the run's error stands)
    }
  }
};

}  // namespace

void addGenerateCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "generate",
      "Generate the path of a scene: passes from its nominal path (path.nominal) or the "
      "parametric impeller's hub, tool axis steered by the repulsive field (CVODE), passes "
      "joined by links, every posture and motion checked (FCL). Writes path.cl, path.apt, "
      "angles.csv, report.json");
  struct Options {
    std::string scene, out;
    bool direct = false, nominal = false, fail_unsafe = false;
    double voxel_mm = 0.0;
    std::string backend;  ///< "": the scene's field.backend
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("scene", options->scene, "Scene file (YAML)")->required();
  auto* direct =
      cmd->add_flag("--direct", options->direct, "Exact field (radius search), no voxels");
  auto* voxel = cmd->add_option("--voxel", options->voxel_mm,
                                "Voxel size H, mm (default: the scene's field.voxel_size)")
                    ->check(positiveFinite("mm"));
  direct->excludes(voxel);
  cmd->add_option("--backend", options->backend,
                  "Where the voxel nodes are computed: auto | cpu | cuda | reference (the "
                  "per-node build the others are checked against; default: the scene's "
                  "field.backend)")
      ->check(CLI::IsMember({"auto", "cpu", "cuda", "reference"}))
      ->excludes(direct);
  // The field's options mean nothing without a field: refused, not ignored (a --voxel 1e9 beside
  // --nominal ran and wrote a reach box of 2e9 mm in report.json).
  cmd->add_flag("--nominal", options->nominal,
                "The nominal path: axis on the hub normal (+ lead), no field, no dynamics")
      ->excludes(direct)
      ->excludes(voxel)
      ->excludes("--backend");
  cmd->add_option("--out", options->out, "Output folder")->required();
  cmd->add_flag("--fail-unsafe", options->fail_unsafe,
                "Exit 3 when path.cl is marked UNSAFE TO RUN (the outputs written all the same), "
                "so that `generate ... --fail-unsafe && post` stops");
  cmd->callback([options, &global] {
    common::checkOutputDirectory(options->out, "--out");  // before the work, not after
    // Claimed before the scene is read (a refused scene takes the earlier run's path away), but
    // never the scene's own files (a nominal path.cl in --out).
    common::claimOutputs(options->out, {"path.cl", "path.apt", "angles.csv", "report.json"},
                         {options->scene, nominalPathOf(options->scene)});
    const StaleResults stale = resultsOfReplacedPath(options->out);
    ForgetResultsOnFailure on_failure{options->out, stale};
    common::removeEarlierOutputs();
    // Reading (the scene, its meshes, the nominal path, the passes) is counted apart: the job's
    // total left out 9 s of a 70 MB STL (a helper's).
    const auto read_start = std::chrono::steady_clock::now();
    const Scene scene = loadScene(options->scene);
    common::refuseOutputsOverInputs(options->out,
                                    {"path.cl", "path.apt", "angles.csv", "report.json"}, "--out");
    on_failure.armed = false;  // (an exception from here on finds them gone already)
    forgetResults(options->out, stale, /*failed=*/false);
    requirePostures(scene, common::MemoryUse::kKept);  // held to the end (the field after them)
    pathgen::GenerateRequest job = sceneJob(scene);
    const double read_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - read_start).count();
    job.mode = options->direct ? pathgen::FieldMode::Direct : pathgen::FieldMode::Voxel;
    // 0: not given (positiveFinite rejects anything else that is not > 0).
    if (options->voxel_mm != 0.0) job.field.voxel.voxel_size_mm = options->voxel_mm;
    if (job.mode == pathgen::FieldMode::Voxel && !options->nominal) {
      const char* key = options->voxel_mm != 0.0 ? "--voxel" : "field.voxel_size";
      const double h = job.field.voxel.voxel_size_mm, r0 = scene.field.r0_mm;
      checkVoxelSize(scene, h, key);
      // Allowed up to r0, but coarse grids steer by a field far from eq. 1 (a channel uniform
      // along x read 16.5 deg of lead at h 3.3, r0 5, against 1.4 direct: a helper's finding).
      if (h > 0.2 * r0)
        std::fprintf(stderr,
                     "note: %s %g mm is coarse against field.r0 (%g mm): the interpolated field "
                     "is off by up to 100 %% near the obstacles (the impeller's study: 106 %% at "
                     "r0 / 2.5, 5.4 %% at r0 / 5); for the path's accuracy use h <= r0 / 5 or "
                     "--direct\n",
                     key, h, r0);
    }
    if (!options->backend.empty())
      job.field.voxel.backend = *field::fieldBackendNamed(options->backend);
    job.nominal = options->nominal;
    job.progress = makeProgressLine(global.quiet);
    // CUDA's start-up (the device's context: 0.2-0.3 s on the GPU machine) on a thread while the
    // obstacles are sampled and the build's host work begins; the build's first use of the device
    // waits for it (once per process). Only where the voxel build may take the GPU.
    const field::FieldBackend wanted = job.field.voxel.backend;
    std::future<bool> cuda_start;
    if (job.mode == pathgen::FieldMode::Voxel && !job.nominal &&
        (wanted == field::FieldBackend::Auto || wanted == field::FieldBackend::Cuda))
      cuda_start = std::async(std::launch::async, field::cudaFieldBackendAvailable);
    // The job's errors name a scene key or a pass; the scene file says where to look.
    pathgen::GenerateResult result = [&] {
      try {
        return pathgen::generatePath(job);
      } catch (const InputError& e) {
        const std::string file = scene.file.string();
        if (std::string_view(e.what()).starts_with(file)) throw;
        const std::string placed = placeSceneKey(e.what());  // a key's line, where it names one
        throw InputError(placed != e.what() ? placed : file + ": " + e.what());
      }
    }();

    // Every output is computed; now write them (each atomically).
    const std::filesystem::path out = options->out;
    const std::string what = job.nominal ? "nominal path" : "field path";
    // A path that collides is still written (to look at, and `check`), marked in both files.
    const bool unsafe_any = !unsafeReasons(result.path, result.clearance, result.motions,
                                           result.link_part, result.holder_part)
                                 .empty();
    // Clear of the obstacles but closer than the scene's `clearance`: said where the machine
    // reads it too (report.json's "safe" stays true: nothing is touched), beside the UNSAFE mark
    // when the path is unsafe for another reason (the holder into the part: fixing that alone
    // left the clearance unsaid, a helper's finding); an obstacle touched says it already.
    const bool under_required =
        result.clearance.colliding == 0 && result.motions.colliding == 0 &&
        (result.clearance.min_clearance_mm < job.clearance_mm || result.motions.under_required > 0);
    std::string under_text;
    if (under_required) {
      char text[300];
      // Where the ball itself runs within clearance no axis helps: said here, where the steering
      // would be blamed (a helper's pocket offsets 3.5 mm from the walls: the ball 0.4999 off).
      std::snprintf(text, sizeof text,
                    "UNDER THE REQUIRED CLEARANCE: postures min %.3f mm, motions min >= %.3f mm, "
                    "required %.3f mm%s (report.json)",
                    result.clearance.min_clearance_mm, result.motions.min_clearance_mm,
                    job.clearance_mm,
                    result.balls_under_clearance.empty()
                        ? ""
                        : "; the ball itself runs within it in some passes, whatever the axis "
                          "(balls_under_clearance)");
      under_text = text;
    }
    const std::string about = "fieldpath generate " + scene.file.string() + " (" + what +
                              "): x y z i j k, tool tip and axis, mm\n"
                              "`# pass K` blocks are cut at the feed, `# link` blocks are rapid "
                              "moves between them; `# limit`: an angle limit held there";
    // Every message names a posture's line in path.cl, as check's do of the file it reads (a
    // user of generate's "posture 5123" counted through the file): the lines the writer gives
    // them, the marks one line each whatever their text.
    result.path.file = "path.cl";
    result.path.rows = false;
    result.path.lines = geometry::clFileLines(
        result.path, unsafe_any + under_required + geometry::clCommentLines(about));
    const std::vector<std::string> unsafe =
        unsafeReasons(result.path, result.clearance, result.motions, result.link_part,
                      result.holder_part, kLinkHint);
    std::string unsafe_text;
    for (const std::string& reason : unsafe)
      unsafe_text += (unsafe_text.empty() ? "" : "; ") + reason;
    if (!unsafe.empty()) unsafe_text = "UNSAFE TO RUN: " + unsafe_text + " (report.json)";
    const std::string mark =
        unsafe_text + (!unsafe_text.empty() && !under_text.empty() ? "\n" : "") + under_text;
    geometry::writeClFile(out / "path.cl", result.path, (mark.empty() ? "" : mark + "\n") + about);
    geometry::AptHeader header;
    for (const std::string& reason : unsafe) header.remarks.push_back("UNSAFE TO RUN: " + reason);
    if (!under_text.empty()) header.remarks.push_back(under_text);
    header.part_name = scene.file.stem().string();
    for (char& c : header.part_name)
      c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
    header.tool = job.tool;
    header.feed_mm_per_min = job.dynamics.feed_mm_per_min;
    geometry::writeAptFile(out / "path.apt", result.path, header);
    common::writeTextAtomically(out / "angles.csv", anglesCsv(result));
    const pathgen::AxisTurn axis_turn = pathgen::largestAxisTurn(result.path, job.tool.radius_mm);
    JobNotes notes;
    if (scene.nominal) notes.tool = cutterNotes(scene.tool, *scene.nominal);
    if (std::string holder = noHolderNote(scene.tool, scene.holder); !holder.empty())
      notes.tool.push_back(std::move(holder));
    // The voxel size steered with (--voxel or the scene's); --direct and --nominal have none.
    notes.obstacle =
        openObstacleNotes(scene, job.mode == pathgen::FieldMode::Voxel && !options->nominal
                                     ? std::optional<double>(job.field.voxel.voxel_size_mm)
                                     : std::nullopt);
    if (std::string reach = obstaclesOutOfReachNote(
            scene, obstaclesOutOfReach(scene, result.path, scene.field.r0_mm), scene.field.r0_mm);
        !reach.empty() && !options->nominal)  // (--nominal: nothing steers)
      notes.obstacle.push_back(std::move(reach));
    if (std::string far = farLinkNote(scene, result); !far.empty())
      notes.link.push_back(std::move(far));
    nlohmann::json report = reportJson(scene, job, result, axis_turn, notes);
    const pathgen::RotaryStray rotary =
        pathgen::rotaryStray(result.path.postures, result.motions, job.clearance_mm);
    report["rotary_angles"] = rotaryJson(rotary, result.motions.tool_reach_mm);
    const pathgen::DogLegRapids dog_leg =
        pathgen::dogLegRapids(result.path, result.motions, job.clearance_mm);
    report["dog_leg_rapids"] = dogLegJson(dog_leg);
    // What loading the meshes mended or turned, and the warnings of their scale (said at load:
    // not said again with the notes at the end, a reviewer's).
    std::vector<std::string> mesh_notes = scene.mesh_notes;
    for (const MeshScaleWarning& warning : scene.scale_warnings)
      mesh_notes.push_back("WARNING: " + warning.text);
    report["mesh_notes"] = mesh_notes;
    // `total` as the summary line's, reading included (the stages read 1.0746 s against a total
    // of 1.0699: reading was outside it; a claims audit's).
    report["times_s"]["read"] = read_s;
    report["times_s"]["total"] = read_s + result.times.total_s;
    report["times_note"] =
        "total: read + setup + field + steering + clearance (and the path's writing between "
        "them); field_near_path is part of field";
    // The files this report is of (written before it, renamed one by one): a folder holding
    // another run's path beside this report can be told (as check.json's path_digest).
    report["path_digest"] = {{"path.cl", common::fileDigest(out / "path.cl")},
                             {"path.apt", common::fileDigest(out / "path.apt")}};
    common::writeTextAtomically(out / "report.json", jsonText(report));
    common::commitOutputs();  // a summary or note lost from here takes none of them away

    const auto& c = result.clearance;
    const auto& m = result.motions;
    std::printf(
        "%s: %zu postures on %zu pass%s (%.1f mm) + %zu link postures; max tilt %.2f deg, max "
        "lead %.2f deg, %zu postures held at a limit; min clearance %.3f mm (required %.3f), "
        "%zu colliding postures, %zu colliding motions (of %zu, min >= %.3f mm); %.2f s "
        "(%.2f s reading) -> %s\n",
        what.c_str(), result.postures.size(), result.passes.size(),
        result.passes.size() == 1 ? "" : "es", result.path_length_mm, result.link_postures,
        result.max_tilt_deg, result.max_lead_deg, result.limited_postures, c.min_clearance_mm,
        job.clearance_mm, c.colliding, m.colliding, m.motions, m.min_clearance_mm,
        read_s + result.times.total_s, read_s, out.string().c_str());
    if (!unsafe.empty()) std::fprintf(stderr, "warning: %s\n", unsafe_text.c_str());
    if (const std::string limits =
            limitsAtCollisionsNote(result, job.dynamics.max_lead_deg, job.dynamics.max_tilt_deg);
        !limits.empty())
      std::fprintf(stderr, "note: %s\n", limits.c_str());
    if (options->fail_unsafe && !unsafe.empty()) verdictExitCode() = kVerdictExitCode;
    printJobMessages(scene, job, result, {axis_turn, rotary, dog_leg, notes, under_required});
  });
}

}  // namespace fieldpath::app
