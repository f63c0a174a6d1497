/// Reliability of the outputs (issue 14): the same inputs give the same files, bit for bit,
/// whatever the number of threads (generate, simulate, check, tool, field build and probe, view,
/// study, convert; the run's own timings aside).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "files.h"
#include "reliability_runs.h"

namespace fieldpath {
namespace {

namespace fs = std::filesystem;
using namespace test::reliability;

// ---- determinism ------------------------------------------------------------------------------

/// Removes `key` from every object in `j`, however deep.
void eraseEverywhere(nlohmann::json& j, const std::string& key) {
  if (j.is_object()) j.erase(key);
  if (j.is_structured())
    for (auto& child : j) eraseEverywhere(child, key);
}

/// The files of two output folders are the same, byte for byte (`except`: keys of JSON files
/// that are measurements of the run, removed before comparing).
void expectSameFiles(const fs::path& a, const fs::path& b,
                     const std::vector<std::string>& except = {}) {
  const auto names = filesUnder(a);
  ASSERT_FALSE(names.empty());
  ASSERT_EQ(names, filesUnder(b));
  for (const auto& name : names) {
    std::string x = slurp(a / name), y = slurp(b / name);
    if (!except.empty() && fs::path(name).extension() == ".json") {
      auto jx = nlohmann::json::parse(x), jy = nlohmann::json::parse(y);
      for (const auto& key : except) {
        eraseEverywhere(jx, key);
        eraseEverywhere(jy, key);
      }
      x = jx.dump();
      y = jy.dump();
    }
    EXPECT_TRUE(x == y) << name << " differs between runs";
  }
}

TEST(Deterministic, GenerateOnOneAndOnAllCores) {
  const TempDir dir;
  ASSERT_EQ(run(dir, {"generate", kImpeller.string(), "--out", "one"}, "0"), 0);
  ASSERT_EQ(run(dir, {"generate", kImpeller.string(), "--out", "all"}), 0);
  // report.json's times_s are the run's own timings: everything else must match.
  expectSameFiles(dir.path() / "one", dir.path() / "all", {"times_s"});
}

/// The most threads of `pid` seen at once with CPU time of their own (/proc/PID/task/*/stat,
/// polled every 20 ms until it exits; libraries' idle threads never count), and its exit code.
std::pair<int, int> busyThreads(pid_t pid) {
  int most = 0, status = 0;
  while (waitpid(pid, &status, WNOHANG) == 0) {
    int busy = 0;
    std::error_code ec;
    for (const auto& task : fs::directory_iterator("/proc/" + std::to_string(pid) + "/task", ec)) {
      std::istringstream stat(slurp(task.path() / "stat"));
      std::string field;  // pid (comm) state ... utime (14th) stime (15th); comm has no spaces
      long ticks = 0;
      for (int k = 1; k <= 15 && stat >> field; ++k)
        if (k >= 14) ticks += std::atol(field.c_str());
      busy += ticks > 0;
    }
    most = std::max(most, busy);
    usleep(20000);
  }
  return {most, WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status)};
}

// `--threads N` caps the threads that work (TBB: the steering, the checks, the field; OpenMP: the
// Z-buffer): on one, no second thread of the run ever has CPU time (uncapped, TBB's workers steer
// passes and check postures beside the main thread), and its files are those of a run on every
// core. On the CPU backends: where a GPU is present, CUDA's start-up thread and the driver's own
// would have time of their own (not the program's work, and not capped).
TEST(Deterministic, OneThreadByTheOptionGivesTheSameFiles) {
  const TempDir dir;
  const auto [generating, generated] = busyThreads(start(
      dir, {"--threads", "1", "generate", kImpeller.string(), "--backend", "cpu", "--out", "one"}));
  ASSERT_EQ(generated, 0);
  EXPECT_EQ(generating, 1) << "generate --threads 1 ran on more threads";
  const auto [checking, checked] =
      busyThreads(start(dir, {"--threads", "1", "check", kImpeller.string(), "--path",
                              "one/path.cl", "--out", "one.check"}));
  ASSERT_EQ(checked, 0);
  EXPECT_EQ(checking, 1) << "check --threads 1 ran on more threads";
  ASSERT_EQ(run(dir, {"generate", kImpeller.string(), "--backend", "cpu", "--out", "all"}), 0);
  ASSERT_EQ(run(dir, {"check", kImpeller.string(), "--path", "all/path.cl", "--backend", "cpu",
                      "--out", "all.check"}),
            0);
  expectSameFiles(dir.path() / "one", dir.path() / "all", {"times_s"});
  EXPECT_EQ(slurp(dir.path() / "one.check/clearance.csv"),
            slurp(dir.path() / "all.check/clearance.csv"));
  EXPECT_EQ(slurp(dir.path() / "one.check/deviation.npy"),
            slurp(dir.path() / "all.check/deviation.npy"));
  // (0 threads is a usage error naming the option)
  EXPECT_EQ(run(dir, {"--threads", "0", "generate", kImpeller.string(), "--out", "none"}), 1);
  EXPECT_NE(slurp(dir.path() / "stderr.txt").find("--threads"), std::string::npos);
}

TEST(Deterministic, SimulateOnOneAndOnAllCores) {
  const TempDir dir;
  dir.write("path.cl",
            "# pass 1\n0 0 0 0 0 1\n20 0 -1 0.6 0 0.8\n20 20 0 0 0.6 0.8\n# pass 2\n"
            "0 20 0.5 0 0 1\n-5 10 0 0 0 1\n");
  for (const char* out : {"one", "all"})
    ASSERT_EQ(run(dir,
                  {"simulate", "--tool", "torus:3:1", "--path", "path.cl", "--grid", "700x500",
                   "--backend", "cpu", "--out", out},
                  std::string(out) == "one" ? "0" : ""),
              0)
        << slurp(dir.path() / "stderr.txt");
  // simulate.json's measurements of the run itself (times, rates, peak memory) aside.
  expectSameFiles(
      dir.path() / "one", dir.path() / "all",
      {"seconds", "peak_memory_mib", "postures_per_second", "read_megabytes_per_second"});
}

TEST(Deterministic, ToolMeshTwice) {
  const TempDir dir;
  for (const char* out : {"a/tool.stl", "b/tool.stl"})
    ASSERT_EQ(run(dir, {"tool", "--shape", "torus:4:1:20", "--holder", "20:6,40:6", "--tol", "0.01",
                        "--out", out}),
              0);
  expectSameFiles(dir.path() / "a", dir.path() / "b");
}

TEST(Deterministic, CheckOnOneAndOnAllCores) {
  const TempDir dir;
  ASSERT_EQ(run(dir, {"generate", kImpeller.string(), "--out", "gen"}), 0);
  const std::string path = (dir.path() / "gen" / "path.cl").string();
  ASSERT_EQ(run(dir, {"check", kImpeller.string(), "--path", path, "--out", "one"}, "0"), 0);
  ASSERT_EQ(run(dir, {"check", kImpeller.string(), "--path", path, "--out", "all"}), 0);
  // times_s and the surface's simulation_s are the run's own timings.
  expectSameFiles(dir.path() / "one", dir.path() / "all", {"times_s", "simulation_s"});
}

TEST(Deterministic, FieldBuildOnOneAndOnAllCores) {
  const TempDir dir;
  for (const char* out : {"one/field.vdb", "all/field.vdb"})
    ASSERT_EQ(run(dir, {"field", "build", kImpeller.string(), "--voxel", "1", "--out", out},
                  std::string(out).starts_with("one") ? "0" : ""),
              0)
        << slurp(dir.path() / "stderr.txt");
  std::string one = slurp(dir.path() / "one/field.vdb"), all = slurp(dir.path() / "all/field.vdb");
  ASSERT_EQ(one.size(), all.size());
  // OpenVDB stamps each file it writes with a random UUID (36 characters after the 21-byte
  // header of magic, versions and a flag): that, and only that, may differ.
  constexpr std::size_t kUuidAt = 21, kUuidLength = 36;
  ASSERT_GT(one.size(), kUuidAt + kUuidLength);
  for (std::string* bytes : {&one, &all}) {
    for (std::size_t dash : {8, 13, 18, 23}) ASSERT_EQ((*bytes)[kUuidAt + dash], '-') << "no UUID";
    bytes->replace(kUuidAt, kUuidLength, kUuidLength, '0');
  }
  EXPECT_TRUE(one == all) << "field.vdb differs between runs beyond its UUID";
}

TEST(Deterministic, FieldProbeOnOneAndOnAllCores) {
  const TempDir dir;
  // Points beside the blades and the hub of the example (forces not zero) and one far away.
  dir.write("points.txt",
            "72.2339 3.64426 12.2036\n53.1535 14.4135 6.75502\n"
            "60.1569 7.84445 7.90092\n55.7093 11.7358 6.92473\n0 0 200\n");
  for (const std::vector<std::string>& mode :
       {std::vector<std::string>{"--direct"}, {"--voxel", "0.5"}, {}}) {
    std::string printed[2];
    for (int k = 0; k < 2; ++k) {
      std::vector<std::string> args{"field", "probe", kImpeller.string(), "--points", "points.txt"};
      args.insert(args.end(), mode.begin(), mode.end());
      ASSERT_EQ(run(dir, args, k == 0 ? "0" : ""), 0) << slurp(dir.path() / "stderr.txt");
      printed[k] = slurp(dir.path() / "stdout.txt");
    }
    EXPECT_EQ(printed[0], printed[1]) << (mode.empty() ? "scene's field" : mode[0]);
    // Not a table of zeros: some force is felt.
    EXPECT_NE(printed[0].find_first_of("123456789", printed[0].find('\n')), std::string::npos);
  }
}

TEST(Deterministic, ViewPageOnOneAndOnAllCores) {
  const TempDir dir;
  dir.write("scene.yaml", app::test::kSmallImpellerScene);
  ASSERT_EQ(run(dir, {"generate", "scene.yaml", "--out", "gen"}), 0);
  for (const char* out : {"one/view.html", "all/view.html"})
    ASSERT_EQ(run(dir, {"view", "scene.yaml", "--path", "gen/path.cl", "--out", out},
                  std::string(out).starts_with("one") ? "0" : ""),
              0)
        << slurp(dir.path() / "stderr.txt");
  expectSameFiles(dir.path() / "one", dir.path() / "all");
}

/// `csv` without the columns named in `drop` (the header names them).
std::string withoutColumns(const std::string& csv, const std::vector<std::string>& drop) {
  std::istringstream in(csv);
  std::string line, out;
  std::vector<bool> keep;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::istringstream row(line);
    for (std::string cell; std::getline(row, cell, ',');) cells.push_back(cell);
    if (keep.empty())
      for (const auto& name : cells)
        keep.push_back(std::find(drop.begin(), drop.end(), name) == drop.end());
    for (std::size_t i = 0; i < cells.size(); ++i)
      if (i >= keep.size() || keep[i]) out += cells[i] + ',';
    out += '\n';
  }
  return out;
}

TEST(Deterministic, StudyOnOneAndOnAllCores) {
  const TempDir dir;
  dir.write("scene.yaml", app::test::kSmallImpellerScene);
  for (const char* out : {"one", "all"})
    ASSERT_EQ(run(dir,
                  {"study", "scene.yaml", "--voxels", "2", "--no-brute-force", "--line-step", "0.5",
                   "--out", out},
                  std::string(out) == "one" ? "0" : ""),
              0)
        << slurp(dir.path() / "stderr.txt");
  ASSERT_EQ(filesUnder(dir.path() / "one"), filesUnder(dir.path() / "all"));
  // The lines and the tilt, and their pictures, bit for bit (pictures only where matplotlib made
  // them).
  for (const char* name : {"lines.csv", "tilt.csv", "force_error_lines.png", "tilt_along_path.png"})
    if (fs::exists(dir.path() / "one" / name))
      EXPECT_TRUE(slurp(dir.path() / "one" / name) == slurp(dir.path() / "all" / name)) << name;
  // study.csv less the run's own timings and the speed-ups made of them; study.md and
  // speed_vs_error.png show those timings.
  const std::vector<std::string> timings{"field_s",
                                         "path_s",
                                         "clearance_s",
                                         "total_s",
                                         "speedup_vs_brute",
                                         "speedup_vs_direct",
                                         "path_speedup_vs_direct"};
  const std::string one = withoutColumns(slurp(dir.path() / "one/study.csv"), timings);
  EXPECT_EQ(one, withoutColumns(slurp(dir.path() / "all/study.csv"), timings));
  EXPECT_NE(one.find("line_a_max_pct"), std::string::npos);  // the errors are compared
}

TEST(Deterministic, ConvertOnOneAndOnAllCores) {
  const TempDir dir;
  // ~11 MB of .cl: more than two of the readers' 4 MiB chunks, so all cores read it in parallel.
  std::string cl;
  char line[128];
  for (int i = 0; i < 250000; ++i) {
    if (i % 50000 == 0) cl += "# pass " + std::to_string(i / 50000 + 1) + "\n";
    const double t = 1e-3 * i, ai = 0.3 * std::sin(7 * t), aj = 0.3 * std::cos(5 * t);
    const double ak = std::sqrt(1 - ai * ai - aj * aj);  // a unit axis, tilted up to 25 deg
    std::snprintf(line, sizeof line, "%.6f %.6f %.6f %.9f %.9f %.9f\n", 40 * std::cos(t),
                  40 * std::sin(t), 0.01 * i, ai, aj, ak);
    cl += line;
  }
  dir.write("in.cl", cl);
  for (const std::string out : {"one", "all"}) {
    const std::string cpus = out == "one" ? "0" : "";
    for (const std::vector<std::string>& args :
         {std::vector<std::string>{"in.cl", out + "/a.npy"},
          {"in.cl", out + "/b.apt", "--tool", "ball:3", "--feed", "800"},
          {out + "/a.npy", out + "/c.cl"},
          {out + "/b.apt", out + "/d.cl"}}) {
      std::vector<std::string> command{"convert"};
      command.insert(command.end(), args.begin(), args.end());
      ASSERT_EQ(run(dir, command, cpus), 0) << slurp(dir.path() / "stderr.txt");
    }
  }
  expectSameFiles(dir.path() / "one", dir.path() / "all");
}

}  // namespace
}  // namespace fieldpath
