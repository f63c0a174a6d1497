/// `fieldpath field probe|build`, run as a program: output against the closed form of a plane, and
/// bad input → exit 1 with one line on stderr and nothing on stdout.
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <Eigen/Geometry>

#include "fieldpath/field/law.h"
#include "files.h"

using fieldpath::app::test::Outcome;
using fieldpath::app::test::runFieldpath;
using fieldpath::app::test::slurp;
using fieldpath::app::test::TempDir;

namespace {

std::size_t lines(const std::string& text) {
  std::size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

/// A plane obstacle (z = 0, 16 × 16 mm: infinite for r0 = 5 at its middle) and its scene.
void planeScene(const TempDir& dir, const std::string& field_keys = "") {
  dir.write("plane.stl", fieldpath::app::test::squareStl(8));
  dir.write("scene.yaml",
            "obstacles:\n  - mesh: plane.stl\nfield:\n  sample_step: 0.5\n" + field_keys);
}

}  // namespace

TEST(CliField, ProbeMatchesThePlaneClosedForm) {
  TempDir dir;
  planeScene(dir);
  // (a UTF-8 byte-order mark at its start is read past, as in the other text inputs)
  dir.write("points.txt", "\xEF\xBB\xBF# x y z\n0 0 1\n0.5 -0.5 2.5   # a comment\n\n0 0 3.75\n");
  fieldpath::field::FieldParams p;
  for (const std::string mode : {"--direct", "--voxel 0.25", ""}) {  // "": the scene's h = 0.5
    const Outcome run = runFieldpath(dir, "field probe scene.yaml --points points.txt " + mode);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    std::istringstream out(run.out);
    std::string line;
    std::vector<double> z, fz;
    while (std::getline(out, line)) {
      if (line.empty() || line[0] == '#') continue;
      std::istringstream fields(line);
      double x, y, zz, fx, fy, f;
      ASSERT_TRUE(fields >> x >> y >> zz >> fx >> fy >> f) << line;
      z.push_back(zz);
      fz.push_back(f);
    }
    ASSERT_EQ(z.size(), 3u) << run.out;
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double exact = fieldpath::field::planeFieldMagnitude(z[i], p);
      // 2 %: the sampling's quadrature; 10 % off the nodes for the voxels (0.25, 0.5 mm)
      const bool off_node = mode != "--direct" && z[i] == 3.75;
      EXPECT_NEAR(fz[i], exact, (off_node ? 0.1 : 0.02) * exact) << mode << " z " << z[i];
    }
  }
}

// Every column is its own component: a plane through the origin with normal n = (1, 2, 2) / 3
// (16 × 16 mm, infinite for r0 at its middle) gives P(d) n at a point d along n, Fx : Fy : Fz =
// 1 : 2 : 2 (the plane z = 0 gave Fx = Fy = 0: a column printed twice passed). The header says
// the voxel size and interpolation probed, and --save-field writes the VDB. (A test audit.)
TEST(CliField, ProbeWritesEachComponentAndSaysWhatItProbed) {
  TempDir dir;
  const Eigen::Vector3d n = Eigen::Vector3d(1, 2, 2) / 3.0;
  const Eigen::Vector3d u = n.unitOrthogonal(), v = n.cross(u);
  std::ostringstream stl;
  stl << "solid tilted\n";
  const Eigen::Vector3d c[4] = {-8 * u - 8 * v, 8 * u - 8 * v, 8 * u + 8 * v, -8 * u + 8 * v};
  for (const auto& tri : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
    stl << "facet normal " << n.x() << ' ' << n.y() << ' ' << n.z() << "\nouter loop\n";
    for (int k : tri) stl << "vertex " << c[k].x() << ' ' << c[k].y() << ' ' << c[k].z() << '\n';
    stl << "endloop\nendfacet\n";
  }
  stl << "endsolid tilted\n";
  dir.write("tilted.stl", stl.str());
  dir.write("scene.yaml", "obstacles:\n  - mesh: tilted.stl\nfield:\n  sample_step: 0.5\n");
  const Eigen::Vector3d at = 1.5 * n;
  std::ostringstream point;
  point << at.x() << ' ' << at.y() << ' ' << at.z() << '\n';
  dir.write("point.txt", point.str());
  const double exact = fieldpath::field::planeFieldMagnitude(1.5, fieldpath::field::FieldParams{});
  for (const std::string mode :
       {"--direct", "--voxel 0.25 --interpolation quadratic --save-field f.vdb"}) {
    const Outcome run = runFieldpath(dir, "field probe scene.yaml --points point.txt " + mode);
    ASSERT_EQ(run.exit_code, 0) << run.err;
    std::istringstream out(run.out);
    std::string header, line;
    std::getline(out, header);
    std::getline(out, line);
    std::istringstream fields(line);
    double x, y, z, f[3];
    ASSERT_TRUE(fields >> x >> y >> z >> f[0] >> f[1] >> f[2]) << line;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], exact * n[k], 0.03 * exact) << mode << " " << k;
    if (mode == "--direct") {
      EXPECT_EQ(header, "# x y z Fx Fy Fz (mm; direct field)");
    } else {
      EXPECT_EQ(header, "# x y z Fx Fy Fz (mm; voxel field, h 0.25 mm, quadratic)");
      EXPECT_EQ(slurp(dir.path() / "f.vdb").substr(0, 4), std::string(" BDV"));
    }
  }
}

TEST(CliField, BuildWritesTheVdbAndReportsNodes) {
  TempDir dir;
  planeScene(dir);
  const Outcome run = runFieldpath(dir, "field build scene.yaml --voxel 1 --out out/field.vdb");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.out.find("active nodes: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("dense-box nodes: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("memory: "), std::string::npos) << run.out;
  EXPECT_NE(run.out.find("build "), std::string::npos) << run.out;
  EXPECT_GT(std::filesystem::file_size(dir.path() / "out/field.vdb"), 1000u);

  // As the global option, with a unit or without (MiB): `512M` after the command was refused.
  for (const char* limit : {"64", "64M"}) {
    const Outcome refused =
        runFieldpath(dir, std::string("field build scene.yaml --voxel 0.01 --max-memory ") + limit +
                              " --out big.vdb");
    EXPECT_EQ(refused.exit_code, 1);
    EXPECT_NE(refused.err.find("candidate leaves hold"), std::string::npos) << refused.err;
    EXPECT_EQ(lines(refused.err), 1u) << refused.err;
    EXPECT_FALSE(std::filesystem::exists(dir.path() / "big.vdb"));
  }
}

// A refined build's share of the dense box is level 0's (the box is of h): all levels' nodes
// over it read "1532.86 % of the dense box" (a claims audit's). Level 0 is the uniform grid of h:
// its nodes and share are the uniform build's, run apart.
TEST(CliField, ARefinedBuildsShareOfTheDenseBoxIsItsFirstLevels) {
  TempDir dir;
  const std::string scene =
      (std::filesystem::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml").string();
  struct Share {
    std::size_t all = 0, first = 0;
    double percent = 0.0;
  };
  auto build = [&](const std::string& tolerance) {
    const Outcome run =
        runFieldpath(dir, "field build " + scene + " --voxel 1 --refine-tolerance " + tolerance +
                              " --out field.vdb");
    EXPECT_EQ(run.exit_code, 0) << run.err;
    Share share;
    const std::size_t at = run.out.find("active nodes: ");
    EXPECT_NE(at, std::string::npos) << run.out;
    if (at == std::string::npos) return share;
    if (std::sscanf(run.out.c_str() + at, "active nodes: %zu (level 0 %zu: %lf %%", &share.all,
                    &share.first, &share.percent) != 3) {
      EXPECT_EQ(std::sscanf(run.out.c_str() + at, "active nodes: %zu (%lf %%", &share.all,
                            &share.percent),
                2)
          << run.out;
      share.first = share.all;
    }
    return share;
  };
  const Share refined = build("0.02"), uniform = build("0");
  EXPECT_GT(refined.all, refined.first);  // refined
  EXPECT_EQ(refined.first, uniform.all);
  EXPECT_EQ(refined.percent, uniform.percent);
  EXPECT_LE(refined.percent, 100.0);
}

TEST(CliField, BadInputExitsOneWithOneLine) {
  struct Case {
    std::string scene, points, key;
  };
  const std::string wall = "obstacles:\n  - mesh: plane.stl\n";
  const std::vector<Case> cases{
      {"obstacles:\n  - mesh: nowhere.stl\n", "0 0 1\n", "nowhere.stl"},
      {wall + "field:\n  r0: -2\n", "0 0 1\n", "field.r0"},
      {wall + "field:\n  r0: 2\n  r_min: 3\n", "0 0 1\n", "field.r_min"},
      {wall + "field:\n  voxel_size: 0\n", "0 0 1\n", "field.voxel_size"},
      {wall + "field:\n  r0: 2\nfeild: {}\n", "0 0 1\n", "feild"},
      {wall + "field:\n  r0: [2]\n", "0 0 1\n", "field.r0"},
      {wall, "0 0 1\n1 2\n", "points.txt:2"},
      {wall, "0 0 1\n1 2 nan\n", "points.txt:2"},
      {wall, "0 0 1\n1 2 -2e6\n", "points.txt:2: '-2e6' is beyond +-1e6 mm"},
  };
  for (const Case& c : cases) {
    TempDir dir;
    dir.write("plane.stl", fieldpath::app::test::squareStl(20));
    dir.write("scene.yaml", c.scene);
    dir.write("points.txt", c.points);
    const Outcome run = runFieldpath(dir, "field probe scene.yaml --points points.txt");
    EXPECT_EQ(run.exit_code, 1) << c.scene << run.err;
    EXPECT_EQ(lines(run.err), 1u) << run.err;
    EXPECT_NE(run.err.find(c.key), std::string::npos) << run.err;
    EXPECT_TRUE(run.out.empty()) << run.out;
  }
}

// The field commands need the obstacles and the field's keys only (DESIGN): a scene's part and
// nominal path are not read (field build was refused naming a part's mesh it never uses, a
// memory sweep's), whether they are there, broken or missing.
TEST(CliField, TheFieldCommandsReadNeitherThePartNorTheNominalPath) {
  TempDir dir;
  planeScene(dir);
  dir.write("broken.stl", "solid nothing\nfacet normal 0 0 1\n");
  dir.write("scene.yaml", slurp(dir.path() / "scene.yaml") +
                              "part: broken.stl\ntool: { shape: ball, radius: 1, length: 10 }\n"
                              "path: { nominal: missing.cl }\n");
  const Outcome build = runFieldpath(dir, "field build scene.yaml --voxel 1 --out f.vdb");
  EXPECT_EQ(build.exit_code, 0) << build.err;
  dir.write("points.txt", "0 0 1\n");
  const Outcome probe = runFieldpath(dir, "field probe scene.yaml --points points.txt --direct");
  EXPECT_EQ(probe.exit_code, 0) << probe.err;
  // generate reads both: the part refused by its key.
  const Outcome generate = runFieldpath(dir, "generate scene.yaml --out g");
  EXPECT_EQ(generate.exit_code, 1);
  EXPECT_NE(generate.err.find("part"), std::string::npos) << generate.err;
}

TEST(CliField, BuildRefusesAnOutputNotNamedVdb) {
  TempDir dir;
  planeScene(dir);
  // The file would be OpenVDB's binary whatever its name: a typo is refused before the work.
  const Outcome run = runFieldpath(dir, "field build scene.yaml --voxel 1 --out field.txt");
  EXPECT_EQ(run.exit_code, 1) << run.err;
  EXPECT_EQ(lines(run.err), 1u) << run.err;
  EXPECT_NE(run.err.find("field.txt"), std::string::npos) << run.err;
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "field.txt"));
  EXPECT_EQ(runFieldpath(dir, "field build scene.yaml --voxel 1 --out FIELD.VDB").exit_code, 0);
}

TEST(CliField, AnUnknownCommandIsNamed) {
  TempDir dir;
  // CLI11 alone says "a subcommand is required", which hides the typo.
  const std::pair<std::string, std::string> cases[] = {
      {"fields build x.yaml", "'fields'"},
      {"--max-memory 1G genrate x.yaml", "'genrate'"},
      {"--quiet field prob x.yaml --points p.txt", "'prob' (fieldpath field takes: probe, build"}};
  // and a command left out is asked for, with the list.
  const Outcome bare = runFieldpath(dir, "--quiet field");
  EXPECT_EQ(bare.exit_code, 1);
  EXPECT_NE(bare.err.find("fieldpath field needs a command: probe, build"), std::string::npos)
      << bare.err;
  for (const auto& [args, said] : cases) {
    const Outcome run = runFieldpath(dir, args);
    EXPECT_EQ(run.exit_code, 1) << args;
    EXPECT_EQ(lines(run.err), 1u) << run.err;
    EXPECT_NE(run.err.find("unknown command " + said), std::string::npos) << run.err;
  }
  // A scene named with a leading '-' reads as an option: said, with the way round it ("scene is
  // required" alone, a review's).
  planeScene(dir);
  std::filesystem::copy_file(dir.path() / "scene.yaml", dir.path() / "-scene.yaml");
  const Outcome dashed = runFieldpath(dir, "field build -scene.yaml --voxel 1 --out f.vdb");
  EXPECT_EQ(dashed.exit_code, 1);
  EXPECT_EQ(lines(dashed.err), 1u) << dashed.err;
  EXPECT_NE(dashed.err.find("'-scene.yaml' reads as an option: name it ./-scene.yaml"),
            std::string::npos)
      << dashed.err;
  EXPECT_EQ(runFieldpath(dir, "field build ./-scene.yaml --voxel 1 --out f.vdb").exit_code, 0);
  // Not for an option's value, read as one, beside another mistake (a review's: `--path -in.cl`
  // and a bad --spacing were told to rename the path).
  const Outcome other = runFieldpath(dir, "field build scene.yaml --out -scene.yaml --voxel 0");
  EXPECT_EQ(other.exit_code, 1);
  EXPECT_EQ(other.err.find("reads as an option"), std::string::npos) << other.err;
  // Nor where a required option is missing (`./` would not help: --points is required); said
  // after a flag, which takes no value (--quiet read as waiting for one hid the hint).
  const Outcome option = runFieldpath(dir, "field probe scene.yaml -scene.yaml");
  EXPECT_EQ(option.exit_code, 1);
  EXPECT_EQ(option.err.find("reads as an option"), std::string::npos) << option.err;
  const Outcome after_flag =
      runFieldpath(dir, "field build --quiet -scene.yaml --voxel 1 --out f.vdb");
  EXPECT_NE(after_flag.err.find("'-scene.yaml' reads as an option"), std::string::npos)
      << after_flag.err;
}
