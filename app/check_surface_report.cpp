#include "check_surface_report.h"

#include <cmath>
#include <cstdio>

#include "fieldpath/common/short_number.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

/// Why the surface was not checked (nullptr: it was), as check.json's surface_skipped says it.
const char* surfaceSkipped(const SurfaceFacts& f) {
  if (!f.part) return "the scene has no `part`";
  if (f.never_cut && f.touches_part)
    return "the tool lowers no line of the stock over the part (it enters the part where no "
           "line falls: cutter_part)";
  if (!f.surface && f.reaches_part)
    return "the ball reaches the part where the Z-buffer, looking down, lowers no line (a wall "
           "or an undercut): its gouges are cutter_part's, its scallop is not measured";
  if (f.never_cut)
    return "the tool never cuts the stock over the part (no line over it lowered): is the part in "
           "the "
           "path's frame and units?";
  if (!f.surface) return "the passes do not pass over the part (`part` mesh)";
  return nullptr;
}

nlohmann::json surfaceJson(const SurfaceResult& s) {
  using nlohmann::json;
  auto scallop = [&s](double um) { return s.band_lines > 0 ? json(um) : json(nullptr); };
  return {
      {"grid",
       {{"origin", {s.grid.x0_mm, s.grid.y0_mm}},
        {"spacing", {s.grid.dx_mm, s.grid.dy_mm}},
        {"shape", {s.grid.ny, s.grid.nx}}}},
      {"spacing_coarsened", s.coarsened},
      {"deviation",
       "along the part's normal, um: a line's machined height less the part's, times the "
       "cosine of the slope of the part's facet under it (exact over a plane facet)"},
      {"backend", zbuffer::backendName(s.backend)},
      {"simulation_s", s.simulation_s},
      {"swept",
       "the Z-buffer cuts at the postures and along every motion between them that can reach "
       "the stock (tip and axis interpolated linearly, no point of the tool moving more than "
       "sweep_step_mm between cuts; a ball's cut between two is at most sweep_error_um "
       "shallower than the swept one along the ball's normal there, so along the part's normal "
       "where the ball finishes it; vertically 1/cos of the ball's slope more, e.g. 2-3 um on "
       "the stock a pass's end leaves to the ball's side)"},
      {"sweep_step_mm", s.sweep_step_mm},
      {"sweep_error_um", s.sweep_error_um},
      {"simulated_postures", s.simulated_postures},
      {"cut_lines", s.cut_lines},
      {"part_cut_lines", s.part_cut_lines},
      {"beneath_lines", s.beneath_lines},
      {"beneath_unmeasured_lines", s.beneath_unmeasured},
      {"beneath",
       "lines the tool reached beneath the underside of the part's top layer (under an "
       "overhang, or through the part): a line keeps the tool's lowest point only, which says "
       "nothing of that layer there; they are measured against the highest top of the part under "
       "the lowest underside above the cut (beneath_unmeasured_lines: none, not measured); the "
       "layer's underside is the cutter "
       "test's (cutter_part, exact)"},
      {"part_lines", s.part_lines},
      {"band_lines", s.band_lines},
      {"uncut_band_lines", s.uncut_band_lines},
      {"uncut_band",
       "lines between two passes that no pass cut (passes farther apart than the tool reaches, or "
       "running more than the stock allowance over the part): "
       "the stock allowance stands there; not in band_lines nor the scallop figures"},
      {"gouged_lines", s.gouged_lines},
      {"gouge_tolerance_um", s.gouge_tolerance_um},
      {"max_gouge_um", s.max_gouge_um},
      // No band (a lone pass, passes too far apart to be neighbours): no scallop to tell.
      {"max_scallop_um", scallop(s.max_scallop_um)},
      {"scallop_grid_error_um",
       std::isfinite(s.scallop_grid_error_um) ? scallop(s.scallop_grid_error_um) : json(nullptr)},
      {"scallop_grid_error",
       "the lines may miss the highest cusp: it may stand up to scallop_grid_error_um above "
       "max_scallop_um (each cusp within spacing/sqrt(2) of a line, the cutting edge's slope "
       "there over the part's; null: a band line on a wall of 85 deg or more, where vertical "
       "lines bound no cusp)"},
      {"scallop_skipped", s.band_lines > 0 ? json(nullptr)
                                           : json("no two neighbouring passes: a scallop is "
                                                  "what is left between them")},
      {"unreachable_band_lines", s.unreachable_band_lines},
      {"max_reachable_scallop_um",
       std::isnan(s.max_reachable_scallop_um) ? json(nullptr) : json(s.max_reachable_scallop_um)},
      {"unreachable",
       "band lines above max_reachable_scallop_um where the ball, set on the part (its centre R "
       "along the part's normal), meets an obstacle: stock beside a wall or a rib that no ball "
       "of R reaches without meeting one, counted in max_scallop_um, not a cusp the passes "
       "leave; max_reachable_scallop_um: the highest band line the ball can touch (null: none "
       "can, unreachable_band_lines then band_lines; or not told: no obstacle, not a ball, "
       "unreachable_band_lines then 0)"},
      {"mean_deviation_um", scallop(s.mean_um)},
      {"rms_deviation_um", scallop(s.rms_um)},
      {"stock_allowance_mm", kStockAllowanceMm}};
}

namespace {

/// What the summary and the --max-scallop reason add of the stock no ball reaches (empty where
/// none was told).
std::string unreachableText(const SurfaceResult& s) {
  if (s.unreachable_band_lines == 0) return {};
  if (std::isnan(s.max_reachable_scallop_um))
    return "no band line where a ball of this radius can touch the part without meeting an "
           "obstacle";
  char text[160];
  std::snprintf(text, sizeof text,
                "%.1f um where the ball can reach: %zu lines above it lie beside obstacles no "
                "ball of this radius reaches",
                s.max_reachable_scallop_um, s.unreachable_band_lines);
  return text;
}

}  // namespace

std::string surfaceLine(const SurfaceResult& s) {
  char scallop[160] = "no scallop (no two neighbouring passes)";
  if (s.band_lines > 0 && std::isfinite(s.scallop_grid_error_um))
    std::snprintf(scallop, sizeof scallop,
                  "max scallop %.1f um (a cusp between the lines up to %.1f um more), rms %.1f um",
                  s.max_scallop_um, s.scallop_grid_error_um, s.rms_um);
  else if (s.band_lines > 0)
    std::snprintf(scallop, sizeof scallop,
                  "max scallop %.1f um (a cusp between the lines on a wall of 85 deg or more: not "
                  "bounded), rms %.1f um",
                  s.max_scallop_um, s.rms_um);
  const std::string unreachable = unreachableText(s);
  const std::string beside = unreachable.empty() ? "" : "; " + unreachable;
  char line[600];
  std::snprintf(line, sizeof line,
                "surface: %zu lines in the band, max gouge %.2f um (%zu lines below %.1f um), "
                "%s%s (%s, %.2f s)",
                s.band_lines, s.max_gouge_um, s.gouged_lines, -s.gouge_tolerance_um, scallop,
                beside.c_str(), zbuffer::backendName(s.backend), s.simulation_s);
  return line;
}

std::vector<std::string> finishReasons(const SurfaceResult* surface,
                                       const std::optional<double>& max_scallop_um,
                                       const char* skipped) {
  std::vector<std::string> out;
  if (!max_scallop_um) return out;
  const std::string bound = common::shortNumber(*max_scallop_um);
  if (!surface || surface->band_lines == 0) {
    out.push_back("--max-scallop " + bound + " um not proven: no scallop measured (" +
                  (surface ? std::string("no two neighbouring passes over the part")
                           : std::string(skipped ? skipped : "no surface")) +
                  ")");
    if (!surface) return out;
  }
  const auto um = [](double v) { return std::to_string(static_cast<long long>(std::lround(v))); };
  const double measured = surface->max_scallop_um, between = surface->scallop_grid_error_um;
  if (surface->band_lines > 0 && measured > *max_scallop_um)
    out.push_back(
        "max scallop " + um(measured) + " um, over --max-scallop " + bound + " um" +
        (unreachableText(*surface).empty() ? "" : " (" + unreachableText(*surface) + ")"));
  else if (surface->band_lines > 0 && !std::isfinite(between))
    out.push_back("max scallop " + um(measured) +
                  " um on the lines, a cusp between them on a wall of 85 deg or more not "
                  "bounded: --max-scallop " +
                  bound + " um not proven");
  else if (surface->band_lines > 0 && measured + between > *max_scallop_um)
    out.push_back("max scallop " + um(measured) + " um on the lines, a cusp between them up to " +
                  um(measured + between) + " um: over --max-scallop " + bound +
                  " um unless a finer --spacing bounds it under");
  if (surface->uncut_band_lines > 0)
    out.push_back(std::to_string(surface->uncut_band_lines) +
                  " lines between passes not cut (the stock stands there; --max-scallop " + bound +
                  " um)");
  return out;
}

}  // namespace fieldpath::app
