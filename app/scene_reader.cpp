#include "scene_reader.h"

#include <cmath>
#include <cstdlib>
#include <string>
#include <utility>
#include <vector>

#include "fieldpath/common/errors.h"
#include "scene.h"
#include "scene_mesh.h"

namespace fieldpath::app {

using common::InputError;

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

void Reader::fail(const YAML::Node& at, const std::string& key, const std::string& why) const {
  std::string where = file_.string();
  int line = at.IsDefined() && at.Mark().line >= 0 ? at.Mark().line + 1 : 0;
  // An empty value (`tool:` alone) is marked where the next key starts: the key's own line.
  const SceneKeyLines& keys = sceneKeyLines();
  if ((!at.IsDefined() || at.IsNull()) && keys.file == file_)
    if (const auto it = keys.lines.find(key); it != keys.lines.end()) line = it->second;
  if (line > 0) where += ":" + std::to_string(line);
  throw InputError(where + ": " + key + ": " + why);
}

void Reader::expectMap(const YAML::Node& node, const std::string& key,
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

double Reader::number(const YAML::Node& node, const std::string& key) const {
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

double Reader::number(const YAML::Node& node, const std::string& key,
                      const std::function<bool(double)>& check, const std::string& what) const {
  const double value = number(node, key);
  if (!check(value)) fail(node, key, "must be " + what + " (got " + node.Scalar() + ")");
  return value;
}

double Reader::positive(const YAML::Node& node, const std::string& key) const {
  return number(
      node, key, [](double v) { return v > 0.0; }, "> 0");
}

std::string Reader::word(const YAML::Node& node, const std::string& key,
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

std::filesystem::path Reader::path(const YAML::Node& node, const std::string& key) const {
  if (!node.IsScalar() || node.Scalar().empty()) fail(node, key, "expected a file name");
  const std::filesystem::path p = node.Scalar();
  return p.is_absolute() ? p : file_.parent_path() / p;
}

geometry::TriangleMesh Reader::mesh(const YAML::Node& node, const std::string& key) const {
  try {
    return loadSceneMesh(path(node, key));
  } catch (const InputError& e) {
    fail(node, key, e.what());
  }
}

void Reader::check(const YAML::Node& node, const std::string& key,
                   const std::function<void()>& validate) const {
  try {
    validate();
  } catch (const InputError& e) {
    fail(valueNamedIn(node, e.what()), key, e.what());
  }
}

}  // namespace fieldpath::app
