#include "estimates.h"

#include "fieldpath/common/file_digest.h"
#include "fieldpath/geometry/cl_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/field/sampling.h"
#include "fieldpath/field/voxel_field.h"

namespace fieldpath::app {
namespace {

using common::InputError;
using geometry::Vec3;

std::string fmt(double value) {
  std::ostringstream s;
  s.precision(3);
  s << value;
  return s.str();
}

/// Axis-aligned box of the obstacles' vertices, mm.
struct Box {
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity());
  Vec3 hi = Vec3::Constant(-std::numeric_limits<double>::infinity());
  bool empty() const { return !(lo.x() <= hi.x()); }
  double diagonal() const { return empty() ? 0.0 : (hi - lo).norm(); }
};

Box obstacleBox(const Scene& scene) {
  Box box;
  for (const auto& mesh : scene.obstacles)
    for (const auto& v : mesh.vertices) {
      box.lo = box.lo.cwiseMin(v);
      box.hi = box.hi.cwiseMax(v);
    }
  return box;
}

double obstacleArea(const Scene& scene) {
  double area = 0.0;
  for (const auto& mesh : scene.obstacles)
    for (const auto& t : mesh.triangles) {
      const int n = static_cast<int>(mesh.vertices.size());
      if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= n || t[1] >= n || t[2] >= n) continue;
      const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
      area += 0.5 * (b - a).cross(c - a).norm();
    }
  return area;
}

/// Ball-centre arc length of the output passes, mm (what `path.step` divides), and how many.
struct PassLength {
  double total_mm = 0.0;
  std::size_t passes = 0;
  std::size_t input_postures = 0;
};

PassLength passLength(const Scene& scene) {
  PassLength out;
  if (scene.impeller_model && scene.guide_impeller) {
    // Passes are iso-v curves of the hub offset by the ball radius: their length is that of the
    // hub curve give or take the offset's curvature (≤ 2 × here for any sane radius).
    const auto& p = scene.impeller_model->params();
    double longest = 0.0;
    for (double v : {p.passes_v[0], p.passes_v[1], 0.5 * (p.passes_v[0] + p.passes_v[1])}) {
      double length = 0.0;
      constexpr int kSamples = 256;
      for (int i = 0; i < kSamples; ++i) {
        const double u0 = p.u_range[0] + (p.u_range[1] - p.u_range[0]) * i / kSamples;
        const double u1 = p.u_range[0] + (p.u_range[1] - p.u_range[0]) * (i + 1) / kSamples;
        length += (scene.impeller_model->hub(u1, v) - scene.impeller_model->hub(u0, v)).norm();
      }
      longest = std::max(longest, length);
    }
    out.passes = static_cast<std::size_t>(scene.path.passes);
    out.total_mm = 2.0 * longest * out.passes;
  } else if (scene.nominal) {
    const auto& postures = scene.nominal->postures;
    out.input_postures = postures.size();
    out.passes = std::max<std::size_t>(1, scene.nominal->blocks.size());
    for (std::size_t i = 1; i < postures.size(); ++i) {
      const double step = (postures[i].tip_mm - postures[i - 1].tip_mm).norm();
      if (std::isfinite(step)) out.total_mm += step;
    }
  }
  return out;
}

}  // namespace

double sampleCount(const Scene& scene, double step_mm) {
  // As field/sampling.h: each triangle cut into n² sub-triangles of area <= step² and edges
  // <= 1.5 step; degenerate triangles skipped; those under a quarter of a step² merged per cell
  // and normal direction, about one sample a step² of them (counted as four: the cells a
  // surface crosses, the directions of a curved one), never more than one a triangle.
  double count = 0.0, small_area = 0.0, small = 0.0;
  for (const auto& mesh : scene.obstacles)
    for (const auto& t : mesh.triangles) {
      const int nv = static_cast<int>(mesh.vertices.size());
      if (t[0] < 0 || t[1] < 0 || t[2] < 0 || t[0] >= nv || t[1] >= nv || t[2] >= nv) continue;
      const Vec3 &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
      const double area = 0.5 * (b - a).cross(c - a).norm();
      if (!(area > 0.0)) continue;
      const double n = field::triangleSplits(a, b, c, step_mm);
      if (n == 1.0 && field::isSmallPiece(area, step_mm)) {
        small_area += area;
        small += 1.0;
        continue;
      }
      count += n * n;
    }
  return count + std::min(small, 4.0 * small_area / (step_mm * step_mm));
}

void checkImpellerSize(const pathgen::Impeller& impeller, const std::string& where) {
  const double triangles = static_cast<double>(impeller.meshTriangleCount());
  // Passing: the meshes, once made, are held as the scene's obstacles (checkSceneSize).
  common::requireMemory(where + "obstacles.impeller.chord_tol", triangles * kBytesPerMeshTriangle,
                        fmt(triangles) + " triangles in the hub and blade meshes at chord_tol " +
                            fmt(impeller.params().chord_tol_mm) + " mm",
                        common::MemoryUse::kPassing);
}

void checkSampleStep(const Scene& scene, double step_mm, const std::string& key,
                     common::MemoryUse use) {
  const double samples = sampleCount(scene, step_mm);
  common::requireMemory(scene.file.string() + ": " + key, samples * kBytesPerSample,
                        fmt(samples) + " obstacle samples at " + fmt(step_mm) + " mm", use);
}

void checkSceneSize(const Scene& scene) {
  const std::string where = scene.file.string() + ": ";
  double triangles = 0.0;
  for (const auto& mesh : scene.obstacles) triangles += static_cast<double>(mesh.triangles.size());
  if (scene.part) triangles += static_cast<double>(scene.part->triangles.size());
  common::requireMemory(where + "obstacles", triangles * kBytesPerMeshTriangle,
                        fmt(triangles) + " mesh triangles with their collision hierarchies");

  // Passing: the samples are held by the field made of them, where a command makes one.
  checkSampleStep(scene, scene.field.sample_step_mm, "field.sample_step",
                  common::MemoryUse::kPassing);

  // field.r0 against the obstacles' extent: beyond it every sample acts on every node, the field
  // is no longer local and its cost (nodes × samples within r0) grows with r0³ for nothing.
  const Box box = obstacleBox(scene);
  if (!box.empty()) {
    for (int k = 0; k < 3; ++k)
      for (double v : {box.lo[k], box.hi[k]})
        if (std::abs(v) > common::kMaxCoordinateMm)
          throw InputError(where + "obstacles: a vertex at " + fmt(v) +
                           " mm is beyond +-1e6 mm (outside any machine)");
    // The tool + holder reach from the tip: the farthest a node can be from the path.
    double reach = scene.tool.length_mm;
    for (const auto& station : scene.holder) reach = std::max(reach, station.z_mm);
    const double limit = box.diagonal() + reach;
    // `check` makes no field: a short tool beside a small post was refused for a default r0 it
    // never uses (a helper's finding).
    if (scene.field.r0_mm > limit && scene.use != SceneUse::kPathGiven)
      throw InputError(where + "field.r0: " + fmt(scene.field.r0_mm) +
                       " mm exceeds the obstacles' extent plus the tool's reach (" + fmt(limit) +
                       " mm): every sample would act on every node at a cost growing as r0^3" +
                       // A scene written in metres lands here first (a blisk in metres read as a
                       // field.r0 its user never set).
                       (box.diagonal() < 1.0 ? "; the obstacles span " + fmt(box.diagonal()) +
                                                   " mm: is the scene in metres? every length is "
                                                   "read in millimetres"
                                             : std::string()));
  }

  // Lengths are millimetres: a scene written in metres (a tool radius of 0.003) ran for minutes
  // and marked every posture (a helper's finding); micro tools are real, so a note, not a refusal.
  const double tool_radius = scene.tool.radius_mm;
  const double span = box.empty() ? 0.0 : box.diagonal();
  // A field-only scene has no tool: the default radius is nobody's (a helper's finding).
  const std::string tool_said =
      scene.tool_given ? "the tool radius is " + fmt(tool_radius) + " mm and " : "";
  if ((scene.tool_given && tool_radius < 0.01) || (!box.empty() && span < 1.0))
    std::fprintf(stderr,
                 "note: %s: %sthe obstacles span %s mm: every length is read in millimetres (is "
                 "the scene in metres?)\n",
                 scene.file.string().c_str(), tool_said.c_str(), fmt(span).c_str());

  // Passing: generate holds them (holdPostures) where the other commands make none.
  requirePostures(scene, common::MemoryUse::kPassing);
}

void requirePostures(const Scene& scene, common::MemoryUse use) {
  // Output postures: path.step against the passes' length (and path.passes).
  const PassLength length = passLength(scene);
  // A nominal path's postures one for one too (no path.step): 1 M of them ran past an accepted
  // --max-memory 78M to 0.8 GB at 45 % of the passes (a memory sweep's).
  const bool stepped = scene.path.step_given || scene.impeller_model;
  if (!(length.total_mm > 0.0) || !(stepped || scene.nominal)) return;
  const double postures = (stepped ? length.total_mm / scene.path.step_mm : 0.0) +
                          2.0 * length.passes + static_cast<double>(length.input_postures);
  const std::string key = scene.guide_impeller ? "path.step (with path.passes)"
                          : stepped            ? "path.step"
                                               : "path.nominal";
  common::requireMemory(
      scene.file.string() + ": " + key, postures * kBytesPerPosture,
      fmt(postures) + " postures: " +
          (stepped ? fmt(length.total_mm) + " mm of passes every " + fmt(scene.path.step_mm) + " mm"
                   : std::string("the nominal path's, one for one")),
      use);
}

double estimatePostures(const std::filesystem::path& file) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const double bytes = double(fs::file_size(file, ec));
  if (ec) return 0.0;
  std::ifstream in(file, std::ios::binary);
  std::string head(std::size_t{1} << 16, '\0');
  in.read(head.data(), std::streamsize(head.size()));
  const std::size_t got = std::size_t(in.gcount());
  head.resize(got);
  const geometry::PathFormat format = geometry::pathFormatOf(file);
  // Text with NUL bytes is no path file (a sparse or binary file: its 10 GB of zero pages were
  // read in parallel for 15-48 s before line 1 was refused).
  if (format != geometry::PathFormat::Npy && head.find('\0') != std::string::npos)
    throw common::InputError(file.string() +
                             ": NUL bytes near its start: binary data, not a text path file "
                             "(.cl, APT)");
  if (format == geometry::PathFormat::Npy) {  // the rows its header says (float32 or 64)
    const auto shape = head.find("'shape': (");
    if (shape != std::string::npos) {
      const double rows = std::strtod(head.c_str() + shape + 10, nullptr);
      if (rows > 0) return rows;
    }
    return bytes / 24.0;
  }
  // A posture a line in .cl, a GOTO in APT (a GOTO may take two lines: cards of 72 columns).
  std::size_t count = 0;
  if (format == geometry::PathFormat::Apt)
    for (std::size_t at = head.find("GOTO"); at != std::string::npos;
         at = head.find("GOTO", at + 4))
      ++count;
  else
    count = std::count(head.begin(), head.end(), '\n');
  return count > 0 ? bytes * double(count) / double(std::max<std::size_t>(got, 1)) : bytes / 30.0;
}

void checkPathFileSize(const std::filesystem::path& file, const std::string& what) {
  // 256 B a posture held whole with its line and block: 1 M postures peaked 290 MB in convert
  // and 299 MB in view (80 B was assumed: both ran past an accepted --max-memory by 3-4 times,
  // a memory sweep's).
  common::requireMemory(what, estimatePostures(file) * 256.0, "its postures, whole");
}

geometry::PathFile readPathFileWhole(const std::filesystem::path& file, const std::string& what) {
  checkPathFileSize(file, what);
  const common::FileStamp stamp = common::fileStamp(file);
  geometry::PathFile path = geometry::readPathFile(file);
  common::requireUnchanged(file, stamp, "read");
  return path;
}

void checkVoxelSize(const Scene& scene, double voxel_mm, const std::string& key) {
  const double r0 = scene.field.r0_mm;
  // The field build refuses it too, but only when it comes (study: after its direct variants).
  if (voxel_mm > r0)
    throw common::InputError(sceneWhere(scene, key) + ": " + fmt(voxel_mm) +
                             " mm is coarser than field.r0 (" + fmt(r0) +
                             " mm): the grid cannot hold a field that ends within r0 "
                             "of the surfaces; use at most r0 (r0 / 10 for an accurate one)");
  const Box box = obstacleBox(scene);
  if (box.empty() || !(voxel_mm > 0.0)) return;
  const Vec3 size = (box.hi - box.lo).array() + 2.0 * r0;
  const double box_volume = size.x() * size.y() * size.z();
  const double shell_volume = obstacleArea(scene) * 2.0 * r0;
  const double nodes = std::min(box_volume, shell_volume) / (voxel_mm * voxel_mm * voxel_mm);
  // Passing: the field built holds its own bytes while it lives (field::VoxelField).
  common::requireMemory(scene.file.string() + ": " + key, nodes * field::kVoxelBytesPerNode,
                        fmt(nodes) + " voxel nodes within r0 = " + fmt(r0) +
                            " mm of the obstacles at h = " + fmt(voxel_mm) + " mm",
                        common::MemoryUse::kPassing);
}

}  // namespace fieldpath::app
