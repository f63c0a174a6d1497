/// app/scene_mesh.h: a scene's mesh file made ready for the job.
#include "scene_mesh.h"

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/mesh_io.h"
#include "progress.h"

namespace fieldpath::app {

std::vector<std::string>& meshNotes() {
  static std::vector<std::string> notes;
  return notes;
}

namespace {

/// Says `text` on stderr as a note and keeps it for the reports (meshNotes).
void sayMeshNote(const std::string& text) {
  std::fprintf(stderr, "note: %s\n", text.c_str());
  meshNotes().push_back(text);
}

/// printf's text of `format` and its arguments.
template <class... Args>
std::string formatted(const char* format, Args... args) {
  const int n = std::snprintf(nullptr, 0, format, args...);
  std::string text(n > 0 ? std::size_t(n) : 0, '\0');
  if (n > 0) std::snprintf(text.data(), text.size() + 1, format, args...);
  return text;
}

}  // namespace

// A solid exported with a T-junction, a sliver or a facet wound the wrong way had no inside: a
// tool wholly inside it read as clear; a tool mesh with every other facet flipped cut 77 034 of
// 262 144 lines up to 0.98 mm too high. Mended where that closes it, and said.
void mendExportDefects(geometry::TriangleMesh& mesh, const std::filesystem::path& file) {
  const geometry::ShellRepair mend = geometry::repairShells(mesh);
  if (mend.search_given_up)
    sayMeshNote(
        formatted("%s: %zu open edges; the search for T-junctions to mend them was given "
                  "up (a triangle soup?): the shells stay as they came",
                  file.string().c_str(), mend.open_edges_before));
  if (!mend.any()) return;
  std::string what;
  const auto add = [&what](std::size_t n, const char* one, const char* many) {
    if (n == 0) return;
    what += (what.empty() ? "" : ", ") + std::to_string(n) + " " + (n == 1 ? one : many);
  };
  add(mend.edges_split, "T-junction edge split", "T-junction edges split");
  add(mend.slivers_removed, "sliver of no area left out", "slivers of no area left out");
  add(mend.facets_turned, "facet turned to agree with its neighbours",
      "facets turned to agree with their neighbours");
  sayMeshNote(formatted("%s: mended as exported solids need (%s): %zu open edges before, %zu now",
                        file.string().c_str(), what.c_str(), mend.open_edges_before,
                        mend.open_edges_after));
}

geometry::TriangleMesh loadSceneMesh(const std::filesystem::path& file) {
  sayReading(file);
  geometry::TriangleMesh mesh = geometry::loadMesh(file);
  // Every triangle degenerate: no surface to sample or to machine (it was read, and the field
  // was zero everywhere without a word: a helper's finding).
  if (!(geometry::meshArea(mesh) > 0.0))
    throw common::InputError(file.string() +
                             ": every triangle has zero area: the mesh has no surface");
  // A facet written twice pushed twice as hard: the field samples it once (field/sampling.h).
  const std::vector<char> repeated = geometry::repeatedFacets(mesh);
  if (const auto n = std::size_t(std::count(repeated.begin(), repeated.end(), 1)))
    sayMeshNote(
        formatted("%s: %zu triangle%s written again the same way round: sampled once for "
                  "the field, kept for the checks",
                  file.string().c_str(), n, n == 1 ? "" : "s"));
  mendExportDefects(mesh, file);
  // Shells wound against their kind would make the field pull into the walls (the samples'
  // normals) and the part's top its bottom: turned, and said.
  if (const std::size_t turned = geometry::orientClosedShells(mesh))
    sayMeshNote(
        formatted("%s: %zu closed shell%s wound the wrong way round (normals into a solid "
                  "or out of a void), turned",
                  file.string().c_str(), turned, turned == 1 ? "" : "s"));
  // Mesh files are read in single precision (binary STL stores floats; assimp reads every format
  // so): far from the origin their points move by half a float's step, which check then reads
  // as microns of gouge or clearance (5e5 mm: 32 um, 32 769 false gouged lines).
  double far_mm = 0.0;
  for (const auto& v : mesh.vertices) far_mm = std::max(far_mm, v.cwiseAbs().maxCoeff());
  if (far_mm > common::kFloatExactMm)
    sayMeshNote(
        formatted("%s: points up to %.4g mm from the origin, read in single precision "
                  "(steps of %.2g mm there): every clearance is lowered by √3 of that "
                  "step; place the job near the origin for micron figures",
                  file.string().c_str(), far_mm, common::floatStepMm(far_mm)));
  return mesh;
}

}  // namespace fieldpath::app
