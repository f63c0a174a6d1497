#include "scene_sections.h"

#include <cctype>
#include <cmath>
#include <string>

#include "fieldpath/common/limits.h"
#include "fieldpath/common/short_number.h"
#include "fieldpath/geometry/tool_model.h"

namespace fieldpath::app {

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
  const auto inRange = [](double v) {
    return v >= common::kMinSpringConstant && v <= common::kMaxSpringConstant;
  };
  const auto constant = [&](const char* key) {
    return r.number(node[key], std::string("dynamics.") + key, inRange, "from 1e-12 to 1e12");
  };
  if (node["inertia"]) d.inertia = constant("inertia");
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
          node["damping"], "dynamics.damping", [&](double v) { return v == 0.0 || inRange(v); },
          "0, from 1e-12 to 1e12, or `critical`");
  }
  if (node["stiffness"]) d.stiffness = constant("stiffness");
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
          node["safe_z"], "links.safe_z",
          [](double v) { return std::abs(v) <= common::kMaxCoordinateMm; },
          "`auto` or a height in mm within 1e6 of 0");
  }
}

}  // namespace fieldpath::app
