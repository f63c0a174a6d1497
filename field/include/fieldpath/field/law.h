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
/// Beside a wall thinner than the sample spacing the nearest sample may be the far face's: the
/// thin-wall rule (isNearFace below) takes the near face's instead.
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

/// The thin-wall rule (ours, beside the surface rule): a wall thinner than the sample spacing,
/// its two faces sampled apart, may have its nearest sample to x on the far face, so that x
/// beside the near face reads inside (η < 0) and the surface rule mirrors it through the wall:
/// the field pulls x in (a 0.2 mm plate sampled every 1 mm: Fz -25 at 0.1 mm over it). Where
/// η* < 0 and q* is a far face (sampling.h farFaces: a sample facing the other way within
/// kThinReachSteps · sample_step behind it), the nearest sample j within |x - q*| +
/// kThinReachSteps · sample_step that is such a near face (isNearFace) stands for q*.
/// Sub-triangles have edges <= 1.5 steps (sampling.h), so a near face's sample lies that close
/// to q*, and to x's foot on it; a wall thicker than the reach needs no rule (its near face's
/// samples are nearer).
constexpr double kThinReachSteps = 1.5;

/// Whether sample (q_j, n_j) is a face between x and the face of q* (normal n*) behind which x
/// reads at height η* < 0: facing away from n* (n_j·n* < 0), on x's side of q*'s plane
/// ((q_j - q*)·n* < 0), x nearer its plane than q*'s (|(x - q_j)·n_j| < -η*). x in front of it
/// is outside beside the near face; x behind it, inside the wall nearer the near face, is
/// mirrored out of that face, the nearer (a point on the near face reads outside whichever way
/// its height rounds).
inline bool isNearFace(const Vec3& x, const Vec3& q, const Vec3& n, double height_mm,
                       const Vec3& q_j, const Vec3& n_j) {
  return n_j.dot(n) < 0.0 && (q_j - q).dot(n) < 0.0 && std::abs((x - q_j).dot(n_j)) < -height_mm;
}

/// A sample's part in the test that a near face's samples surround x's foot on its plane (law.h
/// probe's thin-wall rule): the unit vector from the foot to a sample of the same face (normal
/// within 18° of n_j, within half the reach of its plane, within the reach of the foot), counted
/// in *count; zero for any other sample. In the face's sampled interior the unit vectors cancel
/// (their mean under a half); beyond its edge they all point back (a half-disc's mean is 2/π).
inline Vec3 roundTerm(const Vec3& foot, const Vec3& n_j, double reach_mm, const Vec3& q_i,
                      const Vec3& n_i, int* count) {
  if (!(n_i.dot(n_j) >= 0.95)) return Vec3::Zero();
  const Vec3 d = q_i - foot;
  const double off = d.dot(n_j);
  if (!(std::abs(off) <= 0.5 * reach_mm)) return Vec3::Zero();
  const Vec3 lateral = d - off * n_j;
  const double length = lateral.norm();
  if (!(length <= reach_mm)) return Vec3::Zero();
  ++*count;
  return length > 0.0 ? Vec3((1.0 / length) * lateral) : Vec3::Zero();
}
/// Whether the summed roundTerm of `count` samples says the foot is surrounded: three at least,
/// the mean of their unit vectors under a half.
inline bool surrounded(const Vec3& round, int count) {
  return count >= 3 && round.norm() <= 0.5 * count;
}

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
/// P, N are random-access ranges of Vec3 (points, normals), W of double (weights), F of flags
/// (farFaces, sampling.h: the thin-wall rule's far faces). The nearest sample is sought within
/// `search_mm` (>= r0), the sum runs over those within r0.
template <class ForEachNear, class P, class N, class W, class F>
Probe probe(const Vec3& x_mm, ForEachNear&& for_each_near, const P& points, const N& normals,
            const W& weights, const F& far_face, const FieldParams& params, double search_mm) {
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
  out.nearest_mm = std::sqrt(nearest_sq);
  out.height_mm = (x_mm - points[out.nearest]).dot(normals[out.nearest]);
  if (out.height_mm < 0.0 && far_face[out.nearest]) {  // the thin-wall rule
    const Vec3 q = points[out.nearest], n_far = normals[out.nearest];
    double face_sq = out.nearest_mm + kThinReachSteps * params.sample_step_mm;
    face_sq *= face_sq;
    long face = -1;
    for_each_near(x_mm, std::sqrt(face_sq), [&](std::size_t j) {
      const double r2 = (x_mm - points[j]).squaredNorm();
      if (!(r2 < face_sq || (r2 == face_sq && face >= 0 && static_cast<long>(j) < face))) return;
      if (!isNearFace(x_mm, q, n_far, out.height_mm, points[j], normals[j])) return;
      face_sq = r2;
      face = static_cast<long>(j);
    });
    // The near face must lie under x's foot, its samples round the foot on its plane: beside a
    // wall's root, inside the block it stands on, a plane extended from the wall passes under
    // the point (a flange flush with a block's top: points 0.3-0.9 mm inside the block, within a
    // step of the flange's root, were pushed down into it, a review's).
    if (face >= 0) {
      const Vec3 q_j = points[face], n_j = normals[face];
      const Vec3 foot = x_mm - (x_mm - q_j).dot(n_j) * n_j;
      const double reach_mm = kThinReachSteps * params.sample_step_mm;
      Vec3 round = Vec3::Zero();
      int count = 0;
      for_each_near(foot, reach_mm, [&](std::size_t i) {
        round += roundTerm(foot, n_j, reach_mm, points[i], normals[i], &count);
      });
      if (!surrounded(round, count)) face = -1;
    }
    if (face >= 0) {
      out.nearest = face;
      out.nearest_mm = std::sqrt(face_sq);
      out.height_mm = (x_mm - points[face]).dot(normals[face]);
    }
  }
  const Vec3& n = normals[out.nearest];
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
template <class ForEachNear, class P, class N, class W, class F>
std::optional<Vec3> fieldAt(const Vec3& x_mm, ForEachNear&& for_each_near, const P& points,
                            const N& normals, const W& weights, const F& far_face,
                            const FieldParams& params) {
  return probe(x_mm, for_each_near, points, normals, weights, far_face, params, params.r0_mm).force;
}

}  // namespace detail
}  // namespace fieldpath::field
