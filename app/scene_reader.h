#pragma once
/// Reading a scene's YAML: where each value came from (file, line, dotted key) and the checks
/// every key's value goes through, shared by loadScene and the sections' readers
/// (scene_sections.h).
#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <functional>
#include <initializer_list>
#include <map>
#include <string>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::app {

/// The scene this process read and the 1-based line of each of its keys, top level and one
/// below (`links.safe_z`): for placeSceneKey. One scene a process; written before any worker.
struct SceneKeyLines {
  std::filesystem::path file;
  std::map<std::string, int> lines;
};
SceneKeyLines& sceneKeyLines();

/// Records the lines of `root`'s keys (top level and one below) read from `file`.
void recordKeyLines(const std::filesystem::path& file, const YAML::Node& root);

/// Where a value came from: the file, and the dotted key of the node being read.
class Reader {
 public:
  explicit Reader(std::filesystem::path file) : file_(std::move(file)) {}

  /// "FILE:LINE: key: why" (LINE from the node's YAML mark, 1-based, when it has one).
  [[noreturn]] void fail(const YAML::Node& at, const std::string& key,
                         const std::string& why) const;

  /// Checks that `node` is a map whose keys are all in `allowed`.
  void expectMap(const YAML::Node& node, const std::string& key,
                 std::initializer_list<const char*> allowed) const;

  double number(const YAML::Node& node, const std::string& key) const;

  /// A number with `check(value)` true, else "must be <what>".
  double number(const YAML::Node& node, const std::string& key,
                const std::function<bool(double)>& check, const std::string& what) const;

  double positive(const YAML::Node& node, const std::string& key) const;

  std::string word(const YAML::Node& node, const std::string& key,
                   std::initializer_list<const char*> choices) const;

  /// A file name, relative to the scene file's folder.
  std::filesystem::path path(const YAML::Node& node, const std::string& key) const;

  /// Loads a mesh (loadSceneMesh: read, mended, turned outward), naming the scene's key and
  /// line in the error.
  geometry::TriangleMesh mesh(const YAML::Node& node, const std::string& key) const;

  /// Runs a module's own validation, naming the key and line in its error: the line of the
  /// map's key that the message names (`tool length must cover...`: `length`'s), else the map's.
  void check(const YAML::Node& node, const std::string& key,
             const std::function<void()>& validate) const;

  static std::string join(const std::string& a, const std::string& b) {
    return a.empty() ? b : a + "." + b;
  }

 private:
  std::filesystem::path file_;
};

}  // namespace fieldpath::app
