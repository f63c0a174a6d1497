#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "fieldpath/dynamics/frame.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/reach_box.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;

namespace {

/// A straight pass over a flat floor heading along (cos a, sin a, 0), stations every 1 mm.
Pass straightPass(double heading_rad, double length_mm) {
  Pass pass;
  pass.label = "pass 1";
  pass.ball_radius_mm = 3.0;
  pass.length_mm = length_mm;
  const Vec3 feed(std::cos(heading_rad), std::sin(heading_rad), 0.0);
  for (int i = 0; i <= int(length_mm); ++i) {
    PassSample s;
    s.s_mm = i;
    s.centre_mm = Vec3(0, 0, 3) + double(i) * feed;
    s.feed = feed;
    s.normal = Vec3::UnitZ();
    s.binormal = s.normal.cross(s.feed);
    pass.samples.push_back(s);
  }
  return pass;
}

}  // namespace

// The box holds every tool + holder node at every station with lead and tilt both at their
// limits (the dynamics clamps each alone, so such a posture can be steered to). A pass heading
// diagonally across the world axes is where the corners stick out of the box of each limit
// alone; along an axis they do not. No padding here, so the test is the sampling's alone.
TEST(ReachBox, HoldsTheNodesWithLeadAndTiltBothAtTheirLimits) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  const geometry::HolderProfile holder{{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  std::vector<Vec3> nodes;
  for (const auto& node : geometry::surfaceNodes(tool, holder, defaultNodeSpacingMm(tool, holder)))
    nodes.push_back(node.position_mm);
  dynamics::DynamicsParams dyn;
  dyn.max_lead_deg = 20;
  dyn.max_tilt_deg = 35;
  const double lead = dyn.max_lead_deg * M_PI / 180.0, tilt = dyn.max_tilt_deg * M_PI / 180.0;
  for (const double heading_deg : {0.0, 30.0, 45.0}) {
    const Pass pass = straightPass(heading_deg * M_PI / 180.0, 16.0);  // a station a sample
    const Eigen::AlignedBox3d box = reachBox({pass}, nodes, 3.0, dyn, 0.0, 0.0);
    double worst_mm = 0.0;
    for (const PassSample& s : pass.samples)
      for (const double l : {-lead, lead})
        for (const double t : {-tilt, tilt}) {
          const dynamics::LocalFrame frame{s.feed, s.normal, s.binormal, false};
          const Eigen::Isometry3d placed = geometry::toolToWorld(geometry::ballEndPosture(
              s.centre_mm, dynamics::axisFromAngles(frame, l, t), 3.0));
          for (const Vec3& n : nodes)
            worst_mm = std::max(worst_mm, box.exteriorDistance(placed * n));
        }
    EXPECT_LE(worst_mm, 1e-9) << "heading " << heading_deg << "°";
  }
}
