#include <algorithm>
#include <cmath>
#include <limits>

#include <gtest/gtest.h>

#include "fieldpath/geometry/closed_shells.h"
#include "fieldpath/geometry/mesh.h"

using namespace fieldpath::geometry;

namespace {

/// Unit cube [0,1]³, 12 triangles, outward.
TriangleMesh unitCube() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.emplace_back(q[0], q[1], q[2]);
    m.triangles.emplace_back(q[0], q[2], q[3]);
  }
  return m;
}

}  // namespace

TEST(Mesh, CubeClosedForm) {
  const TriangleMesh cube = unitCube();
  const MeshReport r = validateMesh(cube);
  EXPECT_TRUE(r.closed()) << r.summary();
  EXPECT_EQ(r.vertices, 8u);
  EXPECT_EQ(r.triangles, 12u);
  EXPECT_DOUBLE_EQ(meshArea(cube), 6.0);
  EXPECT_DOUBLE_EQ(meshVolume(cube), 1.0);
  EXPECT_EQ(r.summary(), "8 vertices, 12 triangles, closed");
}

TEST(Mesh, InvertedCubeHasNegativeVolume) {
  TriangleMesh cube = unitCube();
  for (auto& t : cube.triangles) std::swap(t[1], t[2]);
  EXPECT_TRUE(validateMesh(cube).closed());
  EXPECT_DOUBLE_EQ(meshVolume(cube), -1.0);
}

TEST(Mesh, ReportsEachDefect) {
  {
    TriangleMesh m = unitCube();
    m.triangles.pop_back();
    const MeshReport r = validateMesh(m);
    EXPECT_EQ(r.open_edges, 3u);
    EXPECT_FALSE(r.closed());
    EXPECT_NE(r.summary().find("3 open edges"), std::string::npos) << r.summary();
  }
  {
    TriangleMesh m = unitCube();
    std::swap(m.triangles[0][1], m.triangles[0][2]);
    const MeshReport r = validateMesh(m);
    EXPECT_EQ(r.inconsistent_edges, 3u);
    EXPECT_EQ(r.open_edges, 0u);
    EXPECT_FALSE(r.closed());
  }
  {
    TriangleMesh m = unitCube();
    m.triangles.push_back(m.triangles[0]);
    EXPECT_EQ(validateMesh(m).non_manifold_edges, 3u);
  }
  {
    TriangleMesh m = unitCube();
    m.vertices[7].x() = std::numeric_limits<double>::quiet_NaN();
    EXPECT_EQ(validateMesh(m).non_finite_vertices, 1u);
    EXPECT_FALSE(validateMesh(m).closed());
  }
  {
    TriangleMesh m = unitCube();
    m.triangles.emplace_back(0, 0, 1);   // repeated index
    m.triangles.emplace_back(0, 1, 99);  // out of range
    m.vertices.emplace_back(0.5, 0, 0);  // collinear with 0 and 1: zero area
    m.triangles.emplace_back(0, 1, 8);
    EXPECT_EQ(validateMesh(m).degenerate_triangles, 3u);
  }
  {
    const MeshReport r = validateMesh(TriangleMesh{});
    EXPECT_FALSE(r.closed());
    EXPECT_NE(r.summary().find("empty"), std::string::npos);
  }
}

namespace {
/// `shell` scaled by s and moved by d, appended to `mesh`.
void appendShell(TriangleMesh& mesh, const TriangleMesh& shell, double s, const Eigen::Vector3d& d,
                 bool inward) {
  const int base = static_cast<int>(mesh.vertices.size());
  for (const auto& v : shell.vertices) mesh.vertices.push_back(s * v + d);
  for (auto t : shell.triangles) {
    if (inward) std::swap(t[1], t[2]);
    mesh.triangles.push_back(t + Eigen::Vector3i::Constant(base));
  }
}
}  // namespace

// Closed shells wound inward are turned (the enclosed volume comes out positive, shell by
// shell); a cavity inside another shell keeps its inward winding; an open shell is left alone.
TEST(Mesh, OrientClosedShellsTurnsInwardShellsOnly) {
  TriangleMesh two;  // an outward cube and an inward one beside it
  appendShell(two, unitCube(), 1.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(two, unitCube(), 2.0, Eigen::Vector3d(5, 0, 0), true);
  EXPECT_DOUBLE_EQ(meshVolume(two), 1.0 - 8.0);
  EXPECT_EQ(orientClosedShells(two), 1u);
  EXPECT_DOUBLE_EQ(meshVolume(two), 1.0 + 8.0);
  EXPECT_TRUE(validateMesh(two).closed());
  EXPECT_EQ(orientClosedShells(two), 0u);  // nothing left to turn

  TriangleMesh hollow;  // a 4 mm cube with a 1 mm cavity: the cavity's inward winding is right
  appendShell(hollow, unitCube(), 4.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(hollow, unitCube(), 1.0, Eigen::Vector3d(1.5, 1.5, 1.5), true);
  EXPECT_EQ(orientClosedShells(hollow), 0u);
  EXPECT_DOUBLE_EQ(meshVolume(hollow), 64.0 - 1.0);

  TriangleMesh open = unitCube();  // inward and one face missing: no inside to speak of
  for (auto& t : open.triangles) std::swap(t[1], t[2]);
  open.triangles.pop_back();
  const TriangleMesh before = open;
  EXPECT_EQ(orientClosedShells(open), 0u);
  EXPECT_EQ(open.triangles, before.triangles);
}

// The kinds of nested shells, read the same whichever way the whole mesh is wound: a 10 mm block
// [0,10]³ with a 6 mm void [2,8]³ holding a 2 mm island [4,6]³, each point's inside known by
// construction. Flipped whole (outer inward, void outward, island inward), the void read as a
// solid: a tool in it "999.9 um" deep (a helper's case).
TEST(Mesh, NestedShellsKeepTheirKindsWhenTheWholeMeshIsFlipped) {
  TriangleMesh nested;
  appendShell(nested, unitCube(), 10.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(nested, unitCube(), 6.0, Eigen::Vector3d(2, 2, 2), true);
  appendShell(nested, unitCube(), 2.0, Eigen::Vector3d(4, 4, 4), false);
  const Eigen::Vector3d wall(1, 5.3, 5.1), in_void(3, 5.3, 5.1), in_island(5, 5.3, 5.1),
      outside(11, 5.3, 5.1);
  for (const bool flipped : {false, true}) {
    TriangleMesh mesh = nested;
    if (flipped)
      for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
    const ClosedShells shells(mesh);
    EXPECT_TRUE(shells.contains(wall)) << flipped;
    EXPECT_FALSE(shells.contains(in_void)) << flipped;
    EXPECT_TRUE(shells.contains(in_island)) << flipped;
    EXPECT_FALSE(shells.contains(outside)) << flipped;
    EXPECT_EQ(orientClosedShells(mesh), flipped ? 3u : 0u);
    EXPECT_EQ(mesh.triangles, nested.triangles);  // wound as a solid's and a void's shells are
  }
  // The island alone wound inward (as its void is): still an island, air in air meaning nothing
  // (read as a void, a tool buried in it passed: a helper's case).
  TriangleMesh island_flipped = nested;
  for (std::size_t t = 24; t < 36; ++t)
    std::swap(island_flipped.triangles[t][1], island_flipped.triangles[t][2]);
  EXPECT_TRUE(ClosedShells(island_flipped).contains(in_island));
  EXPECT_FALSE(ClosedShells(island_flipped).contains(in_void));
  EXPECT_EQ(orientClosedShells(island_flipped), 1u);
  EXPECT_EQ(island_flipped.triangles, nested.triangles);
}

// A void that shares the block's top plane (a skin of no thickness over it) is a void of it: its
// top vertices lie on the block's surface, not inside (the crossing test cannot say which).
// A body wound as the block, wholly inside it, is more of the solid (assemblies overlap); one
// wound inward that only overlaps it is a solid exported inside out.
TEST(Mesh, AVoidTouchingItsSolidAndBodiesInsideOrAcrossIt) {
  TriangleMesh touching;
  appendShell(touching, unitCube(), 4.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(touching, unitCube(), 2.0, Eigen::Vector3d(1, 1, 2), true);  // z 2..4
  EXPECT_FALSE(ClosedShells(touching).contains(Eigen::Vector3d(2, 2.1, 3)));
  EXPECT_TRUE(ClosedShells(touching).contains(Eigen::Vector3d(2, 2.1, 1)));
  TriangleMesh flipped = touching;
  for (auto& t : flipped.triangles) std::swap(t[1], t[2]);
  EXPECT_EQ(orientClosedShells(flipped), 2u);
  EXPECT_EQ(flipped.triangles, touching.triangles);

  TriangleMesh embedded;
  appendShell(embedded, unitCube(), 4.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(embedded, unitCube(), 2.0, Eigen::Vector3d(1, 1, 1), false);
  EXPECT_TRUE(ClosedShells(embedded).contains(Eigen::Vector3d(2, 2.1, 2)));
  EXPECT_EQ(orientClosedShells(embedded), 0u);

  TriangleMesh across;
  appendShell(across, unitCube(), 4.0, Eigen::Vector3d(0, 0, 0), false);
  appendShell(across, unitCube(), 2.0, Eigen::Vector3d(3, 1, 1), true);  // x 3..5
  EXPECT_TRUE(ClosedShells(across).contains(Eigen::Vector3d(3.5, 2.1, 2)));
  EXPECT_TRUE(ClosedShells(across).contains(Eigen::Vector3d(4.5, 2.1, 2)));
  EXPECT_EQ(orientClosedShells(across), 1u);
}

// A closed shell wound inward inside an open shell's box (a part with a face missing, its cavity
// closed): its winding is all there is to tell, and it says a void. Turned outward, it read as a
// body: a tool in it 999.9 um deep (a helper's case).
TEST(Mesh, AnInwardShellInsideAnOpenShellStaysAVoid) {
  TriangleMesh part = unitCube();
  for (auto& v : part.vertices) v *= 10.0;
  part.triangles.pop_back();  // one face half missing: open
  part.triangles.pop_back();
  appendShell(part, unitCube(), 4.0, Eigen::Vector3d(3, 3, 3), true);
  const TriangleMesh before = part;
  EXPECT_EQ(orientClosedShells(part), 0u);
  EXPECT_EQ(part.triangles, before.triangles);
  EXPECT_FALSE(ClosedShells(part).contains(Eigen::Vector3d(5, 5.1, 5)));
}

// A cube written twice (the second copy's vertices its own, its triangles turned cyclically):
// the copies are marked, the first of each not; a copy written the other way round (a sheet's
// other side) is not.
TEST(Mesh, TrianglesWrittenAgainTheSameWayRoundAreMarked) {
  TriangleMesh twice = unitCube();
  const TriangleMesh once = twice;
  const int at = static_cast<int>(twice.vertices.size());
  twice.vertices.insert(twice.vertices.end(), once.vertices.begin(), once.vertices.end());
  for (const auto& t : once.triangles)
    twice.triangles.emplace_back(at + t[1], at + t[2], at + t[0]);
  const std::vector<char> repeated = repeatedFacets(twice);
  ASSERT_EQ(repeated.size(), twice.triangles.size());
  for (std::size_t i = 0; i < repeated.size(); ++i)
    EXPECT_EQ(repeated[i], i >= once.triangles.size() ? 1 : 0) << i;
  TriangleMesh sides = once;
  for (const auto& t : once.triangles) sides.triangles.emplace_back(t[0], t[2], t[1]);
  const std::vector<char> none = repeatedFacets(sides);
  EXPECT_EQ(std::count(none.begin(), none.end(), 1), 0);
}

// A solid keeps its inside beside what touches it: a needle of no area sharing its corner (its
// single-use edges opened the shell: a tool inside read 20 mm clear, a review's), and a second
// body sharing its bottom face written the same way round (counted once, the edges of both
// bodies did not balance: 4.98 mm clear). Points in the solid, outside it.
TEST(Mesh, ASolidKeepsItsInsideBesideANeedleOrABodySharingAFace) {
  TriangleMesh needle = unitCube();
  const int at = static_cast<int>(needle.vertices.size());
  needle.vertices.insert(needle.vertices.end(), {{101, 1, 1}, {51, 1 + 1e-5, 1}});
  needle.triangles.emplace_back(7, at, at + 1);  // from the corner (1, 1, 1)
  const ClosedShells with_needle(needle);
  EXPECT_TRUE(with_needle.contains(Eigen::Vector3d(0.5, 0.4, 0.3)));
  EXPECT_FALSE(with_needle.contains(Eigen::Vector3d(1.5, 0.4, 0.3)));

  TriangleMesh stacked = unitCube();  // [0,1]³ and [0,1]²×[0,0.5] sharing the bottom z = 0
  const int b = static_cast<int>(stacked.vertices.size());
  for (int i = 0; i < 8; ++i) {
    Eigen::Vector3d v = stacked.vertices[std::size_t(i)];
    if (v.z() > 0.5) v.z() = 0.5;
    stacked.vertices.push_back(v);
  }
  const std::size_t cube_triangles = stacked.triangles.size();
  for (std::size_t t = 0; t < cube_triangles; ++t) {
    const Eigen::Vector3i& tri = stacked.triangles[t];
    // the bottom face through the cube's own vertices (0-3: z = 0), the rest the lower body's
    Eigen::Vector3i lower;
    for (int e = 0; e < 3; ++e) lower[e] = tri[e] < 4 ? tri[e] : b + tri[e];
    stacked.triangles.push_back(lower);
  }
  const ClosedShells both(stacked);
  EXPECT_TRUE(both.contains(Eigen::Vector3d(0.5, 0.4, 0.8)));  // in the cube, over the lower body
  EXPECT_FALSE(both.contains(Eigen::Vector3d(0.5, 0.4, 1.2)));
}

// Export defects that left a solid's shell open (its inside unknown: a tool wholly inside read
// clear), each mended to the closed cube of the same surface: a T-junction (the top face split at
// a point on one of its edges, the face beside it not), a sliver of no area on an edge, facets
// wound against their neighbours. A sheet and a closed cube are left as they are.
TEST(Mesh, RepairShellsClosesExportDefectsOnly) {
  TriangleMesh t_junction = unitCube();  // the top (z = 1: 4 5 7 6) fanned from the middle of 4-5
  t_junction.vertices.emplace_back(0.5, 0, 1);
  const int m = 8;
  t_junction.triangles[2] = Eigen::Vector3i(4, m, 6);
  t_junction.triangles[3] = Eigen::Vector3i(m, 7, 6);
  t_junction.triangles.emplace_back(m, 5, 7);
  ASSERT_GT(validateMesh(t_junction).open_edges, 0u);
  const ShellRepair mended = repairShells(t_junction);
  EXPECT_EQ(mended.edges_split, 1u);
  EXPECT_EQ(mended.open_edges_after, 0u);
  EXPECT_TRUE(validateMesh(t_junction).closed()) << validateMesh(t_junction).summary();
  EXPECT_NEAR(meshArea(t_junction), 6.0, 1e-12);
  EXPECT_NEAR(meshVolume(t_junction), 1.0, 1e-12);
  EXPECT_EQ(closedShells(t_junction).size(), 1u);

  TriangleMesh sliver = unitCube();  // a zero-area triangle on the edge 0-1, through its middle
  sliver.vertices.emplace_back(0.5, 0, 0);
  sliver.triangles.emplace_back(0, 1, 8);
  const TriangleMesh sliver_before = sliver;
  ASSERT_GT(validateMesh(sliver).open_edges, 0u);
  const ShellRepair unslivered = repairShells(sliver);
  EXPECT_EQ(unslivered.slivers_removed, 1u);
  EXPECT_TRUE(validateMesh(sliver).closed()) << validateMesh(sliver).summary();
  EXPECT_EQ(sliver.triangles.size(), 12u);

  for (const std::vector<int> turned : {std::vector<int>{1}, std::vector<int>{0, 3, 4, 7, 8, 11}}) {
    TriangleMesh flipped = unitCube();
    for (const int i : turned) std::swap(flipped.triangles[i][1], flipped.triangles[i][2]);
    ASSERT_GT(validateMesh(flipped).inconsistent_edges, 0u);
    EXPECT_EQ(repairShells(flipped).facets_turned, turned.size());
    EXPECT_TRUE(validateMesh(flipped).closed()) << validateMesh(flipped).summary();
    EXPECT_NEAR(std::abs(meshVolume(flipped)), 1.0, 1e-12);
  }

  TriangleMesh sheet = unitCube();  // a face missing: open, and stays so
  sheet.triangles.resize(10);
  const TriangleMesh sheet_before = sheet;
  EXPECT_FALSE(repairShells(sheet).any());
  EXPECT_EQ(sheet.triangles, sheet_before.triangles);
  TriangleMesh cube = unitCube();
  EXPECT_FALSE(repairShells(cube).any());
  EXPECT_EQ(cube.triangles, unitCube().triangles);

  // A lone sliver closes nothing: it stays, the surface of a needle or a cap (left out, a tool
  // through a 100 mm cap 1e-5 mm high read 200 mm clear: a review's), beside a T-junction mended
  // or not.
  for (const bool with_t_junction : {false, true}) {
    TriangleMesh capped = with_t_junction ? sliver_before : unitCube();
    const int at = static_cast<int>(capped.vertices.size());
    capped.vertices.insert(capped.vertices.end(), {{5, 5, 5}, {105, 5, 5}, {55, 5 + 1e-5, 5}});
    capped.triangles.emplace_back(at, at + 1, at + 2);
    const ShellRepair mended = repairShells(capped);
    EXPECT_EQ(mended.slivers_removed, with_t_junction ? 1u : 0u);
    EXPECT_NE(std::find(capped.triangles.begin(), capped.triangles.end(),
                        Eigen::Vector3i(at, at + 1, at + 2)),
              capped.triangles.end());
  }
}
