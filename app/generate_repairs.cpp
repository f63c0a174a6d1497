#include "generate_repairs.h"

#include <cmath>
#include <cstdio>

namespace fieldpath::app {

nlohmann::json keptNominalJson(const pathgen::GenerateResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& k : r.kept_nominal)
    out.push_back({{"pass", k.pass + 1},
                   {"at", k.label},
                   {"steered_colliding", k.steered_colliding},
                   {"steered_under_required", k.steered_under}});
  return out;
}

nlohmann::json routedLinkEndsJson(const pathgen::GenerateResult& r) {
  nlohmann::json out = nlohmann::json::array();
  for (const auto& e : r.routed_link_ends)
    out.push_back(
        {{"pass", e.pass + 1},
         {"at", e.label},
         {"end", e.into ? "into" : "out of"},
         {"way", {e.way.x(), e.way.y(), e.way.z()}},
         {"retract", e.retract_along_axis ? "along the axis" : "along the way"},
         {"retract_mm", e.retract_mm},
         {"sideways_mm", {e.sideways_mm.x(), e.sideways_mm.y(), e.sideways_mm.z()}},
         // then straight up; null: along `way` to the travel plane
         {"climb_mm", std::isfinite(e.climb_mm) ? nlohmann::json(e.climb_mm) : nlohmann::json()},
         {"off_axis_deg", e.off_axis_deg},
         {"along_axis", {{"collisions", e.axis_collisions}, {"min_clearance_mm", e.axis_min_mm}}},
         {"taken", {{"collisions", 0}, {"min_clearance_mm", e.taken_min_mm}}}});
  return out;
}

void printRepairs(const pathgen::GenerateResult& result, double links_retract_mm) {
  // Passes steered from their end: the axis turns after the field has pushed, and meets the
  // side of an obstacle the pass reaches first late.
  if (const std::size_t n = result.steered_from_end.size(); n > 0)
    std::fprintf(stderr,
                 "note: %zu pass%s (first: pass %d) steered from %s end to %s start: steered "
                 "from the start (the axis turning only after the field has pushed) %s or came "
                 "under `clearance`, and from the end %s checked better; written in the pass's "
                 "own order (report.json passes steered_from_end)\n",
                 n, n == 1 ? "" : "es", result.steered_from_end.front() + 1,
                 n == 1 ? "its" : "their", n == 1 ? "its" : "their",
                 n == 1 ? "it collided" : "they collided", n == 1 ? "it" : "they");
  if (result.steered_from_end_undone > 0)
    std::fprintf(stderr,
                 "note: %zu pass%s checked better steered from %s end, but the path linked to "
                 "them was checked worse: steered from the start is written (report.json "
                 "steered_from_end_undone)\n",
                 result.steered_from_end_undone, result.steered_from_end_undone == 1 ? "" : "es",
                 result.steered_from_end_undone == 1 ? "its" : "their");
  // Passes kept nominal: those that collided steered (a warning), and those that only came
  // under the required clearance steered (a note: the path written keeps it).
  for (const bool collided : {true, false}) {
    std::size_t n = 0;
    const pathgen::GenerateResult::KeptNominal* first = nullptr;
    for (const auto& k : result.kept_nominal)
      if ((k.steered_colliding > 0) == collided) n += 1, first = first ? first : &k;
    if (n == 0) continue;
    std::fprintf(stderr,
                 collided ? "warning: %zu pass%s collided steered (first: %s, %zu postures "
                            "colliding there or on the move to the next: the field of the "
                            "obstacles turned the tool into them or into the part, which never "
                            "repels) and %s written with the nominal axes, which clear the "
                            "obstacles and the part (report.json kept_nominal)\n"
                          : "note: %zu pass%s came under the required clearance steered "
                            "(first: %s, %zu postures under it there or on the move to the "
                            "next: the tilt away from one obstacle brought the tool nearer "
                            "another) and %s written with the nominal axes, which come less "
                            "near (report.json kept_nominal)\n",
                 n, n == 1 ? "" : "es", first->label.c_str(),
                 collided ? first->steered_colliding : first->steered_under, n == 1 ? "is" : "are");
  }
  if (result.kept_nominal_undone > 0)
    std::fprintf(stderr,
                 "note: %zu pass%s cleared with the nominal axes, but the path linked to them "
                 "(the links come down the new axes) was checked worse than the steered one: "
                 "the steering is written (report.json kept_nominal_undone)\n",
                 result.kept_nominal_undone, result.kept_nominal_undone == 1 ? "" : "es");
  if (!result.routed_link_ends.empty()) {
    const auto& e = result.routed_link_ends.front();
    const std::size_t n = result.routed_link_ends.size();
    char sideways[64] = "";
    if (e.sideways_mm.norm() > 0.0)
      std::snprintf(sideways, sizeof sideways, ", a move sideways of %.3g mm",
                    e.sideways_mm.norm());
    std::fprintf(stderr,
                 "note: %zu link end%s taken off the pass's tool axis, the axis held (first: the "
                 "way %s %s, the retract along %s (%.3g mm)%s, the climb %.1f deg from the axis: "
                 "along the "
                 "axis %zu collisions and %.3f mm of the obstacles, the way "
                 "taken none and %.3f mm; the tool moves straight, the rotary axes still) "
                 "(report.json links.routed_off_axis)\n",
                 n, n == 1 ? "" : "s", e.into ? "into" : "out of", e.label.c_str(),
                 e.retract_along_axis ? "the axis" : "the climb", e.retract_mm, sideways,
                 e.off_axis_deg, e.axis_collisions, e.axis_min_mm, e.taken_min_mm);
  }
  // A move sideways after a retract shorter than links.retract runs low over the part, and a
  // link's moves are rapids (path.apt): over stock not yet cut (a pass's start, the passes
  // beside it) that height is not free (a diff review's: a 24 mm rapid 0.5 mm over the start of
  // a pass, links.retract 2).
  {
    std::size_t n = 0;
    const pathgen::GenerateResult::RoutedLinkEnd* lowest = nullptr;
    for (const auto& e : result.routed_link_ends)
      if (e.retract_mm < links_retract_mm && e.sideways_mm.norm() > 0.0) {
        n += 1;
        if (!lowest || e.retract_mm < lowest->retract_mm) lowest = &e;
      }
    if (lowest)
      std::fprintf(stderr,
                   "warning: %zu link end%s move%s sideways after a retract shorter than "
                   "links.retract (%.3g mm; the full one runs into what is over the pass), the "
                   "lowest %.3g mm along the axis from the way %s %s: path.apt writes a link's "
                   "moves as rapids, and over stock not yet cut (a pass's start, the passes "
                   "beside it) that low a rapid cuts: run %s at feed, or make room over the "
                   "pass (report.json links.routed_off_axis retract_mm)\n",
                   n, n == 1 ? "" : "s", n == 1 ? "s" : "", links_retract_mm, lowest->retract_mm,
                   lowest->into ? "into" : "out of", lowest->label.c_str(), n == 1 ? "it" : "them");
  }
  // A retract of a few microns starts every way up within the part's contact tolerance of the
  // pass: 12 ends of the impeller unfreed at 0.001 mm, all freed at 0.05 (a links adversary's).
  char short_retract[160] = "";
  if (links_retract_mm < 1.0)
    std::snprintf(short_retract, sizeof short_retract,
                  "; or give a longer links.retract (%.3g mm: a way up that starts that near "
                  "the pass may read as touching the part)",
                  links_retract_mm);
  if (!result.unfreed_link_ends.empty())
    std::fprintf(stderr,
                 "note: %zu link end%s collide or come under the clearance whichever straight way "
                 "up from the pass, the axis held, is taken (first: %s): generate makes its links "
                 "anew from the passes (a nominal path's `# link` blocks are dropped), so edit "
                 "that link in the written path.cl by hand and `check` it%s (report.json "
                 "links.unfreed)\n",
                 result.unfreed_link_ends.size(), result.unfreed_link_ends.size() == 1 ? "" : "s",
                 result.unfreed_link_ends.front().c_str(), short_retract);
  if (result.routed_link_ends_undone > 0)
    std::fprintf(stderr,
                 "note: %zu link end%s cleared off the pass's axis, but the path linked that way "
                 "was checked worse than the one along the axes, which is written (report.json "
                 "links.routed_off_axis_undone)\n",
                 result.routed_link_ends_undone, result.routed_link_ends_undone == 1 ? "" : "s");
}

}  // namespace fieldpath::app
