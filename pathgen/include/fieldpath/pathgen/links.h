#pragma once
/// Links between passes (DESIGN.md "Links and motion"): the output must be safe to run. Each pass
/// is entered and left along its tool axis; between passes the tool travels in a plane above every
/// mesh with the axis turned smoothly.
#include <cmath>
#include <limits>
#include <optional>
#include <span>
#include <string>
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

/// A way a link leaves a pass's end posture or comes into it, the axis held: `retract` along
/// `retract_dir`, then by `sideways_mm` (a horizontal move, mm; zero: none), then on along `climb`
/// to the travel plane (unit vectors). Zero `climb`: DESIGN's way, along the axis
/// (rerouteLinkEnds sets others where that one runs into something).
/// `climb_mm`: the climb's length along `climb`, then straight up (a knee where the tool is out
/// from under what its axis's way ran into; infinite: all the way to the plane). `retract_mm`:
/// the retract's length, where shorter than `links.retract` (NaN: that one; a pass just under a
/// shelf, whose full retract runs into it, moves out sideways after a shorter one).
struct LinkEndWay {
  Vec3 retract_dir = Vec3::Zero();
  Vec3 climb = Vec3::Zero();
  Vec3 sideways_mm = Vec3::Zero();
  double climb_mm = std::numeric_limits<double>::infinity();
  double retract_mm = std::numeric_limits<double>::quiet_NaN();
  bool alongAxis() const { return climb == Vec3::Zero(); }
  /// The retract's length (mm): its own, else `links_retract_mm` (links.retract).
  double retractMm(double links_retract_mm) const {
    return std::isnan(retract_mm) ? links_retract_mm : retract_mm;
  }
};

/// The tips a link way off the axis (`way`, not alongAxis) passes from the pass's end posture
/// `tip_mm` out to the travel plane (the tip at `z_mm`), in that order: the retract's end, the
/// move sideways' end (if any), the knee (if the climb stops short), the point in the plane.
/// `retract_mm`: links.retract, used where the way has no length of its own.
std::vector<Vec3> wayTips(const Vec3& tip_mm, double z_mm, double retract_mm,
                          const LinkEndWay& way);

struct LinkRequest {
  LinkParams params;
  double safe_z_mm = 0.0;  ///< resolved: nothing of tool + holder goes below it while travelling
  geometry::ToolSpec tool;
  geometry::HolderProfile holder;
  /// Per pass (by position in `passes`), the way its link leaves it and comes into it; absent:
  /// along its axis (DESIGN).
  std::vector<LinkEndWay> out_ways, in_ways;
  /// Per pass, its name in messages ("pass 3 (nominal.cl:120)"); absent: "pass K".
  std::vector<std::string> labels;
};

/// The whole output path: an approach link before the first pass (down its axis from the travel
/// plane), a link between consecutive passes (retract along the axis, up to the travel plane,
/// across with the axis turned by ≤ kMaxLinkTurnDeg per posture, down the next axis) and a
/// departure after the last one. Throws common::InputError naming `links.` keys when a pass ends
/// or starts with an axis too close to horizontal to leave along it, or for bad settings.
geometry::PathFile linkPasses(std::span<const std::vector<geometry::Posture>> passes,
                              const LinkRequest& request);

}  // namespace fieldpath::pathgen
