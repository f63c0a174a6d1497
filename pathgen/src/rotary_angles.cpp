/// The stray of interpolated rotary angles from the checked motions (rotary_angles.h).
#include "fieldpath/pathgen/rotary_angles.h"

#include <algorithm>
#include <cmath>

namespace fieldpath::pathgen {
namespace {

/// Samples of a motion's stray: the angle paths differ smoothly in t (their largest gap is
/// read within a few per cent of it; the warning compares it with a clearance, not a tolerance).
constexpr int kStraySamples = 32;

/// An axis within this sine of the vertical has no azimuth of its own.
constexpr double kPoleSine = 1e-9;

struct Angles {
  double tilt, azimuth;
  bool pole;
};

Angles anglesOf(const Vec3& a) {
  const double across = std::hypot(a.x(), a.y());
  return {std::atan2(across, a.z()), std::atan2(a.y(), a.x()), across < kPoleSine};
}

/// b's azimuth less a's, the shorter way round, in (-pi, pi]; 0 where either is on the vertical.
double cTurn(const Angles& a, const Angles& b) {
  if (a.pole || b.pole) return 0.0;
  double d = std::remainder(b.azimuth - a.azimuth, 2.0 * M_PI);
  if (d <= -M_PI) d += 2.0 * M_PI;
  return d;
}

/// The axis at t on the great circle from a to b at an even pace (a controller given the tool
/// vector). check paces it as the normalised chord (geometry::alongMotion): the same arc, apart by
/// 0.0085 mm at 100 mm for a 10 deg turn (the axis_turn warning's), 0.07 for 20.
Vec3 greatCircle(const Vec3& a, const Vec3& b, double t) {
  const double angle = geometry::axisAngle(a, b);
  geometry::Posture p, q;
  p.axis = a;
  q.axis = b;
  if (angle < 1e-12 || M_PI - angle < 1e-9) return geometry::alongMotion(p, q, t).axis;
  return (std::sin((1 - t) * angle) * a + std::sin(t * angle) * b) / std::sin(angle);
}

}  // namespace

Vec3 axisByAngles(const Vec3& a, const Vec3& b, double t) {
  const Angles p = anglesOf(a.normalized()), q = anglesOf(b.normalized());
  const double tilt = (1 - t) * p.tilt + t * q.tilt;
  const double azimuth = p.pole ? q.azimuth : p.azimuth + t * cTurn(p, q);
  return {std::sin(tilt) * std::cos(azimuth), std::sin(tilt) * std::sin(azimuth), std::cos(tilt)};
}

RotaryStray rotaryStray(std::span<const geometry::Posture> postures, const MotionResult& motions,
                        double required_mm) {
  RotaryStray out;
  const std::size_t n = postures.size() < 2 ? 0 : postures.size() - 1;
  out.offset_mm.assign(n, 0.0);
  const double reach = motions.tool_reach_mm;
  for (std::size_t i = 0; i < n; ++i) {
    const geometry::Posture &a = postures[i], &b = postures[i + 1];
    double gap = 0.0;  // the largest chord between the two axes at one instant
    for (int k = 1; k < kStraySamples; ++k) {
      const double t = double(k) / kStraySamples;
      gap =
          std::max(gap, (axisByAngles(a.axis, b.axis, t) - greatCircle(a.axis, b.axis, t)).norm());
    }
    const double offset = reach * gap;
    out.offset_mm[i] = offset;
    if (offset > out.max_offset_mm) {
      out.max_offset_mm = offset;
      out.max_at = i;
    }
    // A motion under the required clearance as checked is said by the check itself: here only
    // those that the check passes.
    if (i < motions.clearance_mm.size() && motions.clearance_mm[i] >= required_mm) {
      const double clear = motions.clearance_mm[i];
      if (offset >= clear && out.beyond_clearance++ == 0) out.first_beyond = i;
      if (clear - offset < required_mm) ++out.under_required;
    }
  }
  const std::size_t said = out.first_beyond != RotaryStray::npos ? out.first_beyond : out.max_at;
  if (said != RotaryStray::npos) {
    const Vec3 &a = postures[said].axis, &b = postures[said + 1].axis;
    out.c_deg = cTurn(anglesOf(a.normalized()), anglesOf(b.normalized())) * 180.0 / M_PI;
    out.turn_deg = geometry::axisAngle(a, b) * 180.0 / M_PI;
  }
  return out;
}

}  // namespace fieldpath::pathgen
