#include "fieldpath/dynamics/frame.h"

#include <cmath>
#include <sstream>

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

}  // namespace fieldpath::dynamics
