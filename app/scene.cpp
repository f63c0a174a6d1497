#include "scene.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
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
#include "scene_reader.h"
#include "scene_sections.h"

namespace fieldpath::app {
namespace {

using common::InputError;

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
      scene.obstacle_keys.push_back(key);
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

std::string obstacleName(const Scene& scene, std::size_t index) {
  if (index < scene.obstacle_files.size() && index < scene.obstacle_keys.size())
    return scene.obstacle_keys[index] + " (" + scene.obstacle_files[index].filename().string() +
           ")";
  return "the impeller's blade " + std::to_string(index + 1 - scene.obstacle_files.size());
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

Scene loadScene(const std::filesystem::path& file, SceneUse use) {
  const bool read_nominal = use == SceneUse::kJob, read_part = use != SceneUse::kField;
  sceneKeyLines() = SceneKeyLines{};  // none of another scene's
  meshNotes().clear();
  common::requireRegularFile(file, "scene file (YAML)");
  sceneSizeOk(file, /*refuse=*/true);
  YAML::Node root;
  errno = 0;  // what a failed open leaves, said beside yaml-cpp's "bad file"
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
    // yaml-cpp says "bad file" of any open that failed: the system's reason is errno's (too many
    // open files read as a bad file: an environment sweep's).
    const int error = errno;
    throw InputError(file.string() + ": cannot read scene file: " + e.msg +
                     (error != 0 && e.msg.rfind("bad file", 0) == 0
                          ? std::string(" (") + std::strerror(error) + ")"
                          : std::string()));
  }
  const Reader r(file);
  if (!root.IsMap()) r.fail(root, "scene", "expected a map of keys (obstacles, guide, tool, ...)");
  r.expectMap(root, "",
              {"obstacles", "part", "guide", "tool", "holder", "clearance", "field", "dynamics",
               "path", "links"});
  recordKeyLines(file, root);

  Scene scene;
  scene.file = file;
  scene.use = use;
  std::vector<MeshLoad> loads;
  if (!root["obstacles"]) r.fail(root, "obstacles", "missing (the surfaces that repel the tool)");
  readObstacles(r, root["obstacles"], scene, loads);
  if (root["part"] && root["guide"])
    r.fail(root["guide"], "guide", "give either `part: FILE` or `guide: { impeller: hub }`");
  if (root["part"]) {
    scene.part_file = r.path(root["part"], "part");
    if (read_part) loads.push_back({root["part"], "part", true});
  }
  if (root["guide"]) readGuide(r, root["guide"], scene);
  if (root["tool"]) {
    readTool(r, root["tool"], scene.tool);
    scene.tool_given = true;
    if (root["tool"]["shape"].Mark().line >= 0)
      scene.tool_shape_line = root["tool"]["shape"].Mark().line + 1;
  }
  if (root["holder"]) {
    readHolder(r, root["holder"], scene.holder);
    // Named here, with the file and line (it was said with neither where the mesh was made);
    // against the scene's own tool only (the `field` commands need neither).
    if (scene.tool_given)
      r.check(root["holder"], "holder",
              [&] { geometry::validateHolderOnTool(scene.tool, scene.holder); });
  }
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
  scene.mesh_notes = meshNotes();
  scene.scale_warnings = meshScaleWarnings(scene);
  for (const MeshScaleWarning& warning : scene.scale_warnings)
    std::fprintf(stderr, "warning: %s: %s\n", scene.file.string().c_str(), warning.text.c_str());
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
