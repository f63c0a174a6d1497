#include "fieldpath/geometry/tool_model.h"

#include <stdexcept>

#include "fieldpath/common/errors.h"

namespace fieldpath::geometry {

ToolSpec parseToolSpec(std::string_view text) {
  throw common::InputError("tool shape '" + std::string(text) + "': not implemented yet");
}
HolderProfile parseHolderProfile(std::string_view text) {
  if (text.empty()) return {};
  throw common::InputError("holder '" + std::string(text) + "': not implemented yet");
}
void validateToolSpec(const ToolSpec&) {}
void validateHolderProfile(const HolderProfile&) {}
TriangleMesh toolMesh(const ToolSpec&, const HolderProfile&, double) {
  throw std::logic_error("toolMesh: not implemented yet");
}
std::vector<SurfaceNode> surfaceNodes(const ToolSpec&, const HolderProfile&, double) {
  throw std::logic_error("surfaceNodes: not implemented yet");
}
double toolSurfaceDistance(const ToolSpec&, const Vec3&) {
  throw std::logic_error("toolSurfaceDistance: not implemented yet");
}

}  // namespace fieldpath::geometry
