#include "fieldpath/pathgen/passes.h"

#include <algorithm>
#include <memory>
#include <cmath>
#include <sstream>
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/dynamics/frame.h"

namespace fieldpath::pathgen {
namespace {

/// Dense samples per pass for the arc-length table; the chord/arc difference per segment is
/// κ² Δs³ / 24, far below 1e-9 mm here.
constexpr int kDense = 8192;

/// Ball centre on the hub offset: C(u) = S(u, v) + R n(u, v).
Vec3 ballCentre(const Impeller& impeller, double u, double v, double radius_mm) {
  return impeller.hub(u, v) + radius_mm * impeller.hubNormal(u, v);
}

/// Arc length → u, dense and increasing: the stations at any s by inverse interpolation.
struct ArcTable {
  std::vector<double> s_mm, u;
};

PassSample impellerSample(const Impeller& impeller, const ArcTable& table, double v,
                          double radius_mm, double length_mm, double s_mm);

}  // namespace

std::vector<Pass> impellerPasses(const Impeller& impeller, const PathParams& path,
                                 double ball_radius_mm) {
  using common::InputError;
  if (path.passes < 1)
    throw InputError("path.passes: must be >= 1 (got " + std::to_string(path.passes) + ")");
  if (!(path.step_mm >= kMinPathStepMm) || !std::isfinite(path.step_mm))
    throw InputError("path.step: must be a finite number >= 0.001 mm (a machine's resolution)");
  if (!std::isfinite(path.lead_deg) || std::abs(path.lead_deg) >= 60.0)
    throw InputError("path.lead_deg: must be a finite angle with |lead| < 60 deg");
  if (!std::isfinite(ball_radius_mm) || ball_radius_mm <= 0.0)
    throw InputError("tool.radius: must be > 0");

  const auto& params = impeller.params();
  const double u0 = params.u_range[0], u1 = params.u_range[1];
  const double v_first = params.passes_v[0], v_last = params.passes_v[1];
  const double r = ball_radius_mm;

  std::vector<Pass> passes;
  passes.reserve(path.passes);
  for (int k = 0; k < path.passes; ++k) {
    Pass pass;
    pass.index = k;
    pass.v = path.passes == 1 ? 0.5 * (v_first + v_last)
                              : v_first + (v_last - v_first) * k / (path.passes - 1);
    auto centre = [&](double u) { return ballCentre(impeller, u, pass.v, r); };
    std::ostringstream label;
    label << "pass " << k + 1 << " (v = " << pass.v << ")";
    pass.label = label.str();

    pass.ball_radius_mm = r;
    auto table = std::make_shared<ArcTable>();
    table->s_mm.resize(kDense + 1);
    table->u.resize(kDense + 1);
    Vec3 prev = centre(u0);
    for (int i = 0; i <= kDense; ++i) {
      table->u[i] = u0 + (u1 - u0) * i / kDense;
      const Vec3 c = centre(table->u[i]);
      table->s_mm[i] = i == 0 ? 0.0 : table->s_mm[i - 1] + (c - prev).norm();
      prev = c;
    }
    pass.length_mm = table->s_mm.back();
    pass.at = [model = std::make_shared<const Impeller>(impeller), table, v = pass.v, r,
               length = pass.length_mm](double s_mm) {
      return impellerSample(*model, *table, v, r, length, s_mm);
    };
    if (!(pass.length_mm >= path.step_mm)) {
      std::ostringstream msg;
      msg << "pass " << k + 1 << " (v = " << pass.v << "): empty: its length " << pass.length_mm
          << " mm is shorter than one step (path.step = " << path.step_mm
          << " mm); widen impeller.u_range";
      throw InputError(msg.str());
    }
    const int intervals = static_cast<int>(std::ceil(pass.length_mm / path.step_mm - 1e-9));
    pass.samples.reserve(intervals + 1);
    for (int j = 0; j <= intervals; ++j)
      pass.samples.push_back(pass.at(pass.length_mm * j / intervals));
    passes.push_back(std::move(pass));
  }
  return passes;
}

namespace {

PassSample impellerSample(const Impeller& impeller, const ArcTable& table, double v,
                          double radius_mm, double length_mm, double s_mm) {
  const auto& s_table = table.s_mm;
  const auto& u_table = table.u;
  PassSample sample;
  sample.s_mm = std::clamp(s_mm, 0.0, length_mm);
  // u at this arc length: linear inverse interpolation in the dense table.
  const auto it = std::lower_bound(s_table.begin(), s_table.end(), sample.s_mm);
  const size_t i = std::clamp<size_t>(it - s_table.begin(), 1, s_table.size() - 1);
  const double span = s_table[i] - s_table[i - 1];
  const double w = span > 0.0 ? (sample.s_mm - s_table[i - 1]) / span : 0.0;
  sample.u = u_table[i - 1] + w * (u_table[i] - u_table[i - 1]);
  auto centre = [&](double u) { return ballCentre(impeller, u, v, radius_mm); };
  sample.normal = impeller.hubNormal(sample.u, v);
  sample.centre_mm = impeller.hub(sample.u, v) + radius_mm * sample.normal;
  constexpr double du = 1e-5;
  Vec3 tangent = centre(sample.u + du) - centre(sample.u - du);
  tangent -= tangent.dot(sample.normal) * sample.normal;  // exactly ⟂ n despite rounding
  sample.feed = tangent.normalized();
  sample.binormal = sample.normal.cross(sample.feed);
  return sample;
}

}  // namespace

Vec3 nominalAxis(const PassSample& sample, double lead_rad) {
  const dynamics::LocalFrame frame{sample.feed, sample.normal, sample.binormal, false};
  return dynamics::axisFromAngles(frame, lead_rad, 0.0).normalized();
}

std::vector<geometry::Posture> nominalPostures(std::span<const Pass> passes, double lead_rad,
                                               double ball_radius_mm) {
  std::vector<geometry::Posture> out;
  for (const Pass& pass : passes)
    for (const PassSample& s : pass.samples)
      out.push_back(
          geometry::ballEndPosture(s.centre_mm, nominalAxis(s, lead_rad), ball_radius_mm));
  return out;
}

}  // namespace fieldpath::pathgen
