#pragma once
/// Spring-damper steering of the tool axis along one pass (seed 004 §1.2, DESIGN.md "The
/// dynamics"): the ball centre follows the pass exactly, the axis turns under the moment of the
/// repulsive field at the tool and holder nodes, and a spring-damper pulls it back to the nominal
/// angles:
///
///   J θ'' + c θ' + k (θ - θ0(s)) = τ(θ),   θ = (lead, tilt),   s = v t,
///   τ = [ M·e, M·f ],   M = Σ (x_i - C) × F(x_i)   (world frame, about the ball centre C),
///   e = cos(tilt) b + sin(tilt) n   (b turned by the tilt about f).
///
/// Integrated in time with CVODE (BDF, dense Newton, difference-quotient Jacobian) or, for
/// comparison, ARKODE's explicit ERK, which reports SolverFailed when stiffness outruns its budget.
/// DESIGN.md writes τ_lead = M·b (seed 004's small angles); the axis being n turned about b by
/// the lead, then about f by the tilt, the lead's generalised force is M·e (τ = -∂U/∂θ where the
/// field is a potential's gradient), which differs by sin(tilt) M·n. That share, which no lead
/// relieves, held the lead at its limit beside a wall on a slope, the holder nearer it
/// (dynamics.md, 2026-12-01). Each steerPass call has its
/// own SUNDIALS context: calls for different passes may run in parallel (if the field is
/// thread-safe, as ForceField requires).
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/dynamics/frame.h"
#include "fieldpath/dynamics/params.h"
#include "fieldpath/field/force_field.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::dynamics {

/// The programmed pass: ball-centre curve with its frame as a function of arc length s in
/// [0, length_mm]. Called at arbitrary s (solver stages), so it must be cheap and deterministic.
struct Pass {
  double length_mm = 0.0;
  std::function<PassFrame(double s_mm)> frameAt;
};

struct SteeringRequest {
  const field::ForceField* field = nullptr;  ///< not owned; null = no field (free response)
  /// Tool + holder nodes, tool frame (tip at 0, axis +z), mm; not owned.
  std::span<const Vec3> nodes_tool_frame_mm;
  double ball_radius_mm = 3.0;  ///< R: the ball centre is at (0, 0, R) in the tool frame
  DynamicsParams params;
  double step_mm = 0.5;  ///< arc length between output samples (the last one lands on length_mm)
  /// Output stations instead (mm, from 0, increasing, within the pass), e.g. a nominal path's
  /// postures one for one; `step_mm` then only bounds the solver's step.
  std::vector<double> output_s_mm;
  std::optional<double> initial_lead_rad;  ///< default: nominal θ0(0)
  std::optional<double> initial_tilt_rad;  ///< default: nominal θ0(0)
  double initial_lead_rate_rad_per_s = 0.0;
  double initial_tilt_rate_rad_per_s = 0.0;
  /// Between output samples, either angle; 0 = unchecked.
  double max_angle_change_deg_per_mm = 0.0;
  /// Solver step budget per output interval. BDF needs a few hundred to resolve a stiff start at
  /// tight tolerances; ERK runs out of it when stability, not accuracy, limits its step.
  long max_steps_per_output = 5000;
  /// Optional: distance (mm) from the placed nodes (world frame) to the obstacles, stored in each
  /// sample (pathgen passes an FCL or point query). NaN in the samples when unset.
  std::function<double(std::span<const Vec3> nodes_world_mm)> clearance;
  common::Progress progress;
  /// Corners (the feed turning by over 20° within 2 mm: steering.cpp kCornerTurnDeg): false,
  /// DESIGN's frame, the axis turning with the feed; true, the feed held through each corner and
  /// the angles re-expressed after it, the axis keeping its direction. Neither is right at every
  /// corner (a tilt held away from a wall the pass turns from leans at it after the turn; a lean
  /// away from a boss the pass turns round is lost when held): pathgen steers a pass with corners
  /// held only where DESIGN's comes under its clearance, and keeps the clearer.
  bool hold_corners = false;
};

/// One output sample, every `step_mm` along the pass.
struct PostureSample {
  double s_mm = 0.0;
  double lead_rad = 0.0, tilt_rad = 0.0;
  double lead_rate_rad_per_s = 0.0, tilt_rate_rad_per_s = 0.0;
  double lead_torque = 0.0, tilt_torque = 0.0;  ///< τ = [M·e, M·f] (above)
  Vec3 moment = Vec3::Zero();                   ///< M about the ball centre, world frame
  double clearance_mm = 0.0;                    ///< from SteeringRequest::clearance, else NaN
  geometry::Posture posture;                    ///< tip = C - R a, axis a
  bool limited = false;  ///< clamped (params.on_limit Clamp) or rate over limit
};

/// Solver counters, summed over restarts (clamps).
struct SolverStats {
  long steps = 0;
  long rhs_evals = 0;       ///< all right-hand-side evaluations, Jacobian ones included
  long jacobian_evals = 0;  ///< dense difference-quotient Jacobians (BDF only)
  long error_test_failures = 0;
  long convergence_failures = 0;  ///< nonlinear (Newton) convergence failures (BDF only)
  long restarts = 0;              ///< re-initialisations after a clamp
};

enum class Status {
  Ok,
  TiltLimit,     ///< an angle left [-max, max] (LimitPolicy::Fail)
  RateLimit,     ///< an angle changed faster than max_angle_change_deg_per_mm (Report)
  SolverFailed,  ///< the integrator gave up (step budget, convergence, non-finite moment)
};
const char* toString(Status status);

struct SteeringResult {
  std::vector<PostureSample> samples;  ///< s = 0, step, 2 step, ..., length (up to a failure)
  SolverStats stats;
  Status status = Status::Ok;
  std::string message;  ///< empty when Ok; otherwise names the arc length (mm) and the cause
  int clamped_samples = 0;
  /// Stations with a corner (kCornerTurnDeg within kCornerWindowMm) ahead, held or not: 0 where
  /// the pass has none.
  int corners = 0;
};

/// Integrates one pass. Throws common::InputError for bad settings (naming the `dynamics.` key) and
/// common::Interrupted when the progress hook asks to stop; numerical outcomes are in `status`.
SteeringResult steerPass(const Pass& pass, const SteeringRequest& request);

/// The most stations settleAtStart integrates a decay time over (its step widened past the pass's
/// where the decay is longer than this many of them).
inline constexpr double kSettleStations = 2000.0;
/// A decay time longer than this much path (mm, at the feed) is not settled: the pass starts from
/// the nominal axis and settleAtStart says why.
inline constexpr double kMaxSettleMm = 1e5;

/// The axis at rest at a pass's start (DynamicsParams::start): the pass's first frame held while
/// the spring-damper runs from the nominal angles at rest, one decay time (the slower of 2J/c and
/// c/k) after another (c the spring's; `critical` adds the field's stiffness, which only shortens
/// the decay; with no spring, the field's at the nominal axis), until the axis moves less than
/// kSettledRad in one, or for kSettleDecays of them (the amplitude down by e^-20), or until it
/// cycles (kSettleCycleDecays decays in a row move no less than the least before); the angles
/// held at their limits on the way (on_limit: clamp whatever the pass's: the settling is not
/// machined, its swing beyond a limit is no failure; a rest beyond one is held at it, and a pass
/// with on_limit: fail then stops where the field pushes it further). `settled` false (and
/// `why`) where it cannot: no damping, the solver failing.
struct SettledStart {
  bool settled = false;
  double lead_rad = 0.0, tilt_rad = 0.0;
  std::string why;
  std::size_t stations =
      0;  ///< the stations integrated on the way (the work kSettleStations bounds)
};
constexpr double kSettleDecays = 20.0;
constexpr double kSettledRad = 1e-7;  ///< 6e-6 deg: far below DESIGN's 0.01 deg
/// Decays in a row that move no less than the least so far: the axis is cycling (settleAtStart).
constexpr int kSettleCycleDecays = 3;
SettledStart settleAtStart(const Pass& pass, const SteeringRequest& request);

/// The moment of the field on the nodes placed at axis angles (lead, tilt) at one pass frame, about
/// the ball centre: τ = [M·e, M·f] (node_moments.h momentOfNodes).
struct AxisMoment {
  Vec3 moment = Vec3::Zero();
  double lead_torque = 0.0, tilt_torque = 0.0;
};

/// The field's own angular stiffness K = -∂τ/∂θ (2×2, rows/columns lead, tilt; torque per rad) at
/// one pose, by central differences of the moment (step `delta_rad`). Near a wall K adds to the
/// spring: the default "critical" c = 2·sqrt(k·J) is then underdamped (a step in a wall
/// overshoots); a damping of 2·sqrt((k + K_tilt,tilt)·J) for the stiffest expected pose keeps the
/// response critical.
Eigen::Matrix2d fieldStiffness(const field::ForceField& field,
                               std::span<const Vec3> nodes_tool_frame_mm, double ball_radius_mm,
                               const LocalFrame& frame, const Vec3& centre_mm, double lead_rad,
                               double tilt_rad, double delta_rad = 1e-4);

}  // namespace fieldpath::dynamics
