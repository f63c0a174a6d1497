/// The clearance checker where FCL's surface distances alone read clear: a tool wholly inside a
/// closed obstacle (also one written with repeats or as touching bodies), an obstacle wholly
/// inside the tool. (Sheets inside the tool: test_clearance.cpp.)
#include <array>
#include <map>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fixtures.h"

using namespace fieldpath;
using namespace fieldpath::pathgen;
using geometry::Posture;
using pathgen::test::boxMesh;

namespace {

// A mesh whose identical positions are one vertex (as loadMesh joins them).
geometry::TriangleMesh joined(const geometry::TriangleMesh& in) {
  geometry::TriangleMesh out;
  std::map<std::array<double, 3>, int> index_of;
  std::vector<int> remap;
  for (const auto& v : in.vertices) {
    const auto [it, added] = index_of.emplace(std::array<double, 3>{v.x(), v.y(), v.z()},
                                              static_cast<int>(out.vertices.size()));
    if (added) out.vertices.push_back(v);
    remap.push_back(it->second);
  }
  for (const auto& t : in.triangles)
    out.triangles.emplace_back(remap[t[0]], remap[t[1]], remap[t[2]]);
  return out;
}

}  // namespace

// A tool wholly inside a solid obstacle collides also when the obstacle's file writes a triangle
// twice, or holds two bodies sharing a face or an edge (a multi-body export): the shells are
// still closed (every edge as often one way as the other) and their inside is known. Each of
// these read as clear (17.48 mm) before.
TEST(Clearance, InsideASolidWithRepeatsOrTouchingBodiesIsColliding) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 1.0, 0.0, 4.0};
  const geometry::TriangleMesh tool_mesh = geometry::toolMesh(tool, {{4, 1.5}, {8, 1.5}}, 0.02);
  const Posture inside{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ(), 0.0, false};
  geometry::TriangleMesh repeated = boxMesh(-20, 20, -20, 20, -20, 80);
  repeated.triangles.push_back(repeated.triangles.front());
  geometry::TriangleMesh stacked = boxMesh(-20, 20, -20, 20, -20, 30);
  pathgen::test::addBox(stacked, -20, 20, -20, 20, 30, 80);
  geometry::TriangleMesh by_edge = boxMesh(-20, 20, -20, 20, -20, 80);
  pathgen::test::addBox(by_edge, 20, 40, 20, 40, -20, 80);
  for (const auto& [name, mesh] : {std::pair{"repeated", repeated}, std::pair{"stacked", stacked},
                                   std::pair{"by_edge", by_edge}}) {
    const std::vector<geometry::TriangleMesh> obstacle = {joined(mesh)};
    EXPECT_EQ(geometry::closedShells(obstacle[0]).size(), 1u) << name;  // joined through vertices
    const ClearanceChecker checker(tool_mesh, obstacle, 0.02);
    EXPECT_EQ(checker.clearance(inside), 0.0) << name;
    // outside every body, beside it: clear
    const Posture beside{Eigen::Vector3d(-30, 0, 0), Eigen::Vector3d::UnitZ(), 0.0, false};
    EXPECT_GT(checker.clearance(beside), 5.0) << name;
  }
}

// FCL measures between surfaces: a tool wholly inside a closed obstacle, or an obstacle wholly
// inside the tool, touches no triangle. Both collide; the same tool beside the box is clear.
TEST(Clearance, InsideOneAnotherIsColliding) {
  const geometry::ToolSpec tool{geometry::ToolShape::Ball, 3.0, 0.0, 20.0};
  const geometry::TriangleMesh tool_mesh = geometry::toolMesh(tool, {{20, 8}, {40, 8}}, 0.02);
  const std::vector<geometry::TriangleMesh> room = {boxMesh(-50, 50, -50, 50, -50, 100)};
  const ClearanceChecker in_room(tool_mesh, room, 0.02);
  const Posture up{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d::UnitZ(), 0.0, false};
  int obstacle = -1;
  EXPECT_EQ(in_room.clearance(up, &obstacle), 0.0);
  EXPECT_EQ(obstacle, 0);
  EXPECT_EQ(in_room.check(std::vector<Posture>{up}).colliding, 1u);
  // A 2 mm cube inside the holder (radius 8 from z = 20 to 40 above the tip).
  const std::vector<geometry::TriangleMesh> pebble = {boxMesh(-1, 1, -1, 1, 29, 31)};
  const ClearanceChecker held(tool_mesh, pebble, 0.02);
  EXPECT_EQ(held.clearance(up), 0.0);
  // Beside the cube, 10 mm off the holder's side: clear by that.
  const Posture beside{Eigen::Vector3d(19, 0, 0), Eigen::Vector3d::UnitZ(), 0.0, false};
  EXPECT_NEAR(held.clearance(beside), 19 - 1 - 8 - 0.02, 0.05);
  // The ball's centre inside the room's walls is inside an obstacle too.
  EXPECT_EQ(in_room.ballClearance(std::vector<Eigen::Vector3d>{{0, 0, 3}}, 3.0), 0.0);
}
