/// libFuzzer target: tool specs (ball:R[:L] | torus:R:r[:L] | flat:R[:L]) and holder profiles
/// (z0:r0,z1:r1,...), as `tool --shape/--holder` and `simulate --tool` read them. The input is
/// "SPEC\nHOLDER"; a valid pair is also meshed at a coarse tolerance and given surface nodes (a
/// few thousand, as generate asks for).
#include <algorithm>
#include <cmath>
#include <numbers>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/tool_model.h"
#include "fuzz_support.h"

namespace {

/// Node spacing (mm) for about 2000 surface nodes, from the area of the revolved profile, as the
/// program picks it (pathgen::defaultNodeSpacingMm, for 500): a spacing tied to the tool radius
/// alone asked a 613 mm holder on a 1 mm ball for ~10 M nodes (fuzz_tool timeout-93cb5020).
double spacingForFewNodes(const fieldpath::geometry::ToolSpec& tool,
                          const fieldpath::geometry::HolderProfile& holder) {
  const double r = tool.radius_mm;
  double area = 2 * std::numbers::pi * r * std::max(tool.length_mm, r);
  double prev_z = tool.length_mm, prev_r = r;
  for (const auto& station : holder) {
    area += std::numbers::pi * (station.radius_mm + prev_r) *
            std::hypot(station.z_mm - prev_z, station.radius_mm - prev_r);
    prev_z = station.z_mm;
    prev_r = station.radius_mm;
  }
  area += std::numbers::pi * prev_r * prev_r;
  return std::sqrt(area / 2000.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fieldpath::common::releaseHeldMemory();  // each input a run of its own (--max-memory)
  using namespace fieldpath;
  const std::string_view text = fuzz::view(data, size);
  const auto cut = text.find('\n');
  const std::string_view spec = text.substr(0, cut);
  const std::string_view holder =
      cut == std::string_view::npos ? std::string_view{} : text.substr(cut + 1);
  try {
    const geometry::ToolSpec tool = geometry::parseToolSpec(spec);
    const geometry::HolderProfile profile = geometry::parseHolderProfile(holder);
    // A tolerance relative to the tool: meshes of a few thousand triangles whatever its size.
    const auto mesh = geometry::toolMesh(tool, profile, 0.05 * tool.radius_mm);
    (void)mesh;
    (void)geometry::surfaceNodes(tool, profile, spacingForFewNodes(tool, profile));
  } catch (const common::InputError&) {
  }
  return 0;
}
