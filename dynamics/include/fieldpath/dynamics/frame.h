#pragma once
#include <array>
/// The local frame of a pass and the tool axis as a function of the lead and tilt angles
/// (DESIGN.md "The dynamics"). Pure geometry; no solver here.
#include "fieldpath/geometry/posture.h"

namespace fieldpath::dynamics {

using geometry::Vec3;

/// What the programmed pass gives at one arc length: the ball centre and a (possibly sloppy) frame.
struct PassFrame {
  Vec3 centre_mm = Vec3::Zero();  ///< ball centre C, mm, world frame
  Vec3 feed = Vec3::UnitX();      ///< feed direction; need not be unit nor orthogonal to `normal`
  Vec3 normal = Vec3::UnitZ();    ///< guide-surface normal (towards the tool); need not be unit
  double lead0_rad = 0.0;         ///< nominal lead θ0 (about b)
  double tilt0_rad = 0.0;         ///< nominal tilt θ0 (about f)
};

/// Orthonormal right-handed local frame at the ball centre: f (feed), n (normal), b = n × f.
struct LocalFrame {
  Vec3 f = Vec3::UnitX();
  Vec3 n = Vec3::UnitZ();
  Vec3 b = Vec3::UnitY();
  bool degenerate =
      false;  ///< the feed was (nearly) parallel to the normal; f came from the fallback
};

/// n normalised; f = the feed with its n component removed, normalised. When that is (nearly) zero
/// (feed parallel to the normal, or a zero feed), f is `fallback_feed` projected the same way, and
/// if that fails too, a fixed unit vector orthogonal to n (Eigen's unitOrthogonal), so the frame is
/// always finite. Throws common::InputError if the normal is zero or not finite.
LocalFrame localFrame(const PassFrame& frame, const Vec3& fallback_feed = Vec3::Zero());

/// Tool axis a (unit, tip → spindle): n turned by `lead_rad` about b (towards +f), then by
/// `tilt_rad` about f (towards -b):  a = sin(L) f + cos(L) (cos(T) n - sin(T) b).
Vec3 axisFromAngles(const LocalFrame& frame, double lead_rad, double tilt_rad);

/// The (lead, tilt) of unit `axis` in `frame`, rad: axisFromAngles inverted (lead in
/// [-90, 90] deg).
std::array<double, 2> anglesOfAxis(const LocalFrame& frame, const Vec3& axis);

/// A steering state (lead, tilt in rad, their rates in rad/s) in `from` expressed in `to`: the
/// same axis, and the same velocity of the axis where `to`'s angles can give it (least squares).
/// What a corner held by the steering needs (steerPass, SteeringRequest::hold_corners).
std::array<double, 4> reexpressState(const LocalFrame& from, const LocalFrame& to,
                                     const std::array<double, 4>& state);

}  // namespace fieldpath::dynamics
