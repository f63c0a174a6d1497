#pragma once
/// Where a machine's own interpolation leaves the checked motions: rotary angles interpolated
/// (below) and rapids run axis by axis (dogLegRapids).
///
/// A post-processor that writes rotary angles leaves the checked motions. `check` and
/// `generate` prove a motion with the tip on a line and the tool axis on the great circle between
/// two postures (what a controller given the tool vector runs). A machine whose C axis turns
/// about z and whose tilt is measured from z (A/C and B/C heads and tables), given angles, turns
/// them linearly: near the vertical a small turn of the axis is a large C swing, and the tool
/// strays from the checked one (a machine-side helper's finding: 8.7 deg of axis turn 5 deg off
/// the vertical swung C 120 deg and crossed an obstacle that the checked motion cleared by 1.5 mm).
#include <cstddef>
#include <limits>
#include <span>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/pathgen/clearance.h"

namespace fieldpath::pathgen {

/// The axis at t in [0, 1] between a and b as angles interpolated: tilt from +z and the azimuth
/// (C) each linear in t, the tilt kept >= 0 and C the shorter way round (an axis on the vertical
/// takes the other's azimuth: C does not turn there).
Vec3 axisByAngles(const Vec3& a, const Vec3& b, double t);

/// The stray of every motion: the largest distance, over the motion, between the tool placed by
/// interpolated angles and the one on the great circle at an even pace at the same instant (same
/// tip), at the tool's reach from the tip (every point of an axisymmetric tool within reach moves
/// no more). A turn with C still strays 0: the same arc (check's own pace, the normalised chord,
/// differs from an even one by 0.0085 mm at 100 mm for 10 deg of turn: the axis_turn warning's).
struct RotaryStray {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::vector<double> offset_mm;  ///< per motion (posture i to i + 1)
  double max_offset_mm = 0.0;
  std::size_t max_at = npos;
  /// Of the motions that keep the required clearance as checked: those whose stray reaches their
  /// certified clearance (the machine's tool may touch), and those it takes under the required.
  std::size_t beyond_clearance = 0, first_beyond = npos;
  std::size_t under_required = 0;
  /// C's turn (deg, signed) and the axis' turn (deg) on `first_beyond`, else on `max_at`.
  double c_deg = 0.0, turn_deg = 0.0;
};

RotaryStray rotaryStray(std::span<const geometry::Posture> postures, const MotionResult& motions,
                        double required_mm);

/// The rapids (the motions into link postures: APT's RAPID before each link GOTO) that a
/// controller running rapids axis by axis (a dog-leg: each linear axis on its own, at its own
/// rate) is proven to run clear. Such a tip stays in the box its two ends span, within `dev` of
/// the straight segment (the farthest corner: distance to a segment is convex), and the axis
/// between the two ends': every point of the tool within dev + reach × turn of the checked tool
/// at some instant, so the motion's certified clearance less that bound holds for any order and
/// pace of the axes. A bound, not a simulation: a motion not proven is not shown to collide.
struct DogLegRapids {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t rapids = 0;
  std::size_t unproven = 0;      ///< rapids whose bound falls under the required clearance
  /// Rapids under the required clearance as checked (straight): the check's own findings, in
  /// no proof (a note said "the 7 rapid moves are proven clear" with 2 of them colliding).
  std::size_t checked_under = 0;
  std::size_t lowest = npos;     ///< the unproven rapid of the lowest bound
  double lowest_bound_mm = 0.0;  ///< the bound there (may be negative)
  double lowest_box_mm = 0.0;    ///< its dev + reach × turn
};

DogLegRapids dogLegRapids(const geometry::PathFile& path, const MotionResult& motions,
                          double required_mm);

}  // namespace fieldpath::pathgen
