/// `fieldpath simulate` whatever the path's format and block size, and `fieldpath convert`, run as
/// programs: the same postures as `.cl`, APT, `.npy` float64 and float32 give the same heights bit
/// for bit, cut whole or streamed in blocks of any size; `--outputs` writes what it names;
/// simulate.json says where the time went; bad `.npy` and `.cl` files are one line and exit 1
/// with no output directory, also when the bad line comes after blocks already cut.
#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "files.h"

namespace fieldpath::app::test {
namespace {

namespace fs = std::filesystem;
using geometry::PathBlock;
using geometry::PathFile;
using geometry::Posture;
using geometry::Vec3;

/// A value as float32 carries it: the .npy float32 file then holds the same numbers as the others.
double asFloat(double v) { return double(float(v)); }

/// A 5-axis finishing path over a waved surface: rows 0.5 mm apart, axes tilted 15° sideways off
/// +z and turning along the row; three passes. Every number already float-exact.
PathFile wavedPath() {
  PathFile path;
  const double tilt = 15.0 * M_PI / 180.0;
  for (int row = 0; row < 3; ++row) {
    const std::size_t begin = path.postures.size();
    for (int i = 0; i < 400; ++i) {
      const double x = -10.0 + 0.05 * i, y = -4.0 + 0.5 * row;
      const double phi = 0.02 * i + row;
      Posture p;
      p.tip_mm = {asFloat(x), asFloat(y), asFloat(0.5 * std::sin(x / 3.0) * std::cos(y / 2.0))};
      p.axis = {asFloat(std::sin(tilt) * std::cos(phi)), asFloat(std::sin(tilt) * std::sin(phi)),
                asFloat(std::cos(tilt))};
      path.postures.push_back(p);
    }
    path.blocks.push_back({PathBlock::Kind::Pass, begin, path.postures.size()});
  }
  return path;
}

/// A version-1 .npy file: header dictionary `dict`, then `data` (bytes).
std::string npyBytes(const std::string& dict, const std::string& data) {
  std::string header = dict;
  while ((10 + header.size() + 1) % 64 != 0) header += ' ';
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes += char(header.size() & 0xff);
  bytes += char(header.size() >> 8);
  return bytes + header + data;
}

/// The postures as a float32 N×6 array's bytes.
std::string float32Rows(const std::vector<Posture>& postures) {
  std::string data;
  for (const Posture& p : postures) {
    const float row[6] = {float(p.tip_mm.x()), float(p.tip_mm.y()), float(p.tip_mm.z()),
                          float(p.axis.x()),   float(p.axis.y()),   float(p.axis.z())};
    data.append(reinterpret_cast<const char*>(row), sizeof row);
  }
  return data;
}

std::string rowsDict(const char* descr, std::size_t rows, int columns, bool fortran = false) {
  return std::string("{'descr': '") + descr + "', 'fortran_order': " +
         (fortran ? "True" : "False") + ", 'shape': (" + std::to_string(rows) + ", " +
         std::to_string(columns) + "), }";
}

/// The scratch folder with the waved path in every format.
struct Formats {
  TempDir dir;
  PathFile path = wavedPath();
  Formats() {
    geometry::writeClFile(dir.path() / "path.cl", path);
    geometry::AptHeader header;
    header.tool.radius_mm = 1.0;
    geometry::writeAptFile(dir.path() / "path.apt", path, header);
    geometry::writeNpyFile(dir.path() / "path64.npy", path.postures);
    dir.write("path32.npy",
              npyBytes(rowsDict("<f4", path.postures.size(), 6), float32Rows(path.postures)));
    // as a CAM system writes 32-bit values: shortest float text (other doubles than the .npy's)
    std::string text;
    char buffer[32];
    for (const Posture& p : path.postures)
      for (int k = 0; k < 6; ++k) {
        const float v = float(k < 3 ? p.tip_mm[k] : p.axis[k - 3]);
        text.append(buffer, std::to_chars(buffer, buffer + sizeof buffer, v).ptr);
        text += k < 5 ? ' ' : '\n';
      }
    dir.write("path32.cl", text);
  }
  /// Runs simulate on `file` with `extra` options; returns heights.npy's bytes (empty on failure).
  std::string heights(const std::string& file, const std::string& extra) const {
    const std::string out = "out-" + std::to_string(++runs);
    const Outcome run = runFieldpath(dir, "simulate --tool ball:1 --path " + file +
                                              " --grid 160x90 --backend cpu --outputs npy " +
                                              extra + " --out " + out);
    EXPECT_EQ(run.exit_code, 0) << file << " " << extra << ": " << run.err;
    return slurp(dir.path() / out / "heights.npy");
  }
  mutable int runs = 0;
};

TEST(SimulateFormats, HeightsBitIdenticalWhateverTheFormatAndBlock) {
  const Formats f;
  const std::string whole = f.heights("path.cl", "");
  ASSERT_GT(whole.size(), 160u * 90u * 4u);
  for (const char* file : {"path.apt", "path64.npy", "path32.npy", "path32.cl"})
    EXPECT_TRUE(f.heights(file, "") == whole) << file << " read whole";  // no binary dump

  // Streamed (--region): the chunks are cut while the rest is read; any block size.
  const std::string region = "--region -11.2,-5.2,10.2,-1.8 --stock 1";
  const std::string streamed = f.heights("path.cl", region);
  ASSERT_GT(streamed.size(), 160u * 90u * 4u);
  EXPECT_NE(streamed, std::string(streamed.size(), '\0'));
  for (const char* file : {"path.cl", "path.apt", "path64.npy", "path32.npy"})
    for (const char* block : {"13", "100", "5000"})
      EXPECT_TRUE(f.heights(file, region + " --block " + block) == streamed)
          << file << " --block " << block;
}

TEST(SimulateFormats, OutputsAreTheOnesNamedAndSimulateJsonSaysWhereTheTimeWent) {
  const Formats f;
  const Outcome run = runFieldpath(f.dir, "simulate --tool ball:1 --path path.cl --grid 64x64 "
                                          "--backend cpu --outputs png,npy --out out");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  const fs::path out = f.dir.path() / "out";
  EXPECT_TRUE(fs::exists(out / "heights.npy"));
  EXPECT_TRUE(fs::exists(out / "heights.png"));
  EXPECT_TRUE(fs::exists(out / "heights.json"));  // the array's grid comes with it (DESIGN)
  EXPECT_FALSE(fs::exists(out / "surface.stl"));
  const nlohmann::json report = nlohmann::json::parse(slurp(out / "simulate.json"));
  EXPECT_EQ(report.at("postures").get<std::size_t>(), f.path.postures.size());
  const auto& s = report.at("seconds");
  for (const char* phase : {"read", "prepare", "cut", "write", "total"}) {
    ASSERT_TRUE(s.at(phase).is_number()) << phase;
    EXPECT_GE(s.at(phase).get<double>(), 0.0) << phase;
    EXPECT_LE(s.at(phase).get<double>(), s.at("total").get<double>() + 1e-9) << phase;
  }
  EXPECT_GT(report.at("postures_per_second").get<double>(), 0.0);
  EXPECT_GT(report.at("peak_memory_mib").get<double>(), 1.0);
  EXPECT_NE(run.out.find("read"), std::string::npos) << run.out;

  const Outcome bad = runFieldpath(f.dir, "simulate --tool ball:1 --path path.cl --outputs npy,vtk "
                                          "--out out2");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.err.find("'vtk'"), std::string::npos) << bad.err;
  EXPECT_FALSE(fs::exists(f.dir.path() / "out2"));
}

/// An --out (or OUT) that cannot be a directory (a file on its way) is refused before any work.
TEST(SimulateFormats, OutUnderAFileIsOneLineBeforeTheWork) {
  const Formats f;
  f.dir.write("afile", "x");
  for (const std::string args :
       {"simulate --tool ball:1 --path path.cl --out afile/sub", "convert path.cl afile/x.npy"}) {
    const Outcome run = runFieldpath(f.dir, args);
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << args << ": " << run.err;
    EXPECT_NE(run.err.find("afile"), std::string::npos) << run.err;
    EXPECT_EQ(run.err.find("filesystem error"), std::string::npos) << run.err;
  }
}

TEST(SimulateFormats, QuietAfterTheSubCommand) {
  const Formats f;
  const Outcome run = runFieldpathAsTyped(
      f.dir, "simulate --tool ball:1 --path path.cl --grid 32x32 --backend cpu --out out --quiet");
  EXPECT_EQ(run.exit_code, 0) << run.err;
  EXPECT_EQ(run.err, "");
}

/// Every bad .npy: exit 1, one line naming the file (and the row where a row is bad), no outputs.
TEST(SimulateFormats, BadNpyIsOneLineAndNoOutputs) {
  const Formats f;
  const std::vector<Posture>& p = f.path.postures;
  std::string with_nan = float32Rows(p);
  const float nan = std::nanf("");
  std::memcpy(with_nan.data() + (3 * 6 + 2) * 4, &nan, 4);  // row 3, z
  std::string axis_zero = float32Rows(p);
  std::memset(axis_zero.data() + (5 * 6 + 3) * 4, 0, 12);  // row 5, axis 0
  const std::string rows = float32Rows(p);
  struct Case {
    const char* name;
    std::string bytes;
    const char* says;
  };
  const std::vector<Case> cases = {
      {"int.npy", npyBytes(rowsDict("<i4", p.size(), 6), rows), "dtype"},
      {"five.npy", npyBytes(rowsDict("<f4", p.size() * 6 / 5, 5), rows), "shape"},
      {"order.npy",
       npyBytes(
           "{'descr': '<f4', 'fortran_order': 1, 'shape': (" + std::to_string(p.size()) + ", 6), }",
           rows),
       "fortran_order"},
      {"big64.npy", npyBytes(rowsDict(">i8", p.size(), 6), rows), "dtype"},
      {"short.npy", npyBytes(rowsDict("<f4", p.size(), 6), rows.substr(0, rows.size() - 10)),
       "truncated"},
      {"nan.npy", npyBytes(rowsDict("<f4", p.size(), 6), with_nan), "row 3"},
      {"axis.npy", npyBytes(rowsDict("<f4", p.size(), 6), axis_zero), "row 5"},
      {"noheader.npy", "\x93NUMPY", "npy"},
  };
  for (const Case& c : cases) {
    f.dir.write(c.name, c.bytes);
    for (const std::string extra : {"", " --region -11,-5,10,-2 --stock 1 --block 10"}) {
      const Outcome run = runFieldpath(
          f.dir, std::string("simulate --tool ball:1 --path ") + c.name + " --out out" + extra);
      EXPECT_EQ(run.exit_code, 1) << c.name << extra << ": " << run.err;
      EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << c.name << ": " << run.err;
      EXPECT_NE(run.err.find(c.name), std::string::npos) << run.err;
      std::string lower = run.err;
      std::transform(lower.begin(), lower.end(), lower.begin(), ::tolower);
      EXPECT_NE(lower.find(c.says), std::string::npos) << c.name << ": " << run.err;
      EXPECT_FALSE(fs::exists(f.dir.path() / "out")) << c.name << extra;
    }
  }
}

/// A big-endian array and one in Fortran order (a transposed array saved: numpy reads both)
/// give the heights of the same rows in C order, little-endian (both were refused).
TEST(SimulateFormats, BigEndianAndFortranOrderNpyAreRead) {
  const Formats f;
  const std::string whole = f.heights("path32.npy", "");
  const std::string rows = float32Rows(f.path.postures);
  const std::size_t n = f.path.postures.size();
  std::string big = rows, fortran(rows.size(), '\0');
  for (std::size_t i = 0; i < rows.size(); i += 4)
    std::reverse(big.begin() + i, big.begin() + i + 4);
  for (std::size_t r = 0; r < n; ++r)
    for (std::size_t c = 0; c < 6; ++c)
      std::memcpy(fortran.data() + (c * n + r) * 4, rows.data() + (r * 6 + c) * 4, 4);
  f.dir.write("big.npy", npyBytes(rowsDict(">f4", n, 6), big));
  f.dir.write("fortran.npy", npyBytes(rowsDict("<f4", n, 6, true), fortran));
  EXPECT_TRUE(f.heights("big.npy", "") == whole);
  EXPECT_TRUE(f.heights("fortran.npy", "") == whole);
  EXPECT_TRUE(f.heights("fortran.npy", "--region -11.2,-5.2,10.2,-1.8 --stock 1 --block 13") ==
              f.heights("path32.npy", "--region -11.2,-5.2,10.2,-1.8 --stock 1 --block 13"));
  // dtypes as numpy.load takes them (`<f`, `float32`, no byte order) and Python 2's long sizes
  // in a version-1 header (`(243L, 6L)`): the same rows (they were refused).
  const std::string sizes = "(" + std::to_string(n) + "L, 6L)";
  for (const std::string dict :
       {"{'descr': '<f', 'fortran_order': False, 'shape': (" + std::to_string(n) + ", 6), }",
        "{'descr': 'float32', 'fortran_order': False, 'shape': (" + std::to_string(n) + ", 6), }",
        "{'descr': 'f4', 'fortran_order': False, 'shape': " + sizes + ", }"}) {
    f.dir.write("variant.npy", npyBytes(dict, rows));
    EXPECT_TRUE(f.heights("variant.npy", "") == whole) << dict;
  }
}

/// A bad line far into a big `.cl`: the blocks before it were cut already (streamed); still one
/// line with the right line number and no outputs.
TEST(SimulateFormats, BadClLineAfterManyBlocksIsOneLineAndNoOutputs) {
  const TempDir dir;
  std::string text;
  for (int i = 1; i <= 6000; ++i)
    text += i == 4321 ? "1 2 three 0 0 1\n"
                      : std::to_string(0.001 * i) + " 0.5 0 0 0 1\n";
  dir.write("big.cl", text);
  for (const std::string extra : {"", " --region -1,-1,7,2 --stock 1 --block 50"}) {
    const Outcome run =
        runFieldpath(dir, "simulate --tool ball:1 --path big.cl --backend cpu --out out" + extra);
    EXPECT_EQ(run.exit_code, 1) << extra << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_NE(run.err.find("big.cl:4321"), std::string::npos) << run.err;
    EXPECT_FALSE(fs::exists(dir.path() / "out")) << extra;
  }
  // 3.5 M postures of 32 bytes and the file mapped (its lines' length and its 40 MiB; the rest
  // sparse) against a 100 MiB limit that the program (~42 MiB) leaves less of: refused before
  // reading, naming the file and the estimate
  std::string many;
  for (int i = 0; i < 60000; ++i) many += "1 2 3 0 0 1\n";
  fs::resize_file(dir.write("many.cl", many), 40 << 20);
  const Outcome big =
      runFieldpath(dir, "--max-memory 100M simulate --tool ball:1 --path many.cl --out out");
  EXPECT_EQ(big.exit_code, 1) << big.err;
  EXPECT_NE(big.err.find("--path many.cl: needs about 147 MiB"), std::string::npos) << big.err;
  EXPECT_FALSE(fs::exists(dir.path() / "out"));
}

// An empty value is refused, not read as the option left out (`--part ""` took the default
// stock, `--region ""` the default region: a helper's); so is an option where a name goes.
TEST(EmptyValues, AreRefusedWithTheOptionNamed) {
  const TempDir dir;
  dir.write("p.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  const std::pair<std::string, std::string> cases[] = {
      {"simulate --tool ball:1 --path p.cl --part '' --out s", "--part: an empty value"},
      {"simulate --tool ball:1 --path p.cl --region= --out s", "--region: an empty value"},
      {"simulate --tool ball:1 --path p.cl --out ''", "--out: an empty value"},
      {"check '' --path p.cl", "an empty argument after 'check'"},
      // an option where a name goes: it made a folder named `--quiet`
      {"simulate --tool ball:1 --path p.cl --out --quiet", "--out: '--quiet' is an option"}};
  for (const auto& [args, message] : cases) {
    const Outcome run = runFieldpath(dir, args);
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_NE(run.err.find(message), std::string::npos) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << run.err;
    EXPECT_FALSE(fs::exists(dir.path() / "s")) << args;
  }
}

// Inputs read whole are sized before they are read (a helper's sparse files: a 3 GB scene took
// 4.2 GB of memory, a 10 GB path.nominal was mapped and 16 GiB reserved before its first line
// was refused, a 3 GB points file ran to 12.6 GB under --max-memory 256M): one line, at once; a
// text path file of NUL bytes is no path file.
TEST(InputSizes, FilesReadWholeAreSizedBeforeTheRead) {
  const TempDir dir;
  dir.write("wall.stl", squareStl(10));
  dir.write("s.yaml",
            "obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 1, length: 20 }\n"
            "path: { nominal: huge.cl }\n");
  const auto sparse = [&](const char* name, std::uintmax_t bytes) {
    std::ofstream(dir.path() / name).put('\n');
    fs::resize_file(dir.path() / name, bytes);
  };
  sparse("huge.cl", std::uintmax_t{4} << 30);
  sparse("huge.yaml", std::uintmax_t{1} << 30);
  sparse("points.txt", std::uintmax_t{1} << 30);
  struct Case {
    std::string args, message;
  };
  std::string many;  // 3.5 M postures by its lines' length and its 40 MiB (the rest sparse)
  for (int i = 0; i < 60000; ++i) many += "1 2 3 0 0 1\n";
  fs::resize_file(dir.write("many.cl", many), 40 << 20);
  // 60000 postures a generate steers one for one: ~3.5 KB each (a 1 M posture path ran past an
  // accepted --max-memory 78M to 0.8 GB: a memory sweep's), refused before the work.
  std::string steered;
  for (int i = 0; i < 60000; ++i) steered += std::to_string(0.01 * i) + " 2 3 0 0 1\n";
  dir.write("steered.cl", steered);
  dir.write("steered.yaml",
            "obstacles:\n  - mesh: wall.stl\ntool: { shape: ball, radius: 1, length: 20 }\n"
            "path: { nominal: steered.cl }\n");
  const Case cases[] = {
      {"--max-memory 100M generate steered.yaml --out g",
       "steered.yaml: path.nominal: needs about 205 MiB of memory (6e+04 postures: the nominal "
       "path's, one for one)"},
      {"generate s.yaml --out g", "s.yaml:4: path.nominal: huge.cl: NUL bytes near its start"},
      {"check s.yaml --path huge.cl", "huge.cl: NUL bytes near its start"},
      {"convert huge.cl h.npy", "huge.cl: NUL bytes near its start"},
      {"--max-memory 100M check s.yaml --path many.cl", "--path many.cl: needs about 853 MiB"},
      {"--max-memory 100M convert many.cl h.npy", "many.cl: needs about 853 MiB"},
      {"generate huge.yaml --out g", "huge.yaml: 1 GiB: not a scene file"},
      {"--max-memory 1G field probe s.yaml --points points.txt", "--points points.txt: needs"}};
  for (const Case& c : cases) {
    const auto start = std::chrono::steady_clock::now();
    const Outcome run = runFieldpath(dir, c.args);
    EXPECT_EQ(run.exit_code, 1) << c.args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << c.args << ": " << run.err;
    EXPECT_NE(run.err.find(c.message), std::string::npos) << c.args << ": " << run.err;
    // (seconds, where reading the sparse files took 15-48 s: a loaded CI machine is slow too)
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(10)) << c.args;
    EXPECT_FALSE(fs::exists(dir.path() / "g")) << c.args;
    EXPECT_FALSE(fs::exists(dir.path() / "h.npy")) << c.args;
  }
}

/// convert: .cl (passes, a link, a limit mark) → .npy → APT → .cl gives the same postures bit for
/// bit; what .npy cannot keep is said; bad requests are one line and write nothing.
TEST(Convert, RoundTripsKeepThePosturesBitForBit) {
  const Formats f;
  PathFile marked = f.path;
  marked.blocks[1].kind = PathBlock::Kind::Link;
  marked.limited = {17};
  geometry::writeClFile(f.dir.path() / "marked.cl", marked);

  const Outcome to_npy = runFieldpath(f.dir, "convert marked.cl a.npy");
  ASSERT_EQ(to_npy.exit_code, 0) << to_npy.err;
  EXPECT_NE(to_npy.err.find("dropped"), std::string::npos) << to_npy.err;
  EXPECT_NE(to_npy.out.find("1200 postures"), std::string::npos) << to_npy.out;
  ASSERT_EQ(runFieldpath(f.dir, "convert a.npy b.apt --tool ball:1 --feed 1000").exit_code, 0);
  ASSERT_EQ(runFieldpath(f.dir, "convert b.apt c.cl").exit_code, 0);
  ASSERT_EQ(runFieldpath(f.dir, "convert marked.cl d.cls --tool torus:2:0.5 --feed 1000").exit_code,
            0);
  // Output names in capitals, as the readers take them (they were refused).
  ASSERT_EQ(runFieldpath(f.dir, "convert marked.cl E.CL").exit_code, 0);
  ASSERT_EQ(runFieldpath(f.dir, "convert marked.cl F.NPY").exit_code, 0);

  // The reference is the .cl as read (the readers normalise the float-rounded axes).
  marked = geometry::readPathFile(f.dir.path() / "marked.cl");
  for (const char* file : {"a.npy", "b.apt", "c.cl", "d.cls", "E.CL", "F.NPY"}) {
    const PathFile back = geometry::readPathFile(f.dir.path() / file);
    ASSERT_EQ(back.postures.size(), marked.postures.size()) << file;
    for (std::size_t i = 0; i < back.postures.size(); ++i) {
      ASSERT_EQ(back.postures[i].tip_mm, marked.postures[i].tip_mm) << file << " " << i;
      ASSERT_EQ(back.postures[i].axis, marked.postures[i].axis) << file << " " << i;
    }
  }
  // APT keeps the link (RAPID) and .cl the blocks and the limit marks (a test audit: convert
  // writing one pass to .cl, links read back as cutting moves, passed); the limit mark APT
  // cannot hold is said.
  EXPECT_EQ(geometry::readPathFile(f.dir.path() / "d.cls").blocks, marked.blocks);
  ASSERT_EQ(marked.limited, std::vector<std::size_t>{17});
  const PathFile e = geometry::readPathFile(f.dir.path() / "E.CL");
  EXPECT_EQ(e.blocks, marked.blocks);
  EXPECT_EQ(e.limited, marked.limited);
  // An APT link comes back a link block in .cl.
  ASSERT_EQ(runFieldpath(f.dir, "convert d.cls h.cl").exit_code, 0);
  EXPECT_EQ(geometry::readPathFile(f.dir.path() / "h.cl").blocks, marked.blocks);
  const Outcome to_apt = runFieldpath(f.dir, "convert marked.cl g.apt --tool ball:1 --feed 1000");
  ASSERT_EQ(to_apt.exit_code, 0) << to_apt.err;
  EXPECT_NE(to_apt.err.find("note: APT has no `# limit` marks: 1 dropped"), std::string::npos)
      << to_apt.err;
  EXPECT_EQ(to_apt.err.find("no link between"), std::string::npos) << to_apt.err;

  for (const std::string args :
       {"convert marked.cl e.txt", "convert marked.cl e.apt", "convert missing.cl e.cl",
        "convert marked.cl e.apt --tool cone"}) {
    const Outcome run = runFieldpath(f.dir, args);
    EXPECT_EQ(run.exit_code, 1) << args << ": " << run.err;
    EXPECT_EQ(std::count(run.err.begin(), run.err.end(), '\n'), 1) << args << ": " << run.err;
    for (const char* name : {"e.txt", "e.apt", "e.cl"})
      EXPECT_FALSE(fs::exists(f.dir.path() / name)) << args;
  }
}

// Passes with no link between them (a .cl of three `# pass` blocks) are one pass in APT, which
// breaks a pass only with RAPID: said, not silent (a helper found it silent).
TEST(Convert, PassesWithNoLinkBetweenThemAreSaidToJoinInApt) {
  const Formats f;
  const Outcome run = runFieldpath(f.dir, "convert path.cl joined.apt --tool ball:1 --feed 1000");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("note: 2 pass breaks with no link between the passes (first: passes 1 "
                         "and 2): APT breaks a pass only with RAPID"),
            std::string::npos)
      << run.err;
  const PathFile back = geometry::readPathFile(f.dir.path() / "joined.apt");
  EXPECT_EQ(back.count(PathBlock::Kind::Pass), 1u);  // what the note says
  EXPECT_EQ(back.postures.size(), f.path.postures.size());
  // To .cl the blocks stay: no note.
  const Outcome to_cl = runFieldpath(f.dir, "convert path.cl same.cl");
  ASSERT_EQ(to_cl.exit_code, 0) << to_cl.err;
  EXPECT_EQ(to_cl.err.find("note:"), std::string::npos) << to_cl.err;
}

// The 7th column (spindle angle, rad) through .npy (N×7) and back, bit for bit; a hand-written
// float32 N×7 array read as spindle angles (a test audit: no test wrote or read the 7th column
// of an .npy: dropping it would have been silent, a mesh tool simulated unturned).
TEST(Convert, TheSpindleColumnGoesThroughNpy) {
  const TempDir dir;
  dir.write("s.cl", "0 0 0 0 0 1 0.5\n1 0 0 0 0 1 -0.25\n2 0 0 0 0 1 3.125\n");
  ASSERT_EQ(runFieldpath(dir, "convert s.cl s.npy").exit_code, 0);
  const PathFile npy = geometry::readPathFile(dir.path() / "s.npy");
  ASSERT_EQ(npy.postures.size(), 3u);
  const double spindle[] = {0.5, -0.25, 3.125};
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_TRUE(npy.postures[i].has_spindle) << i;
    EXPECT_EQ(npy.postures[i].spindle_rad, spindle[i]) << i;
  }
  ASSERT_EQ(runFieldpath(dir, "convert s.npy back.cl").exit_code, 0);
  const PathFile back = geometry::readPathFile(dir.path() / "back.cl");
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(back.postures[i].spindle_rad, spindle[i]) << i;
  // float32, shape (2, 7), written by hand as numpy writes it (version 1.0, header to 128 bytes).
  std::string header = "{'descr': '<f4', 'fortran_order': False, 'shape': (2, 7), }";
  header.append(128 - 10 - header.size() - 1, ' ');
  header += '\n';
  std::string bytes = std::string("\x93NUMPY\x01\x00", 8);
  bytes += char(header.size() & 0xff);
  bytes += char(header.size() >> 8);
  bytes += header;
  const float rows[2][7] = {{1, 2, 3, 0, 0, 1, 0.75f}, {4, 5, 6, 0, 1, 0, -1.5f}};
  bytes.append(reinterpret_cast<const char*>(rows), sizeof rows);
  dir.write("hand.npy", bytes);
  const PathFile hand = geometry::readPathFile(dir.path() / "hand.npy");
  ASSERT_EQ(hand.postures.size(), 2u);
  EXPECT_EQ(hand.postures[1].tip_mm, Vec3(4, 5, 6));
  EXPECT_EQ(hand.postures[1].axis, Vec3(0, 1, 0));
  EXPECT_TRUE(hand.postures[0].has_spindle);
  EXPECT_EQ(hand.postures[0].spindle_rad, 0.75);
  EXPECT_EQ(hand.postures[1].spindle_rad, -1.5);
}

TEST(Convert, ASpindleColumnDroppedInAptIsSaid) {
  // GOTO has six values: the 7th column of a .cl goes, and the note counts it; none, no note.
  const TempDir dir;
  dir.write("s.cl", "0 0 0 0 0 1 0.5\n1 0 0 0 0 1 0.25\n2 0 0 0 0 1\n");
  const Outcome run = runFieldpath(dir, "convert s.cl s.apt --tool ball:1 --feed 1000");
  ASSERT_EQ(run.exit_code, 0) << run.err;
  EXPECT_NE(run.err.find("note: APT's GOTO has no spindle angle: the 7th column of 2 postures "
                         "dropped"),
            std::string::npos)
      << run.err;
  dir.write("n.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  const Outcome none = runFieldpath(dir, "convert n.cl n.apt --tool ball:1 --feed 1000");
  ASSERT_EQ(none.exit_code, 0) << none.err;
  EXPECT_EQ(none.err.find("spindle"), std::string::npos) << none.err;
}

// A path marked unsafe by generate (`# UNSAFE TO RUN: ...`, `PPRINT/UNSAFE TO RUN: ...`, and
// `UNDER THE REQUIRED CLEARANCE`) keeps its marks through convert to .cl and APT and back, each
// said on stderr; .npy cannot hold them: said as DROPPED (they were dropped without a word: a
// colliding path read as a clean program, a helper's finding).
TEST(Convert, SafetyMarksGoWithThePathOrTheirLossIsSaid) {
  const TempDir dir;
  dir.write("u.cl",
            "# UNSAFE TO RUN: 2 postures touch an obstacle (first: posture 1) (report.json)\n"
            "# under the required clearance: postures min 0.3 mm\n"
            "# fieldpath generate scene.yaml\n# pass 1\n0 0 0 0 0 1\n1 0 0 0 0 1\n2 0 0 0 0 1\n");
  const std::vector<std::string> marks = {
      "UNSAFE TO RUN: 2 postures touch an obstacle (first: posture 1) (report.json)",
      "under the required clearance: postures min 0.3 mm"};
  EXPECT_EQ(geometry::readPathFile(dir.path() / "u.cl").warnings, marks);
  const Outcome to_apt = runFieldpath(dir, "convert u.cl u.apt --tool ball:1 --feed 1000");
  ASSERT_EQ(to_apt.exit_code, 0) << to_apt.err;
  EXPECT_NE(to_apt.err.find("warning: u.cl is marked \"UNSAFE TO RUN"), std::string::npos)
      << to_apt.err;
  const std::string apt = slurp(dir.path() / "u.apt");
  EXPECT_NE(apt.find("PPRINT/UNSAFE TO RUN: 2 POSTURES TOUCH"), std::string::npos) << apt;
  EXPECT_NE(apt.find("PPRINT/UNDER THE REQUIRED CLEARANCE"), std::string::npos) << apt;
  // ... and the machine halts before the first motion (a PPRINT is only read).
  ASSERT_NE(apt.find("\nSTOP\n"), std::string::npos) << apt;
  EXPECT_LT(apt.find("\nSTOP\n"), apt.find("GOTO/")) << apt;
  EXPECT_EQ(geometry::readPathFile(dir.path() / "u.apt").warnings.size(), 2u);
  ASSERT_EQ(runFieldpath(dir, "convert u.apt back.cl").exit_code, 0);
  const PathFile back = geometry::readPathFile(dir.path() / "back.cl");
  ASSERT_EQ(back.warnings.size(), 2u);
  EXPECT_EQ(back.warnings[0].rfind("UNSAFE TO RUN: 2 POSTURES", 0), 0u) << back.warnings[0];
  EXPECT_EQ(back.postures.size(), 3u);
  const Outcome to_npy = runFieldpath(dir, "convert u.cl u.npy");
  ASSERT_EQ(to_npy.exit_code, 0) << to_npy.err;
  EXPECT_NE(to_npy.err.find("DROPPED"), std::string::npos) << to_npy.err;
  // An unmarked path: no warning; a comment that only mentions the words is not a mark.
  dir.write("c.cl", "# the tool is not UNSAFE TO RUN here\n0 0 0 0 0 1\n1 0 0 0 0 1\n");
  EXPECT_TRUE(geometry::readPathFile(dir.path() / "c.cl").warnings.empty());
  const Outcome clean = runFieldpath(dir, "convert c.cl c.apt --tool ball:1 --feed 1000");
  EXPECT_EQ(clean.err.find("warning"), std::string::npos) << clean.err;
}

}  // namespace
}  // namespace fieldpath::app::test
