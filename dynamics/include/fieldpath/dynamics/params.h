#pragma once
#include <cmath>

#include "fieldpath/geometry/units.h"

/// Settings of the tool-axis dynamics (scene `dynamics:` block). Defaults documented here, once.

namespace fieldpath::dynamics {

/// `integrator`: CVODE BDF (default) or ARKODE ERK (explicit reference).
enum class Integrator { Bdf, Erk };

/// `on_limit`: what to do when an output sample leaves the configured angle limits.
enum class LimitPolicy {
  Clamp,  ///< `clamp`: hold the angle at the limit (rate zeroed, solver restarted); flagged
  Fail,   ///< `fail`: stop; status TiltLimit / RateLimit and a message naming the arc length
};

/// `start`: the axis a pass starts from (DESIGN.md leaves it open; seed 004 starts at the
/// nominal angles). A pass whose nominal start posture already crowds an obstacle would begin
/// colliding and then swing at once; settled, it begins where the field and the spring balance.
enum class StartPolicy {
  Auto,     ///< `auto`: settled where the nominal start posture is within `clearance` (pathgen)
  Nominal,  ///< `nominal`: the nominal angles at rest
  Settled,  ///< `settled`: the axis at rest under the field at the pass's first frame
};

/// Torques are in the field's unit times mm (τ = Σ (x_i - C) × F(x_i)); time in seconds.
struct DynamicsParams {
  double inertia = 1.0;  ///< J, torque·s²/rad
  /// c, torque·s/rad; negative = critical: 2·sqrt(k·J) where the field is flat and, with a
  /// field, the matrix 2·sqrt(J·(k + K_f)), K_f the field's stiffness -∂τ/∂θ (its symmetric
  /// part, negative modes left to the spring) at the start of each output step: critical for
  /// each mode (a wall's stiffness is 10²-10⁴ × k: the spring's alone left the axis ringing into
  /// the far wall of a channel).
  double damping = -1.0;
  double stiffness = 1.0;           ///< k, torque/rad
  double feed_mm_per_min = 1000.0;  ///< v: s = v t
  double rtol = 1.0e-6;
  double atol =
      1.0e-9;  ///< on the angles (rad); the rates get atol·max(sqrt(k/J), 1 / output interval)
  double max_tilt_deg = 35.0;
  double max_lead_deg = 20.0;
  Integrator integrator = Integrator::Bdf;
  LimitPolicy on_limit = LimitPolicy::Clamp;
  StartPolicy start = StartPolicy::Auto;

  /// The angle limits in radians, as the steering holds them (one conversion for every user: a
  /// clear start on a grid converted otherwise lay 3e-17 rad over the steering's limit).
  double maxTiltRad() const { return max_tilt_deg * geometry::kDegToRad; }
  double maxLeadRad() const { return max_lead_deg * geometry::kDegToRad; }

  /// c, with the critical default resolved for the spring alone (a field adds its stiffness
  /// during a pass: steering.cpp).
  double effectiveDamping() const {
    return damping >= 0.0 ? damping : 2.0 * std::sqrt(stiffness * inertia);
  }

  /// The path length (mm) over which the axis answers a change of torque: v √(J/k), the spring's
  /// time constant at the feed (a wall's own stiffness shortens it). The feed is the dynamics'
  /// time scale (s = v t): ten times the feed, ten times the length, and the axis turns from a
  /// wall after passing it (a helper's 10 000 mm/min: 127 postures into the blades). In s the
  /// equation is J v² θ'' + c v θ' + k (θ - θ0) = τ: n times the feed steers as J / n² does.
  double responseLengthMm() const {
    return feed_mm_per_min / 60.0 * std::sqrt(inertia / stiffness);
  }
};

}  // namespace fieldpath::dynamics
