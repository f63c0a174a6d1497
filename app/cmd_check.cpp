/// `fieldpath check SCENE --path FILE [--out DIR]`: (a) exact clearance of tool + holder against
/// the obstacles (FCL) at every posture and along every motion between consecutive postures,
/// links included; (b) the Z-buffer simulation of the path over the scene's `part`, compared with
/// the part: gouge (below) and scallop (above), deviation.png. Exit 0 even when collisions are
/// found (they are reported); 1 on bad input.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "check_surface_report.h"
#include "commands.h"
#include "cutter_note.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/csv.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/input_file.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"
#include "fieldpath/pathgen/passes.h"
#include "fieldpath/zbuffer/outputs.h"
#include "json_text.h"
#include "path_report.h"
#include "progress.h"
#include "scene.h"
#include "surface_check.h"

namespace fieldpath::app {
namespace {

using nlohmann::json;

/// The links whose last posture is the next pass's first, where the ball cuts: their rapid move
/// ends on the part (a path written with no retract; generate refuses links.retract 0). The
/// links' part check takes such a posture for the pass's, so it said nothing of it (a machine
/// safety helper's finding). Returns (count, path index of the first such posture).
std::pair<std::size_t, std::size_t> rapidsOntoPasses(const geometry::PathFile& path) {
  std::size_t count = 0, first = 0;
  for (std::size_t k = 0; k + 1 < path.blocks.size(); ++k) {
    const geometry::PathBlock& link = path.blocks[k];
    const geometry::PathBlock& pass = path.blocks[k + 1];
    if (link.kind != geometry::PathBlock::Kind::Link ||
        pass.kind != geometry::PathBlock::Kind::Pass || link.size() == 0 || pass.size() == 0)
      continue;
    // The rapid into the link's last posture: from the posture before it (the link's own, or the
    // pass before when the link holds one), unless that is the same place (no move).
    const std::size_t end = link.end - 1;
    if (!geometry::samePose(path.postures[end], path.postures[pass.begin]) || end == 0 ||
        geometry::samePose(path.postures[end - 1], path.postures[end]))
      continue;
    // The pass written from the rapid's end, down the tool axis at feed (an engage: RAPID to a
    // point above the part, FEDRAT, the same point again, down): the ball does not cut there (a
    // CAM engineer's file read UNSAFE). Within kApproachDeg of the axis, as generate reads
    // approaches.
    std::size_t next = pass.begin + 1;
    while (next < pass.end && geometry::samePose(path.postures[next], path.postures[pass.begin]))
      ++next;
    if (next < pass.end) {
      const geometry::Vec3 step = path.postures[next].tip_mm - path.postures[pass.begin].tip_mm;
      if (path.postures[pass.begin].axis.dot(step) <=
          -std::cos(pathgen::kApproachDeg * geometry::kDegToRad) * step.norm())
        continue;
    }
    if (count++ == 0) first = end;
  }
  return {count, first};
}

/// The passes generate would take from the path as a nominal one: its pass blocks split at gaps
/// and turns (passRanges), a lone posture a gap parts from the rest of its block not counted (a
/// link's: a reviewer counted 5 for generate's 1).
std::size_t passesSplitAtGaps(const geometry::PathFile& path, const Scene& scene) {
  std::size_t n = 0;
  for (const auto& [begin, end] :
       pathgen::passRanges(path, scene.path.pass_gap_mm, scene.tool.radius_mm))
    n += end - begin >= 2;
  return n;
}

/// Per posture: block, clearance and the lower bound of the motion to the next one.
/// clearance.csv: a row a posture; the last two columns say where the links, the holder or the
/// cutter (beyond the gouge tolerance) touch
/// the part (1 / 0; empty when the scene has no part), at the posture and on the motion to the
/// next (`view --check` colours them).
std::string clearanceCsv(const geometry::PathFile& path, const pathgen::ClearanceResult& c,
                         const pathgen::MotionResult& m,
                         const std::optional<pathgen::PartContacts::Marks>& part) {
  std::ostringstream csv;
  csv.precision(9);
  csv << "posture,block,pass,clearance_mm,motion_to_next_mm,limited,part_contact,"
         "part_contact_to_next\n";
  std::size_t pass = 0, next_limited = 0;
  for (const geometry::PathBlock& block : path.blocks) {
    const bool is_pass = block.kind == geometry::PathBlock::Kind::Pass;
    pass += is_pass;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      while (next_limited < path.limited.size() && path.limited[next_limited] < i) ++next_limited;
      const bool limited = next_limited < path.limited.size() && path.limited[next_limited] == i;
      csv << i << ',' << (is_pass ? "pass" : "link") << ',';
      if (is_pass) csv << pass;
      csv << ',' << common::csvNumber(c.clearance_mm[i]) << ',';
      if (i < m.clearance_mm.size()) csv << common::csvNumber(m.clearance_mm[i]);
      csv << ',' << (limited ? 1 : 0) << ',';
      if (part) csv << int(part->posture[i]);
      csv << ',';
      if (part && i + 1 < path.postures.size()) csv << int(part->motion[i]);
      csv << '\n';
    }
  }
  return csv.str();
}

}  // namespace

void addCheckCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "check",
      "Check a path of a scene: exact clearance of tool + holder (FCL) at every posture and along "
      "every motion (links included), and the machined part (Z-buffer) against the `part` mesh: "
      "gouge, scallop, deviation.png. Exit 0 even when postures collide (they are reported), "
      "unless --fail-unsafe");
  struct Options {
    std::string scene, path, out;
    double spacing_mm = 0.05;
    double gouge_tol_um = kGougeToleranceUm;
    std::optional<double> max_scallop_um;  // none: the scallop is measured, not judged
    std::string backend = "auto";
    bool fail_unsafe = false;
  };
  auto options = std::make_shared<Options>();
  cmd->add_option("scene", options->scene, "Scene file (YAML)")->required();
  cmd->add_flag("--fail-unsafe", options->fail_unsafe,
                "Exit 3 when the verdict is NOT OK (the outputs written all the same), so that "
                "`check ... --fail-unsafe && post` stops");
  cmd->add_option("--path", options->path,
                  "Path file: .cl (x y z i j k per line, `# pass` / `# link` blocks), APT "
                  "(.apt/.cls) or .npy")
      ->required();
  cmd->add_option("--out", options->out,
                  "Output folder (check.json, clearance.csv, deviation.png, deviation.npy)");
  cmd->add_option("--spacing", options->spacing_mm, "Z-buffer line spacing, mm")
      ->check(positiveFinite("mm"))
      ->capture_default_str();
  cmd->add_option("--gouge-tol", options->gouge_tol_um,
                  "Depth under the part, along its normal, that counts as a gouge, um (the part "
                  "mesh's own chordal "
                  "error reads as a gouge where it is concave; 0.1 to 1000)")
      ->check(numberFromTo(0.1, 1000.0, "um"))  // (CLI::Range let nan through)
      ->capture_default_str();
  cmd->add_option("--max-scallop", options->max_scallop_um,
                  "The finish the check holds the path to, um: a larger scallop, or lines "
                  "between passes no pass cut, make it NOT OK (0.1 to 1e5; default: measured, "
                  "not judged)")
      ->check(numberFromTo(0.1, 1e5, "um"));
  cmd->add_option("--backend", options->backend, "Z-buffer backend: auto | cpu | cuda")
      ->check(CLI::IsMember({"auto", "cpu", "cuda"}))
      ->capture_default_str();
  cmd->callback([options, &global] {
    const zbuffer::Backend backend = zbuffer::backendFromName(options->backend, "--backend");
    if (!options->out.empty()) {
      common::checkOutputDirectory(options->out, "--out");
      common::claimOutputs(
          options->out,
          {"check.json", "clearance.csv", "deviation.npy", "deviation.json", "deviation.png"},
          {options->scene, options->path});
      common::removeEarlierOutputs();
    }
    // A missing path is said before the scene's meshes are read (and their notes printed).
    common::requireRegularFile(options->path, "path file");
    const Scene scene = loadScene(options->scene, SceneUse::kPathGiven);
    checkPathFileSize(options->path, "--path " + options->path);
    const common::FileStamp path_stamp = common::fileStamp(options->path);
    const geometry::PathFile path = geometry::readPathFile(options->path);
    const std::string path_digest = common::fileDigest(options->path);
    // The scene's meshes beside the path checked (loading compared them with each other only: a
    // scene in metres beside the path read ok, a reviewer's): what the path adds, said.
    const std::vector<MeshScaleWarning> scale_warnings = meshScaleWarnings(scene, &path);
    {
      const std::vector<MeshScaleWarning>& at_load = scene.scale_warnings;  // each mesh once
      for (const MeshScaleWarning& warning : scale_warnings)
        if (std::none_of(at_load.begin(), at_load.end(),
                         [&](const MeshScaleWarning& w) { return w.mesh == warning.mesh; }))
          std::fprintf(stderr, "warning: %s: %s\n", scene.file.string().c_str(),
                       warning.text.c_str());
    }
    const common::Progress progress = makeProgressLine(global.quiet);
    if (!scene.tool_given)
      throw InputError(scene.file.string() + ": tool: missing: check needs the cutter (`tool: { "
                                             "shape: ball, radius: R, length: L }`)");
    pathgen::requireSteadyAxes(path, scene.path.pass_gap_mm,
                               scene.tool.radius_mm);  // a flipped axis in a pass
    // A flat end's rim is sharp: tilted along the feed, the cut between two stamps is too shallow
    // by up to step · tan(tilt) (30 um at 10 deg; a helper's 10 um ridge passed), not the
    // curvature bound the stamps are spaced by. Ball and torus (the corner's curvature) only.
    // The cutter shrunk by the tolerance must remain (a tolerance of the radius tested nothing,
    // and said ok: a reviewer's case).
    if (!(1e-3 * options->gouge_tol_um < 0.5 * scene.tool.radius_mm))
      throw InputError("--gouge-tol " + common::shortNumber(options->gouge_tol_um) +
                       " um: must be under half the tool radius (" +
                       common::shortNumber(0.5e3 * scene.tool.radius_mm) + " um)");
    if (scene.tool.shape == geometry::ToolShape::Flat)
      throw InputError(toolShapeWhere(scene) +
                       ": check proves ball and torus tools; a flat end's sharp rim, tilted, is "
                       "not bounded by its Z-buffer stamps yet (`simulate --tool flat:R` cuts "
                       "with it)");
    std::vector<std::string> tool_notes = cutterNotes(scene.tool, path);
    if (std::string holder = noHolderNote(scene.tool, scene.holder); !holder.empty())
      tool_notes.push_back(std::move(holder));
    // The path's voxel size is not known here: the scene's (what `generate` takes by default).
    const std::vector<std::string> obstacle_notes =
        openObstacleNotes(scene, scene.field.voxel.voxel_size_mm);
    // What the path file holds that check does not prove: an APT start point (FROM/).
    std::vector<std::string> path_notes;
    if (path.from_line > 0)
      path_notes.push_back(path.file.string() + ":" + std::to_string(path.from_line) +
                           ": FROM/ (the start point) is read past: the machine's move from it to "
                           "the first GOTO is not checked (write it as a GOTO after RAPID to have "
                           "it checked)");
    if (path.msys_line > 0)
      path_notes.push_back(path.file.string() + ":" + std::to_string(path.msys_line) +
                           ": MSYS/ (a frame shifted or turned) is read past: the path is checked "
                           "in the file's coordinates, where the scene's meshes are");
    if (path.cutcom_line > 0)
      path_notes.push_back(path.file.string() + ":" + std::to_string(path.cutcom_line) +
                           ": CUTCOM/ (the control's cutter offset) is read past: the path is "
                           "checked where it is written, not where the offset puts the tool");
    const pathgen::AxisTurn axis_turn = pathgen::largestAxisTurn(path, scene.tool.radius_mm);
    SurfaceRequest surface_request;
    std::optional<SurfaceGrid> surface_grid;
    if (scene.part) {
      surface_request.part = &*scene.part;
      surface_request.path = &path;
      surface_request.tool = scene.tool;
      surface_request.spacing_mm = options->spacing_mm;
      surface_request.gouge_tolerance_um = options->gouge_tol_um;
      surface_request.backend = backend;
      surface_request.progress = progress;
      surface_grid = surfaceGrid(surface_request);  // refused now, not after the clearance work
    }

    // (a) exact clearance of postures and motions
    const double tol_mm = pathgen::clearanceMeshTolMm(scene.tool, scene.holder);
    const geometry::TriangleMesh tool_mesh = geometry::toolMesh(scene.tool, scene.holder, tol_mm);
    const pathgen::ClearanceChecker checker(tool_mesh, scene.obstacles, tol_mm);
    surface_request.obstacles = &checker;  // the stock beside them told from the scallop
    const pathgen::ClearanceResult clearance = checker.check(path.postures, {}, progress);
    pathgen::MotionRequest motion_request;
    motion_request.required_mm = scene.clearance_mm;
    motion_request.posture_clearance_mm = clearance.clearance_mm;
    const pathgen::MotionResult motions =
        checker.checkMotions(path.postures, motion_request, progress);
    const pathgen::RotaryStray rotary =
        pathgen::rotaryStray(path.postures, motions, scene.clearance_mm);
    const pathgen::DogLegRapids dog_leg = pathgen::dogLegRapids(path, motions, scene.clearance_mm);
    // The links (rapid moves) and the holder (it never cuts) must not touch the part.
    pathgen::PartContacts contacts;
    if (scene.part)
      contacts = pathgen::checkAgainstPart(scene.tool, scene.holder, *scene.part, path,
                                           1e-3 * options->gouge_tol_um, progress);
    const std::optional<pathgen::LinkPartResult>& link_part = contacts.links;
    const std::optional<pathgen::LinkPartResult>& holder_part = contacts.holder;
    std::size_t limited_colliding = 0;
    for (std::size_t i : path.limited) limited_colliding += clearance.clearance_mm[i] <= 0.0;

    // (b) the machined part
    std::optional<SurfaceResult> surface;
    if (surface_grid) surface = checkSurface(surface_request, *surface_grid);
    // A path that never cuts the stock over the part (another frame or units, a path over
    // another part) left only the stock's figures: 2000 um of 'scallop' and ok read as a check.
    const bool never_cut = surface && surface->part_cut_lines == 0;
    if (never_cut) surface.reset();
    // The cutter entering the part is no path in another frame (a side cut under the stock's
    // lines asked 'is the part in the path's frame?' while cutter_part read its 9.9 um).
    const bool touches_part = contacts.cutter && contacts.cutter->gouges();
    // The ball reaching the part where no line falls: a wall finished with the axis tilted (a
    // helper's walls at 30-85 deg read "is the part in the path's frame?" and never ok).
    const bool reaches_part =
        contacts.ball_part_mm && *contacts.ball_part_mm <= pathgen::kReachesPartMm;
    const char* surface_skipped = surfaceSkipped(
        {scene.part.has_value(), surface.has_value(), never_cut, touches_part, reaches_part});

    // Why the check fails, one line each (empty: ok): the collisions of `unsafe`, a clearance
    // under the required one, and the gouges (a flank driven into a wall of the part is one).
    const std::optional<pathgen::CutterPartResult>& cutter_part = contacts.cutter;
    std::vector<std::string> unsafe =
        unsafeReasons(path, clearance, motions, link_part, holder_part);
    const auto [rapids_onto_passes, first_rapid_onto_pass] = rapidsOntoPasses(path);
    if (rapids_onto_passes > 0)
      unsafe.push_back(std::to_string(rapids_onto_passes) +
                       " links end with a rapid move onto a pass's first posture, where the ball "
                       "cuts (first: " +
                       postureWhere(path, first_rapid_onto_pass) + "): no retract before the pass");
    std::vector<std::string> not_ok = unsafe;
    if (const std::string gouge = cutterGougeReason(path, cutter_part); !gouge.empty())
      not_ok.push_back(gouge);
    // Each with where it is first, as the collisions are (a fault injection's: the verdict named
    // no posture, stdout's lines and check.json's fields did).
    if (clearance.colliding == 0 && clearance.min_clearance_mm < scene.clearance_mm)
      not_ok.push_back("postures come within " + std::to_string(clearance.min_clearance_mm) +
                       " mm of the obstacles, under the required clearance (lowest: " +
                       postureWhere(path, clearance.min_index) + ")");
    if (motions.colliding == 0 && motions.under_required > 0)
      not_ok.push_back(std::to_string(motions.under_required) +
                       " motions come under the required clearance (first: " +
                       motionWhere(path, motions.first_under_required) + ")");
    // A part given and never reached: the machined surface is unproven, most likely a path in
    // other units or another frame (a helper's inch file 165 mm from its part read `ok: true`).
    const bool part_never_reached = scene.part && !surface && !touches_part && !reaches_part;
    if (part_never_reached)
      not_ok.push_back(std::string("the surface is not checked: ") + surface_skipped);
    // A part a hundred times smaller than the rest under 1 mm (a part in metres): its surface was
    // checked at that size, one line of it (a helper's part read `check: ok` beside the warning
    // that a path read safe beside it is not). Where the passes are at the part's scale too, it
    // is a micro part among a fixture's jaws: warned of, not failed (a reviewer's 0.6 mm plate).
    if (scene.part_file && pathExtentMm(path, true) >= 100.0 * meshExtentMm(*scene.part))
      for (const MeshScaleWarning& warning : scale_warnings)
        if (warning.mesh.rfind("part (", 0) == 0)
          not_ok.push_back("the surface is checked against a part of another scale: " +
                           warning.text);
    // The finish, where the user gives one (finishReasons).
    for (std::string& reason :
         finishReasons(surface ? &*surface : nullptr, options->max_scallop_um, surface_skipped))
      not_ok.push_back(std::move(reason));
    if (surface && surface->gouged_lines > 0)
      not_ok.push_back(std::to_string(surface->gouged_lines) + " Z-buffer lines cut below the part "
                       "by more than the gouge tolerance (max " +
                       std::to_string(static_cast<long long>(std::lround(surface->max_gouge_um))) +
                       " um)");
    // The verdict is on the bytes read: a path rewritten meanwhile gets none (it was "ok").
    common::requireUnchanged(options->path, path_stamp, "checked");
    const json report = {
        {"scene", scene.file.string()},
        {"path", options->path},
        {"path_digest", path_digest},
        {"scene_digest", sceneDigest(scene)},
        {"postures", path.postures.size()},
        // The file's pass blocks, as clearance.csv's `pass`, the reasons and view number them (a
        // file without markers is one; a helper read 50 here and 1 in every other output), and
        // beside them the passes generate would take from it as a nominal path.
        {"passes", path.count(geometry::PathBlock::Kind::Pass)},
        {"passes_split_at_gaps", passesSplitAtGaps(path, scene)},
        {"links", path.count(geometry::PathBlock::Kind::Link)},
        {"clearance",
         clearanceJson(
             clearance, scene.clearance_mm, pathgen::clearanceMeshTolMm(scene.tool, scene.holder),
             clearance.min_obstacle < 0 ? "" : obstacleName(scene, clearance.min_obstacle))},
        {"motions", motionsJson(motions, scene.clearance_mm, motion_request.resolution_mm)},
        {"link_part", linkPartJson(link_part)},
        {"link_part_skipped",
         link_part ? json(nullptr)
                   : json("no `part` in the scene, or no `# link` blocks in the path")},
        {"holder_part", holderPartJson(holder_part)},
        {"holder_part_skipped",
         holder_part ? json(nullptr) : json("no `part` or no `holder` in the scene")},
        {"cutter_part", cutterPartJson(cutter_part)},
        {"cutter_part_skipped", cutter_part ? json(nullptr) : json("no `part` in the scene")},
        {"unsafe", unsafe},
        {"tool_notes", tool_notes},
        {"obstacle_notes", obstacle_notes},
        {"path_notes", path_notes},
        {"axis_turn", axisTurnJson(axis_turn)},
        {"rotary_angles", rotaryJson(rotary, motions.tool_reach_mm)},
        {"dog_leg_rapids", dogLegJson(dog_leg)},
        {"limits",
         {{"limited_postures", path.limited.size()},
          {"limited_colliding", limited_colliding},
          // An object, as generate's report.json `limits.first_limited` is (was a bare number).
          {"first_limited", path.limited.empty()
                                ? json(nullptr)
                                : json({{"posture", path.limited.front()},
                                        {"at", path.limited.front() < path.lines.size()
                                                   ? json(path.where(path.limited.front()))
                                                   : json(nullptr)}})}}},
        {"surface", surface ? surfaceJson(*surface) : json(nullptr)},
        // The file's passes (from 1) whose ball stays past far_from_part_mm at every posture (a
        // ball end mill and a part): they cut nothing.
        {"far_passes", contacts.ball_part_mm ? json(contacts.far.passes) : json(nullptr)},
        {"far_postures", contacts.ball_part_mm ? json(contacts.far.postures) : json(nullptr)},
        {"far_from_part_mm", pathgen::farFromPartMm(scene.tool.radius_mm)},
        {"max_scallop_um",
         options->max_scallop_um ? json(*options->max_scallop_um) : json(nullptr)},
        {"surface_skipped", surface_skipped ? json(surface_skipped) : json(nullptr)},
        {"ok", not_ok.empty()},
        {"not_ok_because", not_ok},
    };
    if (!options->out.empty()) {
      const std::filesystem::path out = options->out;
      if (surface) {
        zbuffer::writeHeightsNpy(out / "deviation.npy", surface->grid, surface->deviation_um);
        zbuffer::writeHeightsJson(out / "deviation.json", surface->grid);
        writeDeviationPng(out / "deviation.png", *surface);
      } else {
        common::removeStaleOutputs(out, {"deviation.npy", "deviation.json", "deviation.png"});
      }
      common::writeTextAtomically(
          out / "clearance.csv",
          clearanceCsv(
              path, clearance, motions,
              scene.part ? std::optional(contacts.marks(path.postures.size())) : std::nullopt));
      common::writeTextAtomically(out / "check.json", jsonText(report));
    }
    common::commitOutputs();  // a summary lost from here takes none of them away
    // Postures numbered from 0 in the file's order, as clearance.csv, check.json and view's
    // #posture= number them, with the file's line (motion i: from posture i to i + 1).
    auto index = [&path](std::size_t i) {
      return i == pathgen::ClearanceResult::npos
                 ? std::string("-")
                 : std::to_string(i) + (i < path.lines.size() ? " (" + path.where(i) + ")" : "");
    };
    std::printf(
        "clearance: %zu postures, min %.3f mm (required %.3f) at posture %s, %zu colliding%s\n",
        path.postures.size(), clearance.min_clearance_mm, scene.clearance_mm,
        index(clearance.min_index).c_str(), clearance.colliding,
        clearance.colliding ? " (COLLISIONS)" : "");
    if (motions.motions == 0)  // one posture: no motion, no minimum (check.json: null)
      std::printf("motions: 0\n");
    else
      std::printf(
          "motions: %zu, min >= %.3f mm at motion %s, %zu colliding%s, %zu under the required "
          "clearance (%zu samples)\n",
          motions.motions, motions.min_clearance_mm, index(motions.min_index).c_str(),
          motions.colliding, motions.colliding ? " (COLLISIONS)" : "", motions.under_required,
          motions.samples);
    using Contacts = std::pair<const char*, const std::optional<pathgen::LinkPartResult>*>;
    for (const auto& [what, contacts] :
         {Contacts{"links", &link_part}, Contacts{"holder", &holder_part}})
      if (*contacts)
        std::printf("%s vs part: %zu postures, %zu motions, min >= %.3f mm, %zu colliding "
                    "postures, %zu colliding motions%s\n",
                    what, (*contacts)->postures, (*contacts)->motions,
                    (*contacts)->min_clearance_mm, (*contacts)->colliding_postures,
                    (*contacts)->colliding_motions, (*contacts)->collides() ? " (COLLISIONS)" : "");
    if (cutter_part)
      std::printf(
          "cutter vs part: %zu stamps, %zu postures and %zu motions enter it deeper than "
          "%.1f um, max %.1f um (corner and shank, exact)%s\n",
          cutter_part->stamps, cutter_part->gouging_postures, cutter_part->gouging_motions,
          1e3 * cutter_part->tolerance_mm, 1e3 * cutter_part->max_depth_mm,
          cutter_part->gouges() ? " (GOUGES)" : "");
    if (!path.limited.empty())
      std::printf("limits: %zu postures held at an angle limit, %zu of them colliding\n",
                  path.limited.size(), limited_colliding);
    if (surface) {
      std::printf("%s\n", surfaceLine(*surface).c_str());
      if (surface->uncut_band_lines > 0)
        std::fprintf(stderr,
                     "warning: %zu lines between passes were not cut: passes there lie farther "
                     "apart than the tool reaches, or run more than the stock allowance (2 mm) "
                     "over the part, and the stock stands there "
                     "(check.json surface.uncut_band_lines; sand on deviation.png)\n",
                     surface->uncut_band_lines);
    } else
      std::printf("surface: not checked (%s)\n", surface_skipped);
    // The verdict last, as a user looks for it (the reasons were only in check.json: a
    // newcomer's 352 colliding postures ended on a line of statistics).
    std::string reasons;
    for (const std::string& reason : not_ok) reasons += (reasons.empty() ? "" : "; ") + reason;
    if (not_ok.empty())
      std::printf("check: ok\n");
    else
      std::printf("check: NOT OK%s: %s (check.json not_ok_because)\n",
                  unsafe.empty() ? "" : ", UNSAFE TO RUN", reasons.c_str());
    if (options->fail_unsafe && !not_ok.empty()) verdictExitCode() = kVerdictExitCode;
    for (const std::string& note : tool_notes) std::fprintf(stderr, "note: %s\n", note.c_str());
    for (const std::string& note : obstacle_notes) std::fprintf(stderr, "note: %s\n", note.c_str());
    for (const std::string& note : path_notes) std::fprintf(stderr, "note: %s\n", note.c_str());
    if (const std::string turn = axisTurnWarning(path, axis_turn); !turn.empty())
      std::fprintf(stderr, "warning: %s (check.json axis_turn)\n", turn.c_str());
    if (const std::string stray = rotaryWarning(path, rotary, motions); !stray.empty())
      std::fprintf(stderr, "warning: %s (check.json rotary_angles)\n", stray.c_str());
    if (const std::string rapids = dogLegNote(path, dog_leg, motions, scene.part.has_value());
        !rapids.empty())
      std::fprintf(stderr, "note: %s (check.json dog_leg_rapids)\n", rapids.c_str());
    if (surface && surface->beneath_lines > 0)
      std::fprintf(stderr,
                   "note: the tool passed beneath the part's top layer on %zu Z-buffer lines "
                   "(under an overhang, or through the part): there they are measured against the "
                   "part below that layer (%zu with none: not measured); the overhang itself is "
                   "the cutter test's (check.json `surface.beneath`)\n",
                   surface->beneath_lines, surface->beneath_unmeasured);
    if (surface && surface->coarsened)
      std::fprintf(stderr,
                   "note: --spacing %g mm would make more Z-buffer lines than a check takes: "
                   "lines every %.4g mm (check.json `surface.grid.spacing`)\n",
                   options->spacing_mm, surface->grid.dx_mm);
    if (rapids_onto_passes > 0)
      std::fprintf(stderr, "warning: %s (check.json unsafe)\n", unsafe.back().c_str());
    if (const std::string far =
            farPassesWarning(path, contacts.far, pathgen::farFromPartMm(scene.tool.radius_mm));
        !far.empty())
      std::fprintf(stderr, "warning: %s (check.json far_passes)\n", far.c_str());
    if (part_never_reached)
      std::fprintf(stderr,
                   "warning: the path never reaches the part (%s): is the part in the path's "
                   "frame and units? (check.json not ok)\n",
                   never_cut ? "no line of the surface cut" : "no pass over it");
  });
}

}  // namespace fieldpath::app
