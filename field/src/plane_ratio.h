#pragma once
/// The plane ratio of one node (voxel_field.h `stored: plane_ratio`): the pair (s, G) a node holds
/// so that P(s)·G gives back the field, and the side of the surface the node lies on; the CPU
/// reference rule the block and CUDA builds follow (their constants are asserted equal here).
#include <algorithm>
#include <cmath>

#include "fieldpath/field/law.h"
#include "fieldpath/field/voxel_field.h"
#include "node_kernel.h"

namespace fieldpath::field::voxel {

/// Whether x lies over (or under) the sampled surface: its nearest sample less than `over_mm`
/// sideways. Beyond the edge of an open wall it does not, and "inside" means nothing there.
inline bool overSurface(const detail::Probe& p, double over_mm) {
  const double lateral_sq = p.nearest_mm * p.nearest_mm - p.height_mm * p.height_mm;
  return lateral_sq <= over_mm * over_mm;
}

constexpr double kOverCos = 0.7;  ///< |cos| of the field's angle to n* over the surface
static_assert(kernel::kPlaneFit == kPlaneFitTolerance &&
                  kernel::kPlaneRescale == kPlaneRescaleLimit && kernel::kOverCos == kOverCos,
              "the block and CUDA builds' rules are the reference's");

/// One node of the plane ratio: s (mm), G, and whether it lies over/under the surface.
struct RatioNode {
  double s_mm;
  Vec3 g;
  bool over;
};

/// The plane-ratio pair (s, G) of one node from its probe (law.h): P(s)·G is the field there
/// and s is the plane height η on both sides of a plane, G the plane's normal.
/// - Elsewhere than below: s = P⁻¹(|F|), the height at which a plane gives |F|, and
///   G = F / P(s), the unit field direction: the node gives back F.
/// - Over the sampled surface closer than `near_mm` above it, or under it (inside the obstacle,
///   down to the inside band): the samples' own field there is not yet a plane's (each sample's
///   1/r³ shows, the r_min hold; inside, the surface rule's mirror), so the node holds the
///   continuation of the field at the point x' lifted to near_mm above the surface: s = s' - δ
///   (δ the lift) and G = G' of x'. Cells that reach down to or through the wall then
///   interpolate the field above it, and a node inside gets P(|s|)·G, finite and outward.
/// - Past r0 (the shell, no sample within r0): s = max(η, r0) and G the wall's direction, the
///   plane's continuation, so that a cell straddling r0 interpolates s linearly through it.
/// "Over the surface" (overSurface, and a field along n*) decides the side: beyond the edge of
/// an open wall the field is even about the wall's plane and s stays positive there.
/// `field_at(x')` is the direct field at a point.
template <class FieldAt>
RatioNode planeRatio(const detail::Probe& p, const Vec3& x, const Vec3& q, const Vec3& n,
                     const PlaneLaw& law, double gain, double over_mm, double near_mm,
                     FieldAt&& field_at) {
  const double eta = p.height_mm;
  // Over the surface, and the field along its normal (beyond an edge it turns sideways, away
  // from the edge, and the sign of η says nothing).
  const bool over = overSurface(p, over_mm) &&
                    (!p.force || std::abs(p.force->dot(n)) >= kOverCos * p.force->norm());
  const double sign = gain < 0.0 ? -1.0 : 1.0;
  if (!p.force) {  // shell: no sample within r0
    if (!over) return {std::max(p.nearest_mm, law.r0_mm), sign * (x - q) / p.nearest_mm, false};
    if (eta >= 0.0) return {std::max(eta, law.r0_mm), sign * n, true};
    return {-std::max(-eta, law.r0_mm), Vec3::Zero(), true};
  }
  auto ratioOf = [&](const Vec3& f, double lift_mm, bool is_over) {
    const double e = law.height(f.norm());
    const double plane = law.at(e);
    return RatioNode{e - lift_mm, plane > 0.0 ? Vec3(f / plane) : Vec3::Zero(), is_over};
  };
  if (!over || eta >= near_mm) return ratioOf(*p.force, 0.0, over);
  const double lift_mm = near_mm - eta;
  const Vec3 lifted = field_at(Vec3(x + lift_mm * n));
  // The continuation at the node itself, against the node's exact force (kPlaneFitTolerance):
  // where it overstates it up to kPlaneRescaleLimit ×, its height kept and G scaled to the
  // node's own force; beyond, the node's own force, s = P⁻¹(|F|); under the surface s < 0 and
  // no deeper than the node (η <= s: the refinement's inside test reads s as a height).
  const double e = law.height(lifted.norm());
  const double plane = law.at(e);
  const double continued = law.at(e - lift_mm) * lifted.norm(), own = plane * p.force->norm();
  if (plane > 0.0 && continued > (1.0 + kPlaneFitTolerance) * own &&
      continued <= kPlaneRescaleLimit * own) {
    const double at_node = law.at(e - lift_mm);
    return {e - lift_mm, at_node > 0.0 ? Vec3(*p.force / at_node) : Vec3::Zero(), over};
  }
  if (plane > 0.0 && continued > (1.0 + kPlaneFitTolerance) * own) {
    double s_mm = law.height(p.force->norm());
    if (eta < 0.0) s_mm = std::max(-s_mm, eta);
    const double own = law.at(s_mm);
    return {s_mm, own > 0.0 ? Vec3(*p.force / own) : Vec3::Zero(), false};
  }
  return {e - lift_mm, plane > 0.0 ? Vec3(lifted / plane) : Vec3::Zero(), over};
}

}  // namespace fieldpath::field::voxel
