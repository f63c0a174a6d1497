/// libFuzzer target: tool specs (ball:R[:L] | torus:R:r[:L] | flat:R[:L]) and holder profiles
/// (z0:r0,z1:r1,...), as `tool --shape/--holder` and `simulate --tool` read them. The input is
/// "SPEC\nHOLDER"; a valid pair is also meshed at a coarse tolerance and given surface nodes.
#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/tool_model.h"
#include "fuzz_support.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fieldpath;
  const std::string_view text = fuzz::view(data, size);
  const auto cut = text.find('\n');
  const std::string_view spec = text.substr(0, cut);
  const std::string_view holder = cut == std::string_view::npos ? std::string_view{} : text.substr(cut + 1);
  try {
    const geometry::ToolSpec tool = geometry::parseToolSpec(spec);
    const geometry::HolderProfile profile = geometry::parseHolderProfile(holder);
    // A tolerance relative to the tool: meshes of a few thousand triangles whatever its size.
    const auto mesh = geometry::toolMesh(tool, profile, 0.05 * tool.radius_mm);
    (void)mesh;
    (void)geometry::surfaceNodes(tool, profile, 0.5 * tool.radius_mm);
  } catch (const common::InputError&) {
  }
  return 0;
}
