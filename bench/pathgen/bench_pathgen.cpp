#include <cstdio>
#include <cstdlib>
#include "fieldpath/pathgen/generate.h"
using namespace fieldpath;
int main(int argc, char** argv) {
  pathgen::GenerateRequest req;
  req.tool = {geometry::ToolShape::Ball, 3.0, 0.0, 40.0};
  req.holder = {{40, 6}, {55, 6}, {55, 12}, {90, 12}};
  req.clearance_mm = 0.5;
  req.nominal = argc > 1 && argv[1][0] == 'n';
  req.mode = argc > 1 && argv[1][0] == 'd' ? pathgen::FieldMode::Direct : pathgen::FieldMode::Voxel;
  auto r = pathgen::generateImpellerPath(req);
  printf("postures %zu len %.1f nodes %zu pts %zu vox %zu mem %.1fMB tooltri %zu box %.0f cm3\n", r.postures.size(), r.path_length_mm, r.tool_nodes, r.obstacle_points, r.voxel_nodes, r.voxel_memory_bytes/1e6, r.tool_triangles, r.reach_box_mm.volume()/1000);
  printf("times setup %.2f field %.2f steer %.2f clear %.2f total %.2f\n", r.times.setup_s, r.times.field_s, r.times.steering_s, r.times.clearance_s, r.times.total_s);
  printf("min clearance %.3f at %zu colliding %zu maxtilt %.2f maxlead %.2f steps %ld rhs %ld\n", r.clearance.min_clearance_mm, r.clearance.min_index, r.clearance.colliding, r.max_tilt_deg, r.max_lead_deg, r.solver_steps, r.rhs_evals);
  for (int k = 0; k < 7; ++k) { double mn=1e9, mt=0; int col=0; for (auto& g : r.postures) if (g.pass==k) { mn = std::min(mn, g.clearance_mm); mt = std::max(mt, std::abs(g.tilt_rad)*57.3); col += g.clearance_mm<=0; } printf(" pass %d minclr %.3f maxtilt %.2f colliding %d\n", k, mn, mt, col); }
}
