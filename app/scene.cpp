#include "scene.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "estimates.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/input_file.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool_model.h"
#include "scene_mesh.h"

namespace fieldpath::app {
namespace {

using common::InputError;

/// The scene this process read and the 1-based line of each of its keys, top level and one
/// below (`links.safe_z`): for placeSceneKey. One scene a process; written before any worker.
struct SceneKeyLines {
  std::filesystem::path file;
  std::map<std::string, int> lines;
};
SceneKeyLines& sceneKeyLines() {
  static SceneKeyLines keys;
  return keys;
}

void recordKeyLines(const std::filesystem::path& file, const YAML::Node& root) {
  SceneKeyLines& keys = sceneKeyLines();
  keys.file = file;
  keys.lines.clear();
  for (const auto& kv : root) {
    const std::string key = kv.first.Scalar();
    if (kv.first.Mark().line >= 0) keys.lines[key] = kv.first.Mark().line + 1;
    if (!kv.second.IsMap()) continue;
    for (const auto& sub : kv.second)
      if (sub.first.IsScalar() && sub.first.Mark().line >= 0)
        keys.lines[key + "." + sub.first.Scalar()] = sub.first.Mark().line + 1;
  }
}

/// Where a value came from: the file, and the dotted key of the node being read.
class Reader {
 public:
  explicit Reader(std::filesystem::path file) : file_(std::move(file)) {}

  /// "FILE:LINE: key: why" (LINE from the node's YAML mark, 1-based, when it has one).
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& why) const {
    std::string where = file_.string();
    int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 0;
    // An empty value (`tool:` alone) is marked where the next key starts: the key's own line.
    const SceneKeyLines& keys = sceneKeyLines();
    if ((!at.IsDefined() || at.IsNull()) && keys.file == file_)
      if (const auto it = keys.lines.find(key); it != keys.lines.end()) line = it->second;
    if (line > 0) where += ":" + std::to_string(line);
    throw InputError(where + ": " + key + ": " + why);
  }

  /// Checks that `node` is a map whose keys are all in `allowed`.
  void expectMap(const YAML::Node& node, const std::string& key,
                 std::initializer_list<const char*> allowed) const {
    if (!node.IsMap()) fail(node, key, "expected a map of keys");
    std::vector<std::pair<std::string, int>> seen;  // a key given twice: YAML keeps one silently
    for (const auto& kv : node) {
      const std::string name = kv.first.Scalar();
      for (const auto& [other, line] : seen)
        if (other == name)
          fail(kv.first, join(key, name),
               "given twice (also on line " + std::to_string(line + 1) + ")");
      seen.emplace_back(name, kv.first.Mark().line);
      bool known = false;
      for (const char* a : allowed) known = known || name == a;
      if (!known) {
        std::string list;
        for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
        fail(kv.first, join(key, name), "unknown key (expected one of: " + list + ")");
      }
    }
  }

  double number(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar()) fail(node, key, "expected a number");
    double value = 0.0;
    try {
      value = node.as<double>();
    } catch (const YAML::Exception&) {
      // yaml-cpp's stream read fails on numbers past a double's range (1e-320, 1e400): read
      // them as strtod does (a denormal or 0, an infinity refused below).
      const std::string& text = node.Scalar();
      char* end = nullptr;
      value = std::strtod(text.c_str(), &end);
      if (text.empty() || end != text.c_str() + text.size())
        fail(node, key, "expected a number, got '" + text + "'");
    }
    if (!std::isfinite(value)) fail(node, key, "must be finite");
    return value;
  }

  /// A number with `check(value)` true, else "must be <what>".
  double number(const YAML::Node& node, const std::string& key,
                const std::function<bool(double)>& check, const std::string& what) const {
    const double value = number(node, key);
    if (!check(value)) fail(node, key, "must be " + what + " (got " + node.Scalar() + ")");
    return value;
  }

  double positive(const YAML::Node& node, const std::string& key) const {
    return number(
        node, key, [](double v) { return v > 0.0; }, "> 0");
  }

  std::string word(const YAML::Node& node, const std::string& key,
                   std::initializer_list<const char*> choices) const {
    if (!node.IsScalar()) fail(node, key, "expected a word");
    const std::string value = node.Scalar();
    std::string list;
    for (const char* c : choices) {
      if (value == c) return value;
      list += std::string(list.empty() ? "" : " | ") + c;
    }
    fail(node, key, "expected " + list + ", got '" + value + "'");
  }

  std::filesystem::path path(const YAML::Node& node, const std::string& key) const {
    if (!node.IsScalar() || node.Scalar().empty()) fail(node, key, "expected a file name");
    const std::filesystem::path p = node.Scalar();
    return p.is_absolute() ? p : file_.parent_path() / p;
  }

  /// Loads a mesh (loadSceneMesh: read, mended, turned outward), naming the scene's key and
  /// line in the error.
  geometry::TriangleMesh mesh(const YAML::Node& node, const std::string& key) const {
    try {
      return loadSceneMesh(path(node, key));
    } catch (const InputError& e) {
      fail(node, key, e.what());
    }
  }

  /// Runs a module's own validation, naming the key and line in its error: the line of the
  /// map's key that the message names (`tool length must cover...`: `length`'s), else the map's.
  void check(const YAML::Node& node, const std::string& key,
             const std::function<void()>& validate) const {
    try {
      validate();
    } catch (const InputError& e) {
      fail(valueNamedIn(node, e.what()), key, e.what());
    }
  }

  static std::string join(const std::string& a, const std::string& b) {
    return a.empty() ? b : a + "." + b;
  }

 private:
  std::filesystem::path file_;
};

/// A pending mesh load: done after every key has been checked.
struct MeshLoad {
  YAML::Node node;
  std::string key;
  bool part;
};

void readObstacles(const Reader& r, const YAML::Node& node, Scene& scene,
                   std::vector<MeshLoad>& loads) {
  if (node.IsSequence() && node.size() == 0)
    r.fail(node, "obstacles",
           "the list is empty: a scene needs at least one obstacle (`- mesh: FILE` or "
           "`- impeller: {...}`)");
  if (!node.IsSequence())
    r.fail(node, "obstacles", "expected a list of `- mesh: FILE` or `- impeller: {...}`");
  for (std::size_t i = 0; i < node.size(); ++i) {
    const YAML::Node item = node[i];
    const std::string key = "obstacles[" + std::to_string(i + 1) + "]";
    r.expectMap(item, key, {"mesh", "impeller"});
    if (item.size() != 1) r.fail(item, key, "expected exactly one of mesh, impeller");
    if (item["mesh"]) {
      const auto file = r.path(item["mesh"], key + ".mesh");
      // The same surfaces twice would repel twice as hard (the field is a sum over samples).
      std::error_code ec;
      for (std::size_t j = 0; j < scene.obstacle_files.size(); ++j)
        if (scene.obstacle_files[j] == file ||
            std::filesystem::equivalent(scene.obstacle_files[j], file, ec))
          r.fail(item["mesh"], key + ".mesh",
                 "the same file as an obstacle before it (" + scene.obstacle_files[j].string() +
                     "): its field would count twice");
      scene.obstacle_files.push_back(file);
      loads.push_back({item["mesh"], key + ".mesh", false});
    } else {
      if (scene.impeller) r.fail(item, key + ".impeller", "the impeller is given twice");
      scene.impeller = item["impeller"];
    }
  }
}

/// `guide: { impeller: hub }`: the parametric impeller's hub as the part.
void readGuide(const Reader& r, const YAML::Node& node, Scene& scene) {
  r.expectMap(node, "guide", {"impeller"});
  if (!node["impeller"]) r.fail(node, "guide", "expected `{ impeller: hub }`");
  scene.guide_impeller = node["impeller"];
}

void readTool(const Reader& r, const YAML::Node& node, geometry::ToolSpec& tool) {
  r.expectMap(node, "tool", {"shape", "radius", "corner_radius", "length"});
  if (!node["shape"]) r.fail(node, "tool.shape", "missing (ball, torus or flat)");
  const std::string shape = r.word(node["shape"], "tool.shape", {"ball", "torus", "flat"});
  tool.shape = shape == "ball"    ? geometry::ToolShape::Ball
               : shape == "torus" ? geometry::ToolShape::Torus
                                  : geometry::ToolShape::Flat;
  if (!node["radius"]) r.fail(node, "tool.radius", "missing");
  tool.radius_mm = r.positive(node["radius"], "tool.radius");
  if (node["corner_radius"])
    tool.corner_radius_mm = r.positive(node["corner_radius"], "tool.corner_radius");
  if (node["length"]) tool.length_mm = r.positive(node["length"], "tool.length");
  if (tool.shape == geometry::ToolShape::Torus && !node["corner_radius"])
    r.fail(node, "tool.corner_radius", "required for a torus tool");
  // Only a torus has a corner radius of its own (a ball's is its radius): one given otherwise was
  // read past without a word.
  if (tool.shape != geometry::ToolShape::Torus && node["corner_radius"] &&
      !(tool.shape == geometry::ToolShape::Ball && tool.corner_radius_mm == tool.radius_mm))
    r.fail(node["corner_radius"], "tool.corner_radius",
           "only a torus tool has one (a ball's is its radius, a flat end's 0)");
  if (tool.shape != geometry::ToolShape::Torus) tool.corner_radius_mm = 0.0;
  r.check(node, "tool", [&] { geometry::validateToolSpec(tool); });
}

void readHolder(const Reader& r, const YAML::Node& node, geometry::HolderProfile& holder) {
  if (!node.IsSequence()) r.fail(node, "holder", "expected a list of [z, radius] stations");
  holder.clear();
  for (std::size_t i = 0; i < node.size(); ++i) {
    const std::string key = "holder[" + std::to_string(i + 1) + "]";
    if (!node[i].IsSequence() || node[i].size() != 2) r.fail(node[i], key, "expected [z, radius]");
    holder.push_back({r.number(node[i][0], key + ".z"), r.positive(node[i][1], key + ".radius")});
  }
  r.check(node, "holder", [&] { geometry::validateHolderProfile(holder); });
}

void readField(const Reader& r, const YAML::Node& node, field::FieldParams& f) {
  r.expectMap(node, "field",
              {"r0", "r_min", "gain", "sample_step", "weights", "voxel_size", "interpolation",
               "stored", "refine_tolerance", "refine_levels", "refine_region", "backend"});
  if (node["r0"]) f.r0_mm = r.positive(node["r0"], "field.r0");
  if (node["r_min"]) f.r_min_mm = r.positive(node["r_min"], "field.r_min");
  if (!(f.r_min_mm < f.r0_mm)) {
    const YAML::Node at = node["r_min"] ? node["r_min"] : node["r0"];
    r.fail(at, "field.r_min",
           "must be < r0 (r_min " + common::shortNumber(f.r_min_mm) + ", r0 " +
               common::shortNumber(f.r0_mm) + ")");
  }
  // A negative gain attracts the tool to the obstacles (it was accepted: every posture pulled
  // into the walls); 0 turns the field off (the nominal path).
  if (node["gain"])
    f.gain = r.number(
        node["gain"], "field.gain", [](double v) { return v >= 0.0 && v <= 1e30; },
        "in [0, 1e30] (>= 0: the field pushes the tool away from the obstacles; past 1e30 the "
        "voxels' single-precision forces overflow)");
  if (node["sample_step"]) f.sample_step_mm = r.positive(node["sample_step"], "field.sample_step");
  if (node["weights"])  // `1`: DESIGN's "w_j = 1, the paper's choice", as a third party writes it
    f.weights = r.word(node["weights"], "field.weights", {"area", "unit", "1"}) == "area"
                    ? field::Weights::Area
                    : field::Weights::Unit;
  if (node["voxel_size"])
    f.voxel.voxel_size_mm = r.positive(node["voxel_size"], "field.voxel_size");
  if (node["interpolation"])
    f.voxel.interpolation = r.word(node["interpolation"], "field.interpolation",
                                   {"trilinear", "quadratic"}) == "trilinear"
                                ? field::Interpolation::Trilinear
                                : field::Interpolation::Quadratic;
  if (node["stored"])
    f.voxel.stored = r.word(node["stored"], "field.stored", {"plane_ratio", "force"}) == "force"
                         ? field::StoredQuantity::Force
                         : field::StoredQuantity::PlaneRatio;
  if (node["refine_tolerance"]) {
    f.voxel.refine_tolerance = r.number(node["refine_tolerance"], "field.refine_tolerance");
    if (!(f.voxel.refine_tolerance >= 0.0) || !std::isfinite(f.voxel.refine_tolerance))
      r.fail(node["refine_tolerance"], "field.refine_tolerance",
             "must be >= 0 (a fraction; 0: no refinement)");
  }
  if (node["refine_levels"]) {
    const double levels = r.number(node["refine_levels"], "field.refine_levels");
    if (!(levels >= 0.0 && levels <= 6.0) || levels != std::floor(levels))
      r.fail(node["refine_levels"], "field.refine_levels", "must be an integer in [0, 6]");
    f.voxel.refine_levels = static_cast<int>(levels);
  }
  if (node["refine_region"])
    f.voxel.refine_region = *field::refineRegionNamed(
        r.word(node["refine_region"], "field.refine_region", {"path", "reach"}));
  if (node["backend"])
    f.voxel.backend = *field::fieldBackendNamed(
        r.word(node["backend"], "field.backend", {"auto", "cpu", "cuda", "reference"}));
}

void readDynamics(const Reader& r, const YAML::Node& node, dynamics::DynamicsParams& d) {
  r.expectMap(node, "dynamics",
              {"inertia", "damping", "stiffness", "feed", "rtol", "atol", "max_tilt_deg",
               "max_lead_deg", "on_limit", "integrator", "start"});
  if (node["inertia"]) d.inertia = r.positive(node["inertia"], "dynamics.inertia");
  if (node["damping"]) {
    const YAML::Node damping = node["damping"];
    if (damping.IsScalar() && damping.Scalar() == "critical")
      d.damping = -1.0;
    else if (damping.IsScalar() && !damping.Scalar().empty() &&
             std::isalpha(static_cast<unsigned char>(damping.Scalar()[0])) &&
             damping.Scalar() != "inf" && damping.Scalar() != "nan")
      r.fail(damping, "dynamics.damping",
             "expected a number >= 0 or `critical`, got '" + damping.Scalar() + "'");
    else
      d.damping = r.number(
          node["damping"], "dynamics.damping", [](double v) { return v >= 0.0; },
          ">= 0 or `critical`");
  }
  if (node["stiffness"]) d.stiffness = r.positive(node["stiffness"], "dynamics.stiffness");
  if (node["feed"])
    d.feed_mm_per_min = r.number(
        node["feed"], "dynamics.feed",
        [](double v) { return v >= common::kMinFeedMmPerMin && v <= common::kMaxFeedMmPerMin; },
        "a feed from 0.001 to 1e6 mm/min");
  // Tolerances of 1 or more accept any step (rtol 1e6 moved the lead by 1.6 deg without a word).
  const auto tolerance = [](double v) { return v > 0.0 && v < 1.0; };
  if (node["rtol"])
    d.rtol = r.number(node["rtol"], "dynamics.rtol", tolerance, "in (0, 1), e.g. 1e-6");
  if (node["atol"])
    d.atol = r.number(node["atol"], "dynamics.atol", tolerance, "in (0, 1) rad, e.g. 1e-9");
  auto angle = [&](const char* key) {
    return r.number(
        node[key], std::string("dynamics.") + key, [](double v) { return v > 0.0 && v < 90.0; },
        "in (0, 90)");
  };
  if (node["max_tilt_deg"]) d.max_tilt_deg = angle("max_tilt_deg");
  if (node["max_lead_deg"]) d.max_lead_deg = angle("max_lead_deg");
  if (node["on_limit"])
    d.on_limit = r.word(node["on_limit"], "dynamics.on_limit", {"clamp", "fail"}) == "clamp"
                     ? dynamics::LimitPolicy::Clamp
                     : dynamics::LimitPolicy::Fail;
  if (node["start"]) {
    const std::string start =
        r.word(node["start"], "dynamics.start", {"auto", "nominal", "settled"});
    d.start = start == "auto"      ? dynamics::StartPolicy::Auto
              : start == "nominal" ? dynamics::StartPolicy::Nominal
                                   : dynamics::StartPolicy::Settled;
  }
  if (node["integrator"])
    d.integrator = r.word(node["integrator"], "dynamics.integrator", {"bdf", "erk"}) == "bdf"
                       ? dynamics::Integrator::Bdf
                       : dynamics::Integrator::Erk;
}

void readPath(const Reader& r, const YAML::Node& node, pathgen::PathParams& p) {
  r.expectMap(node, "path", {"nominal", "passes", "step", "lead_deg", "pass_gap"});
  if (node["passes"]) {
    const double passes = r.number(
        node["passes"], "path.passes",
        [](double v) { return v >= 1.0 && v == std::floor(v) && v <= 1e6; }, "a whole number >= 1");
    p.passes = static_cast<int>(passes);
    p.passes_given = true;
  }
  if (node["step"]) {
    p.step_mm = r.number(
        node["step"], "path.step", [](double v) { return v >= pathgen::kMinPathStepMm; },
        ">= " + common::shortNumber(pathgen::kMinPathStepMm) +
            " mm (a machine's resolution: a finer step only multiplies the postures)");
    p.step_given = true;
  }
  if (node["lead_deg"])
    p.lead_deg = r.number(
        node["lead_deg"], "path.lead_deg", [](double v) { return std::abs(v) < 90.0; },
        "in (-90, 90)");
  if (node["pass_gap"]) p.pass_gap_mm = r.positive(node["pass_gap"], "path.pass_gap");
}

void readLinks(const Reader& r, const YAML::Node& node, pathgen::LinkParams& links) {
  r.expectMap(node, "links", {"retract", "safe_z"});
  if (node["retract"])
    links.retract_mm = r.number(
        node["retract"], "links.retract", [](double v) { return v > 0.0 && v <= 1e4; },
        "a distance in (0, 10000] mm (at 0 each link's last rapid move would end on the part, "
        "at the pass's first posture)");
  if (node["safe_z"]) {
    if (node["safe_z"].IsScalar() && node["safe_z"].Scalar() == "auto")
      links.safe_z_mm.reset();
    else
      links.safe_z_mm = r.number(
          node["safe_z"], "links.safe_z", [](double v) { return std::abs(v) <= 1e6; },
          "`auto` or a height in mm within 1e6 of 0");
  }
}

}  // namespace

YAML::Node valueNamedIn(const YAML::Node& map, const std::string& message) {
  if (!map.IsMap()) return map;
  YAML::Node best = map;
  std::size_t best_at = std::string::npos;
  const auto word = [](char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; };
  for (const auto& kv : map) {
    if (!kv.first.IsScalar() || kv.first.Scalar().empty()) continue;
    std::string spaced = kv.first.Scalar();
    std::replace(spaced.begin(), spaced.end(), '_', ' ');
    for (const std::string& name : {kv.first.Scalar(), spaced})
      for (std::size_t at = message.find(name); at != std::string::npos && at < best_at;
           at = message.find(name, at + 1)) {
        const std::size_t end = at + name.size();
        if ((at == 0 || !word(message[at - 1])) && (end == message.size() || !word(message[end]))) {
          best_at = at;
          best = kv.second.IsDefined() && kv.second.Mark().line >= 0 ? kv.second : kv.first;
          break;
        }
      }
  }
  return best;
}

std::string sceneWhere(const Scene& scene, const std::string& key) {
  const SceneKeyLines& keys = sceneKeyLines();
  const auto at = keys.lines.find(key);
  return scene.file.string() +
         (keys.file == scene.file && at != keys.lines.end() ? ":" + std::to_string(at->second)
                                                            : "") +
         ": " + key;
}

std::string placeSceneKey(const std::string& message) {
  const SceneKeyLines& keys = sceneKeyLines();
  const std::size_t colon = message.find(": ");
  if (keys.file.empty() || colon == std::string::npos) return message;
  const auto at = keys.lines.find(message.substr(0, colon));
  if (at == keys.lines.end()) return message;
  return keys.file.string() + ":" + std::to_string(at->second) + ": " + message;
}

namespace {
/// A scene file is a few kB of text (its meshes and paths are files it names); past this it is
/// not one, and reading it whole took minutes and gigabytes (a helper's 3 GB sparse file:
/// 4.2 GB of memory, then "unknown escape character").
constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{16} << 20;

/// False (nothing to read) for a file over kMaxSceneBytes; throws InputError saying so when
/// `refuse`.
bool sceneSizeOk(const std::filesystem::path& file, bool refuse) {
  std::error_code ec;
  const std::uintmax_t bytes = std::filesystem::file_size(file, ec);
  if (ec || bytes <= kMaxSceneBytes) return true;
  if (refuse)
    throw InputError(file.string() + ": " + common::formatBytes(double(bytes)) +
                     ": not a scene file (a scene is YAML text of a few kB that names its mesh "
                     "and path files; at most 16 MiB)");
  return false;
}
}  // namespace

Scene loadScene(const std::filesystem::path& file, bool read_nominal) {
  sceneKeyLines() = SceneKeyLines{};  // none of another scene's
  common::requireRegularFile(file, "scene file (YAML)");
  sceneSizeOk(file, /*refuse=*/true);
  YAML::Node root;
  try {
    // Every document read, so that one past the scene (after `---`, or text after `...`) is
    // refused rather than silently ignored.
    const std::vector<YAML::Node> documents = YAML::LoadAllFromFile(file.string());
    if (!documents.empty()) root = documents.front();
    for (std::size_t d = 1; d < documents.size(); ++d)
      if (!documents[d].IsNull())
        throw InputError(file.string() + ":" + std::to_string(documents[d].Mark().line + 1) +
                         ": a second YAML document (after `---` or `...`): a scene file holds "
                         "one scene; remove it or put it in its own file");
  } catch (const YAML::ParserException& e) {
    // A tab in the indentation reads as "illegal block entry" and the like: say the tab (a
    // newcomer's scene, pasted from an editor that indents with tabs).
    std::string hint;
    {
      std::ifstream in(file);
      std::string line;
      for (int n = 0; n <= e.mark.line && std::getline(in, line);) ++n;
      const std::size_t text = line.find_first_not_of(" \t");
      if (line.substr(0, text).find('\t') != std::string::npos)
        hint = " (the line is indented with a tab: YAML indents with spaces only)";
    }
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) +
                     ": YAML syntax: " + e.msg + hint);
  } catch (const YAML::Exception& e) {
    throw InputError(file.string() + ": cannot read scene file: " + e.msg);
  }
  const Reader r(file);
  if (!root.IsMap()) r.fail(root, "scene", "expected a map of keys (obstacles, guide, tool, ...)");
  r.expectMap(root, "",
              {"obstacles", "part", "guide", "tool", "holder", "clearance", "field", "dynamics",
               "path", "links"});
  recordKeyLines(file, root);

  Scene scene;
  scene.file = file;
  std::vector<MeshLoad> loads;
  if (!root["obstacles"]) r.fail(root, "obstacles", "missing (the surfaces that repel the tool)");
  readObstacles(r, root["obstacles"], scene, loads);
  if (root["part"] && root["guide"])
    r.fail(root["guide"], "guide", "give either `part: FILE` or `guide: { impeller: hub }`");
  if (root["part"]) {
    scene.part_file = r.path(root["part"], "part");
    loads.push_back({root["part"], "part", true});
  }
  if (root["guide"]) readGuide(r, root["guide"], scene);
  if (root["tool"]) {
    readTool(r, root["tool"], scene.tool);
    scene.tool_given = true;
    if (root["tool"]["shape"].Mark().line >= 0)
      scene.tool_shape_line = root["tool"]["shape"].Mark().line + 1;
  }
  if (root["holder"]) readHolder(r, root["holder"], scene.holder);
  if (root["clearance"])
    scene.clearance_mm = r.number(
        root["clearance"], "clearance", [](double v) { return v >= 0.0; }, ">= 0");
  if (root["field"]) readField(r, root["field"], scene.field);
  if (root["dynamics"]) readDynamics(r, root["dynamics"], scene.dynamics);
  if (root["path"]) readPath(r, root["path"], scene.path);
  if (root["links"]) readLinks(r, root["links"], scene.links);
  // A lead past the lead limit is held at it from the first posture (a helper's 50 deg read 20,
  // unsaid, and the held posture collided).
  if (std::abs(scene.path.lead_deg) > scene.dynamics.max_lead_deg) {
    const YAML::Node at = root["path"] && root["path"]["lead_deg"] ? root["path"]["lead_deg"]
                          : root["dynamics"] && root["dynamics"]["max_lead_deg"]
                              ? root["dynamics"]["max_lead_deg"]
                              : root;
    r.fail(at, "path.lead_deg",
           "must be within dynamics.max_lead_deg (lead " +
               common::shortNumber(scene.path.lead_deg) + " deg, limit " +
               common::shortNumber(scene.dynamics.max_lead_deg) +
               " deg): the steering holds the lead inside the limit");
  }

  // Meshes last: every key is checked before the slow part.
  std::vector<const MeshLoad*> obstacle_loads;
  for (const MeshLoad& load : loads) {
    if (load.part) {
      scene.part = r.mesh(load.node, load.key);
      continue;
    }
    scene.obstacles.push_back(r.mesh(load.node, load.key));
    obstacle_loads.push_back(&load);
    // The same surfaces from another file (a copy, or the same mesh written again) would repel
    // twice as hard, as the same file twice would.
    const geometry::TriangleMesh& added = scene.obstacles.back();
    for (std::size_t j = 0; j + 1 < scene.obstacles.size(); ++j) {
      const geometry::TriangleMesh& before = scene.obstacles[j];
      if (before.vertices == added.vertices && before.triangles == added.triangles &&
          !added.triangles.empty())
        r.fail(load.node, load.key,
               "the same surfaces as " + obstacle_loads[j]->key + " (" +
                   scene.obstacle_files[j].string() + "): their field would count twice");
    }
  }
  if (read_nominal && root["path"] && root["path"]["nominal"]) {
    const YAML::Node node = root["path"]["nominal"];
    const auto file = r.path(node, "path.nominal");
    try {
      scene.nominal = readPathFileWhole(file, file.string());
    } catch (const InputError& e) {
      // The path file's own message names its line; say which key led there.
      r.fail(node, "path.nominal", e.what());
    }
  }
  if (scene.impeller || scene.guide_impeller) resolveImpeller(scene);
  checkSceneSize(scene);  // before any command's heavy work
  return scene;
}

std::filesystem::path nominalPathOf(const std::filesystem::path& file) {
  std::error_code ec;  // a FIFO would block the read before loadScene refuses it
  if (!std::filesystem::is_regular_file(file, ec) || !sceneSizeOk(file, /*refuse=*/false))
    return {};
  try {
    const YAML::Node root = YAML::LoadFile(file.string());
    const YAML::Node node = root["path"] ? root["path"]["nominal"] : YAML::Node();
    if (!node || !node.IsScalar() || node.Scalar().empty()) return {};
    const std::filesystem::path p = node.Scalar();
    return p.is_absolute() ? p : file.parent_path() / p;
  } catch (const std::exception&) {
    return {};  // loadScene says what is wrong
  }
}

}  // namespace fieldpath::app
