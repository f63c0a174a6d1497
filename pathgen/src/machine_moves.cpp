/// Where a machine's interpolation leaves the checked motions (machine_moves.h).
#include "fieldpath/pathgen/machine_moves.h"

#include <algorithm>
#include <cmath>

#include "fieldpath/geometry/units.h"

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
    // An axis held (a 3-axis pass, a straight retract) strays nothing: no trigonometry for it.
    for (int k = 1; k < kStraySamples && a.axis != b.axis; ++k) {
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
    out.c_deg = cTurn(anglesOf(a.normalized()), anglesOf(b.normalized())) * geometry::kRadToDeg;
    out.turn_deg = geometry::axisAngle(a, b) * geometry::kRadToDeg;
  }
  return out;
}

namespace {

/// The farthest point of the box spanned by a and b from the segment ab (mm): one of its corners.
double boxFromSegment(const Vec3& a, const Vec3& b) {
  const Vec3 d = b - a;
  const double length_sq = d.squaredNorm();
  double farthest = 0.0;
  for (int corner = 0; corner < 8; ++corner) {
    const Vec3 c((corner & 1) ? b.x() : a.x(), (corner & 2) ? b.y() : a.y(),
                 (corner & 4) ? b.z() : a.z());
    const double t = length_sq > 0.0 ? std::clamp((c - a).dot(d) / length_sq, 0.0, 1.0) : 0.0;
    farthest = std::max(farthest, (c - (a + t * d)).norm());
  }
  return farthest;
}

}  // namespace

DogLegRapids dogLegRapids(const geometry::PathFile& path, const MotionResult& motions,
                          double required_mm) {
  DogLegRapids out;
  std::vector<char> link(path.postures.size(), 0);
  for (const geometry::PathBlock& b : path.blocks)
    if (b.kind == geometry::PathBlock::Kind::Link)
      std::fill(link.begin() + std::ptrdiff_t(b.begin), link.begin() + std::ptrdiff_t(b.end), 1);
  for (std::size_t i = 0; i + 1 < path.postures.size(); ++i) {
    if (!link[i + 1] || i >= motions.clearance_mm.size()) continue;
    ++out.rapids;
    const geometry::Posture &a = path.postures[i], &b = path.postures[i + 1];
    const double box_mm = boxFromSegment(a.tip_mm, b.tip_mm) +
                          motions.tool_reach_mm * geometry::axisAngle(a.axis, b.axis);
    const double bound = motions.clearance_mm[i] - box_mm;
    // A motion under the required clearance as checked is said by the check itself.
    if (motions.clearance_mm[i] < required_mm) {
      ++out.checked_under;
      continue;
    }
    if (bound >= required_mm) continue;
    if (out.unproven++ == 0 || bound < out.lowest_bound_mm) {
      out.lowest = i;
      out.lowest_bound_mm = bound;
      out.lowest_box_mm = box_mm;
    }
  }
  return out;
}

}  // namespace fieldpath::pathgen
