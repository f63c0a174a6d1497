/// The parametric impeller in scene files: `obstacles: - impeller: {...}` (keys of
/// pathgen::ImpellerParams, documented in examples/impeller/scene.yaml) and `guide: { impeller: hub
/// }`.
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/pathgen/generate.h"
#include "estimates.h"
#include "scene.h"

namespace fieldpath::app {
namespace {

using common::InputError;

/// "FILE:LINE: " of a node.
std::string where(const Scene& scene, const YAML::Node& node) {
  std::string at = scene.file.string();
  if (node.IsDefined() && node.Mark().line >= 0) at += ":" + std::to_string(node.Mark().line + 1);
  return at + ": ";
}

double number(const Scene& scene, const YAML::Node& node, const std::string& key) {
  try {
    if (node.IsScalar()) return node.as<double>();
  } catch (const YAML::Exception&) {
  }
  throw InputError(where(scene, node) + key + ": expected a number");
}

std::array<double, 2> pair(const Scene& scene, const YAML::Node& node, const std::string& key) {
  if (!node.IsSequence() || node.size() != 2)
    throw InputError(where(scene, node) + key + ": expected [first, second]");
  return {number(scene, node[0], key), number(scene, node[1], key)};
}

pathgen::ImpellerParams readImpeller(const Scene& scene, const YAML::Node& node) {
  const std::string prefix = "obstacles.impeller.";
  pathgen::ImpellerParams p;
  if (node.IsNull()) return p;  // `- impeller:` alone: every default
  if (!node.IsMap())
    throw InputError(where(scene, node) + "obstacles.impeller: expected a map of keys");
  for (const auto& kv : node) {
    const std::string key = kv.first.Scalar();
    const YAML::Node& value = kv.second;
    const std::string name = prefix + key;
    if (key == "length")
      p.length_mm = number(scene, value, name);
    else if (key == "width_in")
      p.width_in_mm = number(scene, value, name);
    else if (key == "width_out")
      p.width_out_mm = number(scene, value, name);
    else if (key == "bend")
      p.bend_mm = number(scene, value, name);
    else if (key == "hub_rise")
      p.hub_rise_mm = number(scene, value, name);
    else if (key == "hub_dish")
      p.hub_dish_mm = number(scene, value, name);
    else if (key == "blade_height")
      p.blade_height_mm = number(scene, value, name);
    else if (key == "lean_left_deg")
      p.lean_left_deg = pair(scene, value, name);
    else if (key == "lean_right_deg")
      p.lean_right_deg = pair(scene, value, name);
    else if (key == "passes_v")
      p.passes_v = pair(scene, value, name);
    else if (key == "u_range")
      p.u_range = pair(scene, value, name);
    else if (key == "chord_tol")
      p.chord_tol_mm = number(scene, value, name);
    else
      throw InputError(
          where(scene, kv.first) + name +
          ": unknown key (expected one of: length, width_in, width_out, bend, hub_rise, "
          "hub_dish, blade_height, lean_left_deg, lean_right_deg, passes_v, u_range, "
          "chord_tol)");
  }
  return p;
}

}  // namespace

void resolveImpeller(Scene& scene) {
  if (!scene.impeller)
    throw InputError(
        where(scene, *scene.guide_impeller) +
        "guide.impeller: needs the impeller among the obstacles (`- impeller: {...}`)");
  const YAML::Node& node = *scene.impeller;
  const pathgen::ImpellerParams params = readImpeller(scene, node);
  try {
    scene.impeller_model.emplace(params);
  } catch (const InputError& e) {
    throw InputError(where(scene, valueNamedIn(node, e.what())) + "obstacles." + e.what());
  }
  checkImpellerSize(*scene.impeller_model, where(scene, node));  // before the meshes are made
  for (auto& blade : pathgen::bladeMeshes(*scene.impeller_model))
    scene.obstacles.push_back(std::move(blade));
  if (scene.guide_impeller) {
    const YAML::Node& guide = *scene.guide_impeller;
    if (!guide.IsScalar() || guide.Scalar() != "hub")
      throw InputError(where(scene, guide) + "guide.impeller: expected `hub`");
    scene.part = scene.impeller_model->hubMesh();
  }
}

}  // namespace fieldpath::app
