#pragma once
/// Cutting tool and holder descriptions (tool frame: tip at origin, axis +z, mm).
/// The meshing and node generation live beside this in tool_model.h.
#include <utility>
#include <vector>

namespace fieldpath::geometry {

enum class ToolShape { Ball, Torus, Flat };

/// A milling tool with a cylindrical shank closed by a flat top at `length_mm`.
struct ToolSpec {
  ToolShape shape = ToolShape::Ball;
  double radius_mm = 3.0;         ///< R, tool radius
  double corner_radius_mm = 0.0;  ///< r, torus only (0 < r <= R)
  double length_mm = 12.0;        ///< L, from the tip to the top of the cutting body
};

/// Corner radius of the cutting end, mm: R for a ball, r for a torus, 0 for a flat end. It is also
/// the height above the tip where the cutting end meets the shank cylinder.
inline double cornerRadius(const ToolSpec& tool) {
  return tool.shape == ToolShape::Ball    ? tool.radius_mm
         : tool.shape == ToolShape::Torus ? tool.corner_radius_mm
                                          : 0.0;
}

/// Holder: (z from the tip, radius) stations, mm, revolved about +z; z increases, except that two
/// stations may share z to make a step to another radius.
struct HolderStation {
  double z_mm;
  double radius_mm;
};
using HolderProfile = std::vector<HolderStation>;

}  // namespace fieldpath::geometry
