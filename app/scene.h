#pragma once
/// Scene files (DESIGN.md "Scene files"): one YAML file describes a job. Every key is read into a
/// Scene here, checked, and its meshes loaded; relative paths are relative to the scene file.
/// Defaults are those of the params structs (field/params.h, dynamics/params.h, pathgen/params.h,
/// geometry/tool.h), documented there once.
#include <filesystem>
#include <optional>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "fieldpath/dynamics/params.h"
#include "fieldpath/field/params.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/params.h"

namespace fieldpath::app {

/// What a command reads of a scene (loadScene).
enum class SceneUse { kJob, kPathGiven, kField };

/// A mesh file of a scene much smaller than the rest of it (meshScaleWarnings).
struct MeshScaleWarning {
  std::string mesh;  ///< "obstacles[2] (pin.stl)", "part (hub.stl)"
  std::string text;  ///< the whole warning, naming the mesh first
};

struct Scene {
  std::filesystem::path file;  ///< the scene file itself
  SceneUse use = SceneUse::kJob;  ///< what it was read for

  /// `obstacles:` surfaces that repel (world frame, mm), loaded: `- mesh: FILE` entries in order,
  /// then the impeller's blades once resolveImpeller has run.
  std::vector<geometry::TriangleMesh> obstacles;
  std::vector<std::filesystem::path> obstacle_files;  ///< the `- mesh:` files, resolved
  /// Their keys in the scene's list (`obstacles[2]`: an impeller entry may come before them).
  std::vector<std::string> obstacle_keys;

  /// `part:` the machined surface (a mesh file, loaded here), or the impeller's hub with
  /// `guide: { impeller: hub }` (once resolveImpeller has run). Never repels.
  std::optional<geometry::TriangleMesh> part;
  std::optional<std::filesystem::path> part_file;
  /// What loading the meshes said: their mending and turning (meshNotes), and the warnings of
  /// their scale against each other and the nominal path (meshScaleWarnings), for the reports.
  std::vector<std::string> mesh_notes;
  std::vector<MeshScaleWarning> scale_warnings;

  /// `obstacles: - impeller: {...}`: the node as written, for resolveImpeller.
  std::optional<YAML::Node> impeller;
  /// `guide: { impeller: X }`: X as written (e.g. `hub`), for resolveImpeller.
  std::optional<YAML::Node> guide_impeller;
  /// Filled by resolveImpeller.
  std::optional<pathgen::Impeller> impeller_model;

  geometry::ToolSpec tool;            ///< `tool:`
  bool tool_given = false;            ///< `tool:` is in the file (generate and check need it)
  int tool_shape_line = 0;            ///< 1-based line of `tool.shape` (0: not known)
  geometry::HolderProfile holder;     ///< `holder:` [[z, radius], ...]
  double clearance_mm = 0.5;          ///< `clearance:` tool+holder ↔ obstacles, mm
  field::FieldParams field;           ///< `field:`
  dynamics::DynamicsParams dynamics;  ///< `dynamics:`
  pathgen::PathParams path;           ///< `path:`
  /// `path.nominal:` the nominal path file (.cl, APT, .npy), read here: the passes' source.
  std::optional<geometry::PathFile> nominal;
  pathgen::LinkParams links;  ///< `links:`
};

/// Reads `file`, checks every key and value, loads the mesh files and, where the scene names the
/// parametric impeller, calls resolveImpeller. Throws common::InputError "FILE:LINE: key: why"
/// (key as a dotted path, e.g. `field.r0`, `obstacles[2].mesh`) for a missing or unreadable
/// file, bad YAML, an unknown key, a value of the wrong type or out of range, or a mesh that
/// cannot be loaded.
/// `use` SceneUse::kPathGiven for the commands given their own path (`check --path`): the
/// scene's `path.nominal` is then not read (a stale or broken one does not stop them); kField for
/// the field commands (DESIGN: they need only `obstacles` and `field`): neither it nor the
/// `part:` file is read (the part's mesh was estimated and refused). (The meshes are sized with
/// their collision hierarchies all the same: without them field build ran 1.1 times past an
/// accepted limit, its build's own passing structures being in no estimate.)
Scene loadScene(const std::filesystem::path& file, SceneUse use = SceneUse::kJob);
/// The scene's `path.nominal` file, where the file reads as YAML that names one (else empty):
/// what a command must not take for an output of its own before the scene is loaded.
std::filesystem::path nominalPathOf(const std::filesystem::path& file);

/// A refusal raised below the app that begins with a key of the scene this process read
/// ("links.safe_z: must be ...", "field.refine_tolerance: ..."): the scene's file and the key's
/// line put in front, as the scene's own checks write them. Any other message as it is.
std::string placeSceneKey(const std::string& message);

/// Obstacle `index` (0-based, in scene.obstacles' order) as a user finds it in the scene:
/// "obstacles[2] (pin.stl)" (the list's 1-based key and the file), or "the impeller's blade 3".
/// Reports and messages name the file, not only a number ("obstacle 8" sent a user counting).
std::string obstacleName(const Scene& scene, std::size_t index);

/// "FILE:LINE: key" (LINE where the scene gives the key): the start of a refusal of one setting.
std::string sceneWhere(const Scene& scene, const std::string& key);

/// The value of `map`'s key that a module's error `message` names first as a whole word
/// (`corner_radius` also as `corner radius`), else `map` itself: its line is the key's.
YAML::Node valueNamedIn(const YAML::Node& map, const std::string& message);

/// "FILE:LINE: tool.shape" (LINE where known): the start of a refusal of the scene's tool.
inline std::string toolShapeWhere(const Scene& scene) {
  return scene.file.string() +
         (scene.tool_shape_line > 0 ? ":" + std::to_string(scene.tool_shape_line) : "") +
         ": tool.shape";
}

/// One note per obstacle mesh file with open shells (triangles joined through their vertices
/// whose surface does not close): its surface repels and is checked, but an open shell has no
/// inside, so a tool wholly inside the solid it was meant to bound (a fixture exported with a
/// facet missing) reads as clear. Empty when every shell is closed; the impeller's blades, sheets
/// by design, are not files and get none. The part's file gets one too, first (its open shells
/// have no inside for the cutter test, and their winding says which side is the part's). A part
/// file named as an obstacle too gets one (it repels the tool from the surface it cuts). Walls
/// thinner than half of `voxel_mm` (the voxel size the job steers with; none: no voxels) get one.
std::vector<std::string> openObstacleNotes(const Scene& scene, std::optional<double> voxel_mm);
/// The diagonal of a mesh's box (mm; 0 for none).
double meshExtentMm(const geometry::TriangleMesh& mesh);
/// The diagonal of the box of a path's tips (mm; 0 for none), of its pass blocks only where
/// `passes_only` (not the links' climbs to the travel plane).
double pathExtentMm(const geometry::PathFile& path, bool passes_only);

/// A mesh file (an obstacle or the part) whose whole extent is under 1 mm beside a mesh, the
/// nominal path or `path` (check's) 100 times larger: one warning each (a mesh in metres among
/// millimetres). Said by loadScene on stderr (check says those `path` adds), kept in
/// generate's report.json (mesh_notes).
std::vector<MeshScaleWarning> meshScaleWarnings(const Scene& scene,
                                                const geometry::PathFile* path = nullptr);

/// Turns scene.impeller / scene.guide_impeller into meshes (obstacles, part) and
/// scene.impeller_model. Lives in scene_impeller.cpp (the impeller's owner replaces it).
void resolveImpeller(Scene& scene);

}  // namespace fieldpath::app
