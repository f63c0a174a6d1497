#include "view_data.h"

#include "estimates.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "cutter_note.h"
#include "errors.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/dynamics/frame.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"
#include "job.h"
#include "path_report.h"
#include "scene.h"
#include "surface_check.h"
#include "to_zbuffer.h"

#include "view_files.h"

namespace fieldpath::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using view_files::CheckJson;
using view_files::readCheckJson;
using view_files::readJson;
using view_files::readSurface;
using view_files::SurfaceFigures;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ------------------------------------------------------------------------------ meshes, tool

Eigen::AlignedBox3d boxOf(const std::vector<ViewMesh>& meshes) {
  Eigen::AlignedBox3d box;
  for (const ViewMesh& m : meshes)
    for (const auto& v : m.mesh.vertices) box.extend(v);
  return box;
}

/// Chordal tolerance of the page's tool mesh: fine enough to look round, small enough to ship.
double displayChordMm(const geometry::ToolSpec& tool) {
  return std::max(0.002, tool.radius_mm / 250.0);
}

// ------------------------------------------------------------------------------ angles

/// The stations of the scene's passes in a hash grid of cells `cell_mm` wide: the nearest one to
/// a ball centre.
class Stations {
 public:
  Stations(const std::vector<pathgen::Pass>& passes) {
    std::vector<double> steps;
    for (const pathgen::Pass& p : passes)
      for (std::size_t i = 0; i < p.samples.size(); ++i) {
        samples_.push_back(&p.samples[i]);
        if (i > 0) steps.push_back((p.samples[i].centre_mm - p.samples[i - 1].centre_mm).norm());
      }
    double step = 1.0;
    if (!steps.empty()) {
      std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
      step = steps[steps.size() / 2];
    }
    cell_mm_ = std::max(2.0 * step, 0.05);
    for (std::size_t i = 0; i < samples_.size(); ++i)
      cells_[key(cellOf(samples_[i]->centre_mm))].push_back(i);
  }

  /// The nearest station within `max_mm`, or null.
  const pathgen::PassSample* nearest(const geometry::Vec3& c, double max_mm,
                                     double* distance) const {
    const Eigen::Vector3i home = cellOf(c);
    const int rings = static_cast<int>(std::ceil(max_mm / cell_mm_)) + 1;
    const pathgen::PassSample* best = nullptr;
    double best_d = max_mm;
    for (int r = 0; r <= rings; ++r) {
      if (best && (r - 1) * cell_mm_ > best_d) break;
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
            const auto it = cells_.find(key(home + Eigen::Vector3i(dx, dy, dz)));
            if (it == cells_.end()) continue;
            for (std::size_t i : it->second) {
              const double d = (samples_[i]->centre_mm - c).norm();
              if (d <= best_d) best_d = d, best = samples_[i];
            }
          }
    }
    if (distance) *distance = best_d;
    return best;
  }

 private:
  Eigen::Vector3i cellOf(const geometry::Vec3& p) const {
    const auto f = [this](double x) {
      return static_cast<int>(std::clamp(std::floor(x / cell_mm_), -1e6, 1e6));
    };
    return {f(p.x()), f(p.y()), f(p.z())};
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffff; };
    return u(c.x()) | (u(c.y()) << 21) | (u(c.z()) << 42);
  }
  std::vector<const pathgen::PassSample*> samples_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
  double cell_mm_ = 1.0;
};

/// Pass numbers and arc length from the file's blocks; tilt and lead in the frame (f, n, b) of
/// the nearest station of the scene's passes (DESIGN.md "The dynamics": a = sin L f + cos L
/// (cos T n − sin T b)), the frames `generate` steers in.
void computeAngles(const Scene& scene, ViewPath& p) {
  const auto& postures = p.file.postures;
  const std::size_t n = postures.size();
  const double offset = geometry::cornerRadius(scene.tool);
  p.pass.assign(n, 0);
  p.s_mm.assign(n, kNaN);
  p.tilt_deg.assign(n, kNaN);
  p.lead_deg.assign(n, kNaN);
  int pass = 0;
  for (const geometry::PathBlock& block : p.file.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Pass) continue;
    ++pass;
    double s = 0;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      if (i > block.begin)
        s += (geometry::ballCentre(postures[i], offset) -
              geometry::ballCentre(postures[i - 1], offset))
                 .norm();
      p.pass[i] = pass;
      p.s_mm[i] = s;
    }
  }
  std::vector<pathgen::Pass> passes;
  try {
    passes = sceneJob(scene).passes;
  } catch (const InputError& e) {
    p.angles_source = std::string("not known: the scene has no passes (") + e.what() + ")";
    return;
  }
  const Stations stations(passes);
  const double max_mm = std::max(2.0, scene.tool.radius_mm);
  double worst = 0;
  std::size_t found = 0, wanted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.pass[i] == 0) continue;
    ++wanted;
    const geometry::Vec3 c = geometry::ballCentre(postures[i], offset);
    double d = 0;
    const pathgen::PassSample* at = stations.nearest(c, max_mm, &d);
    if (!at) continue;
    ++found;
    worst = std::max(worst, d);
    const std::array<double, 2> angles =
        dynamics::anglesOfAxis({at->feed, at->normal, at->binormal}, postures[i].axis);
    p.lead_deg[i] = angles[0] * geometry::kRadToDeg;
    p.tilt_deg[i] = angles[1] * geometry::kRadToDeg;
  }
  std::ostringstream s;
  s.precision(3);
  s << "in the frames of the scene's passes";
  if (worst < 1e-6)
    s << " (at their stations)";
  else
    s << " (nearest station, up to " << worst << " mm away)";
  if (found < wanted)
    s << "; " << wanted - found << " pass postures have no station within " << max_mm << " mm";
  p.angles_source = s.str();
}

}  // namespace

geometry::TriangleMesh decimateMesh(const geometry::TriangleMesh& mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles || mesh.vertices.empty()) return mesh;
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  const double diag = std::max(box.diagonal().norm(), 1e-9);
  double cell = std::max(
      std::sqrt(2.0 * geometry::meshArea(mesh) / double(std::max<std::size_t>(1, max_triangles))),
      diag * 1e-6);
  geometry::TriangleMesh out;
  for (int attempt = 0; attempt < 60; ++attempt, cell *= 1.15) {
    out = {};
    std::unordered_map<std::uint64_t, int> index;
    std::vector<Eigen::Vector3d> sum;
    std::vector<int> weight, map(mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3d q = ((mesh.vertices[i] - box.min()) / cell).array().floor();
      const std::uint64_t key =
          std::uint64_t(q.x()) | (std::uint64_t(q.y()) << 21) | (std::uint64_t(q.z()) << 42);
      const auto [it, added] = index.emplace(key, int(sum.size()));
      if (added) sum.emplace_back(Eigen::Vector3d::Zero()), weight.push_back(0);
      sum[it->second] += mesh.vertices[i];
      ++weight[it->second];
      map[i] = it->second;
    }
    std::set<std::array<int, 3>> seen;
    for (const auto& t : mesh.triangles) {
      const Eigen::Vector3i m(map[t.x()], map[t.y()], map[t.z()]);
      if (m.x() == m.y() || m.y() == m.z() || m.x() == m.z()) continue;
      std::array<int, 3> sorted{m.x(), m.y(), m.z()};
      std::sort(sorted.begin(), sorted.end());
      if (seen.insert(sorted).second) out.triangles.push_back(m);
    }
    if (out.triangles.size() > max_triangles) continue;
    // Keep the used vertices only, at the mean of their cell.
    std::vector<int> used(sum.size(), -1);
    for (auto& t : out.triangles)
      for (int c = 0; c < 3; ++c) {
        int& u = used[t[c]];
        if (u < 0) {
          u = int(out.vertices.size());
          out.vertices.push_back(sum[t[c]] / weight[t[c]]);
        }
        t[c] = u;
      }
    return out;
  }
  throw std::runtime_error("decimateMesh: no cell size fits " + std::to_string(max_triangles) +
                           " triangles");
}

// ------------------------------------------------------------------------------ gatherView

ViewData gatherView(const ViewRequest& request) {
  ViewData d;
  // Given its own path, view reads it beside a scene whose path.nominal is stale or gone, as
  // check does (a helper's: view refused what check and simulate read); the passes' frames, and
  // so the lead and tilt, are then not known, and a note says why.
  std::string nominal_unread;
  const Scene scene = [&] {
    if (request.path.empty()) return loadScene(request.scene);
    try {
      return loadScene(request.scene);
    } catch (const InputError& e) {
      Scene given = loadScene(request.scene, SceneUse::kPathGiven);  // throws if not the nominal
      nominal_unread = e.what();
      return given;
    }
  }();
  if (!nominal_unread.empty())
    d.notes.push_back("the scene's path.nominal is not read (" + nominal_unread +
                      "): --path is shown without the passes' lead and tilt");
  d.scene_file = scene.file;
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    ViewMesh m;
    m.name = i < scene.obstacle_files.size()
                 ? scene.obstacle_files[i].filename().string()
                 : "impeller blade " + std::to_string(i - scene.obstacle_files.size() + 1);
    m.mesh = scene.obstacles[i];
    d.meshes.push_back(std::move(m));
  }
  if (scene.part) {
    ViewMesh m;
    m.name = scene.part_file ? scene.part_file->filename().string() : "impeller hub";
    m.role = ViewMesh::Role::Part;
    m.mesh = *scene.part;
    d.meshes.push_back(std::move(m));
  } else {
    d.notes.push_back("the scene has no `part`");
  }
  d.box = boxOf(d.meshes);
  if (d.box.isEmpty()) throw InputError(scene.file.string() + ": no mesh to show");
  d.tool_spec = scene.tool;
  d.tool = geometry::toolMesh(scene.tool, scene.holder, displayChordMm(scene.tool));
  d.required_mm = scene.clearance_mm;

  // The check folder first: it names the path it checked.
  std::optional<CheckJson> check;
  if (!request.check_dir.empty()) check = readCheckJson(request.check_dir);

  fs::path path_file = request.path;
  if (path_file.empty() && check && !check->path.empty()) {
    if (!fs::exists(check->path))
      throw InputError("--check " + request.check_dir.string() + ": check.json names the path " +
                       check->path + ", which is not there: give --path FILE");
    path_file = check->path;
  }
  if (!path_file.empty()) {
    ViewPath p;
    p.file = readPathFileWhole(path_file,
                               (request.path.empty() ? "path " : "--path ") + path_file.string());
    pathgen::requireSteadyAxes(p.file, scene.path.pass_gap_mm,
                               scene.tool.radius_mm);  // a flipped axis in a pass
    p.what = path_file.string();
    d.path = std::move(p);
  } else if (scene.nominal) {
    ViewPath p;
    p.file = *scene.nominal;
    p.what = scene.nominal->file.string() + " (the scene's path.nominal)";
    d.path = std::move(p);
  } else {
    if (check)
      throw InputError("--check " + request.check_dir.string() +
                       ": check.json names no path: give --path FILE");
    d.missing.push_back(
        "No path: give --path FILE (path.cl of `fieldpath generate`); the scene names no "
        "path.nominal either");
  }

  fs::path surface_dir = request.surface_dir;
  if (surface_dir.empty() && check && fs::exists(request.check_dir / "deviation.npy"))
    surface_dir = request.check_dir;

  if (d.path)
    for (const std::string& note : cutterNotes(scene.tool, d.path->file)) d.notes.push_back(note);
  if (d.path) {
    ViewPath& p = *d.path;
    const auto& postures = p.file.postures;
    const std::size_t n = postures.size();
    // Per posture here: clearance, motion, s, tilt, lead (double), pass (int), the page's arrays.
    common::requireMemory("view " + p.what, double(n) * 96.0, std::to_string(n) + " postures");

    // Postures far outside the scene: a path for another scene (or another unit).
    const double reach =
        std::max(scene.tool.length_mm, scene.holder.empty() ? 0.0 : scene.holder.back().z_mm);
    const double margin = std::max(reach, 0.25 * d.box.diagonal().norm());
    Eigen::AlignedBox3d near = d.box;
    near.min().array() -= margin;
    near.max().array() += margin;
    // Link postures are told apart: generate's links climb the last posture's axis to safe_z,
    // which on a steep axis ends far aside (a blisk's links 150 mm out, in the red banner as if
    // the path were another scene's); said in a note, the banner kept for the cutting postures.
    const std::vector<bool> link = linkMask(p.file);
    const std::size_t links = std::size_t(std::count(link.begin(), link.end(), true));
    std::size_t links_outside = 0, first_link_outside = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (near.contains(postures[i].tip_mm)) continue;
      if (i < link.size() && link[i]) {
        if (links_outside++ == 0) first_link_outside = i;
      } else if (p.outside++ == 0) {
        p.first_outside = i;
      }
    }
    auto boxText = [&] {
      std::ostringstream s;
      s.precision(4);
      s << "x " << d.box.min().x() << ".." << d.box.max().x() << ", y " << d.box.min().y() << ".."
        << d.box.max().y() << ", z " << d.box.min().z() << ".." << d.box.max().z() << " mm";
      return s.str();
    };
    if (p.outside > 0) {
      std::ostringstream s;
      s.precision(4);
      s << p.outside << " of " << n - links << (links ? " cutting" : "")
        << " postures lie more than " << margin << " mm outside the scene's meshes (" << boxText()
        << "), the first at posture " << p.first_outside << " (" << p.file.where(p.first_outside)
        << ")";
      if (2 * p.outside > n - links)
        throw InputError(p.file.file.string() + ": " + s.str() + ": a path for another scene?");
      d.warnings.push_back(s.str());
    }
    if (links_outside > 0) {
      std::ostringstream s;
      s.precision(4);
      s << links_outside << " of " << links << " link postures lie more than " << margin
        << " mm outside the scene's meshes, the first at posture " << first_link_outside << " ("
        << p.file.where(first_link_outside)
        << "): a link climbs the tool axis to links.safe_z, far aside where the axis is steep";
      d.notes.push_back(s.str());
    }
    // With a part, the passes' tips lie on it: the margin above (the holder's reach) let an inch
    // file over a part 5 mm wide pass (its postures 41 mm outside, a helper's). A pass posture
    // farther from the part's box than its ball's reach and generate's far-from-part distance
    // cannot finish it; a path none of whose pass postures comes nearer is refused (passes that
    // run on past the part's edge, most of them off it, are a path for this part).
    if (scene.part && !scene.part->vertices.empty()) {
      Eigen::AlignedBox3d part_box;
      for (const geometry::Vec3& v : scene.part->vertices) part_box.extend(v);
      const double pass_margin =
          pathgen::farFromPartMm(scene.tool.radius_mm) + 2.0 * scene.tool.radius_mm;
      std::size_t pass_postures = 0, far = 0, first_far = 0;
      for (const geometry::PathBlock& block : p.file.blocks) {
        if (block.kind != geometry::PathBlock::Kind::Pass) continue;
        for (std::size_t i = block.begin; i < block.end; ++i, ++pass_postures)
          if (part_box.exteriorDistance(postures[i].tip_mm) > pass_margin && far++ == 0)
            first_far = i;
      }
      if (pass_postures > 0 && far == pass_postures) {
        std::ostringstream s;
        s.precision(4);
        s << "all " << pass_postures << " pass postures lie more than " << pass_margin
          << " mm outside the part's box (the first at posture " << first_far << ", "
          << p.file.where(first_far)
          << "): the passes do not finish the part; a path in other units or another frame, "
             "or for another scene?";
        throw InputError(p.file.file.string() + ": " + s.str());
      }
    }

    if (check) {
      if (check->postures != n)
        throw InputError("--check " + request.check_dir.string() + ": a check of " +
                         std::to_string(check->postures) + " postures (" + check->path + "), but " +
                         p.what + " has " + std::to_string(n) +
                         ": give the folder that `check --path " + p.what + " --out` wrote");
      std::error_code ec;
      if (!check->path.empty() && fs::exists(check->path) && fs::exists(p.file.file) &&
          !fs::equivalent(check->path, p.file.file, ec))
        throw InputError("--check " + request.check_dir.string() + ": the check of " + check->path +
                         ", not of " + p.what);
      // A check against another scene (its obstacles): its clearances are not this scene's.
      if (!check->scene.empty() && fs::exists(check->scene) && fs::exists(request.scene) &&
          !fs::equivalent(check->scene, request.scene, ec))
        throw InputError("--check " + request.check_dir.string() + ": a check against " +
                         check->scene + ", not " + request.scene.string() +
                         ": give the folder that `check " + request.scene.string() + "` wrote");
      // The same file, but edited since it was checked: the check says nothing of it now.
      if (!check->path_digest.empty() && fs::exists(p.file.file) &&
          common::fileDigest(p.file.file) != check->path_digest)
        throw InputError("--check " + request.check_dir.string() + ": " + p.what +
                         " has changed since it was checked (check.json's path_digest differs): "
                         "run `fieldpath check` on it again");
      // The scene or its meshes edited since (a part added after the check: its contacts
      // were never looked for).
      if (!check->scene_digest.empty() && check->scene_digest != sceneDigest(scene))
        throw InputError("--check " + request.check_dir.string() + ": " + request.scene.string() +
                         " or its meshes have changed since the check (check.json's scene_digest "
                         "differs): run `fieldpath check` again");
      readClearanceCsv(request.check_dir / "clearance.csv", n, p.clearance_mm, p.motion_mm,
                       p.part_contact, p.part_contact_to_next);
      if (scene.part && p.part_contact.empty())
        d.warnings.push_back(
            "The part's contacts (links, holder, cutter) are not shown: " +
            (request.check_dir / "clearance.csv").string() +
            " does not mark them (a check written before it did, or without the part): run "
            "`fieldpath check` again, or view without --check");
      p.clearance_source = "check.json of " + request.check_dir.string();
      p.clearance_known = true;
    } else if (scene.obstacles.empty()) {
      p.clearance_mm.assign(n, kNaN);
      p.motion_mm.assign(n, kNaN);
      p.clearance_source = "not known: the scene has no obstacles";
    } else if (n > request.max_clearance_postures) {
      p.clearance_mm.assign(n, kNaN);
      p.motion_mm.assign(n, kNaN);
      p.clearance_source = "not computed for " + std::to_string(n) +
                           " postures: run `fieldpath check` and give --check DIR";
      d.missing.push_back("Clearance not shown: " + p.clearance_source);
    } else {
      // As `check` computes it (cmd_check.cpp): the same mesh, tolerance and motion request.
      const double tol_mm = pathgen::clearanceMeshTolMm(scene.tool, scene.holder);
      const pathgen::ClearanceChecker checker(geometry::toolMesh(scene.tool, scene.holder, tol_mm),
                                              scene.obstacles, tol_mm);
      const pathgen::ClearanceResult c = checker.check(postures, {}, request.progress);
      pathgen::MotionRequest motion_request;
      motion_request.required_mm = scene.clearance_mm;
      motion_request.posture_clearance_mm = c.clearance_mm;
      const pathgen::MotionResult m =
          checker.checkMotions(postures, motion_request, request.progress);
      p.clearance_mm = c.clearance_mm;
      p.motion_mm = m.clearance_mm;
      p.motion_mm.resize(n, kNaN);
      p.clearance_source =
          "computed here, as `fieldpath check` computes it (FCL, postures and motions)";
      check = CheckJson{n, c.colliding, m.colliding, c.min_index, p.what};
      // The part's contacts (the links', the holder's), as `check` finds them: marked on the
      // page apart from the obstacles' and said above it.
      if (scene.part) {
        pathgen::PartContacts contacts =
            pathgen::checkAgainstPart(scene.tool, scene.holder, *scene.part, p.file);
        pathgen::PartContacts::Marks marks = contacts.marks(n);
        p.part_contact = std::move(marks.posture);
        p.part_contact_to_next = std::move(marks.motion);
        check->link_part = std::move(contacts.links);
        check->holder_part = std::move(contacts.holder);
        check->cutter_part = std::move(contacts.cutter);
      }
      p.clearance_known = true;
    }
    if (check)
      for (const std::string& reason :
           unsafeReasons(p.file, {}, {}, check->link_part, check->holder_part))
        d.warnings.push_back("UNSAFE TO RUN: " + reason);
    if (check)
      if (const std::string gouge = cutterGougeReason(p.file, check->cutter_part); !gouge.empty())
        d.warnings.push_back("GOUGE: " + gouge);
    for (std::size_t i = 0; i < n; ++i) {
      p.colliding_postures += p.clearance_mm[i] <= 0.0;
      p.colliding_motions += p.motion_mm[i] <= 0.0;
      p.motions_under_required += p.motion_mm[i] < scene.clearance_mm;
    }
    // In the banner above the page too, as path.cl's mark says it (only the counts said it).
    if (p.colliding_postures > 0 || p.colliding_motions > 0)
      d.warnings.push_back("UNSAFE TO RUN: " + std::to_string(p.colliding_postures) +
                           (p.colliding_postures == 1 ? " posture and " : " postures and ") +
                           std::to_string(p.colliding_motions) +
                           (p.colliding_motions == 1 ? " motion" : " motions") +
                           " touch an obstacle (red on the path)");
    // Clear of the obstacles but under the scene's clearance: said as path.cl's mark says it
    // (the page had no word of it, its side panel read "colliding: 0": a helper's finding).
    std::size_t postures_under = 0, closest = ViewPath::npos;
    for (std::size_t i = 0; i < n; ++i)
      if (p.clearance_mm[i] < scene.clearance_mm) {
        ++postures_under;
        if (closest == ViewPath::npos || p.clearance_mm[i] < p.clearance_mm[closest]) closest = i;
      }
    // The posture check named (its exact distances; the file's rounded ones tie, and the page
    // named another posture of the same clearance than check and generate: a helper's finding).
    if (check && check->min_posture < n && closest != ViewPath::npos &&
        p.clearance_mm[check->min_posture] <= p.clearance_mm[closest])
      closest = check->min_posture;
    p.postures_under_required = postures_under;
    if (p.colliding_postures == 0 && p.colliding_motions == 0 &&
        (postures_under > 0 || p.motions_under_required > 0)) {
      const auto count = [](std::size_t n, const char* what) {
        return std::to_string(n) + " " + what + (n == 1 ? "" : "s");
      };
      char text[160];
      std::snprintf(text, sizeof text,
                    "UNDER THE REQUIRED CLEARANCE (%.3f mm): ", scene.clearance_mm);
      std::string line = text;
      if (postures_under > 0) {
        std::snprintf(text, sizeof text, " (closest %.3f mm, ", p.clearance_mm[closest]);
        line += count(postures_under, "posture") + text + postureWhere(p.file, closest) + ")";
      }
      if (p.motions_under_required > 0)
        line += std::string(postures_under > 0 ? " and " : "") +
                count(p.motions_under_required, "motion");
      line += " under it (orange on the path coloured by clearance)";
      d.warnings.push_back(line);
    }
    if (check) {  // whose the part's contacts are (the page called a cutter's gouge the holder's)
      if (check->holder_part)
        p.holder_part_contacts =
            check->holder_part->colliding_postures + check->holder_part->colliding_motions;
      if (check->cutter_part)
        p.cutter_part_contacts =
            check->cutter_part->gouging_postures + check->cutter_part->gouging_motions;
    }
    for (std::size_t i : p.file.limited) p.limited_colliding += p.clearance_mm[i] <= 0.0;
    if (check && (check->colliding_postures != p.colliding_postures ||
                  check->colliding_motions != p.colliding_motions))
      d.warnings.push_back("check.json counts " + std::to_string(check->colliding_postures) +
                           " colliding postures and " + std::to_string(check->colliding_motions) +
                           " colliding motions, clearance.csv " +
                           std::to_string(p.colliding_postures) + " and " +
                           std::to_string(p.colliding_motions));
    computeAngles(scene, p);
  }

  if (!surface_dir.empty()) {
    SurfaceFigures figures;
    if (fs::exists(surface_dir / "check.json") && fs::exists(surface_dir / "deviation.npy")) {
      const json j = readJson(surface_dir / "check.json");
      const json surface = j.is_object() ? j.value("surface", json()) : json();
      figures.from_check = surface.is_object();
      auto number = [&](const char* key, double& out) {
        if (surface.is_object() && surface.value(key, json()).is_number())
          out = surface[key].get<double>();
      };
      number("gouge_tolerance_um", figures.gouge_tolerance_um);
      number("max_scallop_um", figures.max_scallop_um);
      number("max_gouge_um", figures.max_gouge_um);
      // A gouge lies under the part's surface, which the page draws over it: said in the banner
      // (a page of a path that gouged 2.2 mm looked like a clean part: a helper's finding).
      double gouged_lines = 0.0;
      number("gouged_lines", gouged_lines);
      if (gouged_lines > 0.0) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "GOUGE: %.0f lines cut up to %.1f um below the part (tolerance %.1f um): "
                      "blue on the surface, under the part (hide the part to see it)",
                      gouged_lines, figures.max_gouge_um, figures.gouge_tolerance_um);
        d.warnings.push_back(text);
      }
    }
    d.surface = readSurface(surface_dir, scene, request.max_surface_lines, figures, d.warnings);
  }
  return d;
}

}  // namespace fieldpath::app
