/// pathgen/reach_box.h: the box tool + holder can reach along the passes.
#include "fieldpath/pathgen/reach_box.h"

#include <algorithm>
#include <utility>

#include "fieldpath/dynamics/frame.h"
#include "fieldpath/geometry/units.h"

namespace fieldpath::pathgen {

using geometry::kDegToRad;

Eigen::AlignedBox3d reachBox(const std::vector<Pass>& passes, const std::vector<Vec3>& nodes,
                             double ball_radius_mm, const dynamics::DynamicsParams& dyn,
                             double lead_rad, double pad_mm) {
  Eigen::AlignedBox3d box;
  double station_gap_mm = 0.0;
  const double max_tilt = dyn.max_tilt_deg * kDegToRad, max_lead = dyn.max_lead_deg * kDegToRad;
  std::vector<std::pair<double, double>> corners;
  for (const double lead : {lead_rad, max_lead, -max_lead})
    for (const double tilt : {0.0, max_tilt, -max_tilt}) corners.emplace_back(lead, tilt);
  for (const Pass& pass : passes) {
    const size_t stride = std::max<size_t>(1, pass.samples.size() / 16);
    if (pass.samples.size() > stride)
      station_gap_mm = std::max(station_gap_mm, pass.samples[stride].s_mm);
    for (size_t i = 0; i < pass.samples.size(); i += stride) {
      const PassSample& s = pass.samples[i];
      const dynamics::LocalFrame frame{s.feed, s.normal, s.binormal, false};
      for (const auto& [lead, tilt] : corners) {
        const geometry::Posture p = geometry::ballEndPosture(
            s.centre_mm, dynamics::axisFromAngles(frame, lead, tilt), ball_radius_mm);
        const Eigen::Isometry3d placed = geometry::toolToWorld(p);
        for (const Vec3& n : nodes) box.extend(placed * n);
      }
    }
  }
  box.min().array() -= pad_mm + station_gap_mm;
  box.max().array() += pad_mm + station_gap_mm;
  return box;
}

}  // namespace fieldpath::pathgen
