/// `fieldpath view SCENE [--path FILE] [--check DIR] [--surface DIR] --out FILE.html`: the job in
/// 3-D in one self-contained page (view_page.h): the scene's meshes, the path coloured by tilt,
/// lead or clearance, links, colliding postures and motions and clamped-limit postures marked, the
/// tool + holder at the posture of a slider, the simulated surface coloured by deviation, axes in
/// millimetres. Exit 1 on bad input (one line); a page that lacks a path says so.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>

#include "commands.h"
#include "errors.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/short_number.h"
#include "progress.h"
#include "view_data.h"
#include "view_page.h"

namespace fieldpath::app {

void addViewCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "view",
      "The job in 3-D: one self-contained HTML page (three.js inlined, no server, no network) with "
      "the scene's meshes, the path coloured by tilt, lead or clearance, links, collisions and "
      "clamped limits marked, tool + holder at any posture (slider, play), the simulated surface "
      "coloured by deviation (um), axes in mm");
  struct Options {
    std::string scene, path, check, surface, out;
    std::size_t max_triangles = PageBudget{}.max_triangles;
    std::size_t max_postures = PageBudget{}.max_postures;
    std::size_t surface_lines = ViewRequest{}.max_surface_lines;
    double max_mb = 15.0;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("scene", o->scene, "Scene file (YAML)")->required();
  cmd->add_option("--path", o->path,
                  "Path file (.cl with `# pass` / `# link` blocks and `# limit` marks, APT, .npy); "
                  "default: the path named by --check's check.json, else the scene's "
                  "path.nominal, else none (the page says so)");
  cmd->add_option("--check", o->check,
                  "Output folder of `fieldpath check` for this path: clearance per posture and "
                  "motion from its clearance.csv (agreeing with its check.json), and its "
                  "deviation.npy as the surface. Without it the clearance is computed here, as "
                  "check computes it");
  cmd->add_option("--surface", o->surface,
                  "Folder with deviation.npy + .json (`check --out`) or heights.npy + .json "
                  "(`simulate --out`): the surface, coloured by deviation from the part (um)");
  cmd->add_option("--out", o->out, "The page to write (FILE.html)")->required();
  cmd->add_option("--max-triangles", o->max_triangles,
                  "Triangles of the scene's meshes at most (decimated beyond)")
      ->check(CLI::Range(std::size_t{1000}, std::size_t{20'000'000}))
      ->capture_default_str();
  cmd->add_option("--max-postures", o->max_postures,
                  "Postures on the slider at most (every k-th; colliding, limited and block ends "
                  "always kept)")
      ->check(CLI::Range(std::size_t{100}, std::size_t{50'000'000}))
      ->capture_default_str();
  cmd->add_option("--surface-lines", o->surface_lines,
                  "Lines of the surface at most (square blocks beyond; a block shows its deepest "
                  "gouge, else its largest scallop)")
      ->check(CLI::Range(std::size_t{100}, std::size_t{50'000'000}))
      ->capture_default_str();
  cmd->add_option("--max-mb", o->max_mb,
                  "Size of the page at most, MB (the budgets above are halved until it fits)")
      ->check(positiveFinite("MB"))
      ->capture_default_str();
  cmd->callback([o, &global] {
    // The page must not replace what it is made from (`--out` naming the scene or the path
    // wrote the HTML over it without a word).
    std::error_code same;
    for (const std::string& input : {o->scene, o->path})
      if (!input.empty() && (o->out == input || std::filesystem::equivalent(o->out, input, same)))
        throw InputError("--out: " + o->out + " is an input of this view (" + input +
                         "): give another file for the page");
    // three.js first: without it there is no page to write.
    const ThreeJs three = loadThreeJs(threeJsDir());
    ViewRequest request;
    request.scene = o->scene;
    request.path = o->path;
    request.check_dir = o->check;
    request.surface_dir = o->surface;
    request.max_surface_lines = o->surface_lines;
    request.progress = makeProgressLine(global.quiet);
    const ViewData data = gatherView(request);

    std::string generator = "fieldpath view " + o->scene;
    if (!o->path.empty()) generator += " --path " + o->path;
    if (!o->check.empty()) generator += " --check " + o->check;
    if (!o->surface.empty()) generator += " --surface " + o->surface;
    PageBudget budget;
    budget.max_triangles = o->max_triangles;
    budget.max_postures = o->max_postures;
    const double max_bytes = o->max_mb * 1e6;  // a double: 2e13 MB overflowed a size_t
    PageStats stats;
    std::string page;
    for (int attempt = 0;; ++attempt) {
      page = viewPage(data, three, budget, generator, &stats);
      if (double(stats.bytes) <= max_bytes) break;
      // Halved down to a floor that is never above the user's own budget (the floor of 2000
      // raised --max-triangles 1000 to 1653 shown, a reviewer's).
      const std::size_t triangle_floor = std::min<std::size_t>(2000, o->max_triangles),
                        posture_floor = std::min<std::size_t>(1000, o->max_postures);
      if (attempt == 6 ||
          (budget.max_triangles <= triangle_floor && budget.max_postures <= posture_floor))
        throw InputError("--max-mb " + common::shortNumber(o->max_mb) +
                         ": the smallest page at these budgets is " +
                         common::shortNumber(stats.bytes / 1e6) +
                         " MB (its meshes, postures and surface: lower --surface-lines, or "
                         "--max-triangles and --max-postures further)");
      budget.max_triangles = std::max(triangle_floor, budget.max_triangles / 2);
      budget.max_postures = std::max(posture_floor, budget.max_postures / 2);
    }
    common::writeTextAtomically(o->out, page);
    common::commitOutputs();  // a summary lost from here takes it not away

    std::printf("view: %s (%.2f MB)\n", o->out.c_str(), stats.bytes / 1e6);
    std::printf("meshes: %zu, %zu triangles shown of %zu\n", data.meshes.size(), stats.triangles,
                stats.source_triangles);
    if (data.path) {
      const ViewPath& p = *data.path;
      std::printf(
          "path: %s, %zu postures (%zu on the slider), %zu postures held at an angle limit\n",
          p.what.c_str(), p.file.postures.size(), stats.shown_postures, p.file.limited.size());
      if (p.clearance_known)
        std::printf("clearance: %zu colliding postures, %zu colliding motions (%s)\n",
                    p.colliding_postures, p.colliding_motions, p.clearance_source.c_str());
      else
        std::printf("clearance: %s\n", p.clearance_source.c_str());
    }
    if (data.surface) std::printf("surface: %s\n", data.surface->source.c_str());
    for (const std::string& line : data.missing) std::printf("missing: %s\n", line.c_str());
    for (const std::string& line : data.warnings) std::printf("warning: %s\n", line.c_str());
    // The side panel's notes on the terminal too (an APT file's CUTTER against the scene's tool
    // was on the page only: an adversary read view as saying nothing of it).
    for (const std::string& line : data.notes) std::printf("note: %s\n", line.c_str());
  });
}

}  // namespace fieldpath::app
