#include "fieldpath/dynamics/steering.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "fieldpath/common/errors.h"
#include "fieldpath/dynamics/reversed_pass.h"
#include "node_moments.h"
#include "sundials_support.h"

namespace fieldpath::dynamics {
namespace {

using detail::centralStiffness;
using detail::momentOfNodes;
using detail::offsetsFromCentre;
using detail::placeNodes;

using geometry::kDegToRad;
using geometry::kRadToDeg;
constexpr int kStateSize = 4;  ///< lead, tilt (rad), lead rate, tilt rate (rad/s)

void requireThat(bool ok, const char* key, const char* condition, double value) {
  if (ok) return;
  std::ostringstream msg;
  msg << key << " must be " << condition << " (got " << value << ")";
  throw common::InputError(msg.str());
}

void validate(const Pass& pass, const SteeringRequest& request) {
  const DynamicsParams& p = request.params;
  requireThat(std::isfinite(p.inertia) && p.inertia > 0.0, "dynamics.inertia", "> 0", p.inertia);
  requireThat(!std::isnan(p.damping) && std::isfinite(p.effectiveDamping()), "dynamics.damping",
              ">= 0 (negative = critical)", p.damping);
  requireThat(std::isfinite(p.stiffness) && p.stiffness >= 0.0, "dynamics.stiffness", ">= 0",
              p.stiffness);
  requireThat(std::isfinite(p.feed_mm_per_min) && p.feed_mm_per_min > 0.0, "dynamics.feed", "> 0",
              p.feed_mm_per_min);
  requireThat(p.rtol > 0.0 && p.rtol < 1.0, "dynamics.rtol", "in (0, 1)", p.rtol);
  requireThat(p.atol > 0.0 && p.atol < 1.0, "dynamics.atol", "in (0, 1)", p.atol);
  requireThat(p.max_tilt_deg > 0.0 && p.max_tilt_deg <= 90.0, "dynamics.max_tilt_deg", "in (0, 90]",
              p.max_tilt_deg);
  requireThat(p.max_lead_deg > 0.0 && p.max_lead_deg <= 90.0, "dynamics.max_lead_deg", "in (0, 90]",
              p.max_lead_deg);
  requireThat(std::isfinite(request.step_mm) && request.step_mm > 0.0, "path.step", "> 0",
              request.step_mm);
  const auto& stations = request.output_s_mm;
  for (std::size_t i = 0; i < stations.size(); ++i)
    requireThat(std::isfinite(stations[i]) &&
                    (i == 0 ? stations[i] == 0.0 : stations[i] > stations[i - 1]) &&
                    stations[i] <= pass.length_mm,
                "output station (mm)", "0 first, increasing, within the pass", stations[i]);
  requireThat(std::isfinite(request.ball_radius_mm) && request.ball_radius_mm > 0.0, "tool.radius",
              "> 0", request.ball_radius_mm);
  requireThat(std::isfinite(pass.length_mm) && pass.length_mm >= 0.0, "pass length (mm)", ">= 0",
              pass.length_mm);
  requireThat(request.max_angle_change_deg_per_mm >= 0.0, "max angle change (deg/mm)", ">= 0",
              request.max_angle_change_deg_per_mm);
  requireThat(request.max_steps_per_output > 0, "max steps per output", "> 0",
              static_cast<double>(request.max_steps_per_output));
  if (!pass.frameAt) throw common::InputError("pass: no frame function (frameAt is empty)");
}

/// "s = 12.500 mm: ", the prefix of every message about a path position.
std::string at(double s_mm) {
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(3);
  out << "s = " << s_mm << " mm: ";
  return out.str();
}

/// Step of the angles for the field's stiffness (central differences), rad: wide enough to
/// span a few voxels at the holder (0.3 mm at 60 mm), so that a voxel field's piecewise slopes
/// give the direct field's stiffness, not their own.
constexpr double kStiffnessDeltaRad = 5e-3;

/// Arc length between two updates of the damping that follows the field (`critical`), mm: a grid
/// of its own from the pass's start, not the output stations, so that the angles do not depend on
/// `path.step` (a helper's ribs: 0.79° of lead between steps 0.5 and 0.25 mm, halving with the
/// step, as the damping was held from station to station). The impeller's default step: its
/// stations fall on the grid.
constexpr double kDampingSpacingMm = 0.5;

/// A corner (steerPass, SteeringRequest::hold_corners): the feed turning by more than
/// kCornerTurnDeg from a station to the first station kCornerWindowMm or more on (the next where
/// they lie farther apart): a sharp corner, or one filleted with a radius under ~5.7 mm (a circle
/// round a small pin too). The impeller's passes turn under 1 deg in 2 mm.
constexpr double kCornerTurnDeg = 20.0;
constexpr double kCornerWindowMm = 2.0;

/// localFrame of the pass frame at s; a zero or non-finite normal is bad input naming s.
LocalFrame localFrameAt(const PassFrame& frame, double s_mm) {
  try {
    return localFrame(frame);
  } catch (const common::InputError& e) {
    throw common::InputError(at(s_mm) + e.what());
  }
}

/// J θ'' + c θ' + k (θ - θ0(s)) = τ(θ), first-order form, time in s, s = v t.
class SteeringSystem final : public detail::OdeSystem {
 public:
  SteeringSystem(const Pass& pass, const SteeringRequest& request)
      : pass_(pass),
        request_(request),
        offsets_mm_(offsetsFromCentre(request.nodes_tool_frame_mm, request.ball_radius_mm)),
        feed_mm_per_s_(request.params.feed_mm_per_min / 60.0),
        inertia_(request.params.inertia),
        damping_(request.params.effectiveDamping() * Eigen::Matrix2d::Identity()),
        stiffness_(request.params.stiffness),
        field_critical_(request.params.damping < 0.0 && request.field != nullptr) {}

  /// `damping: critical` with a field: the damping matrix C = 2 sqrt(J (k I + K_f)), critical
  /// for every mode of the spring and the field together (K_f = -∂τ/∂θ by central differences,
  /// fieldStiffness's, made symmetric, its negative modes left to the spring), at s for state y,
  /// held until the next call. Near a wall K_f is 10²-10⁴ × k: c = 2 sqrt(k J) left the axis
  /// ringing (ζ 0.01-0.08), and its first swing drove the shank into the far wall of a channel
  /// whose nominal path was clear (a helper's). The whole matrix, not its diagonal: a wall
  /// oblique to the frame splits its stiffness between the angles (ζ 0.71 from the diagonal at
  /// 45°). Set at every output station, without a threshold (a switch would make paths on two
  /// fields differ by where it fell); true when set (the solver restarts there: steerPass).
  bool updateDamping(double s_mm, const std::array<double, kStateSize>& y) {
    if (!field_critical_) return false;
    const Frames frames = frameAt(s_mm);
    const Eigen::Matrix2d k_field =
        centralStiffness([&](double lead, double tilt) { return moment(frames, lead, tilt); }, y[0],
                         y[1], kStiffnessDeltaRad);
    if (!k_field.allFinite()) return false;  // (the moment's own check names a bad field)
    const Eigen::Matrix2d total =
        stiffness_ * Eigen::Matrix2d::Identity() + 0.5 * (k_field + k_field.transpose());
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> modes(total);
    const Eigen::Vector2d rates = modes.eigenvalues().cwiseMax(stiffness_).cwiseSqrt();
    damping_ = 2.0 * std::sqrt(inertia_) * modes.eigenvectors() * rates.asDiagonal() *
               modes.eigenvectors().transpose();
    return true;
  }

  double feedMmPerS() const { return feed_mm_per_s_; }

  /// Arc length at time t, kept on the pass (solver stages may look slightly past the end).
  double arcLength(double t_s) const {
    return std::clamp(feed_mm_per_s_ * t_s, 0.0, pass_.length_mm);
  }

  int rhs(double t_s, const double* y, double* ydot) override {
    const double s_mm = arcLength(t_s);
    const Frames frames = frameAt(s_mm);
    const AxisMoment m = moment(frames, y[0], y[1]);
    const PassFrame& pass_frame = frames.pass;
    ydot[0] = y[2];
    ydot[1] = y[3];
    const Eigen::Vector2d damped = damping_ * Eigen::Vector2d(y[2], y[3]);
    ydot[2] = (m.lead_torque - damped[0] - stiffness_ * (y[0] - pass_frame.lead0_rad)) / inertia_;
    ydot[3] = (m.tilt_torque - damped[1] - stiffness_ * (y[1] - pass_frame.tilt0_rad)) / inertia_;
    const bool finite = std::isfinite(ydot[2]) && std::isfinite(ydot[3]);
    return finite ? 0 : 1;  // recoverable: the solver retries a shorter step, then gives up
  }

  /// The sample at arc length s for state y; also leaves the placed nodes in nodes_mm_.
  PostureSample sample(double s_mm, const std::array<double, kStateSize>& y) {
    const Frames frames = frameAt(s_mm);
    const AxisMoment m = moment(frames, y[0], y[1]);
    PostureSample out;
    out.s_mm = s_mm;
    out.lead_rad = y[0];
    out.tilt_rad = y[1];
    out.lead_rate_rad_per_s = y[2];
    out.tilt_rate_rad_per_s = y[3];
    out.lead_torque = m.lead_torque;
    out.tilt_torque = m.tilt_torque;
    out.moment = m.moment;
    const Vec3 axis = axisFromAngles(frames.local, y[0], y[1]);
    out.posture = geometry::ballEndPosture(frames.pass.centre_mm, axis, request_.ball_radius_mm);
    out.clearance_mm = std::numeric_limits<double>::quiet_NaN();
    if (request_.clearance) {
      if (!request_.field)
        placeNodes(offsets_mm_, frames.pass.centre_mm, axis, frames.local.f, nodes_mm_);
      out.clearance_mm = request_.clearance(nodes_mm_);
    }
    return out;
  }

 private:
  /// The pass frame at s and its local frame, computed once per evaluation.
  struct Frames {
    PassFrame pass;
    LocalFrame local;
  };

  /// The frames at s; a non-finite centre or a bad normal is bad input naming s.
  Frames frameAt(double s_mm) const {
    const PassFrame f = pass_.frameAt(s_mm);
    try {
      requireThat(f.centre_mm.allFinite(), "pass frame: ball centre", "finite", f.centre_mm.norm());
      requireThat(std::isfinite(f.lead0_rad) && std::isfinite(f.tilt0_rad),
                  "pass frame: nominal angles", "finite", f.lead0_rad + f.tilt0_rad);
    } catch (const common::InputError& e) {
      throw common::InputError(at(s_mm) + e.what());
    }
    return {f, localFrameAt(f, s_mm)};
  }

  AxisMoment moment(const Frames& frames, double lead_rad, double tilt_rad) {
    if (!request_.field) return {};
    return momentOfNodes(*request_.field, offsets_mm_, frames.local, frames.pass.centre_mm,
                         lead_rad, tilt_rad, nodes_mm_, forces_);
  }

  const Pass& pass_;
  const SteeringRequest& request_;
  std::vector<Vec3> offsets_mm_;
  double feed_mm_per_s_, inertia_;
  Eigen::Matrix2d damping_;  ///< C, torque·s/rad: (lead, tilt) rates to damping torques
  double stiffness_;
  bool field_critical_;                  ///< damping: critical, with a field (updateDamping)
  std::vector<Vec3> nodes_mm_, forces_;  // scratch, reused by every evaluation
};

/// Limit checks on one sample; returns the violation (empty if none) and, with Clamp, clamps y.
struct LimitCheck {
  Status status = Status::Ok;
  std::string what;
  bool clamped = false;
};

LimitCheck checkAngles(const DynamicsParams& p, LimitPolicy policy,
                       std::array<double, kStateSize>& y) {
  LimitCheck out;
  const struct {
    const char* name;
    const char* key;
    double max_deg, max_rad;
    int index;
  } angles[] = {{"lead", "dynamics.max_lead_deg", p.max_lead_deg, p.maxLeadRad(), 0},
                {"tilt", "dynamics.max_tilt_deg", p.max_tilt_deg, p.maxTiltRad(), 1}};
  for (const auto& a : angles) {
    const double max_rad = a.max_rad;
    if (std::abs(y[a.index]) <= max_rad) continue;
    if (policy == LimitPolicy::Clamp) {
      y[a.index] = std::copysign(max_rad, y[a.index]);
      y[a.index + 2] = 0.0;  // the stop absorbs the motion
      out.clamped = true;
      continue;
    }
    std::ostringstream msg;
    msg.precision(4);
    msg << a.name << " " << y[a.index] * kRadToDeg << "° exceeds " << a.key << " = " << a.max_deg
        << "°";
    out.status = Status::TiltLimit;
    out.what = msg.str();
    return out;
  }
  return out;
}

}  // namespace

const char* toString(Status status) {
  switch (status) {
    case Status::Ok:
      return "ok";
    case Status::TiltLimit:
      return "angle limit";  // tilt or lead: the message names which
    case Status::RateLimit:
      return "angle change limit";
    case Status::SolverFailed:
      return "solver failed";
  }
  return "?";
}

SteeringResult steerPass(const Pass& pass, const SteeringRequest& request) {
  validate(pass, request);
  // Corners (request.hold_corners): where the feed turns by more than kCornerTurnDeg within
  // kCornerWindowMm, the feed (the normal, centre and nominal angles run on) is held from a
  // station to the one that far on and the angles and their rates re-expressed in the frame
  // there, so that the axis does not turn with the frame about the normal (the stations between
  // are written in the held frame, whose limits they keep: within a corner the feed, a central
  // difference, is no one frame's). Held in the turning frame, a tilt leaning away from a wall
  // leaned at it after a 90 deg turn, the field kicked and the tilt swung to the opposite limit
  // (holder 2.3 mm into the wall, a helper's pocket corner); held in the world, a lean away from
  // a boss the pass turns round is lost (a reviewer's): the caller chooses.
  struct CornerHold {
    bool on = false;
    Vec3 feed;
    double until_mm = 0.0;  // the station where the angles are re-expressed
  } hold;
  Pass cornered = pass;
  cornered.frameAt = [&pass, &hold](double s_mm) {
    PassFrame f = pass.frameAt(s_mm);
    if (hold.on) f.feed = hold.feed;  // made square to the normal at s by localFrame
    return f;
  };
  SteeringSystem system(cornered, request);
  const double v = system.feedMmPerS();

  const PassFrame start = pass.frameAt(0.0);
  std::array<double, kStateSize> y = {request.initial_lead_rad.value_or(start.lead0_rad),
                                      request.initial_tilt_rad.value_or(start.tilt0_rad),
                                      request.initial_lead_rate_rad_per_s,
                                      request.initial_tilt_rate_rad_per_s};
  for (double value : y) requireThat(std::isfinite(value), "initial axis state", "finite", value);

  detail::IntegratorSettings settings;
  settings.rtol = request.params.rtol;
  // Angles get atol (rad); rates atol · ω (rad/s), ω the spring's natural frequency sqrt(k/J) or,
  // if slower, one output interval: a rate tolerance on the angle tolerance's scale. One atol for
  // both would be far below the rounding noise of the rates when k/J is large (stiff cases).
  const double rate_scale_per_s =
      std::max(std::sqrt(request.params.stiffness / request.params.inertia), v / request.step_mm);
  const double atol = request.params.atol;
  settings.atol = {atol, atol, atol * rate_scale_per_s, atol * rate_scale_per_s};
  settings.max_step_s =
      request.step_mm / v;  // never step over a feature longer than one output step
  settings.max_steps = request.max_steps_per_output;
  std::unique_ptr<detail::Integrator> integrator =
      request.params.integrator == Integrator::Erk
          ? detail::makeArkodeErk(system, kStateSize, 0.0, y.data(), settings)
          : detail::makeCvodeBdf(system, kStateSize, 0.0, y.data(), settings);

  SteeringResult result;
  const std::vector<double> stations = outputStations(pass, request);
  const long intervals = static_cast<long>(stations.size()) - 1;
  result.samples.reserve(stations.size());
  const double max_change_rad_per_mm = request.max_angle_change_deg_per_mm * kDegToRad;
  const long report_every = std::max(1L, intervals / 100);

  // The damping's grid (kDampingSpacingMm): point `update` is the next it takes; a point within
  // 1e-9 mm of a station is taken there.
  long update = 0;
  const auto gridAt = [](long j) { return static_cast<double>(j) * kDampingSpacingMm; };
  const auto advanceTo = [&](double to_mm) {
    double t_reached_s = 0.0;
    const int flag = integrator->advance(to_mm / v, y.data(), t_reached_s);
    if (flag >= 0) return true;
    result.status = Status::SolverFailed;
    result.message = at(system.arcLength(t_reached_s)) +
                     (request.params.integrator == Integrator::Erk ? "ARKODE ERK" : "CVODE BDF") +
                     " failed (" + integrator->flagName(flag) + "): " + integrator->lastError();
    return false;
  };
  const double end_mm = stations.back();
  long corner_end = 0;  // the station a corner's window from the current one reaches
  for (long k = 0; k <= intervals; ++k) {
    const double s_mm = stations[static_cast<std::size_t>(k)];
    if (k > 0) {
      // The damping follows the field from each grid point on: the solver restarts there with
      // it (its steps stand anywhere up to one interval past; taking it from there made the
      // angles depend on the tolerances, 0.05° on an oblique wall's approach against DESIGN's
      // 0.01°).
      // (the points up to the last station were taken: gridAt(update) lies past it)
      for (; gridAt(update) < s_mm - 1e-9; ++update) {
        if (!advanceTo(gridAt(update))) break;
        // From the angles held at the limits, as at a station (the limits are held there: a
        // station 1.5e-9 mm off a grid point took it from beyond them and settled 2 deg
        // elsewhere, a reviewer's); the state itself runs on.
        std::array<double, kStateSize> held = y;
        checkAngles(request.params, LimitPolicy::Clamp, held);
        if (system.updateDamping(gridAt(update), held))
          integrator->restart(gridAt(update) / v, y.data());
      }
      if (result.status == Status::SolverFailed || !advanceTo(s_mm)) break;
    }
    bool corner = false;
    if (hold.on && s_mm >= hold.until_mm - 1e-9) {  // a corner's end: the axis in the frame at s
      y = reexpressState(localFrameAt(cornered.frameAt(s_mm), s_mm),
                         localFrameAt(pass.frameAt(s_mm), s_mm), y);
      hold.on = false;
      corner = true;
    }
    // Within a held corner the limits and the angles written are DESIGN's frame's, as everywhere
    // (held, a tilt re-expressed as a lead wrote 26 deg where max_lead_deg is 20, and angles.csv
    // said 18: a reviewer's): the state checked there and put back in the held frame if clamped.
    std::array<double, kStateSize> written = y;
    LocalFrame held_frame, design_frame;
    if (hold.on) {
      held_frame = localFrameAt(cornered.frameAt(s_mm), s_mm);
      design_frame = localFrameAt(pass.frameAt(s_mm), s_mm);
      written = reexpressState(held_frame, design_frame, y);
    }
    LimitCheck check = checkAngles(request.params, request.params.on_limit, written);
    if (!hold.on)
      y = written;
    else if (check.clamped)
      y = reexpressState(design_frame, held_frame, written);
    bool damping_follows = false;
    if (std::abs(gridAt(update) - s_mm) <= 1e-9) {
      damping_follows = s_mm < end_mm && system.updateDamping(s_mm, y);
      ++update;
    }
    if (check.clamped || damping_follows || corner) integrator->restart(s_mm / v, y.data());
    PostureSample sample = system.sample(s_mm, y);
    sample.lead_rad = written[0];
    sample.tilt_rad = written[1];
    sample.lead_rate_rad_per_s = written[2];
    sample.tilt_rate_rad_per_s = written[3];
    // At a limit without a clamp there too (a start settled or turned onto it: a pass steered
    // from its end wrote its last posture at lead -20 unmarked, a reviewer's).
    sample.limited = check.clamped ||
                     std::abs(written[0]) >= request.params.maxLeadRad() * (1.0 - 1e-12) ||
                     std::abs(written[1]) >= request.params.maxTiltRad() * (1.0 - 1e-12);
    if (!sample.moment.allFinite()) {  // the solver saw it too late (at s = 0) or not at all
      result.status = Status::SolverFailed;
      result.message = at(s_mm) + "the field gave a non-finite moment";
      break;
    }
    if (check.status == Status::Ok && max_change_rad_per_mm > 0.0 && !result.samples.empty()) {
      const PostureSample& prev = result.samples.back();
      const double ds_mm = s_mm - prev.s_mm;
      const double change = std::max(std::abs(sample.lead_rad - prev.lead_rad),
                                     std::abs(sample.tilt_rad - prev.tilt_rad));
      if (ds_mm > 0.0 && change > max_change_rad_per_mm * ds_mm) {
        sample.limited = true;
        if (request.params.on_limit == LimitPolicy::Fail) {
          std::ostringstream msg;
          msg.precision(4);
          msg << "axis turned " << change / ds_mm * kRadToDeg << "°/mm, over the limit of "
              << request.max_angle_change_deg_per_mm << "°/mm";
          check.status = Status::RateLimit;
          check.what = msg.str();
        }
      }
    }
    result.clamped_samples += check.clamped ? 1 : 0;
    result.samples.push_back(sample);
    if (check.status != Status::Ok) {
      result.status = check.status;
      result.message = at(s_mm) + check.what;
      break;
    }
    if (k < intervals && !hold.on) {  // a corner ahead: held from here to its far station
      // (over kCornerWindowMm at least: a corner sampled finely turns little per station)
      corner_end = std::max(corner_end, k + 1);  // (it only moves on: linear in the stations)
      while (corner_end < intervals &&
             stations[static_cast<std::size_t>(corner_end)] < s_mm + kCornerWindowMm - 1e-9)
        ++corner_end;
      const double until_mm = stations[static_cast<std::size_t>(corner_end)];
      // (a bad frame ahead is the integrator's to name where it first meets it: not held)
      LocalFrame from, to;
      bool framed = true;
      try {
        from = localFrame(pass.frameAt(s_mm));
        to = localFrame(pass.frameAt(until_mm));
      } catch (const common::InputError&) {
        framed = false;
      }
      if (framed && from.f.dot(to.f) < std::cos(kCornerTurnDeg * kDegToRad)) {
        ++result.corners;
        if (request.hold_corners) {
          hold = {true, from.f, until_mm};
          integrator->restart(s_mm / v, y.data());
        }
      }
    }
    if (k % report_every == 0)
      common::report(request.progress, intervals > 0 ? static_cast<double>(k) / intervals : 1.0,
                     "dynamics");
  }
  result.stats = integrator->stats();
  return result;
}

SettledStart settleAtStart(const Pass& pass, const SteeringRequest& request) {
  validate(pass, request);
  SettledStart out;
  // `critical` with a field damps with the field's stiffness too (updateDamping), faster than
  // the spring's c: chunks of the spring's decay time are generous; with no spring, one of the
  // field's is read at the first frame's nominal axis.
  double c = request.params.effectiveDamping();
  if (!(c > 0.0) && request.params.damping < 0.0 && request.field) {
    const PassFrame at = pass.frameAt(0.0);
    const Eigen::Matrix2d k_field = fieldStiffness(
        *request.field, request.nodes_tool_frame_mm, request.ball_radius_mm, localFrame(at),
        at.centre_mm, at.lead0_rad, at.tilt0_rad, kStiffnessDeltaRad);
    c = 2.0 * std::sqrt(std::max(0.0, k_field.diagonal().maxCoeff()) * request.params.inertia);
  }
  if (!(c > 0.0)) {
    out.why =
        "no damping (dynamics.damping: 0, or critical with no spring and no field's "
        "stiffness there): the axis never comes to rest";
    return out;
  }
  // The first frame held, one decay time 2J/c at a time (as a pass of that length at the feed,
  // stations as far apart as the pass's: the limits are applied as often), each from where the
  // last one ended, until the axis moves less than kSettledRad in one or kSettleDecays are run.
  const double v = request.params.feed_mm_per_min / 60.0;
  const PassFrame first = pass.frameAt(0.0);
  Pass held;
  // The slower of the two modes: 2J/c, or c/k where the damping is heavy (an overdamped axis
  // creeps to rest over c/k; with damping 1e4 the axis moved under kSettledRad in a 2J/c and was
  // called settled far from its rest: a diff review's). The spring's k: the field's stiffness
  // only quickens it.
  const double decay_s =
      std::max(2.0 * request.params.inertia / c,
               request.params.stiffness > 0.0 ? c / request.params.stiffness : 0.0);
  held.length_mm = decay_s * v;
  // A decay longer than kMaxSettleMm of path is no rest the pass could start from (damping
  // 1e-300 ran an undamped swing over 1e300 s, never ending: a diff review's).
  if (!(held.length_mm <= kMaxSettleMm)) {
    char why[200];
    std::snprintf(why, sizeof why,
                  "the spring-damper decays over %.3g mm of path (2 inertia / damping at the "
                  "feed), more than %.3g: no rest to start from (dynamics.damping)",
                  held.length_mm, kMaxSettleMm);
    out.why = why;
    return out;
  }
  held.frameAt = [first](double) { return first; };
  SteeringRequest run = request;
  run.output_s_mm.clear();
  // At most kSettleStations a decay: inertia 1e10 over stiffness 1e-10 made a decay of 1.7e11 mm
  // at the pass's 0.5 mm (out of memory after 49 s), 1e300 over 1e-300 a count past any index
  // (a crash: a diff review's). The settling is not machined: its stations may stand apart.
  run.step_mm =
      std::max(std::min(request.step_mm, held.length_mm), held.length_mm / kSettleStations);
  run.initial_lead_rad = first.lead0_rad;
  run.initial_tilt_rad = first.tilt0_rad;
  run.initial_lead_rate_rad_per_s = run.initial_tilt_rate_rad_per_s = 0.0;
  run.max_angle_change_deg_per_mm = 0.0;     // the settling is not machined: its swing on the
  run.params.on_limit = LimitPolicy::Clamp;  // way to rest is held at the limits, never failed
  run.clearance = nullptr;
  // The settling is before the pass: reported as none of it done, but reported (and interruptible)
  // all the same: a pass's settling over a dense direct field ran a minute with no progress line
  // (a blisk helper's ~60 s silence).
  if (request.progress)
    run.progress = [progress = request.progress](double, std::string_view what) {
      return progress(0.0, what);
    };
  // A decaying axis moves less every decay (by about e: its envelope); one that sets no new
  // least move in kSettleCycleDecays decays is cycling, not coming to rest (held at a limit
  // against a field that pushes on: a helper's pocket corner ran all 20 decays, each clamped at
  // every station, 3 M evaluations of the field and 40 s of a 2-pass job): it stops there, its
  // last state as good a start as any of the cycle's.
  double least_moved = std::numeric_limits<double>::infinity();
  int since_least = 0;
  for (int decay = 0; decay < int(kSettleDecays); ++decay) {
    const SteeringResult chunk = steerPass(held, run);
    if (chunk.status != Status::Ok || chunk.samples.empty()) {
      out.why = chunk.message.empty() ? "no sample" : chunk.message;
      return out;
    }
    out.stations += chunk.samples.size();
    const PostureSample& end = chunk.samples.back();
    const double moved = std::max(std::abs(end.lead_rad - *run.initial_lead_rad),
                                  std::abs(end.tilt_rad - *run.initial_tilt_rad));
    run.initial_lead_rad = end.lead_rad;
    run.initial_tilt_rad = end.tilt_rad;
    run.initial_lead_rate_rad_per_s = end.lead_rate_rad_per_s;
    run.initial_tilt_rate_rad_per_s = end.tilt_rate_rad_per_s;
    if (moved < kSettledRad && decay > 0) break;
    if (moved < least_moved) {
      least_moved = moved;
      since_least = 0;
    } else if (++since_least >= kSettleCycleDecays) {
      break;
    }
  }
  out.settled = true;
  out.lead_rad = *run.initial_lead_rad;
  out.tilt_rad = *run.initial_tilt_rad;
  return out;
}

}  // namespace fieldpath::dynamics
