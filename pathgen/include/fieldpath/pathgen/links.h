#pragma once
/// Links between passes (DESIGN.md "Links and motion"): the output must be safe to run. Each pass
/// is entered and left along its tool axis; between passes the tool travels in a plane above every
/// mesh with the axis turned smoothly.
#include <optional>
#include <span>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/params.h"

namespace fieldpath::pathgen {

using geometry::Vec3;

/// Largest turn of the axis between two link postures (DESIGN.md: no step over 5°).
inline constexpr double kMaxLinkTurnDeg = 5.0;
/// `safe_z: auto`: this far above the highest mesh point, plus the clearance (mm).
inline constexpr double kSafeZMarginMm = 2.0;

/// Lowest z of tool + holder relative to the tip when the axis is `axis` (mm, ≤ 0 for a tool
/// pointing down): the lowest of the cutting end's corner circle and of every profile station.
double lowestPointBelowTip(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                           const Vec3& axis);

/// The highest vertex z of `meshes` (mm); -inf when they have none.
double topOfMeshes(std::span<const geometry::TriangleMesh> meshes);

/// The travel plane of a job's links, `top_mm` the highest vertex of its meshes (topOfMeshes):
/// `given_mm` when set, which must lie at least `clearance_mm` above it (below, the links would
/// travel through the meshes: InputError naming `links.safe_z`); else (`safe_z: auto`)
/// top + clearance + kSafeZMarginMm.
double resolveSafeZ(std::optional<double> given_mm, double top_mm, double clearance_mm);

struct LinkRequest {
  LinkParams params;
  double safe_z_mm = 0.0;  ///< resolved: nothing of tool + holder goes below it while travelling
  geometry::ToolSpec tool;
  geometry::HolderProfile holder;
  /// Per pass (by position in `passes`), the unit direction its link leaves it along and comes
  /// into it along, the axis held; absent or zero: along its axis (DESIGN). rerouteLinkEnds
  /// sets them where the axis's way runs into something.
  std::vector<Vec3> out_ways, in_ways;
};

/// The whole output path: an approach link before the first pass (down its axis from the travel
/// plane), a link between consecutive passes (retract along the axis, up to the travel plane,
/// across with the axis turned by ≤ kMaxLinkTurnDeg per posture, down the next axis) and a
/// departure after the last one. Throws common::InputError naming `links.` keys when a pass ends
/// or starts with an axis too close to horizontal to leave along it, or for bad settings.
geometry::PathFile linkPasses(std::span<const std::vector<geometry::Posture>> passes,
                              const LinkRequest& request);

}  // namespace fieldpath::pathgen
