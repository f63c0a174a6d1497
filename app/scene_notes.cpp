/// What a scene's meshes leave unproven, said as notes by `generate` and `check`: open shells
/// (no inside) of the obstacles and of the part, and a part named as an obstacle too (scene.h
/// openObstacleNotes).
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <string>
#include <system_error>
#include <vector>

#include "estimates.h"
#include "fieldpath/common/memory.h"
#include "fieldpath/field/sampling.h"
#include "fieldpath/geometry/closed_shells.h"
#include "fieldpath/geometry/mesh.h"
#include "scene.h"

namespace fieldpath::app {

std::vector<std::string> openObstacleNotes(const Scene& scene, std::optional<double> voxel) {
  std::vector<std::string> notes;
  if (scene.part && scene.part_file) {
    // An open box wound inward is a pocket by its winding (a tool in it clear); wound outward, a
    // solid missing a face. Geometry cannot tell them: said, so that a mesh exported with a face
    // missing and its normals flipped is not taken on trust (a helper's buried tool read ok).
    // Sheets (a machined surface exported open, as the mesh example's hub) are no such doubt.
    const std::size_t closing = geometry::nearlyClosedOpenShells(*scene.part).size();
    if (closing > 0)
      notes.push_back(
          scene.part_file->string() + ": " + std::to_string(closing) +
          (closing == 1 ? " open shell nearly encloses" : " open shells nearly enclose") +
          " a volume (a solid with facets missing?): an open shell has no inside, so "
          "the cutter test does not see a tool wholly within it, and the surface "
          "check reads its sides by its winding (wound inward, a box with a face "
          "missing is a pocket): close the mesh to have its inside checked");
  }
  // The part named as an obstacle too (DESIGN: obstacles are never the machined surface): it
  // repels the tool from the surface it cuts, and a ball on it reads as colliding at every posture
  // (accepted without a word: a helper's finding). Said, not refused: a mesh of the whole part,
  // hub and blades, may be both where the hub is machined another way.
  if (scene.part_file)
    for (const std::filesystem::path& f : scene.obstacle_files) {
      std::error_code ec;
      if (!std::filesystem::equivalent(f, *scene.part_file, ec)) continue;
      notes.push_back(f.string() +
                      ": the part is also an obstacle: the surface being machined "
                      "repels the tool and a ball on it reads as colliding; obstacles are the "
                      "surfaces to keep clear of (give the machined surface as `part` only)");
    }
  // Walls thinner than half the voxel size: the voxel field interpolates across them between
  // nodes on both sides, and the far side's push outweighs the near side's beside them (a 0.2 mm
  // plate: at 0.02 mm over it Fz +0.67 at h 0.4, -2.0 at 0.5, -6.4 at 1; the direct field +11.6).
  // The samples see such walls whatever their step (law.h's thin-wall rule).
  // Looked for where the samples fit what is left (they are made again here, one obstacle at a
  // time, with a cell map beside them: `check` makes none otherwise).
  const double step_mm = scene.field.sample_step_mm;
  const double voxel_mm = voxel.value_or(0.0);
  const bool look_for_thin =
      step_mm > 0.0 && voxel_mm > 0.0 &&
      sampleCount(scene, step_mm) * (kBytesPerSample + 64.0) <= common::memoryLeftBytes();
  for (std::size_t i = 0; i < scene.obstacle_files.size() && i < scene.obstacles.size(); ++i) {
    if (!look_for_thin) break;
    const field::ThinWall wall = field::thinnestWall(
        field::sampleObstacles({&scene.obstacles[i], 1}, step_mm, scene.field.weights),
        std::max(step_mm, 0.5 * voxel_mm));
    if (!(wall.thickness_mm < 0.5 * voxel_mm)) continue;
    char text[400];
    std::snprintf(text, sizeof text,
                  ": walls down to %.3g mm thick (at %.4g, %.4g, %.4g), under half the voxel "
                  "size steered with (%g mm): the voxel field interpolates across them and may "
                  "pull a point beside them in; a voxel_size of at most %.3g mm (twice their "
                  "thickness) or `generate --direct` keeps it outward",
                  wall.thickness_mm, wall.at_mm.x(), wall.at_mm.y(), wall.at_mm.z(), voxel_mm,
                  2.0 * wall.thickness_mm);
    notes.push_back(scene.obstacle_files[i].string() + text);
  }
  for (std::size_t i = 0; i < scene.obstacle_files.size() && i < scene.obstacles.size(); ++i) {
    const std::size_t open = geometry::openShells(scene.obstacles[i]).size();
    if (open == 0) continue;
    const std::size_t edges = geometry::validateMesh(scene.obstacles[i]).open_edges;
    notes.push_back(scene.obstacle_files[i].string() + ": " + std::to_string(open) +
                    (open == 1 ? " shell is" : " shells are") + " open (" + std::to_string(edges) +
                    " edge" + (edges == 1 ? "" : "s") +
                    " with one triangle): its surface repels and is checked, but an open shell "
                    "has no inside, so a tool or holder wholly inside the solid it bounds reads as "
                    "clear (close the mesh to have its inside checked)");
  }
  return notes;
}

double meshExtentMm(const geometry::TriangleMesh& mesh) {
  if (mesh.vertices.empty()) return 0.0;
  Eigen::AlignedBox3d box;
  for (const geometry::Vec3& v : mesh.vertices) box.extend(v);
  return box.diagonal().norm();
}

double pathExtentMm(const geometry::PathFile& path, bool passes_only) {
  Eigen::AlignedBox3d box;
  for (const geometry::PathBlock& block : path.blocks)
    if (!passes_only || block.kind == geometry::PathBlock::Kind::Pass)
      for (std::size_t i = block.begin; i < block.end && i < path.postures.size(); ++i)
        box.extend(path.postures[i].tip_mm);
  return box.isEmpty() ? 0.0 : box.diagonal().norm();
}

std::vector<MeshScaleWarning> meshScaleWarnings(const Scene& scene,
                                                const geometry::PathFile* path) {
  // Each mesh file's extent (its box's diagonal, mm), and the largest of them and of the nominal
  // path's tips: what a mesh in metres stands beside.
  struct Extent {
    std::string name;
    double diagonal_mm = 0.0;
  };
  const auto diagonal = meshExtentMm;
  std::vector<Extent> meshes;
  for (std::size_t i = 0; i < scene.obstacle_files.size() && i < scene.obstacles.size(); ++i)
    meshes.push_back({obstacleName(scene, i), diagonal(scene.obstacles[i])});
  if (scene.part && scene.part_file)
    meshes.push_back(
        {"part (" + scene.part_file->filename().string() + ")", diagonal(*scene.part)});
  Extent largest{"", 0.0};
  for (const Extent& m : meshes)
    if (m.diagonal_mm > largest.diagonal_mm) largest = m;
  // The parametric impeller's meshes (obstacles past the files', and its hub) are references
  // too, not suspects (a pin in metres beside the impeller went unsaid: a reviewer's).
  for (std::size_t i = scene.obstacle_files.size(); i < scene.obstacles.size(); ++i)
    if (const double d = diagonal(scene.obstacles[i]); d > largest.diagonal_mm)
      largest = {"the impeller's blades", d};
  if (scene.part && !scene.part_file)
    if (const double d = diagonal(*scene.part); d > largest.diagonal_mm)
      largest = {"the impeller's hub", d};
  // The paths the scene's meshes stand beside: its nominal path, and the path `check` reads.
  for (const geometry::PathFile* p : {scene.nominal ? &*scene.nominal : nullptr, path}) {
    if (!p || p->postures.empty()) continue;
    if (const double d = pathExtentMm(*p, false); d > largest.diagonal_mm)
      largest = {"the path (" + p->file.filename().string() + ")", d};
  }
  // A whole mesh under 1 mm beside one at least 100 times larger: a pin exported in metres stood
  // 8 um wide 3 mm from the passes, its field too weak to steer and its solid never met, and the
  // path read safe where the holder ran into the real pin (a CAM engineer's mould, a helper's).
  // Not refused: a speck of that size may be meant, and the scene's other units are right.
  std::vector<MeshScaleWarning> warnings;
  for (const Extent& m : meshes) {
    if (!(m.diagonal_mm > 0.0) || m.diagonal_mm >= 1.0 ||
        largest.diagonal_mm < 100.0 * m.diagonal_mm)
      continue;
    char text[512];
    std::snprintf(text, sizeof text,
                  "%s spans %.3g mm, %.0f times less than %s (%.4g mm): every length is read in "
                  "millimetres; a mesh in metres (scale it by 1000) is checked at that size, "
                  "and a path read safe beside it is not",
                  m.name.c_str(), m.diagonal_mm, largest.diagonal_mm / m.diagonal_mm,
                  largest.name.c_str(), largest.diagonal_mm);
    warnings.push_back({m.name, text});
  }
  return warnings;
}

}  // namespace fieldpath::app
