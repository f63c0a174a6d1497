/// generate's links through the built binary, as a user meets them: a link end freed under a
/// shelf by a move sideways below links.retract (warned: rapids that low cut stock), ends no way
/// frees (named, with what may free them), and the note of a link climbing far outside the
/// meshes (the end whose climb it is). Split from test_cli_generate_edges.cpp (701 lines).
#include <cmath>
#include <filesystem>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fixtures.h"
#include "run_fieldpath.h"

namespace fs = std::filesystem;
using namespace fieldpath;
using test::TempDir;

namespace {

/// A floor (the part, 50 x 40 mm, top at z 0) under a shelf (the obstacle) from z `shelf_z_mm`
/// to 25 reaching y `shelf_y_mm`, and pass.cl: one upright pass of 21 postures along x 0-10 on
/// the floor.
void writeUprightPassUnderAShelf(const TempDir& dir, double shelf_y_mm, double shelf_z_mm) {
  geometry::TriangleMesh floor, shelf;
  pathgen::test::addBox(floor, -20, 30, -20, 20, -10, 0);
  pathgen::test::addBox(shelf, -50, 60, -50, shelf_y_mm, shelf_z_mm, 25);
  geometry::saveMesh(floor, dir.path() / "floor.stl");
  geometry::saveMesh(shelf, dir.path() / "shelf.stl");
  std::string cl = "# pass 1\n";
  for (int k = 0; k <= 20; ++k) cl += std::to_string(0.5 * k) + " 0 0 0 0 1\n";
  dir.write("pass.cl", cl);
}

/// `generate SCENE --nominal --out OUT` in `dir`, its report.json: the run must succeed.
nlohmann::json generateNominal(const TempDir& dir, const std::string& scene,
                               const std::string& out) {
  const auto r = test::runFieldpath(dir, "generate " + scene + " --nominal --out " + out);
  EXPECT_EQ(r.exit_code, 0) << r.output();
  return nlohmann::json::parse(test::slurp(dir.path() / out / "report.json"));
}

}  // namespace

// Links climb along the tool axis: with an axis 60 deg from vertical and the travel plane 100 mm
// up, the climb goes ~170 mm sideways, past a 20 x 32 mm part and rib. Said once, on stdout and in
// report.json `link_notes` (it was on stdout only); none with the axis vertical.
TEST(GenerateLinks, ALinkFarOutsideTheMeshesIsSaidInTheReport) {
  const TempDir dir;
  geometry::TriangleMesh plate, rib;
  pathgen::test::addBox(plate, -10, 10, -10, 10, -5, 0);
  pathgen::test::addBox(rib, -10, 10, 20, 22, -5, 5);
  geometry::saveMesh(plate, dir.path() / "plate.stl");
  geometry::saveMesh(rib, dir.path() / "rib.stl");
  for (const bool tilted : {true, false}) {
    const double s = tilted ? std::sin(M_PI / 3) : 0.0, c = tilted ? std::cos(M_PI / 3) : 1.0;
    std::ostringstream cl;
    for (int pass = 0; pass < 2; ++pass) {
      cl << "# pass " << pass + 1 << "\n";
      for (int i = -5; i <= 5; ++i)
        cl << 2.0 * i << ' ' << 4.0 * pass << " 0 0 " << s << ' ' << c << "\n";
    }
    dir.write("p.cl", cl.str());
    dir.write("scene.yaml",
              "obstacles:\n  - mesh: rib.stl\npart: plate.stl\n"
              "tool: { shape: ball, radius: 3, length: 20 }\nclearance: 0.5\n"
              "links: { safe_z: 100 }\npath: { nominal: p.cl }\n");
    const std::string out = tilted ? "tilted" : "vertical";
    const auto r = test::runFieldpath(dir, "generate scene.yaml --nominal --out " + out);
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const auto report = nlohmann::json::parse(test::slurp(dir.path() / out / "report.json"));
    const std::size_t said = r.err.find("outside the meshes' x-y box") != std::string::npos;
    EXPECT_EQ(report["link_notes"].size(), tilted ? 1u : 0u) << report["link_notes"];
    EXPECT_EQ(said, tilted ? 1u : 0u) << r.err;
    if (tilted) {
      // The climb along the axis leaning 60 deg across the feed (+y) from z ~ 0 to where the
      // holder clears z = 100: ~ 100 tan 60 = 173 mm sideways from y = 4, past the box's y = 22.
      const std::string note = report["link_notes"][0];
      const double outside = std::stod(note.substr(note.find(" lies ") + 6));
      EXPECT_GT(outside, 120.0) << note;
      EXPECT_LT(outside, 200.0) << note;
      // The posture named with its block and its line in path.cl, as the reader gives it.
      const std::size_t open = note.find("travel plane: posture ") + 22;
      const std::size_t at = std::stoul(note.substr(open));
      const geometry::PathFile written = geometry::readPathFile(dir.path() / out / "path.cl");
      EXPECT_NE(note.find("path.cl:" + std::to_string(written.lines.at(at)) + ") lies "),
                std::string::npos)
          << note;
    }
  }
}

// A link end freed by a move sideways after a retract shorter than links.retract runs that low
// over the part, and path.apt writes a link's moves as rapids: over stock not yet cut (here the
// start of the pass) that is not free, and a warning says so (a diff review's: a 24 mm rapid
// 1 mm over the pass's start was said only as a note). None where the full retract is taken (a
// shorter tool, 10 mm under the shelf, climbs out from under it at 60 deg).
TEST(GenerateLinks, AMoveSidewaysUnderTheRetractIsWarned) {
  const TempDir dir;
  writeUprightPassUnderAShelf(dir, 10, 14);
  for (const bool under : {true, false}) {
    dir.write("scene.yaml", std::string("obstacles:\n  - mesh: shelf.stl\npart: floor.stl\n") +
                                "tool: { shape: ball, radius: 3, length: " + (under ? "12" : "4") +
                                " }\nclearance: 0.5\npath: { nominal: pass.cl }\n"
                                "links: { retract: 2 }\n");
    const auto r = test::runFieldpath(dir, "generate scene.yaml --nominal --out out");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    const auto report = nlohmann::json::parse(test::slurp(dir.path() / "out/report.json"));
    const auto& routed = report["links"]["routed_off_axis"];
    EXPECT_EQ(routed.size(), 2u) << routed;  // a shorter tool climbs out at 60 deg
    for (const auto& end : routed)
      EXPECT_EQ(end["retract_mm"].get<double>(), under ? 1.0 : 2.0) << end;
    EXPECT_EQ(r.err.find("warning: 2 link ends move sideways after a retract shorter than "
                         "links.retract (2 mm") != std::string::npos,
              under)
        << r.err;
  }
}

// Link ends no way up frees (under a shelf 100 mm wide): a note names the first and says to
// edit the written path.cl; where links.retract is short it also says a longer one may free
// them (a links adversary's: 12 ends unfreed at 0.001 mm, all freed at 0.05).
TEST(GenerateLinks, UnfreedLinkEndsAreNamedWithWhatMayFreeThem) {
  const TempDir dir;
  writeUprightPassUnderAShelf(dir, 50, 20);
  for (const double retract : {0.5, 5.0}) {
    dir.write("scene.yaml",
              "obstacles:\n  - mesh: shelf.stl\npart: floor.stl\n"
              "tool: { shape: ball, radius: 3, length: 12 }\nclearance: 0.5\n"
              "path: { nominal: pass.cl }\nlinks: { retract: " +
                  std::to_string(retract) + " }\n");
    const auto r = test::runFieldpath(dir, "generate scene.yaml --nominal --out out");
    ASSERT_EQ(r.exit_code, 0) << r.output();
    EXPECT_NE(r.err.find("note: 2 link ends collide or come under the clearance whichever "
                         "straight way up from the pass, the axis held, is taken (first: the "
                         "way into pass 1 (pass.cl:2))"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("or give a longer links.retract (0.5 mm") != std::string::npos,
              retract < 1.0)
        << r.err;
  }
}

// The far link's note names the end whose climb runs far: here the way into pass 2 along its own
// 70 deg axis, not rerouted, while the way out of pass 1 (under a shelf) was rerouted; the note
// blamed the rerouted end and dropped the advice of a steeper axis (a diff review's).
TEST(GenerateLinks, AFarLinkIsTheEndWhoseClimbRunsFar) {
  const TempDir dir;
  geometry::TriangleMesh floor, shelf;
  pathgen::test::addBox(floor, -20, 80, -20, 20, -10, 0);
  pathgen::test::addBox(shelf, -50, 25, -50, 10, 14, 25);
  geometry::saveMesh(floor, dir.path() / "floor.stl");
  geometry::saveMesh(shelf, dir.path() / "shelf.stl");
  const double t = 70.0 * M_PI / 180.0;
  std::ostringstream cl;
  cl << "# pass 1\n";
  for (int k = 0; k <= 20; ++k) cl << 0.5 * k << " 0 0 0 0 1\n";
  cl << "# pass 2\n";
  for (int k = 0; k <= 20; ++k)
    cl << "60 " << 10 - 0.5 * k << ' ' << 3 - 3 * std::cos(t) << ' ' << std::sin(t) << " 0 "
       << std::cos(t) << "\n";
  dir.write("p.cl", cl.str());
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: shelf.stl\npart: floor.stl\n"
            "tool: { shape: ball, radius: 3, length: 12 }\nclearance: 0.5\n"
            "path: { nominal: p.cl }\nlinks: { retract: 2 }\n");
  const nlohmann::json report = generateNominal(dir, "scene.yaml", "out");
  bool out_of_1_routed = false;
  for (const auto& end : report["links"]["routed_off_axis"])
    out_of_1_routed |= end["pass"] == 1 && end["end"] == "out of";
  EXPECT_TRUE(out_of_1_routed) << report["links"]["routed_off_axis"];
  ASSERT_EQ(report["link_notes"].size(), 1u) << report["link_notes"];
  const std::string note = report["link_notes"][0];
  EXPECT_NE(note.find("the links climb along the tool axis to the travel plane: posture "),
            std::string::npos)
      << note;
  EXPECT_NE(note.find("(the link into pass 2, "), std::string::npos) << note;
  EXPECT_NE(note.find("a steeper axis at the pass ends"), std::string::npos) << note;

  // One upright pass under a shelf, the way into it moved 12 mm sideways: the link into pass 1
  // has no way out of a pass before it, and its farthest posture (its first) is that way's (it
  // was called a climb along the axis: a diff review's).
  geometry::saveMesh(pathgen::test::boxMesh(-15, 5, -5, 5, -10, 0), dir.path() / "floor1.stl");
  geometry::saveMesh(pathgen::test::boxMesh(-5, 5, -5, 5, 14, 25), dir.path() / "shelf1.stl");
  std::string one = "# pass 1\n";
  for (int k = 0; k <= 20; ++k) one += std::to_string(-0.5 * k) + " 0 0 0 0 1\n";
  dir.write("one.cl", one);
  dir.write("one.yaml",
            "obstacles:\n  - mesh: shelf1.stl\npart: floor1.stl\n"
            "tool: { shape: ball, radius: 3, length: 12 }\nclearance: 0.5\n"
            "path: { nominal: one.cl }\nlinks: { retract: 2 }\n");
  const nlohmann::json one_report = generateNominal(dir, "one.yaml", "one");
  ASSERT_EQ(one_report["link_notes"].size(), 1u) << one_report["link_notes"];
  const std::string into = one_report["link_notes"][0];
  EXPECT_NE(into.find("the links climb to the travel plane (the way into pass 1 (one.cl:2) off "
                      "its axis"),
            std::string::npos)
      << into;
}
