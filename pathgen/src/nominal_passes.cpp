/// Passes from a nominal path file (DESIGN.md "Passes from a nominal path"): the ball centres
/// C = p + R a of the postures form a polyline per pass; the frame at a posture is the polyline's
/// unit tangent (central differences, one-sided at the ends) and the nominal axis made orthogonal
/// to it; between postures both are interpolated linearly (and re-orthonormalised), so the
/// dynamics sees a continuous frame.
#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {
namespace {

using common::InputError;
using geometry::PathBlock;
using geometry::PathFile;
using geometry::Posture;

/// Ball centres closer than this are one posture repeated (mm).
constexpr double kRepeatMm = 1e-9;
/// A resampled pass (path.step) keeps the input vertices that its stations would cut by more
/// than this (mm).
constexpr double kCornerCutMm = 0.001;
/// Vertex tests of the corners' search past which every vertex is kept.
constexpr std::size_t kMaxCornerWork = 50'000'000;
/// The nominal axis must be at least this far from the feed direction (sin of 0.5°): closer, the
/// frame's normal is the rounding noise of a projection.
constexpr double kMinAxisToFeedSin = 0.0087;

/// The vertices of one pass: ball centres, arc lengths, tangents, normals.
struct Polyline {
  std::vector<double> s_mm;
  std::vector<Vec3> centre_mm, tangent, normal;
};

PassSample vertexSample(const Polyline& line, std::size_t i) {
  PassSample sample;
  sample.s_mm = line.s_mm[i];
  sample.u = static_cast<double>(i);
  sample.centre_mm = line.centre_mm[i];
  sample.feed = line.tangent[i];
  sample.normal = line.normal[i];
  sample.binormal = sample.normal.cross(sample.feed);
  return sample;
}

/// A station of a resampled pass: at arc length s_mm, or an input vertex (its index).
struct Station {
  double s_mm = 0.0;
  long vertex = -1;
};

/// The stations of a pass resampled every `step_mm` (path.step): evenly between kept input
/// vertices, a vertex kept wherever the even stations would leave it more than kCornerCutMm off
/// (split at the worst one, Douglas-Peucker's way, until none is): the ends always. Stations
/// between single vertices of a corner were cut by 0.385 mm at step 1.8 (a 90° corner between
/// two stations), by 0.38 mm where the corner was written as two vertices 2 um apart or as a
/// 0.05 mm fillet, a smooth S of R 5 by 0.076 mm (three reviews'). Past kMaxCornerWork vertex
/// tests (an adversarial million-vertex zigzag) every vertex is kept: exact, and no slower.
std::vector<Station> stations(const Polyline& line, double step_mm) {
  const auto& s = line.s_mm;
  const auto& c = line.centre_mm;
  const std::size_t n = s.size();
  if (n < 2) return {{s.empty() ? 0.0 : s[0], 0}};
  // Equal steps no longer than step (over it by 1e-6 of it at most: a 90 mm pass at 0.25 mm had
  // 361 intervals by its length's rounding).
  auto intervals = [step_mm](double length) {
    return std::max(1L, static_cast<long>(std::ceil(length / step_mm * (1.0 - 1e-6))));
  };
  auto centreAt = [&](double at) {
    const std::size_t j = std::min<std::size_t>(
        n - 1, std::size_t(std::lower_bound(s.begin(), s.end(), at) - s.begin()));
    if (j == 0 || s[j] == at) return c[j];
    const double w = (at - s[j - 1]) / (s[j] - s[j - 1]);
    return Vec3((1 - w) * c[j - 1] + w * c[j]);
  };
  std::vector<std::pair<std::size_t, std::size_t>> todo = {{0, n - 1}}, done;
  std::size_t work = 0;
  bool all = false;
  while (!todo.empty() && !all) {
    const auto [a, b] = todo.back();
    todo.pop_back();
    const double length = s[b] - s[a];
    const long m = intervals(length);
    double worst = kCornerCutMm;
    std::size_t at = 0;
    for (std::size_t k = a + 1; k < b; ++k) {
      const long j = std::min(m - 1, static_cast<long>((s[k] - s[a]) / length * double(m)));
      const Vec3 p = centreAt(s[a] + length * double(j) / double(m));
      const Vec3 q = centreAt(s[a] + length * double(j + 1) / double(m));
      const Vec3 pq = q - p;
      const double t = pq.squaredNorm() > 0.0
                           ? std::clamp((c[k] - p).dot(pq) / pq.squaredNorm(), 0.0, 1.0)
                           : 0.0;
      const double off = (c[k] - (p + t * pq)).norm();
      if (off > worst) {
        worst = off;
        at = k;
      }
    }
    work += b - a;
    all = work > kMaxCornerWork;
    if (at == 0) {
      done.emplace_back(a, b);
    } else {
      todo.emplace_back(a, at);
      todo.emplace_back(at, b);
    }
  }
  if (all) {
    done.clear();
    for (std::size_t k = 0; k + 1 < n; ++k) done.emplace_back(k, k + 1);
  }
  std::sort(done.begin(), done.end());
  std::vector<Station> out = {{s[0], 0}};
  for (const auto& [a, b] : done) {
    const double length = s[b] - s[a];
    const long m = intervals(length);
    for (long j = 1; j < m; ++j) out.push_back({s[a] + length * double(j) / double(m), -1});
    out.push_back({s[b], static_cast<long>(b)});
  }
  return out;
}

/// The station at arc length s: exact at the vertices, linear in between.
PassSample polylineSample(const Polyline& line, double s_mm) {
  const auto& s = line.s_mm;
  s_mm = std::clamp(s_mm, 0.0, s.back());
  const auto it = std::lower_bound(s.begin(), s.end(), s_mm);
  const std::size_t j = static_cast<std::size_t>(it - s.begin());
  if (j < s.size() && s[j] == s_mm) return vertexSample(line, j);
  const std::size_t i = j - 1;  // s[i] < s_mm < s[j]
  const double w = (s_mm - s[i]) / (s[j] - s[i]);
  PassSample sample;
  sample.s_mm = s_mm;
  sample.u = static_cast<double>(i) + w;
  sample.centre_mm = (1 - w) * line.centre_mm[i] + w * line.centre_mm[j];
  Vec3 feed = (1 - w) * line.tangent[i] + w * line.tangent[j];
  if (feed.norm() < 1e-9) feed = line.centre_mm[j] - line.centre_mm[i];  // a reversal
  sample.feed = feed.normalized();
  Vec3 normal = (1 - w) * line.normal[i] + w * line.normal[j];
  normal -= normal.dot(sample.feed) * sample.feed;
  if (normal.norm() < kMinAxisToFeedSin)
    normal = line.normal[i] - line.normal[i].dot(sample.feed) * sample.feed;
  sample.normal = normal.normalized();
  sample.binormal = sample.normal.cross(sample.feed);
  return sample;
}

}  // namespace

AxisTurn largestAxisTurn(const PathFile& path, double ball_radius_mm) {
  AxisTurn out;
  // A file with markers says which moves are cut: every move within a pass block runs at feed,
  // wherever passRanges splits it (a posture turned 15° about its tip threw the ball centre back,
  // split the pass there, and its turn went uncounted, unwarned). Without markers the links are in
  // the one block: passRanges tells them by their gaps.
  std::vector<std::pair<std::size_t, std::size_t>> ranges;
  if (path.blocks.size() > 1) {
    for (const PathBlock& block : path.blocks)
      if (block.kind == PathBlock::Kind::Pass) ranges.emplace_back(block.begin, block.end);
  } else {
    ranges = passRanges(path, 0.0, ball_radius_mm);
  }
  for (const auto& [begin, end] : ranges)
    for (std::size_t i = begin + 1; i < end; ++i) {
      const Posture &a = path.postures[i - 1], &b = path.postures[i];
      const double deg = geometry::axisAngle(a.axis, b.axis) * geometry::kRadToDeg;
      if (out.at != AxisTurn{}.at && !(deg > out.deg)) continue;  // (the first pair counts)
      out.deg = deg;
      out.at = i - 1;
      out.step_mm =
          (geometry::ballCentre(b, ball_radius_mm) - geometry::ballCentre(a, ball_radius_mm))
              .norm();
    }
  return out;
}

void requireSteadyAxes(const PathFile& path, double pass_gap_mm, double ball_radius_mm) {
  std::vector<char> starts(path.postures.size(), 0);  // where passRanges starts a pass
  for (const auto& range : passRanges(path, pass_gap_mm, ball_radius_mm)) starts[range.first] = 1;
  for (const PathBlock& block : path.blocks) {
    if (block.kind != PathBlock::Kind::Pass) continue;
    for (std::size_t i = block.begin + 1; i < block.end; ++i) {
      // A flipped axis throws the ball centre up to 2R (and so splits the pass at a gap) but
      // keeps the tip, or moves it R where tip and centre are confused: across a gap the tips
      // also cross, a turn there is a link's.
      const double tips_mm = (path.postures[i].tip_mm - path.postures[i - 1].tip_mm).norm();
      if (starts[i] && tips_mm > 2.0 * ball_radius_mm) continue;
      geometry::requireSteadyAxis(path, i - 1, i);
    }
  }
}

std::vector<Pass> nominalPasses(const PathFile& path, const PathParams& params,
                                double ball_radius_mm, NominalDropped* dropped) {
  if (!std::isfinite(params.pass_gap_mm) || params.pass_gap_mm < 0.0)
    throw InputError("path.pass_gap: must be a finite distance >= 0 mm (0: automatic)");
  if (params.step_given && (!std::isfinite(params.step_mm) || !(params.step_mm >= kMinPathStepMm)))
    throw InputError("path.step: must be a finite number >= 0.001 mm (a machine's resolution)");
  if (!std::isfinite(params.lead_deg) || std::abs(params.lead_deg) >= 60.0)
    throw InputError("path.lead_deg: must be a finite angle with |lead| < 60 deg");
  if (!std::isfinite(ball_radius_mm) || ball_radius_mm <= 0.0)
    throw InputError("tool.radius: must be > 0");
  const double r = ball_radius_mm;
  NominalDropped said;
  std::vector<Pass> passes;
  const std::vector<std::pair<std::size_t, std::size_t>> ranges =
      passRanges(path, params.pass_gap_mm, r, &said.gaps);
  {  // postures of pass blocks that no range holds
    std::vector<char> held(path.postures.size(), 0);
    for (const auto& [begin, end] : ranges) std::fill(held.begin() + begin, held.begin() + end, 1);
    for (const PathBlock& block : path.blocks)
      if (block.kind == PathBlock::Kind::Pass)
        for (std::size_t i = block.begin; i < block.end; ++i)
          if (!held[i] && said.between_legs++ == 0) said.first_between = i;
  }
  for (const auto& [begin, end] : ranges) {
    const int number = static_cast<int>(passes.size()) + 1;
    // Distinct postures of the pass (consecutive repeats of a ball centre dropped).
    // A swivel about a steady centre, written to a few decimals, moves it by its rounding only:
    // the same place (its steps' directions are noise, and turned the frames 90°).
    std::vector<double> steps;
    for (std::size_t i = begin + 1; i < end; ++i)
      if (const double d = (geometry::ballCentre(path.postures[i], r) -
                            geometry::ballCentre(path.postures[i - 1], r))
                               .norm();
          d > kRepeatMm)
        steps.push_back(d);
    std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
    const double repeat_mm = centreNoiseMm(steps.empty() ? 0.0 : steps[steps.size() / 2]);
    std::vector<std::size_t> kept;
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 c = geometry::ballCentre(path.postures[i], r);
      if (!kept.empty() &&
          (c - geometry::ballCentre(path.postures[kept.back()], r)).norm() <= repeat_mm) {
        ++said.repeated;
        continue;
      }
      kept.push_back(i);
    }
    // A lone posture that a gap parts from the cut of its block, reached along the tool axis
    // (within kApproachDeg): an approach's start above the cut, written after FEDRAT (a
    // verifier's "pass 1 has a single posture"), or a retract's end: the link's too.
    // (its block looked up only for a lone posture: a file of 100 000 passes has as many blocks)
    const auto block =
        kept.size() >= 2
            ? path.blocks.end()
            : std::find_if(path.blocks.begin(), path.blocks.end(),
                           [&](const PathBlock& b) { return b.begin <= begin && begin < b.end; });
    const auto steepTo = [&](std::size_t neighbour) {  // the move between it and a neighbour
      const Vec3 step = geometry::ballCentre(path.postures[neighbour], r) -
                        geometry::ballCentre(path.postures[begin], r);
      return std::abs(path.postures[begin].axis.dot(step)) >=
             std::cos(kApproachDeg * geometry::kDegToRad) * step.norm();
    };
    const bool lone_approach =
        kept.size() < 2 && block != path.blocks.end() &&
        !(block->begin == begin && block->end == end) &&
        ((end < block->end && steepTo(end)) || (begin > block->begin && steepTo(begin - 1)));
    if (lone_approach) {
      if (said.approaches == 0) said.first_approach = begin;
      said.approaches += kept.size();
      continue;
    }
    if (kept.size() < 2) {
      std::ostringstream msg;
      msg << path.where(begin) << ": pass " << number << " has "
          << (end - begin == 1 ? "a single posture"
                               : std::to_string(end - begin) + " postures at one place")
          << ": a pass needs two distinct postures (passes break at `# pass`, blank lines, "
             "RAPID moves, gaps over path.pass_gap and where the feed turns back: a zig-zag's "
             "return leg; the feed is the ball centres', tip + R along the axis: axes that "
             "swing back and forth make it zig-zag)";
      throw InputError(msg.str());
    }
    // An approach down the tool axis at feed before the cut, and a retract up it after (CAM
    // systems write them as feed moves: FEDRAT, GOTO down the axis), are the link's: links are
    // made anew, and a step along the axis has no frame (a verifier's APT was refused at its
    // approach). Only steps along the axis (within kMinAxisToFeedSin), which had been refused:
    // within 30 deg it dropped a ball's climb of a 75 deg wall, a cut (a regression hunt). Down
    // it at the start, up it at the end, of a pass that cuts (a pass all along its axis is
    // refused below, naming its line; a plunge down the axis at the end is the cut's).
    const auto alongAxis = [&](std::size_t from, std::size_t to) {  // cos(step, axis)
      const Vec3 step = geometry::ballCentre(path.postures[kept[to]], r) -
                        geometry::ballCentre(path.postures[kept[from]], r);
      return path.postures[kept[from]].axis.dot(step) / step.norm();
    };
    const double steep = std::sqrt(1.0 - kMinAxisToFeedSin * kMinAxisToFeedSin);
    std::size_t head = 0, tail = kept.size();
    bool cuts = false;
    for (std::size_t k = 1; k < kept.size() && !cuts; ++k)
      cuts = std::abs(alongAxis(k - 1, k)) < steep;
    while (cuts && alongAxis(head, head + 1) <= -steep) ++head;
    while (cuts && alongAxis(tail - 2, tail - 1) >= steep) --tail;
    if (head > 0 || tail < kept.size()) {
      if (said.approaches == 0) said.first_approach = kept[head > 0 ? 0 : tail];
      said.approaches += head + (kept.size() - tail);
      kept = std::vector<std::size_t>(kept.begin() + head, kept.begin() + tail);
    }
    // A cutting move does not turn the axis over (repeats dropped: between the kept postures).
    for (std::size_t k = 1; k < kept.size(); ++k)
      geometry::requireSteadyAxis(path, kept[k - 1], kept[k]);
    auto line = std::make_shared<Polyline>();
    const std::size_t n = kept.size();
    for (std::size_t k = 0; k < n; ++k) {
      line->centre_mm.push_back(geometry::ballCentre(path.postures[kept[k]], r));
      line->s_mm.push_back(k == 0 ? 0.0
                                  : line->s_mm.back() +
                                        (line->centre_mm[k] - line->centre_mm[k - 1]).norm());
    }
    double lean_max_deg = 0.0;
    std::size_t lean_at = kept.front();
    for (std::size_t k = 0; k < n; ++k) {
      const std::size_t a = k == 0 ? 0 : k - 1, b = k + 1 == n ? n - 1 : k + 1;
      Vec3 tangent = line->centre_mm[b] - line->centre_mm[a];
      if (tangent.norm() <= kRepeatMm)  // a reversal: C(k+1) = C(k-1)
        tangent = line->centre_mm[k + 1 == n ? k : k + 1] - line->centre_mm[k + 1 == n ? k - 1 : k];
      tangent.normalize();
      const Vec3& axis = path.postures[kept[k]].axis;
      const Vec3 normal = axis - axis.dot(tangent) * tangent;
      if (normal.norm() < kMinAxisToFeedSin) {
        std::ostringstream msg;
        msg.precision(3);
        msg << path.where(kept[k]) << ": the feed direction runs along the tool axis (angle "
            << std::acos(std::min(1.0, std::abs(axis.dot(tangent)))) * geometry::kRadToDeg
            << " deg): no frame for the dynamics (a plunge belongs in a link, after RAPID or "
               "`# link`)";
        throw InputError(msg.str());
      }
      line->tangent.push_back(tangent);
      line->normal.push_back(normal.normalized());
      const double lean_deg =
          std::asin(std::min(1.0, std::abs(axis.normalized().dot(tangent)))) * geometry::kRadToDeg;
      if (lean_deg > lean_max_deg) {
        lean_max_deg = lean_deg;
        lean_at = kept[k];
      }
    }
    Pass pass;
    pass.nominal_lean_deg = lean_max_deg;
    pass.nominal_lean_at = path.where(lean_at);
    pass.index = number - 1;
    pass.label = "pass " + std::to_string(number) + " (" + path.where(kept.front()) + ")";
    pass.ball_radius_mm = r;
    pass.length_mm = line->s_mm.back();
    pass.at = [line](double s_mm) { return polylineSample(*line, s_mm); };
    {  // the lines of the kept postures, not their texts (a million-posture path)
      geometry::PathFile lines;
      lines.file = path.file;
      lines.rows = path.rows;
      for (const std::size_t i : kept)
        if (i < path.lines.size()) lines.lines.push_back(path.lines[i]);
      pass.whereAt = [line, lines = std::move(lines)](double s_mm) {
        const auto after = std::upper_bound(line->s_mm.begin(), line->s_mm.end(), s_mm);
        const auto k = static_cast<std::size_t>(
            std::max<std::ptrdiff_t>(0, std::distance(line->s_mm.begin(), after) - 1));
        return lines.where(k);
      };
    }
    if (params.step_given) {
      for (const Station& st : stations(*line, params.step_mm))
        pass.samples.push_back(st.vertex >= 0 ? vertexSample(*line, std::size_t(st.vertex))
                                              : pass.at(st.s_mm));
    } else {
      for (std::size_t k = 0; k < n; ++k) pass.samples.push_back(vertexSample(*line, k));
    }
    passes.push_back(std::move(pass));
  }
  if (passes.empty())
    throw InputError(path.file.string() + ": no pass (every block is a `# link` or RAPID move)");
  if (dropped) *dropped = said;
  return passes;
}

}  // namespace fieldpath::pathgen
