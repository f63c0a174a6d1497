#include "job.h"

#include <cstdio>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/short_number.h"

namespace fieldpath::app {

pathgen::GenerateRequest sceneJob(const Scene& scene) {
  using common::InputError;
  const bool impeller = scene.impeller_model && scene.guide_impeller;
  if (scene.nominal && impeller)
    throw InputError(sceneWhere(scene, "path.nominal") +
                     ": the passes come from one source: a nominal path file or the "
                     "parametric impeller's hub (`guide: { impeller: hub }`), not both");
  if (!scene.nominal && !impeller)
    throw InputError(sceneWhere(scene, "path.nominal") +
                     ": missing: generate needs the nominal path (`path: { nominal: "
                     "FILE }`, .cl, APT or .npy) or the parametric impeller (`guide: { impeller: "
                     "hub }` with `- impeller:` among the obstacles)");
  if (scene.nominal && scene.path.passes_given)
    throw InputError(sceneWhere(scene, "path.passes") +
                     ": the parametric impeller's pass count (with `guide: { "
                     "impeller: hub }`); a nominal path's passes are its own");
  if (!scene.tool_given)
    throw InputError(scene.file.string() +
                     ": tool: missing: generate needs the cutter (`tool: { shape: ball, "
                     "radius: R, length: L }`)");
  pathgen::GenerateRequest job;
  job.path = scene.path;
  job.links = scene.links;
  job.field = scene.field;
  job.dynamics = scene.dynamics;
  job.tool = scene.tool;
  job.holder = scene.holder;
  job.clearance_mm = scene.clearance_mm;
  job.obstacles = scene.obstacles;  // the impeller's blades included (resolveImpeller)
  job.part = scene.part;
  if (job.tool.shape != geometry::ToolShape::Ball)
    throw InputError(toolShapeWhere(scene) + ": the passes are for a ball-end mill (shape: ball)");
  pathgen::NominalDropped dropped;
  job.passes = impeller
                   ? pathgen::impellerPasses(*scene.impeller_model, job.path, job.tool.radius_mm)
                   : pathgen::nominalPasses(*scene.nominal, job.path, job.tool.radius_mm, &dropped);
  // DESIGN: a posture kept out of the path is reported (repeats, and a zig-zag's one-posture
  // step-overs, went unsaid: a newcomer's 1319 postures came out as 1308).
  if (dropped.repeated > 0)
    std::fprintf(stderr,
                 "note: %s: %zu posture%s at the ball centre of the one before dropped (a repeat "
                 "is no motion)\n",
                 scene.nominal->file.string().c_str(), dropped.repeated,
                 dropped.repeated == 1 ? "" : "s");
  if (dropped.between_legs > 0)
    std::fprintf(stderr,
                 "note: %zu posture%s between the legs of a zig-zag (a step-over of one posture; "
                 "first: %s) made into links: the passes end and start at the legs\n",
                 dropped.between_legs, dropped.between_legs == 1 ? "" : "s",
                 scene.nominal->where(dropped.first_between).c_str());
  if (!impeller && scene.nominal->msys_line > 0)  // (a CAM engineer's MSYS/0,-5,0 went unsaid)
    std::fprintf(stderr,
                 "note: %s:%zu: MSYS/ (a frame shifted or turned) is read past: the path is "
                 "taken in the file's coordinates, where the scene's meshes are\n",
                 scene.nominal->file.string().c_str(), scene.nominal->msys_line);
  if (!impeller && scene.nominal->cutcom_line > 0)
    std::fprintf(stderr,
                 "note: %s:%zu: CUTCOM/ (the control's cutter offset) is read past: the path is "
                 "taken where it is written\n",
                 scene.nominal->file.string().c_str(), scene.nominal->cutcom_line);
  if (!dropped.gaps.empty()) {
    // Which moves of the file are not cut: a long cutting move split off as a link (a line
    // written as one GOTO between arcs written fine: a CAM engineer's floor cut went unsaid).
    const pathgen::GapSplit& g = dropped.gaps.front();
    std::fprintf(stderr,
                 "note: %zu move%s farther than path.pass_gap (%s: %s mm) made into link%s "
                 "between passes, not cut (first: %s to %s, %s mm): where such a move is meant "
                 "to cut, set path.pass_gap above its length\n",
                 dropped.gaps.size(), dropped.gaps.size() == 1 ? "" : "s",
                 job.path.pass_gap_mm > 0.0 ? "given" : "4 x the pass's median step",
                 common::shortNumber(g.gap_mm).c_str(), dropped.gaps.size() == 1 ? "" : "s",
                 scene.nominal->where(g.at - 1).c_str(), scene.nominal->where(g.at).c_str(),
                 common::shortNumber(g.move_mm).c_str());
  }
  if (dropped.approaches > 0)
    std::fprintf(stderr,
                 "note: %zu posture%s of approaches and retracts at feed at the ends of passes "
                 "(moves along the tool axis, or a lone posture a gap parts from the cut; first: "
                 "%s) made into links: the passes start and end where the cut does\n",
                 dropped.approaches, dropped.approaches == 1 ? "" : "s",
                 scene.nominal->where(dropped.first_approach).c_str());
  if (!impeller) {  // link blocks are dropped (links are made anew): said, with their size, as
    // a `# link` with no `# pass` or blank line after its moves takes the cutting that follows
    std::size_t blocks = 0, postures = 0, first = 0;
    for (const geometry::PathBlock& b : scene.nominal->blocks)
      if (b.kind == geometry::PathBlock::Kind::Link) {
        if (blocks++ == 0) first = b.begin;
        postures += b.size();
      }
    const bool apt = geometry::pathFormatOf(scene.nominal->file) == geometry::PathFormat::Apt;
    if (blocks > 0 && apt)
      std::fprintf(stderr,
                   "note: %s: %zu rapid posture%s (a GOTO after RAPID) not cut: generate makes "
                   "the links anew\n",
                   scene.nominal->where(first).c_str(), postures, postures == 1 ? "" : "s");
    else if (blocks > 0)
      std::fprintf(stderr,
                   "note: %s: %zu posture%s in %zu `# link` block%s not cut: generate makes the "
                   "links anew; a pass starts at `# pass` or a blank line\n",
                   scene.nominal->where(first).c_str(), postures, postures == 1 ? "" : "s", blocks,
                   blocks == 1 ? "" : "s");
  }
  return job;
}

}  // namespace fieldpath::app
