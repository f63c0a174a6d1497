#pragma once
/// Passes: the ball-centre curves the dynamics follow, with their frames, from one of two sources
/// (DESIGN.md "Scene files"):
/// - the parametric impeller (seed 004 §3.2): isoparametric curves v = const of the hub offset by
///   the ball radius, C(u) = S(u, v) + R n(u, v), parametrised by arc length;
/// - a nominal path file (any part): the ball centres C = p + R a of its postures, split into
///   passes at markers and gaps, frames from the polyline (DESIGN.md "Passes from a nominal path").
/// At each station the frame f (feed tangent, unit), n (surface normal or the nominal axis made
/// orthogonal to f, unit), b = n × f.
#include <functional>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/params.h"

namespace fieldpath::pathgen {

/// One station of a pass. mm and unit vectors, world frame.
struct PassSample {
  double s_mm = 0.0;  ///< arc length of the ball-centre curve from the pass start
  /// Source parameter: the impeller's u, or the fractional index of the nominal posture.
  double u = 0.0;
  Vec3 centre_mm;  ///< ball centre C(s)
  Vec3 feed;       ///< f
  Vec3 normal;     ///< n
  Vec3 binormal;   ///< b = n × f
};

struct Pass {
  int index = 0;      ///< 0-based
  std::string label;  ///< for messages: "pass 3 (v = 0.44)", "pass 3 (nominal.cl:120)"
  double v = std::numeric_limits<double>::quiet_NaN();  ///< the impeller's v (NaN otherwise)
  double ball_radius_mm = 0.0;
  double length_mm = 0.0;
  std::vector<PassSample> samples;  ///< output stations, s = 0 ... length_mm
  /// A nominal path's largest lean of its axes along the feed (deg) and where ("FILE:LINE"):
  /// the frame takes the axis made orthogonal to the feed and steers from path.lead_deg, so a
  /// lead written in the file is not kept (generate says so).
  double nominal_lean_deg = 0.0;
  std::string nominal_lean_at;
  /// The station at any s in [0, length_mm] (clamped): cheap, deterministic, thread-safe, so the
  /// dynamics can call it at every solver stage.
  std::function<PassSample(double s_mm)> at;
  /// A nominal pass's: "FILE:LINE" of the input posture at or before arc length s, for messages
  /// that stop at a station (`on_limit: fail` named the pass's first line only); empty: none.
  std::function<std::string(double s_mm)> whereAt;
};

/// The `passes` passes at v evenly spread over impeller.passes_v, covering u_range, for a ball
/// of `ball_radius_mm`, stepped evenly at no more than `path.step` (both ends included). Throws
/// common::InputError naming `path.passes`, `path.step` or the pass ("pass 3: empty ...") for a
/// pass shorter than one step.
std::vector<Pass> impellerPasses(const Impeller& impeller, const PathParams& path,
                                 double ball_radius_mm);

/// Where a gap split a pass block (`gaps` of passRanges): the posture after the gap, the move's
/// tip length and the gap it exceeded (mm).
struct GapSplit {
  std::size_t at = 0;
  double move_mm = 0.0, gap_mm = 0.0;
};

/// The passes of a nominal path: its pass blocks (link blocks dropped), each split where two
/// consecutive tips (and ball centres) are farther apart than `path.pass_gap` (0: 4 × the
/// block's median step; passRanges);
/// consecutive postures with the same ball centre are dropped (counted in `dropped`). Stations:
/// the postures one for one, or every `path.step` mm when `path.step_given`. Throws
/// common::InputError naming the file and line for a pass with fewer than two distinct postures
/// and for a posture whose feed runs along its axis (no frame).
struct NominalDropped {
  std::size_t repeated = 0;  ///< postures at the ball centre of the one before
  /// Postures of pass blocks in no pass: a zig-zag's step-over of one posture between two legs
  /// (passRanges: its moves are the link's, made anew); `first_between` the first (npos: none).
  std::size_t between_legs = 0;
  std::size_t first_between = static_cast<std::size_t>(-1);
  /// Postures of approaches and retracts written as feed moves at a pass's ends: reached by a
  /// move along the tool axis (down it before the cut, up it after), or alone between a gap and
  /// the cut of their block (an approach's start above the part): the link's, made anew;
  /// `first_approach` the first (npos: none).
  std::size_t approaches = 0;
  std::size_t first_approach = static_cast<std::size_t>(-1);
  /// The moves between two passes of one block that a gap split (passRanges): made into links,
  /// not cut (a line written as one GOTO between arcs written fine is such a move: said).
  std::vector<GapSplit> gaps;
};
/// A move into a lone posture a gap parts from the rest of its block within this of the tool axis
/// (deg) is an approach's start above the cut or a retract's end (the link's); a lone posture
/// reached across the axis is a cut written as its two ends, refused as before (a regression
/// hunt: a 7 mm line on the floor written so was dropped from every pass). `check` reads a pass
/// written from a rapid's end down the axis within it as an engage, not a rapid onto the cut.
inline constexpr double kApproachDeg = 30.0;

std::vector<Pass> nominalPasses(const geometry::PathFile& path, const PathParams& params,
                                double ball_radius_mm, NominalDropped* dropped = nullptr);

/// Ball-centre steps no longer than this are no move of the feed, for a pass block whose median
/// centre step is `median_step_mm`: 1e-3 of it, at most 1 µm. An axis swivelled about a steady
/// centre, written to 4-6 decimals, moves the centre by nm-µm in any direction: read as the
/// feed turning back it split the pass ("a single posture", a helper's), and as the feed's
/// direction it turned the frames 90° (a reviewer's). At most 1 µm: a zig-zag's step-over of
/// 50 µm between legs of 60 mm steps stays a move.
double centreNoiseMm(double median_step_mm);

/// Posture ranges [begin, end) of the passes of a path: its pass blocks (link blocks dropped),
/// each split where two consecutive tips are farther apart than `pass_gap_mm` (0: 4 × the
/// block's median tip step), as DESIGN reads a gap, and their ball centres (R = `ball_radius_mm`
/// up the axis from the tip) too (0: 4 × the median centre step): an axis swung about a steady
/// tip or a steady centre is a turn within the pass (counted, and refused at its line where it
/// flips), not a link; and where the centres' feed turns back more than 90° from one of its last
/// three directions (a zig-zag's legs: the new pass starts with the step that turns back). The
/// feed is the centres', not the tips': the programmed path is the centre's, and a tip moves
/// back when the axis leans forward faster than the centre moves on (a 45° swing in 1 mm read as
/// a new pass, and its turn went uncounted).
std::vector<std::pair<std::size_t, std::size_t>> passRanges(const geometry::PathFile& path,
                                                            double pass_gap_mm,
                                                            double ball_radius_mm,
                                                            std::vector<GapSplit>* gaps = nullptr);

/// geometry::requireSteadyAxis for every two consecutive postures of every pass block but
/// those that passRanges (`pass_gap_mm`: the scene's path.pass_gap, 0 automatic, as generate
/// splits them) puts in two passes with their tips more than 2R apart:
/// a flipped axis within a pass is not a cutting move a machine makes; across a gap (a link of
/// a file without markers) the axis may turn as far as it likes (check refused a 120 deg turn
/// between two passes 20 mm apart that generate took).
void requireSteadyAxes(const geometry::PathFile& path, double pass_gap_mm, double ball_radius_mm);

/// The largest turn of the tool axis between two consecutive postures of a pass (a file with
/// markers: within its pass blocks, every move; without, passRanges with the default gap: a file
/// of passes with no markers, or an .npy, holds its links in one block): `deg`, from posture `at`
/// to at + 1, over `step_mm` of ball-centre travel (`at` npos: no pass has two postures; ties: the
/// first). A machine's rotary axes follow a few degrees a millimetre at cutting feed; the steered
/// impeller example turns under 0.5 deg a posture, a field pushing a tool with no room to move
/// turned 30 deg in 0.5 mm.
struct AxisTurn {
  double deg = 0.0, step_mm = 0.0;
  std::size_t at = static_cast<std::size_t>(-1);
};
AxisTurn largestAxisTurn(const geometry::PathFile& path, double ball_radius_mm);

/// Turns larger than this between two postures of a pass are said (generate, check).
constexpr double kNoteAxisTurnDeg = 10.0;

/// Nominal axis of a sample: n turned by `lead_rad` about b (towards f), i.e.
/// dynamics::axisFromAngles of the sample's frame with no tilt.
Vec3 nominalAxis(const PassSample& sample, double lead_rad);

/// The nominal (untilted) postures of all passes, in order.
std::vector<geometry::Posture> nominalPostures(std::span<const Pass> passes, double lead_rad,
                                               double ball_radius_mm);

}  // namespace fieldpath::pathgen
