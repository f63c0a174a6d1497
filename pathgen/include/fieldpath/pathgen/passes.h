#pragma once
/// Nominal passes on the impeller hub (seed 004 §3.2): ball-centre curves are the isoparametric
/// curves v = const of the hub offset by the ball radius, C(u) = S(u, v) + R n(u, v), parametrised
/// by arc length and stepped evenly at no more than `step` mm (both ends included). At each sample
/// the frame f (feed tangent, unit), n (hub normal, unit, ⟂ f exactly since dC/du ⟂ n), b = n × f.
#include <span>
#include <vector>

#include "fieldpath/geometry/posture.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/params.h"

namespace fieldpath::pathgen {

/// One output station of a pass. mm and unit vectors, world frame.
struct PassSample {
  double s_mm = 0.0;  ///< arc length of the ball-centre curve from the pass start
  double u = 0.0;     ///< hub parameter along the channel
  Vec3 centre_mm;     ///< ball centre C(s)
  Vec3 feed;          ///< f
  Vec3 normal;        ///< n, hub normal at the contact point
  Vec3 binormal;      ///< b = n × f
};

struct Pass {
  int index = 0;  ///< 0-based
  double v = 0.0;
  double ball_radius_mm = 0.0;
  double length_mm = 0.0;
  std::vector<PassSample> samples;  ///< output stations, s = 0 ... length_mm evenly
  /// Arc length → u table (dense, increasing), for sampleAt at any s.
  std::vector<double> table_s_mm, table_u;
};

/// The station of `pass` at arc length s_mm (clamped to [0, length]); cheap (a table lookup and
/// one evaluation of the hub), so the dynamics can call it at every solver stage.
PassSample sampleAt(const Impeller& impeller, const Pass& pass, double s_mm);

/// The `passes` passes at v evenly spread over impeller.passes_v, covering u_range, for a ball
/// of `ball_radius_mm`. Throws common::InputError naming `path.passes`, `path.step` or the pass
/// ("pass 3: empty ...") for a pass shorter than one step.
std::vector<Pass> impellerPasses(const Impeller& impeller, const PathParams& path,
                                 double ball_radius_mm);

/// Nominal axis of a sample: n turned by `lead_rad` about b (towards f), i.e.
/// dynamics::axisFromAngles of the sample's frame with no tilt.
Vec3 nominalAxis(const PassSample& sample, double lead_rad);

/// The nominal (untilted) postures of all passes, in order.
std::vector<geometry::Posture> nominalPostures(std::span<const Pass> passes, double lead_rad,
                                               double ball_radius_mm);

}  // namespace fieldpath::pathgen
