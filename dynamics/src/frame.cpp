#include "fieldpath/dynamics/frame.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/QR>

#include "fieldpath/common/errors.h"

namespace fieldpath::dynamics {
namespace {

/// Below this |f⊥| / |f| the feed is taken as parallel to the normal (≈ 0.06°).
constexpr double kParallelTolerance = 1e-3;

/// v with its component along unit n removed, normalised; false if (nearly) nothing is left.
bool orthogonalUnit(const Vec3& v, const Vec3& n, Vec3& out) {
  const double norm = v.norm();
  if (!(norm > 0.0) || !std::isfinite(norm)) return false;
  const Vec3 perp = v - v.dot(n) * n;
  const double perp_norm = perp.norm();
  if (!(perp_norm > kParallelTolerance * norm)) return false;
  out = perp / perp_norm;
  return true;
}

}  // namespace

LocalFrame localFrame(const PassFrame& frame, const Vec3& fallback_feed) {
  const double normal_norm = frame.normal.norm();
  if (!(normal_norm > 0.0) || !std::isfinite(normal_norm)) {
    std::ostringstream msg;
    msg << "pass frame: guide normal (" << frame.normal.transpose() << ") is zero or not finite";
    throw common::InputError(msg.str());
  }
  LocalFrame out;
  out.n = frame.normal / normal_norm;
  if (!orthogonalUnit(frame.feed, out.n, out.f)) {
    out.degenerate = true;
    if (!orthogonalUnit(fallback_feed, out.n, out.f)) out.f = out.n.unitOrthogonal();
  }
  out.b = out.n.cross(out.f);
  return out;
}

Vec3 axisFromAngles(const LocalFrame& frame, double lead_rad, double tilt_rad) {
  const double cl = std::cos(lead_rad), sl = std::sin(lead_rad);
  const double ct = std::cos(tilt_rad), st = std::sin(tilt_rad);
  return sl * frame.f + cl * (ct * frame.n - st * frame.b);
}

namespace {

/// ∂a/∂lead and ∂a/∂tilt of axisFromAngles in `frame`, as columns.
Eigen::Matrix<double, 3, 2> angleDerivatives(const LocalFrame& frame, double lead, double tilt) {
  const double cl = std::cos(lead), sl = std::sin(lead), ct = std::cos(tilt), st = std::sin(tilt);
  Eigen::Matrix<double, 3, 2> d;
  d.col(0) = cl * frame.f - sl * (ct * frame.n - st * frame.b);
  d.col(1) = -cl * (st * frame.n + ct * frame.b);
  return d;
}

}  // namespace

std::array<double, 2> anglesOfAxis(const LocalFrame& frame, const Vec3& axis) {
  return {std::asin(std::clamp(axis.dot(frame.f), -1.0, 1.0)),
          std::atan2(-axis.dot(frame.b), axis.dot(frame.n))};
}

std::array<double, 4> reexpressState(const LocalFrame& from, const LocalFrame& to,
                                     const std::array<double, 4>& state) {
  const Vec3 axis = axisFromAngles(from, state[0], state[1]);
  const Vec3 rate =
      angleDerivatives(from, state[0], state[1]) * Eigen::Vector2d(state[2], state[3]);
  const std::array<double, 2> angles = anglesOfAxis(to, axis);
  std::array<double, 4> out = {angles[0], angles[1], 0.0, 0.0};
  const Eigen::Vector2d rates =
      angleDerivatives(to, out[0], out[1]).colPivHouseholderQr().solve(rate);
  out[2] = rates[0];
  out[3] = rates[1];
  return out;
}

}  // namespace fieldpath::dynamics
