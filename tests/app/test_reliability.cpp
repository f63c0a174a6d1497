/// Reliability of the outputs (issue 14): an interrupted run (SIGINT, SIGTERM) leaves no partial
/// file under a final name, nor a temporary; the same inputs give the same files, bit for bit,
/// whatever the number of threads.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldpath/common/atomic_file.h"
#include "run_fieldpath.h"

namespace fieldpath {
namespace {

namespace fs = std::filesystem;
using test::slurp;
using test::TempDir;

const fs::path kImpeller = fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// Every file under `dir` (relative names, sorted).
std::vector<std::string> filesUnder(const fs::path& dir) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& e : fs::recursive_directory_iterator(dir, ec))
    if (e.is_regular_file()) names.push_back(fs::relative(e.path(), dir).string());
  std::sort(names.begin(), names.end());
  return names;
}

bool isTemporary(const std::string& name) {
  return fs::path(name).filename().string().find(".tmp-") != std::string::npos;
}

/// Starts `fieldpath --quiet ARGS...` in `dir` (output to files there); returns its pid.
/// `cpus` non-empty: run under `taskset -c cpus` (TBB and OpenMP then use those cores only).
pid_t start(const TempDir& dir, std::vector<std::string> args, const std::string& cpus = {}) {
  args.insert(args.begin(), {FIELDPATH_EXE, "--quiet"});
  if (!cpus.empty()) args.insert(args.begin(), {"taskset", "-c", cpus});
  const pid_t pid = fork();
  if (pid == 0) {
    if (chdir(dir.path().c_str()) != 0) _exit(126);
    freopen("stdout.txt", "w", stdout);
    freopen("stderr.txt", "w", stderr);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execvp(argv[0], argv.data());
    _exit(127);
  }
  return pid;
}

/// Waits for `pid`; returns the exit code, or 128 + the signal that ended it.
int finish(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// Runs a command to completion; returns its exit code.
int run(const TempDir& dir, const std::vector<std::string>& args, const std::string& cpus = {}) {
  return finish(start(dir, args, cpus));
}

// ---- the mechanism ---------------------------------------------------------------------------

// A signal in the middle of a write: the handler removes the temporary, the target never appears.
TEST(AtomicOutput, SignalDuringAWriteLeavesNothing) {
  const TempDir dir;
  const fs::path target = dir.path() / "out" / "big.bin";
  for (int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = fork();
    if (pid == 0) {
      common::installTemporaryCleanupOnSignals();
      common::writeFileAtomically(target, [&](std::ofstream& out) {
        out << std::string(1 << 20, 'x');  // half written...
        out.flush();
        raise(sig);                         // ...when the user presses Ctrl-C
        out << std::string(1 << 20, 'y');
      });
      _exit(0);
    }
    EXPECT_EQ(finish(pid), 128 + sig);
    EXPECT_TRUE(filesUnder(dir.path() / "out").empty())
        << "left: " << (filesUnder(dir.path() / "out").empty() ? "" : filesUnder(dir.path() / "out")[0]);
  }
  // And without a signal the file is there, whole, with no temporary beside it.
  common::writeTextAtomically(target, "whole");
  EXPECT_EQ(slurp(target), "whole");
  EXPECT_EQ(filesUnder(dir.path() / "out"), std::vector<std::string>{"big.bin"});
}

// A run that fails after some outputs were written (a full disk at the third) takes them away.
TEST(AtomicOutput, AFailedRunRemovesWhatItWrote) {
  const TempDir dir;
  common::writeTextAtomically(dir.path() / "out" / "a.json", "{}");
  common::writeTextAtomically(dir.path() / "out" / "b.csv", "x\n");
  EXPECT_EQ(filesUnder(dir.path() / "out").size(), 2u);
  common::removeWrittenOutputs();
  EXPECT_TRUE(filesUnder(dir.path() / "out").empty());
}

// ---- the commands, interrupted midway ------------------------------------------------------------

/// Starts the command, signals it after `after`, and checks what is left in `out`: no temporary,
/// and every JSON output that is there parses.
void interruptMidway(const std::vector<std::string>& args, std::chrono::milliseconds after,
                     int sig) {
  const TempDir dir;
  const pid_t pid = start(dir, args);
  std::this_thread::sleep_for(after);
  kill(pid, sig);
  const int code = finish(pid);
  const auto left = filesUnder(dir.path() / "out");
  for (const auto& name : left) {
    EXPECT_FALSE(isTemporary(name)) << name << " left after " << args[0] << " got signal " << sig;
    if (fs::path(name).extension() == ".json")
      EXPECT_NO_THROW((void)nlohmann::json::parse(slurp(dir.path() / "out" / name))) << name;
  }
  // Interrupted midway: killed by the signal (the work outlasts `after`), nothing written yet.
  EXPECT_EQ(code, 128 + sig) << slurp(dir.path() / "stderr.txt");
}

TEST(Interrupted, GenerateLeavesNoPartialFile) {
  interruptMidway({"generate", kImpeller.string(), "--out", "out"}, std::chrono::milliseconds(600),
                  SIGINT);
}

TEST(Interrupted, SimulateLeavesNoPartialFile) {
  const TempDir dir;
  dir.write("path.cl", "0 0 0 0 0 1\n50 0 0 0 0 1\n50 50 0 0 0 1\n");
  const std::string path = (dir.path() / "path.cl").string();
  interruptMidway({"simulate", "--tool", "ball:3", "--path", path, "--grid", "8000x8000",
                   "--backend", "cpu", "--out", "out"},
                  std::chrono::milliseconds(800), SIGTERM);
}

TEST(Interrupted, StudyLeavesNoPartialFile) {
  interruptMidway({"study", kImpeller.string(), "--voxels", "1,0.5", "--out", "out"},
                  std::chrono::milliseconds(1500), SIGINT);
}

// ---- determinism ------------------------------------------------------------------------------

/// Removes `key` from every object in `j`, however deep.
void eraseEverywhere(nlohmann::json& j, const std::string& key) {
  if (j.is_object()) j.erase(key);
  if (j.is_structured())
    for (auto& child : j) eraseEverywhere(child, key);
}

/// The files of two output folders are the same, byte for byte (`except`: keys of JSON files
/// that are measurements of the run, removed before comparing).
void expectSameFiles(const fs::path& a, const fs::path& b, const std::vector<std::string>& except = {}) {
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

TEST(Deterministic, SimulateOnOneAndOnAllCores) {
  const TempDir dir;
  dir.write("path.cl", "# pass 1\n0 0 0 0 0 1\n20 0 -1 0.6 0 0.8\n20 20 0 0 0.6 0.8\n# pass 2\n"
                       "0 20 0.5 0 0 1\n-5 10 0 0 0 1\n");
  for (const char* out : {"one", "all"})
    ASSERT_EQ(run(dir, {"simulate", "--tool", "torus:3:1", "--path", "path.cl", "--grid",
                        "700x500", "--backend", "cpu", "--out", out},
                  std::string(out) == "one" ? "0" : ""),
              0)
        << slurp(dir.path() / "stderr.txt");
  // simulate.json's measurements of the run itself (times, rates, peak memory) aside.
  expectSameFiles(dir.path() / "one", dir.path() / "all",
                  {"seconds", "peak_memory_mib", "postures_per_second", "read_megabytes_per_second"});
}

TEST(Deterministic, ToolMeshTwice) {
  const TempDir dir;
  for (const char* out : {"a/tool.stl", "b/tool.stl"})
    ASSERT_EQ(run(dir, {"tool", "--shape", "torus:4:1:20", "--holder", "20:6,40:6", "--tol",
                        "0.01", "--out", out}),
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

}  // namespace
}  // namespace fieldpath
