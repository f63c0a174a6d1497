#include "fieldpath/pathgen/links.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/units.h"

namespace fieldpath::pathgen {
namespace {

using common::InputError;
using geometry::PathBlock;
using geometry::Posture;

/// An axis lower than this (its z component) points down: sin 0.06°, past a horizontal axis's
/// rounding (one a little below horizontal was taken, and a link's turn hung the tool upside down).
constexpr double kHorizontalZ = 1e-3;
/// An axis must rise at least this much (its z component) to be left along: sin 5°.
constexpr double kMinAxisRise = 0.0872;

/// Unit vector at fraction t of the great-circle arc from a to b (a, b unit, not opposite).
Vec3 slerp(const Vec3& a, const Vec3& b, double t) {
  const double angle = std::acos(std::clamp(a.dot(b), -1.0, 1.0));
  if (angle < 1e-12) return a;
  const double sa = std::sin(angle);
  return (std::sin((1 - t) * angle) / sa * a + std::sin(t * angle) / sa * b).normalized();
}

/// A link's turn of the axis from a to b: the great-circle arc, or, where that arc is undefined
/// or dips below both ends (opposite axes: both sides of a rib milled with the ball's side; a
/// reviewer's link wrote axes of 0 0 0, or hung the tool upside down), the two arcs through +z.
class AxisTurn {
 public:
  AxisTurn(const Vec3& a, const Vec3& b) : a_(a), b_(b) {
    via_up_ = a.dot(b) < -0.9999 || slerp(a, b, 0.5).z() < std::min(a.z(), b.z()) - 1e-12;
    first_rad_ = via_up_ ? angle(a, Vec3::UnitZ()) : angle(a, b);
    total_rad_ = first_rad_ + (via_up_ ? angle(Vec3::UnitZ(), b) : 0.0);
  }
  double degrees() const { return total_rad_ * geometry::kRadToDeg; }
  /// The axis at fraction t of the turn (by angle).
  Vec3 at(double t) const {
    if (!via_up_) return slerp(a_, b_, t);
    const double s = t * total_rad_;
    if (s <= first_rad_) return first_rad_ > 0.0 ? slerp(a_, Vec3::UnitZ(), s / first_rad_) : a_;
    const double second = total_rad_ - first_rad_;
    return second > 0.0 ? slerp(Vec3::UnitZ(), b_, (s - first_rad_) / second) : b_;
  }

 private:
  static double angle(const Vec3& u, const Vec3& v) {
    return std::acos(std::clamp(u.dot(v), -1.0, 1.0));
  }
  Vec3 a_, b_;
  bool via_up_ = false;
  double first_rad_ = 0.0, total_rad_ = 0.0;
};

Posture at(const Vec3& tip, const Vec3& axis) {
  Posture p;
  p.tip_mm = tip;
  p.axis = axis;
  return p;
}

/// Where a link leaving posture p (or entering it) meets the travel plane, the tip at `z_mm`:
/// along its axis (DESIGN), never nearer than `retract`; an axis within 5° of horizontal (side
/// milling, a wall finished with the ball: the climb along it ran hundreds of mm sideways, or
/// never rose, and the job was refused), `retract` along it, then straight up. An axis below
/// horizontal is left from beneath (an undercut): no link from above reaches it.
/// Another `way` (rerouteLinkEnds: the axis's collided): `retract` along its retract direction,
/// then on along its climb to the plane.
Vec3 travelPoint(const Posture& p, double z_mm, double retract_mm, const char* which,
                 const std::string& pass, const LinkEndWay& way) {
  if (!way.alongAxis()) return wayTips(p.tip_mm, z_mm, retract_mm, way).back();
  if (p.axis.z() >= kMinAxisRise)
    return p.tip_mm + std::max(retract_mm, (z_mm - p.tip_mm.z()) / p.axis.z()) * p.axis;
  if (p.axis.z() < -kHorizontalZ) {
    std::ostringstream msg;
    msg.precision(3);
    msg << "links: " << pass << " " << which << " with the tool axis "
        << std::acos(std::clamp(p.axis.z(), -1.0, 1.0)) * geometry::kRadToDeg
        << " deg from vertical, pointing down: no link from the travel plane above reaches it "
           "(write its links in the nominal path and run `check` on it)";
    throw InputError(msg.str());
  }
  Vec3 up = p.tip_mm + retract_mm * p.axis;
  up.z() = std::max(up.z(), z_mm);
  return up;
}

}  // namespace

std::vector<Vec3> wayTips(const Vec3& tip_mm, double z_mm, double retract_mm,
                          const LinkEndWay& way) {
  std::vector<Vec3> out = {tip_mm + way.retractMm(retract_mm) * way.retract_dir};
  if (way.sideways_mm != Vec3::Zero()) out.push_back(out.back() + way.sideways_mm);
  const Vec3 from = out.back();
  const double full = std::max(0.0, (z_mm - from.z()) / way.climb.z());
  if (way.climb_mm < full) {  // the knee, then straight up
    out.push_back(from + way.climb_mm * way.climb);
    out.push_back(Vec3(out.back().x(), out.back().y(), z_mm));
  } else {
    out.push_back(from + full * way.climb);
  }
  return out;
}

double lowestPointBelowTip(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                           const Vec3& axis) {
  const double cos_t = std::clamp(axis.normalized().z(), -1.0, 1.0);
  const double sin_t = std::sqrt(std::max(0.0, 1.0 - cos_t * cos_t));
  // A circle of radius ρ at height z above the tip (tool frame) reaches z cos - ρ sin below.
  const double c = geometry::cornerRadius(tool);
  double lowest = c * cos_t - (tool.radius_mm - c) * sin_t - c;  // the cutting end
  auto station = [&](double z, double radius) {
    lowest = std::min(lowest, z * cos_t - radius * sin_t);
  };
  station(c, tool.radius_mm);
  station(tool.length_mm, tool.radius_mm);
  for (const auto& s : holder) station(s.z_mm, s.radius_mm);
  return lowest;
}

double topOfMeshes(std::span<const geometry::TriangleMesh> meshes) {
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& mesh : meshes)
    for (const auto& v : mesh.vertices) top = std::max(top, v.z());
  return top;
}

double resolveSafeZ(std::optional<double> given_mm, double top_mm, double clearance_mm) {
  if (!std::isfinite(top_mm)) throw InputError("links.safe_z: needs at least one mesh vertex");
  if (!given_mm) return top_mm + clearance_mm + kSafeZMarginMm;
  const double least = top_mm + clearance_mm;
  if (*given_mm < least) {
    std::ostringstream msg;
    msg.precision(6);
    msg << "links.safe_z: " << *given_mm << " mm is below the highest mesh point plus `clearance` ("
        << least << " mm): the links would travel through the obstacles or the part; give at least "
        << least << " or `auto`";
    throw InputError(msg.str());
  }
  return *given_mm;
}

geometry::PathFile linkPasses(std::span<const std::vector<Posture>> passes,
                              const LinkRequest& request) {
  const LinkParams& params = request.params;
  if (!std::isfinite(params.retract_mm) || params.retract_mm <= 0.0)
    throw InputError(
        "links.retract: must be a finite distance > 0 mm (at 0 a link's last rapid "
        "move ends on the part)");
  if (!std::isfinite(request.safe_z_mm)) throw InputError("links.safe_z: must be finite");
  geometry::PathFile out;
  auto add = [&](PathBlock::Kind kind, const Posture& p) {
    if (kind == PathBlock::Kind::Link && !out.postures.empty() &&
        geometry::samePose(out.postures.back(), p))
      return;  // e.g. the travel plane reached by the retract itself
    if (out.blocks.empty() || out.blocks.back().kind != kind)
      out.blocks.push_back({kind, out.postures.size(), out.postures.size()});
    out.postures.push_back(p);
    ++out.blocks.back().end;
  };
  // The tip's height in the travel plane for an axis turning from a to b: the whole tool and
  // holder stay above safe_z at every axis on the way.
  auto travelTipZ = [&](const Vec3& a, const Vec3& b) {
    double lowest = 0.0;
    const AxisTurn turn(a, b);
    for (int k = 0; k <= 32; ++k)
      lowest =
          std::min(lowest, lowestPointBelowTip(request.tool, request.holder, turn.at(k / 32.0)));
    return request.safe_z_mm - lowest;
  };
  // The way out of pass k and into it: along its axis, or as rerouteLinkEnds chose.
  auto way = [&](const std::vector<LinkEndWay>& ways, std::size_t k) {
    return k < ways.size() ? ways[k] : LinkEndWay{};
  };
  const auto link = PathBlock::Kind::Link;
  // Where the link's retract out of `p` along `w` ends.
  auto retracted = [&](const Posture& p, const LinkEndWay& w) {
    return Vec3(p.tip_mm +
                w.retractMm(params.retract_mm) * (w.alongAxis() ? p.axis : w.retract_dir));
  };
  // The postures between the retract and the travel plane of a way off the axis (the move
  // sideways' end, the knee), in the order the link passes them: out of the pass, or into it.
  auto between = [&](const Posture& p, const LinkEndWay& w, double z, bool into) {
    if (w.alongAxis()) return;
    std::vector<Vec3> tips = wayTips(p.tip_mm, z, params.retract_mm, w);
    tips = std::vector<Vec3>(tips.begin() + 1, tips.end() - 1);
    if (into) std::reverse(tips.begin(), tips.end());
    for (const Vec3& tip : tips) add(link, at(tip, p.axis));
  };
  // A pass as messages name it: its label (with its line) where given.
  auto label = [&](std::size_t k) {
    return k < request.labels.size() ? request.labels[k] : "pass " + std::to_string(k + 1);
  };
  for (std::size_t k = 0; k < passes.size(); ++k) {
    const std::vector<Posture>& pass = passes[k];
    if (pass.empty()) continue;
    const Posture& first = pass.front();
    // Down into pass k: from the travel plane (the approach for the first pass, the end of the
    // link otherwise) along its first axis to `retract` above its start.
    const Vec3 from_axis = k == 0 ? first.axis : passes[k - 1].back().axis;
    const double z = travelTipZ(from_axis, first.axis);
    const LinkEndWay in = way(request.in_ways, k);
    if (k == 0) {
      add(link, at(travelPoint(first, z, params.retract_mm, "starts", label(k), in), first.axis));
    } else {
      const Posture& last = passes[k - 1].back();
      const LinkEndWay out = way(request.out_ways, k - 1);
      add(link, at(retracted(last, out), last.axis));
      between(last, out, z, false);
      const Vec3 a = travelPoint(last, z, params.retract_mm, "ends", label(k - 1), out);
      const Vec3 b = travelPoint(first, z, params.retract_mm, "starts", label(k), in);
      const AxisTurn turn(last.axis, first.axis);
      const int steps = std::max(1, static_cast<int>(std::ceil(turn.degrees() / kMaxLinkTurnDeg)));
      for (int j = 0; j <= steps; ++j) {
        const double t = static_cast<double>(j) / steps;
        add(link, at((1 - t) * a + t * b, turn.at(t)));
      }
    }
    between(first, in, z, true);
    add(link, at(retracted(first, in), first.axis));
    for (const Posture& p : pass) add(PathBlock::Kind::Pass, p);
  }
  // Departure: back along the last axis to the travel plane.
  if (!out.postures.empty()) {
    const Posture final_posture = out.postures.back();
    std::size_t last = passes.size() - 1;
    while (passes[last].empty()) --last;
    const LinkEndWay leave = way(request.out_ways, last);
    const double z = travelTipZ(final_posture.axis, final_posture.axis);
    const Vec3 up = travelPoint(final_posture, z, params.retract_mm, "ends", label(last), leave);
    add(link, at(retracted(final_posture, leave), final_posture.axis));
    between(final_posture, leave, z, false);
    add(link, at(up, final_posture.axis));
  }
  return out;
}

}  // namespace fieldpath::pathgen
