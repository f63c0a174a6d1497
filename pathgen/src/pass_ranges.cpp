/// Where the passes of a nominal path file begin and end (DESIGN.md "Passes from a nominal path",
/// "Pass breaks"): the pass blocks, cut at gaps and where the feed turns back (a zig-zag's legs
/// written in one block, as CAM writes them). One block is cut by a BlockSplitter walking its
/// ball centres once.
#include <algorithm>
#include <cmath>
#include <optional>

#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

using geometry::PathBlock;
using geometry::PathFile;

/// Ball centres closer than this are one posture repeated (mm).
constexpr double kRepeatMm = 1e-9;
/// A feed that turns back farther than 120 deg from one of the last few (cos 120 deg = -0.5) is a
/// new leg. Not 90: a square corner in contact is a few degrees more or less in the ball centres
/// over a sloped floor (and +-1e-17 of rounding at 90): a helper's contour loops in one block
/// were cut at random corners (23 uneven pieces, the frame turned at each).
constexpr double kTurnBackCos = -0.5;
/// How many feed directions the turn-back test remembers (repeats skipped).
constexpr std::size_t kRecentSteps = 3;
/// A step-over step runs within 60 deg of square to the leg: |cos| under cos 30 deg.
const double kSquareToLegCos = std::cos(30.0 * geometry::kDegToRad);
/// The return leg runs within 30 deg of the leg reversed: cos under -cos 30 deg.
const double kReverseOfLegCos = std::cos(30.0 * geometry::kDegToRad);
/// A run of ball centres is straight where its chord is at least this fraction of its path.
constexpr double kStraightChord = 0.9;

double median(std::vector<double> values) {
  std::sort(values.begin(), values.end());
  return values.empty() ? 0.0 : values[values.size() / 2];
}

}  // namespace

double centreNoiseMm(double median_step_mm) {
  return std::max(kRepeatMm, std::min(1e-3 * median_step_mm, 1e-3));
}

namespace {

/// Cuts one pass block into posture ranges [begin, end):
/// - at a gap: two consecutive tips (and ball centres) farther apart than the gap;
/// - where the feed turns back past 120 deg from one of the last few steps (the steering's frame
///   (f, n, n x f) turns over with the feed: the same tilt would lean the axis to the other side,
///   into the wall it leaned away from);
/// - around a zig-zag's step-over: from the end of a straight leg (`corner`), steps within 60 deg
///   of square to the leg, up to a ball's diameter in all, then a step within 30 deg of the leg's
///   reverse with the return leg running straight on after it. The leg ends at the corner, the
///   return leg starts with the reversed step (its first posture the one before it), and the
///   turn's postures in between, two or more, are a pass of their own, each frame along its own
///   feed (cut as links they were lost: a rectangle 20 x 4 lost its short sides; cut as the
///   return leg's start, its frame turned there: 43 deg in one step and 38 postures colliding in
///   a helper's pocket). One turn posture is the link's. Any other step ends the turn: its steps
///   are the pass's feed (a corner kept, an L).
/// A step of the gap itself is no gap, within the rounding of the file's decimals (steps of
/// exactly 4 x 0.5 mm read 2.000000000000007 at one x and 1.9999999999999964 at another: one of
/// twelve split its pass).
constexpr double kRounding = 1.0 + 1e-9;

class BlockSplitter {
 public:
  using Ranges = std::vector<std::pair<std::size_t, std::size_t>>;

  BlockSplitter(const PathFile& path, const PathBlock& block, double pass_gap_mm,
                double ball_radius_mm, Ranges& out, std::vector<GapSplit>* gaps)
      : path_(path),
        block_(block),
        radius_mm_(ball_radius_mm),
        out_(out),
        gaps_(gaps),
        begin_(block.begin) {
    std::vector<double> steps, tip_steps;
    for (std::size_t i = block.begin + 1; i < block.end; ++i) {
      if (const double d = (centre(i) - centre(i - 1)).norm(); d > kRepeatMm) steps.push_back(d);
      if (const double d = tipStep(i); d > kRepeatMm) tip_steps.push_back(d);
    }
    gap_mm_ = pass_gap_mm > 0.0 ? pass_gap_mm : 4.0 * median(steps);
    feed_min_mm_ = centreNoiseMm(median(steps));
    tip_gap_mm_ = pass_gap_mm > 0.0 ? pass_gap_mm : 4.0 * median(tip_steps);
  }

  void run() {
    for (std::size_t i = block_.begin + 1; i < block_.end; ++i) {
      const Vec3 step = centre(i) - centre(i - 1);
      // DESIGN's gap is the tips'; the centres' too, so that an axis swung about a steady tip
      // (the centre thrown up to 2R) or about a steady centre (the tip thrown) stays in its
      // pass: such a turn is the axis's, counted and named at its line, not a link.
      if (gap_mm_ > 0.0 && step.norm() > kRounding * gap_mm_) {
        if (tipStep(i) > kRounding * tip_gap_mm_) {  // the link between two passes
          out_.emplace_back(begin_, i);  // (one posture alone: nominalPasses names it)
          if (gaps_) gaps_->push_back({i, tipStep(i), tip_gap_mm_});
          begin_ = i;
          recent_.clear();
          turn_.reset();  // (its steps were no pass's feed but the one ended here)
        }
        // else the axis swung about a steady tip: its centre's jump is no feed direction (a
        // swing along the feed read as a turn back and left a pass of one posture)
        continue;
      }
      if (step.norm() <= feed_min_mm_) continue;
      if (turn_ && continueTurn(i, step)) continue;
      if (startsTurn(i, step)) continue;
      feed(i, step);
    }
    if (turn_) endTurn();
    out_.emplace_back(begin_, block_.end);
  }

 private:
  /// A step-over under way: the straight leg's last posture, its direction (unit: the mean of its
  /// recent steps) and the turn's steps since (the posture at each one's end, the step).
  struct Turn {
    std::size_t corner = 0;
    Vec3 leg = Vec3::Zero();
    std::vector<std::pair<std::size_t, Vec3>> steps;

    double lengthMm() const {
      double sum = 0.0;
      for (const auto& [at, step] : steps) sum += step.norm();
      return sum;
    }
  };

  /// The chord (unit) of the ball centres' path from posture `from` over up to a ball's diameter,
  /// forward (+1) or back (-1), within the block and short of a gap, and whether the path is
  /// straight (chord at least 0.9 of its length; true where there is no path to tell).
  struct Run {
    Vec3 chord = Vec3::Zero();
    bool straight = true;
  };

  Vec3 centre(std::size_t i) const { return geometry::ballCentre(path_.postures[i], radius_mm_); }
  double tipStep(std::size_t i) const {
    return (path_.postures[i].tip_mm - path_.postures[i - 1].tip_mm).norm();
  }
  bool axisSteady(std::size_t i) const {
    return path_.postures[i].axis.dot(path_.postures[i - 1].axis) > 0.0;
  }

  Run chordRun(std::size_t from, int direction) const {
    Run out;
    double length_mm = 0.0;
    std::size_t at = from;
    while (length_mm < 2.0 * radius_mm_) {
      if (direction > 0 ? at + 1 >= block_.end : at <= block_.begin) break;
      const std::size_t to = direction > 0 ? at + 1 : at - 1;
      const double step_mm = (centre(to) - centre(at)).norm();
      if (gap_mm_ > 0.0 && step_mm > kRounding * gap_mm_) break;
      length_mm += step_mm;
      at = to;
    }
    const Vec3 chord = (centre(at) - centre(from)) * static_cast<double>(direction);
    if (length_mm > kRepeatMm) {
      out.chord = chord.normalized();
      out.straight = chord.norm() >= kStraightChord * length_mm;
    }
    return out;
  }

  /// Ends the pass under way at `end` (exclusive) and starts the next at `next_begin`. A block
  /// that begins with its step-over (where the last one ended) leaves a leg of one posture, the
  /// step-over's start: no pass of its own (was "a single posture"). Elsewhere a leg of one
  /// posture stays an error of nominalPasses (a jitter back in a pass).
  void split(std::size_t end, std::size_t next_begin) {
    const bool step_over_start = begin_ == block_.begin && end == begin_ + 1;
    if (end > begin_ && !step_over_start) out_.emplace_back(begin_, end);
    begin_ = next_begin;
    recent_.clear();
  }

  void remember(const Vec3& step) {
    recent_.push_back(step);
    if (recent_.size() > kRecentSteps) recent_.erase(recent_.begin());
  }

  /// A step of the pass's feed: past 120 deg back from a recent one, a new pass starts where it
  /// does (the step before it the link). An axis turned over (more than 90 deg) throws its centre
  /// 2R the other way: that is the axis's fault, named at its line by nominalPasses, not a leg.
  void feed(std::size_t i, const Vec3& step) {
    bool back = false;
    for (const Vec3& before : recent_)
      back = back || step.dot(before) < kTurnBackCos * step.norm() * before.norm();
    if (back && axisSteady(i)) split(i - 1, i - 1);
    remember(step);
  }

  /// Not a step-over: the turn's steps are the pass's feed (a corner).
  void endTurn() {
    const std::vector<std::pair<std::size_t, Vec3>> steps = std::move(turn_->steps);
    turn_.reset();
    for (const auto& [at, step] : steps) feed(at, step);
  }

  /// Step i within a turn: the return leg (the passes cut), one more step of the turn, or the end
  /// of the turn (false: step i is then taken as any other). True where step i is taken.
  bool continueTurn(std::size_t i, const Vec3& step) {
    const Vec3 along = step.normalized();
    // The return leg runs straight on after it: its chord within 30 deg of the leg's reverse (a
    // circle or a helix turning 20 deg a step comes within 30 deg of reversed too, half a turn
    // on: a reviewer's small circles lost their arcs to links; the chord, not each step: ball
    // centres over a sloped floor wiggle by 15 deg a step).
    const Run after = chordRun(i, +1);
    const bool straight_on = after.straight && after.chord.dot(turn_->leg) < -kReverseOfLegCos;
    if (along.dot(turn_->leg) < -kReverseOfLegCos && axisSteady(i) && straight_on) {
      const std::size_t turn_begin = turn_->corner + 1;
      // Distinct postures between the corner and the return leg's first: one a turn step but the
      // last (repeats skipped: a step-over written twice made a pass "at one place", refused).
      const std::size_t between = turn_->steps.size() - 1;
      turn_.reset();
      if (between >= 2) {
        split(turn_begin, turn_begin);  // the leg, to its corner
        split(i - 1, i - 1);            // the turn's postures
      } else {
        split(turn_begin, i - 1);  // the leg; one turn posture (or none) is the link's
      }
      remember(step);
      return true;
    }
    if (std::abs(along.dot(turn_->leg)) < kSquareToLegCos &&
        turn_->lengthMm() + step.norm() <= 2.0 * radius_mm_) {
      turn_->steps.emplace_back(i, step);
      return true;
    }
    endTurn();
    return false;
  }

  /// Whether step i starts a turn: square to a straight leg (its chord over a ball's diameter at
  /// least 0.9 of its length: a curve turns a little every step, and its lagging mean read as a
  /// corner) and no longer than a ball's diameter.
  bool startsTurn(std::size_t i, const Vec3& step) {
    if (recent_.size() < kRecentSteps || step.norm() > 2.0 * radius_mm_) return false;
    Vec3 leg = Vec3::Zero();
    for (const Vec3& before : recent_) leg += before.normalized();
    if (!(leg.norm() > 0.0)) return false;
    leg.normalize();
    if (!(std::abs(step.normalized().dot(leg)) < kSquareToLegCos) || !chordRun(i - 1, -1).straight)
      return false;
    turn_ = Turn{i - 1, leg, {{i, step}}};
    return true;
  }

  const PathFile& path_;
  const PathBlock& block_;
  double radius_mm_;
  Ranges& out_;
  std::vector<GapSplit>* gaps_;
  double gap_mm_ = 0.0, tip_gap_mm_ = 0.0;
  double feed_min_mm_ = kRepeatMm;  // shorter centre steps give no feed direction (centreNoiseMm)
  std::size_t begin_;         ///< first posture of the pass under way
  std::vector<Vec3> recent_;  ///< the last kRecentSteps feed steps of the pass under way
  std::optional<Turn> turn_;
};

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> passRanges(const PathFile& path,
                                                            double pass_gap_mm,
                                                            double ball_radius_mm,
                                                            std::vector<GapSplit>* gaps) {
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  for (const PathBlock& block : path.blocks)
    if (block.kind == PathBlock::Kind::Pass)
      BlockSplitter(path, block, pass_gap_mm, ball_radius_mm, ranges, gaps).run();
  return ranges;
}

}  // namespace fieldpath::pathgen
