/// `fieldpath generate SCENE [--direct | --voxel H] [--nominal] --out DIR`: the path of a scene,
/// passes joined by links (path.cl, path.apt, angles.csv, report.json), written only once the
/// whole job has succeeded.
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <string_view>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "commands.h"
#include "cutter_note.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/csv.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/field/voxel_field.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/units.h"
#include "generate_repairs.h"
#include "generate_report.h"
#include "job.h"
#include "json_text.h"
#include "obstacle_reach.h"
#include "path_report.h"
#include "progress.h"
#include "scene.h"

namespace fieldpath::app {
namespace {

using geometry::kRadToDeg;

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

/// A nominal path whose axes lean along the feed by more than this (deg) gets a note: the
/// steering starts from path.lead_deg, not from the file's lead.
constexpr double kNoteLeanDeg = 1.0;

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
    if (const std::string gouge = cutterGougeReason(result.path, result.cutter_part);
        !gouge.empty())
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
    if (const std::string stray = rotaryWarning(result.path, rotary, result.motions);
        !stray.empty())
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
                     job.nominal ? "the path is written" : "the steering starts",
                     job.path.lead_deg);
    }
    if (!result.settled_starts.empty() && job.dynamics.start == dynamics::StartPolicy::Auto)
      std::fprintf(
          stderr,
          "note: %zu pass%s (first: pass %d) started from the axis settled under the field "
          "at %s start: %s nominal start posture was within `clearance` of an obstacle "
          "(dynamics.start: auto; `nominal` starts there and collides)\n",
          result.settled_starts.size(), result.settled_starts.size() == 1 ? "" : "es",
          result.settled_starts.front() + 1, result.settled_starts.size() == 1 ? "its" : "their",
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
                   result.corners_held.front() + 1,
                   result.corners_held.size() == 1 ? "its" : "their", pathgen::kNoteAxisTurnDeg);
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
  });
}

}  // namespace fieldpath::app
