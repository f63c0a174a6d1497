#pragma once
/// The repulsive law of seed 004, eq. 1 (DESIGN.md "The field"), written once for every evaluator
/// (brute force, direct, voxel nodes). No OpenVDB here.
///
/// F(x) = gain · Σ_j w_j φ(r_j) u_j,  r_j = |x - q_j|,  u_j = (x - q_j) / r_j,
/// φ(r) = (1/r - 1/r0) / r² for r < r0 (0 beyond), held at φ(r_min) for r < r_min.
///
/// Surface rule (ours; the seed is silent, DESIGN.md asks for an outward force inside walls): let
/// q* be the nearest sample within r0, n* its normal and η = (x - q*)·n* the height of x above
/// its tangent plane (η < 0: inside the obstacle, the seed's normal sign test of §2.1). Where
/// η < r_min, x gets the field at x'' = x + (max(|η|, r_min) - η) n*: held at its value r_min
/// off the surface for |η| < r_min, and mirrored out of the wall deeper inside. Eq. 1 alone
/// would give a plane's field that falls to zero on the surface (the r_min hold makes the
/// samples under x pull sideways) and, inside, would push x deeper. So the field is finite and
/// outward on both sides, continuous through η = ±r_min, and even in η (which keeps voxel
/// interpolation across a wall honest); a point exactly on a sample uses its normal for u.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>

#include "fieldpath/field/params.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

using geometry::Vec3;

/// φ of eq. 1 with the r_min hold; r, r0, r_min in mm, result in 1/mm³.
inline double phi(double r_mm, double r0_mm, double r_min_mm) {
  if (r_mm >= r0_mm) return 0.0;
  const double r = std::max(r_mm, r_min_mm);
  return (1.0 / r - 1.0 / r0_mm) / (r * r);
}

/// One sample's term of eq. 1 before the gain (without the surface rule): w · φ(r) · u, world
/// frame, for d = x - q (mm) and r2 = |d|² (the sum has it already: it tracks the nearest sample
/// with it). u = d / r, or the sample's unit outward normal where x = q exactly; zero from r0 on
/// (φ is). The one evaluation of a sample's force, summed by probe() below.
inline Vec3 sampleTerm(const Vec3& d_mm, double r2_mm2, const Vec3& normal, double weight,
                       const FieldParams& params) {
  const double r = std::sqrt(r2_mm2);
  const Vec3 u = r > 0.0 ? Vec3(d_mm / r) : normal;
  return (weight * phi(r, params.r0_mm, params.r_min_mm)) * u;
}

/// Magnitude of the field of an infinite plane of area-weighted samples at distance d (mm) on its
/// outer side: π·gain·(r0 - d)² / (d·r0²) for r_min <= d < r0 (eq. 1 integrated over the plane).
inline double planeFieldMagnitude(double d_mm, const FieldParams& params) {
  if (d_mm >= params.r0_mm) return 0.0;
  const double r0 = params.r0_mm;
  return M_PI * params.gain * (r0 - d_mm) * (r0 - d_mm) / (d_mm * r0 * r0);
}

/// The plane law P calibrated to a sample set: the magnitude of the field of an infinite plane
/// sampled like `samples` (weights per mm² of surface: 1 for area weights), at height d (mm):
/// κ·π·|gain|·(r0 - d)²/(d·r0²). The voxel field's "plane ratio" stores F / P(d) beside d.
struct PlaneLaw {
  double r0_mm = 5.0;
  double r_min_mm = 0.25;
  double scale = 0.0;  ///< κ·π·|gain| / r0², in units of |F|·mm

  PlaneLaw(const FieldParams& params, double weight_per_mm2 = 1.0)
      : r0_mm(params.r0_mm),
        r_min_mm(params.r_min_mm),
        scale(weight_per_mm2 * M_PI * std::abs(params.gain) / (params.r0_mm * params.r0_mm)) {}

  /// P at |d| held below r_min, zero from r0 on; d in mm.
  double at(double d_mm) const {
    const double d = std::max(std::abs(d_mm), r_min_mm);
    if (d >= r0_mm) return 0.0;
    return scale * (r0_mm - d) * (r0_mm - d) / d;
  }
  /// The height d in (0, r0] at which P(d) = magnitude, the lesser root of
  /// scale·(r0 - d)² = magnitude·d, in its cancellation-free form; r0 for a zero magnitude.
  double height(double magnitude) const {
    if (!(magnitude > 0.0) || !(scale > 0.0)) return r0_mm;
    const double b = 2.0 * scale * r0_mm + magnitude;
    return 2.0 * scale * r0_mm * r0_mm /
           (b + std::sqrt(magnitude * (4.0 * scale * r0_mm + magnitude)));
  }
};

namespace detail {

/// What one evaluation of eq. 1 learns at x: the field (with the surface rule) and the nearest
/// sample, which the voxel build uses to place x relative to the surface.
struct Probe {
  std::optional<Vec3> force;     ///< nothing where no sample is within r0 (the field is zero)
  long nearest = -1;             ///< nearest sample within the search radius, -1 if none
  double nearest_mm = HUGE_VAL;  ///< |x - q*|
  double height_mm = 0.0;        ///< η = (x - q*)·n*: < 0 inside the obstacle
};

/// Eq. 1 summed over candidate samples with the surface rule. `for_each_near(center, radius, fn)`
/// must call fn(j) at least for every sample j within `radius` of `center` (a superset is fine);
/// P, N are random-access ranges of Vec3 (points, normals), W of double (weights). The nearest
/// sample is sought within `search_mm` (>= r0), the sum runs over those within r0.
template <class ForEachNear, class P, class N, class W>
Probe probe(const Vec3& x_mm, ForEachNear&& for_each_near, const P& points, const N& normals,
            const W& weights, const FieldParams& params, double search_mm) {
  const double r0_sq = params.r0_mm * params.r0_mm;
  auto sum = [&](const Vec3& at, double radius, double* nearest_sq, long* nearest) {
    Vec3 f = Vec3::Zero();
    for_each_near(at, radius, [&](std::size_t j) {
      const Vec3 d = at - points[j];
      const double r2 = d.squaredNorm();
      // Ties go to the lowest index, whatever order for_each_near visits them in (a cube's
      // edge node lies as near to samples of both faces): the voxel builds agree with it.
      if (nearest && (r2 < *nearest_sq ||
                      (r2 == *nearest_sq && *nearest >= 0 && static_cast<long>(j) < *nearest))) {
        *nearest_sq = r2;
        *nearest = static_cast<long>(j);
      }
      if (r2 >= r0_sq) return;  // sampleTerm is zero there; skip its sqrt
      f += sampleTerm(d, r2, normals[j], weights[j], params);
    });
    return f;
  };
  Probe out;
  double nearest_sq = std::max(search_mm, params.r0_mm);
  nearest_sq *= nearest_sq;
  Vec3 f = sum(x_mm, std::sqrt(nearest_sq), &nearest_sq, &out.nearest);
  if (out.nearest < 0) return out;
  const Vec3& n = normals[out.nearest];
  out.nearest_mm = std::sqrt(nearest_sq);
  out.height_mm = (x_mm - points[out.nearest]).dot(n);
  if (nearest_sq >= r0_sq) return out;
  if (out.height_mm < params.r_min_mm) {
    const double lifted_mm = std::max(std::abs(out.height_mm), params.r_min_mm);
    f = sum(x_mm + (lifted_mm - out.height_mm) * n, params.r0_mm, nullptr, nullptr);
  }
  out.force = Vec3(params.gain * f);
  return out;
}

/// The field at x (probe() with the search radius r0). Returns nothing where no sample is within
/// r0 (the field is zero there).
template <class ForEachNear, class P, class N, class W>
std::optional<Vec3> fieldAt(const Vec3& x_mm, ForEachNear&& for_each_near, const P& points,
                            const N& normals, const W& weights, const FieldParams& params) {
  return probe(x_mm, for_each_near, points, normals, weights, params, params.r0_mm).force;
}

}  // namespace detail
}  // namespace fieldpath::field
