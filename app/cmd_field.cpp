/// fieldpath field probe|build: the repulsive field of a scene's obstacles (DESIGN.md "The field").
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.h"
#include "errors.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_names.h"
#include "fieldpath/common/input_file.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/voxel_field.h"
#include "progress.h"
#include "scene.h"

namespace fieldpath::app {
namespace {

using field::Vec3;

/// `x y z` per line; `#` starts a comment; blank lines are skipped; a UTF-8 byte-order mark is
/// read past, coordinates beyond ±kMaxCoordinateMm are refused (as in every input).
std::vector<Vec3> readPoints(const std::string& file) {
  common::requireRegularFile(file, "points file");
  std::ifstream in(file);
  if (!in) throw InputError(file + ": cannot open points file");
  std::vector<Vec3> points;
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (number == 1 && line.rfind("\xEF\xBB\xBF", 0) == 0) line.erase(0, 3);
    if (const auto hash = line.find('#'); hash != std::string::npos) line.erase(hash);
    std::istringstream fields(line);
    std::vector<std::string> words;
    for (std::string w; fields >> w;) words.push_back(w);
    if (words.empty()) continue;
    if (words.size() != 3)
      throw InputError(file + ":" + std::to_string(number) + ": expected 3 numbers `x y z`, got " +
                       std::to_string(words.size()) + " fields");
    Vec3 p;
    for (int a = 0; a < 3; ++a) {
      std::size_t used = 0;
      try {
        p[a] = std::stod(words[a], &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != words[a].size() || !std::isfinite(p[a]))
        throw InputError(file + ":" + std::to_string(number) + ": '" + words[a] +
                         "' is not a finite number");
      if (std::abs(p[a]) > common::kMaxCoordinateMm)
        throw InputError(file + ":" + std::to_string(number) + ": '" + words[a] +
                         "' is beyond +-1e6 mm (no machine is that large)");
    }
    points.push_back(p);
  }
  return points;
}

struct FieldOptions {
  std::string scene;
  std::string points;
  bool direct = false;
  double voxel_mm = 0.0;      ///< 0: the scene's field.voxel_size
  std::string interpolation;  ///< "" : the scene's
  std::string out;
  std::string save_field;
  /// As the global --max-memory (512, 512M, 4G); empty: the global (common::memoryLimitBytes).
  std::string max_memory;
  std::string backend;            ///< "" : the scene's field.backend
  double refine_tolerance = -1.0; ///< < 0: the scene's field.refine_tolerance
};

/// The scene's obstacle samples and the exact field over them.
struct Obstacles {
  Scene scene;
  std::unique_ptr<field::DirectField> direct;
  double sampling_s = 0.0;
};

Obstacles loadObstacles(const FieldOptions& o) {
  // The sub-command's --max-memory is the limit of every estimate, the scene's included.
  if (!o.max_memory.empty()) common::limitMemory(o.max_memory, "--max-memory");
  // The obstacles and the field's keys: no part, no nominal path (neither is the field's).
  Obstacles result{loadScene(o.scene, SceneUse::kField), nullptr, 0.0};
  const auto start = std::chrono::steady_clock::now();
  const Scene& s = result.scene;
  result.direct = std::make_unique<field::DirectField>(
      field::sampleObstacles(s.obstacles, s.field.sample_step_mm, s.field.weights), s.field);
  result.sampling_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

field::VoxelRequest voxelRequest(const FieldOptions& o, const Scene& scene, bool quiet) {
  field::VoxelRequest request(scene.field.voxel);
  if (o.voxel_mm > 0.0) request.voxel_size_mm = o.voxel_mm;
  if (!o.interpolation.empty())
    request.interpolation = o.interpolation == "quadratic" ? field::Interpolation::Quadratic
                                                           : field::Interpolation::Trilinear;
  if (!o.backend.empty()) request.backend = *field::fieldBackendNamed(o.backend);
  if (o.refine_tolerance >= 0.0) request.refine_tolerance = o.refine_tolerance;
  request.progress = makeProgressLine(quiet);
  return request;
}

std::string mib(std::size_t bytes) {
  char text[32];
  std::snprintf(text, sizeof text, "%.1f MiB", bytes / (1024.0 * 1024.0));
  return text;
}

void probe(const FieldOptions& o, const GlobalOptions& global) {
  // Before reading: the points, their forces and the output text are held whole, ~150 bytes a
  // point, and a point's line is 6 bytes at least (a helper's 3 GB file ran to 12.6 GB under
  // --max-memory 256M).
  std::error_code size_ec;
  const double point_bytes = double(std::filesystem::file_size(o.points, size_ec));
  if (!size_ec)
    common::requireMemory("--points " + o.points, point_bytes / 6.0 * 150.0,
                          "its points, their forces and the output text, whole");
  const std::vector<Vec3> points = readPoints(o.points);
  const Obstacles obstacles = loadObstacles(o);
  std::unique_ptr<field::VoxelField> voxel;
  if (!o.direct) {
    voxel = std::make_unique<field::VoxelField>(*obstacles.direct,
                                                voxelRequest(o, obstacles.scene, global.quiet));
    if (!o.save_field.empty()) voxel->save(o.save_field);
  }
  const field::ForceField& f =
      voxel ? static_cast<const field::ForceField&>(*voxel) : *obstacles.direct;
  std::vector<Vec3> forces(points.size());
  f.evaluate(points, forces);
  // What was probed, in the header: the voxel size and the interpolation (a --voxel or
  // --interpolation not taken read as the scene's, unseen).
  std::string what = "direct field";
  if (voxel) {
    char text[96];
    std::snprintf(
        text, sizeof text, "voxel field, h %g mm, %s", voxel->voxelSizeMm(),
        voxel->interpolation() == field::Interpolation::Quadratic ? "quadratic" : "trilinear");
    what = text;
  }
  std::string out = "# x y z Fx Fy Fz (mm; " + what + ")\n";
  char line[256];
  for (std::size_t i = 0; i < points.size(); ++i) {
    // + 0.0: a component the interpolation left at -0 prints 0.
    std::snprintf(line, sizeof line, "%.9g %.9g %.9g %.9g %.9g %.9g\n", points[i].x(),
                  points[i].y(), points[i].z(), forces[i].x() + 0.0, forces[i].y() + 0.0,
                  forces[i].z() + 0.0);
    out += line;
  }
  std::fputs(out.c_str(), stdout);
}

void build(const FieldOptions& o, const GlobalOptions& global) {
  common::checkOutputFile(o.out, "--out");  // before the work, not after
  // The file is OpenVDB whatever its name: a `field.txt` would be a binary file misnamed.
  if (common::lowerExtension(o.out) != ".vdb")
    throw InputError("--out " + o.out + ": the field is written as OpenVDB, name it *.vdb");
  const Obstacles obstacles = loadObstacles(o);
  const field::VoxelRequest request = voxelRequest(o, obstacles.scene, global.quiet);
  // CUDA's start-up (the device's context, once per process) before the timed build.
  double cuda_start_s = 0.0;
  if (request.backend == field::FieldBackend::Auto ||
      request.backend == field::FieldBackend::Cuda) {
    const auto start = std::chrono::steady_clock::now();
    field::cudaFieldBackendAvailable();
    cuda_start_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  const field::VoxelField voxel(*obstacles.direct, request);
  voxel.save(o.out);
  common::commitOutputs();  // a summary lost from here takes it not away
  const field::VoxelStats& s = voxel.stats();
  const auto& samples = obstacles.direct->samples();
  std::printf("obstacles: %zu meshes, %zu samples (step %g mm, %.0f mm²)\n",
              obstacles.scene.obstacles.size(), samples.size(),
              obstacles.scene.field.sample_step_mm, samples.area_mm2);
  std::printf("voxel size: %g mm, %s\n", request.voxel_size_mm,
              request.interpolation == field::Interpolation::Trilinear ? "trilinear" : "quadratic");
  std::printf("estimated nodes: %zu\n", s.estimated_nodes);
  // The dense box is level 0's (h): the refined levels' nodes are not of it (1532.86 % read).
  const std::size_t level0_nodes = s.active_nodes - std::min(s.active_nodes, s.refined_nodes);
  std::printf("active nodes: %zu (%s%.2f %% of the dense box)\n", s.active_nodes,
              s.levels > 1 ? ("level 0 " + std::to_string(level0_nodes) + ": ").c_str() : "",
              s.dense_box_nodes ? 100.0 * level0_nodes / s.dense_box_nodes : 0.0);
  std::printf("dense-box nodes: %zu\n", s.dense_box_nodes);
  std::printf("memory: %s\n", mib(s.memory_bytes).c_str());
  if (s.levels > 1)
    std::printf("levels: %d (%zu refined cells, %zu refined nodes)\n", s.levels, s.refined_cells,
                s.refined_nodes);
  std::printf("time: sampling %.3f s, build %.3f s (%s nodes %.3f s, refinement %.3f s)\n",
              obstacles.sampling_s, s.build_seconds, s.backend.c_str(), s.nodes_seconds,
              s.refine_seconds);
  if (s.backend == "cuda") std::printf("cuda start-up (before the build): %.3f s\n", cuda_start_s);
  std::printf("wrote %s\n", o.out.c_str());
}

}  // namespace

void addFieldCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand(
      "field", "The repulsive field of a scene's obstacles: probe it, build its voxels");
  cmd->require_subcommand(1);
  auto options = std::make_shared<FieldOptions>();

  auto* probe_cmd = cmd->add_subcommand("probe", "Print `x y z Fx Fy Fz` at the points of a file");
  probe_cmd->add_option("scene", options->scene, "Scene file (YAML)")->required();
  probe_cmd->add_option("--points", options->points, "Points file: `x y z` a line, # comments")
      ->required();
  auto* direct = probe_cmd->add_flag("--direct", options->direct,
                                     "Exact sum over the samples within r0 (no voxels)");
  probe_cmd
      ->add_option("--voxel", options->voxel_mm,
                   "Voxel size h, mm (default: the scene's field.voxel_size)")
      ->check(positiveFinite("mm"))
      ->excludes(direct);
  probe_cmd
      ->add_option("--interpolation", options->interpolation,
                   "trilinear | quadratic (default: the scene's)")
      ->check(CLI::IsMember({"trilinear", "quadratic"}))
      ->excludes(direct);
  probe_cmd
      ->add_option("--save-field", options->save_field,
                   "Also write the voxel field to this .vdb file")
      ->excludes(direct);
  probe_cmd->add_option(
      "--max-memory", options->max_memory,
      "Refuse work estimated above this (MiB, or 512M, 4G; as before the command)");
  probe_cmd->callback([options, &global] { probe(*options, global); });

  auto* build_cmd =
      cmd->add_subcommand("build", "Build the sparse voxel field and write it as OpenVDB (.vdb)");
  build_cmd->add_option("scene", options->scene, "Scene file (YAML)")->required();
  build_cmd
      ->add_option("--voxel", options->voxel_mm,
                   "Voxel size h, mm (default: the scene's field.voxel_size)")
      ->check(positiveFinite("mm"));
  build_cmd
      ->add_option("--interpolation", options->interpolation,
                   "trilinear | quadratic (default: the scene's)")
      ->check(CLI::IsMember({"trilinear", "quadratic"}));
  build_cmd->add_option("--out", options->out, "Output .vdb file")->required();
  for (auto* sub : {probe_cmd, build_cmd})
    sub->add_option("--backend", options->backend,
                    "Where the nodes are computed: auto | cpu | cuda | reference (the per-node "
                    "build the others are checked against; default: the scene's field.backend)")
        ->check(CLI::IsMember({"auto", "cpu", "cuda", "reference"}));
  build_cmd
      ->add_option("--refine-tolerance", options->refine_tolerance,
                   "Split cells whose error estimate exceeds this fraction (default: the "
                   "scene's field.refine_tolerance; 0: uniform)")
      ->check(finiteNumber("", true));
  build_cmd->add_option(
      "--max-memory", options->max_memory,
      "Refuse work estimated above this (MiB, or 512M, 4G; as before the command)");
  build_cmd->callback([options, &global] { build(*options, global); });
}

}  // namespace fieldpath::app
