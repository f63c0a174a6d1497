/// Reliability of the outputs (issue 14): an interrupted run (SIGINT, SIGTERM) leaves no partial
/// file under a final name, nor a temporary; a failed one no earlier run's outputs; files around
/// the program (links, stamps, sizes) handled (test_deterministic.cpp: the same files whatever
/// the number of threads).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/output_signals.h"
#include "files.h"
#include "reliability_runs.h"
#include "run_fieldpath.h"

namespace fieldpath {
namespace {

namespace fs = std::filesystem;
using namespace test::reliability;

// ---- the mechanism ---------------------------------------------------------------------------

// check's verdict is on the bytes it read: a path rewritten in place (same size), replaced by a
// rename or removed while it ran is told by its stamp (a helper replaced a path during `check`:
// "ok" for the old bytes, and the digest taken of the new).
TEST(FileStamp, TellsAFileRewrittenReplacedOrRemoved) {
  const TempDir dir;
  const fs::path file = dir.write("p.cl", "0 0 0 0 0 1\n");
  const common::FileStamp before = common::fileStamp(file);
  EXPECT_NO_THROW(common::requireUnchanged(file, before, "checked"));
  dir.write("p.cl", "1 0 0 0 0 1\n");  // same size, in place
  fs::last_write_time(file, fs::last_write_time(file) + std::chrono::seconds(1));
  try {
    common::requireUnchanged(file, before, "checked");
    ADD_FAILURE() << "a rewritten file passed";
  } catch (const common::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("p.cl: changed while it was checked"), std::string::npos)
        << e.what();
  }
  const common::FileStamp rewritten = common::fileStamp(file);
  dir.write("q.cl", "1 0 0 0 0 1\n");
  fs::last_write_time(dir.path() / "q.cl", fs::last_write_time(file));
  fs::rename(dir.path() / "q.cl", file);  // same bytes and time, another file
  EXPECT_THROW(common::requireUnchanged(file, rewritten, "checked"), common::InputError);
  const common::FileStamp replaced = common::fileStamp(file);
  fs::remove(file);
  EXPECT_THROW(common::requireUnchanged(file, replaced, "checked"), common::InputError);
}

// A link planted under the writer's temporary name (`.NAME.tmp-PID`, in a shared folder) is not
// written through: the victim keeps its bytes, the output is a file of its own (a helper's).
TEST(AtomicOutput, ALinkUnderTheTemporaryNameIsNotWrittenThrough) {
  const TempDir dir;
  const fs::path victim = dir.write("victim.txt", "keep me\n");
  const fs::path out = dir.path() / "out.txt";
  fs::create_symlink(victim, dir.path() / (".out.txt.tmp-" + std::to_string(::getpid())));
  common::writeTextAtomically(out, "the output\n");
  EXPECT_EQ(slurp(victim), "keep me\n");
  EXPECT_FALSE(fs::is_symlink(out));
  EXPECT_EQ(slurp(out), "the output\n");
}

// A run killed where no handler runs (SIGKILL) leaves its temporary, hidden: the next write of
// that output removes it (field build's were 60 and 141 MB, left for good: an environment
// sweep's), not a live process's nor another output's.
TEST(AtomicOutput, ADeadRunsTemporaryIsRemovedByTheNextWrite) {
  const TempDir dir;
  const pid_t child = fork();
  if (child == 0) _exit(0);
  ASSERT_GT(child, 0);
  ASSERT_EQ(waitpid(child, nullptr, 0), child);  // gone: its pid answers no signal
  const std::string dead = std::to_string(child);
  const fs::path dead_tmp = dir.write(".out.txt.tmp-" + dead, "half a");
  const fs::path live_tmp = dir.write(".out.txt.tmp-" + std::to_string(::getppid()), "another's");
  const fs::path other_tmp = dir.write(".other.txt.tmp-" + dead, "another output's");
  const fs::path named = dir.write(".out.txt.tmp-notapid", "not so named");
  const fs::path padded = dir.write(".out.txt.tmp-0" + dead, "no PID the writer names");
  const fs::path fresh = dir.write(".out.txt.tmp-" + std::to_string(child + 1000000), "now");
  // Written a minute ago or more (a fresh one may be a live writer's in another PID namespace).
  for (const fs::path& old : {dead_tmp, live_tmp, other_tmp, named, padded})
    fs::last_write_time(old, fs::file_time_type::clock::now() - std::chrono::minutes(2));
  common::writeTextAtomically(dir.path() / "out.txt", "the output\n");
  EXPECT_EQ(slurp(dir.path() / "out.txt"), "the output\n");
  EXPECT_FALSE(fs::exists(dead_tmp));
  EXPECT_TRUE(fs::exists(live_tmp));
  EXPECT_TRUE(fs::exists(other_tmp));
  EXPECT_TRUE(fs::exists(named));
  EXPECT_TRUE(fs::exists(padded));
  EXPECT_TRUE(fs::exists(fresh));
}

// A signal in the middle of a write: the handler removes the temporary, the target never appears.
TEST(AtomicOutput, SignalDuringAWriteLeavesNothing) {
  const TempDir dir;
  const fs::path target = dir.path() / "out" / "big.bin";
  for (int sig : {SIGINT, SIGTERM}) {
    const pid_t pid = fork();
    if (pid == 0) {
      common::installTemporaryCleanupOnSignals();
      common::writeFileAtomically(target, [&](std::ostream& out) {
        out << std::string(1 << 20, 'x');  // half written...
        out.flush();
        raise(sig);                         // ...when the user presses Ctrl-C
        out << std::string(1 << 20, 'y');
      });
      _exit(0);
    }
    EXPECT_EQ(finish(pid), 128 + sig);
    EXPECT_TRUE(filesUnder(dir.path() / "out").empty())
        << "left: "
        << (filesUnder(dir.path() / "out").empty() ? "" : filesUnder(dir.path() / "out")[0]);
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

// A run that fails leaves no earlier run's outputs either: a generate whose scene is refused
// took away the path.cl of the run before (a script posting out/path.apt after a failed generate
// sent the old path to the machine), and a refused check its check.json ("ok": true); files
// that are not the command's stay.
TEST(AtomicOutput, AFailedRunLeavesNoEarlierRunsOutputs) {
  const TempDir dir;
  for (const char* name : {"path.cl", "path.apt", "report.json", "check.json", "mine.txt"})
    dir.write(std::string("out/") + name, "earlier\n");
  dir.write("scene.yaml", "obstacles:\n  - mesh: missing.stl\n");
  const auto generate = test::runFieldpath(dir, "generate scene.yaml --out out");
  EXPECT_EQ(generate.exit_code, 1) << generate.output();
  EXPECT_EQ(filesUnder(dir.path() / "out"), (std::vector<std::string>{"check.json", "mine.txt"}));
  // A study too (its tables and plots stayed, a helper's sweep).
  for (const char* name : {"study.csv", "study.md", "speed_vs_error.png"})
    dir.write(std::string("out/") + name, "earlier\n");
  EXPECT_EQ(test::runFieldpath(dir, "study scene.yaml --out out").exit_code, 1);
  EXPECT_EQ(filesUnder(dir.path() / "out"), (std::vector<std::string>{"check.json", "mine.txt"}));
  dir.write("p.cl", "0 0 0 0 0 1\n");
  const auto check = test::runFieldpath(dir, "check scene.yaml --path p.cl --out out");
  EXPECT_EQ(check.exit_code, 1) << check.output();
  EXPECT_EQ(filesUnder(dir.path() / "out"), std::vector<std::string>{"mine.txt"});
  // The scene's own nominal path in --out is an input: a refused scene leaves it (a reviewer's
  // finding: `generate job/scene.yaml --out job` with `nominal: path.cl` lost it).
  dir.write("job/path.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  dir.write("job/scene.yaml", "obstacles:\n  - mesh: missing.stl\npath: { nominal: path.cl }\n");
  EXPECT_EQ(test::runFieldpath(dir, "generate job/scene.yaml --out job").exit_code, 1);
  EXPECT_EQ(filesUnder(dir.path() / "job"), (std::vector<std::string>{"path.cl", "scene.yaml"}));
}

// A check of the path.cl a generate replaces goes with it: check.json's `"ok": true` stayed
// beside a new path nobody had checked (a helper's finding); a check of another path stays.
// The same of `simulate --out` into generate's folder (heights.npy stood beside a new path.cl,
// its simulate.json naming out/path.cl: an environment sweep's): simulate.json has the digest of
// the path it simulated, written by the program here.
TEST(AtomicOutput, GenerateTakesAwayTheCheckOfThePathItReplaces) {
  const TempDir dir;
  dir.write("scene.yaml", "obstacles:\n  - mesh: missing.stl\n");
  for (const char* folder : {"same", "apt", "other"}) {
    const std::string f(folder);
    dir.write(f + "/path.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
    dir.write(f + "/path.apt", "GOTO/0,0,0,0,0,1\nFINI\n");
    const std::string digest = f == "same"  ? common::fileDigest(dir.path() / f / "path.cl")
                               : f == "apt" ? common::fileDigest(dir.path() / f / "path.apt")
                                            : std::string("fnv1a64:0000000000000000");
    dir.write(f + "/check.json", "{\"ok\": true, \"path_digest\": \"" + digest + "\"}\n");
    dir.write(f + "/deviation.png", "png\n");
    dir.write(f + "/mine.txt", "mine\n");
    const auto run = test::runFieldpath(dir, "generate scene.yaml --out " + f);
    EXPECT_EQ(run.exit_code, 1) << run.output();  // the scene is refused: path.cl goes too
  }
  EXPECT_EQ(filesUnder(dir.path() / "same"), std::vector<std::string>{"mine.txt"});
  EXPECT_EQ(filesUnder(dir.path() / "apt"), std::vector<std::string>{"mine.txt"});
  EXPECT_EQ(filesUnder(dir.path() / "other"),
            (std::vector<std::string>{"check.json", "deviation.png", "mine.txt"}));

  for (const char* folder : {"sim", "sim_other"}) {
    const std::string f(folder);
    dir.write(f + "/path.cl", "0 0 5 0 0 1\n1 0 5 0 0 1\n");
    dir.write("elsewhere.cl", "0 0 6 0 0 1\n1 0 6 0 0 1\n");
    const std::string simulated = f == "sim" ? f + "/path.cl" : "elsewhere.cl";
    ASSERT_EQ(test::runFieldpath(
                  dir, "simulate --tool ball:3 --path " + simulated + " --grid 8x8 --out " + f)
                  .exit_code,
              0);
    ASSERT_TRUE(fs::exists(dir.path() / f / "heights.npy"));
    const auto run = test::runFieldpath(dir, "generate scene.yaml --out " + f);
    EXPECT_EQ(run.exit_code, 1) << run.output();
  }
  EXPECT_EQ(filesUnder(dir.path() / "sim"), std::vector<std::string>{});
  // Never an input of the run: a scene whose obstacle is the earlier simulation's surface.stl lost
  // it before it was read ("no such mesh file", the folder left empty: a reviewer's).
  dir.write("keep/path.cl", "0 0 5 0 0 1\n1 0 5 0 0 1\n");
  ASSERT_EQ(
      test::runFieldpath(dir, "simulate --tool ball:3 --path keep/path.cl --grid 8x8 --out keep")
          .exit_code,
      0);
  dir.write("scene_in.yaml", "obstacles:\n  - mesh: keep/surface.stl\n");
  const auto in = test::runFieldpath(dir, "generate scene_in.yaml --out keep");
  EXPECT_EQ(in.err.find("no such mesh file"), std::string::npos) << in.output();
  EXPECT_TRUE(fs::exists(dir.path() / "keep/surface.stl")) << in.output();
  EXPECT_EQ(filesUnder(dir.path() / "sim_other"),
            (std::vector<std::string>{"heights.json", "heights.npy", "heights.png", "simulate.json",
                                      "surface.stl"}));
}

// A folder another run is writing (here: held as that run holds it) is refused before any work,
// and nothing in it is taken away: two runs at once left one job's path.cl beside the other's
// path.apt and report.json, both exiting 0, and a failed one took the other's path.cl (a
// helper's finding). A folder the refused run made for itself is not left behind either.
TEST(AtomicOutput, AFolderAnotherRunIsWritingIsRefused) {
  const TempDir dir;
  for (const char* name : {"path.cl", "report.json", "check.json"})
    dir.write(std::string("out/") + name, "the other run's\n");
  dir.write("p.cl", "0 0 0 0 0 1\n1 0 0 0 0 1\n");
  const int held = ::open((dir.path() / "out").c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  ASSERT_GE(held, 0);
  ASSERT_EQ(::flock(held, LOCK_EX | LOCK_NB), 0);
  const std::vector<std::string> commands = {
      "generate " + kImpeller.string() + " --out out",
      "check " + kImpeller.string() + " --path p.cl --out out",
      "simulate --tool ball:3 --path p.cl --out out"};
  for (const std::string& command : commands) {
    SCOPED_TRACE(command);
    const auto run = test::runFieldpath(dir, command);
    EXPECT_EQ(run.exit_code, 1) << run.output();
    EXPECT_NE(run.err.find("out: another fieldpath run is writing this folder"), std::string::npos)
        << run.err;
    EXPECT_EQ(filesUnder(dir.path() / "out"),
              (std::vector<std::string>{"check.json", "path.cl", "report.json"}));
  }
  ::close(held);
  // Released: the next run writes there; and a run refused for its input into a folder of its
  // own making leaves no folder.
  EXPECT_EQ(test::runFieldpath(dir, "simulate --tool ball:3 --path p.cl --out out").exit_code, 0);
  EXPECT_EQ(
      test::runFieldpath(dir, "simulate --tool ball:3 --path missing.cl --out new/deep").exit_code,
      1);
  EXPECT_FALSE(fs::exists(dir.path() / "new"));
}

// An interrupted run (Ctrl-C, `timeout`'s SIGTERM) leaves no earlier run's outputs either, as a
// failed one: a script running `timeout 60 fieldpath generate` and then posting out/path.apt
// sent the old path. A FIFO under a claimed name, a file not claimed and an input stay.
TEST(AtomicOutput, AnInterruptedRunLeavesNoEarlierRunsOutputs) {
  for (int sig : {SIGINT, SIGTERM}) {
    const TempDir dir;
    for (const char* name : {"path.cl", "report.json", "mine.txt", "nominal.cl"})
      dir.write(std::string("out/") + name, "earlier\n");
    ASSERT_EQ(mkfifo((dir.path() / "out" / "path.apt").c_str(), 0600), 0);
    const pid_t pid = fork();
    if (pid == 0) {
      common::installTemporaryCleanupOnSignals();
      common::claimOutputs(dir.path() / "out", {"path.cl", "path.apt", "report.json", "nominal.cl"},
                           {dir.path() / "out" / "nominal.cl"});
      raise(sig);  // the user presses Ctrl-C before the run writes anything
      _exit(0);
    }
    EXPECT_EQ(finish(pid), 128 + sig);
    EXPECT_EQ(filesUnder(dir.path() / "out"), (std::vector<std::string>{"mine.txt", "nominal.cl"}))
        << "signal " << sig;
    EXPECT_TRUE(fs::is_fifo(dir.path() / "out" / "path.apt")) << "signal " << sig;
  }
}

// A legal name of 250 bytes (names run to 255): written, and its temporary stayed under the
// limit too (`.NAME.tmp-PID` of it was 263 bytes: "File name too long"); two long names that
// share their first 180 bytes get temporaries of their own.
TEST(AtomicOutput, NamesUpToTheLimitAreWritten) {
  const TempDir dir;
  const std::string a = std::string(246, 'b') + ".csv", b = std::string(246, 'b') + ".npy";
  common::writeTextAtomically(dir.path() / a, "x\n");
  common::writeTextAtomically(dir.path() / b, "y\n");
  EXPECT_EQ(slurp(dir.path() / a), "x\n");
  EXPECT_EQ(slurp(dir.path() / b), "y\n");
  EXPECT_EQ(filesUnder(dir.path()).size(), 2u);  // no temporary left
}

// A file replaced keeps its permissions, through a link too (a 0600 file became 0644: a helper's
// sweep).
TEST(AtomicOutput, AReplacedFileKeepsItsPermissions) {
  const TempDir dir;
  dir.write("secret.cl", "0 0 0 0 0 1\n");
  ASSERT_EQ(::chmod((dir.path() / "secret.cl").c_str(), 0600), 0);
  fs::create_symlink("secret.cl", dir.path() / "link.cl");
  for (const char* name : {"secret.cl", "link.cl"}) {
    common::writeTextAtomically(dir.path() / name, "1 0 0 0 0 1\n");
    struct stat info {};
    ASSERT_EQ(::stat((dir.path() / "secret.cl").c_str(), &info), 0);
    EXPECT_EQ(info.st_mode & 0777, 0600u) << name;
  }
  EXPECT_TRUE(fs::is_symlink(dir.path() / "link.cl"));
}

// A signal the run was started ignoring stays ignored (under `nohup` a HUP killed the run and
// took its outputs: a reviewer's case); the others clean up; SIGXFSZ is ignored (a write past
// `ulimit -f` fails, and the run cleans up, rather than dying with its temporaries left).
TEST(AtomicOutput, SignalsIgnoredAtStartStayIgnored) {
  const pid_t pid = fork();
  if (pid == 0) {
    ::signal(SIGHUP, SIG_IGN);
    common::installTemporaryCleanupOnSignals();
    struct sigaction hup {
    }, term{}, xfsz{};
    sigaction(SIGHUP, nullptr, &hup);
    sigaction(SIGTERM, nullptr, &term);
    sigaction(SIGXFSZ, nullptr, &xfsz);
    _exit(hup.sa_handler == SIG_IGN && term.sa_handler != SIG_DFL && term.sa_handler != SIG_IGN &&
                  xfsz.sa_handler == SIG_IGN
              ? 0
              : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
}

// An output name that is a FIFO (or /dev/null, a device) is written into, not replaced by a
// regular file (renaming over /dev/null made it one), and a failed run leaves it; a name that is a
// symbolic link is written through it, the link kept.
TEST(AtomicOutput, DevicesAndFifosAreWrittenIntoAndLinksFollowed) {
  const TempDir dir;
  const fs::path fifo = dir.path() / "fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  // The reading end opened first without blocking: the write then fits in the pipe's buffer, and
  // a writer that renamed over the FIFO instead leaves it empty (a failure, not a hang).
  const int fd = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
  ASSERT_GE(fd, 0);
  common::writeTextAtomically(fifo, "through the pipe");
  char buffer[64] = {};
  const ssize_t got = ::read(fd, buffer, sizeof buffer - 1);
  ::close(fd);
  EXPECT_EQ(std::string(buffer, got > 0 ? std::size_t(got) : 0), "through the pipe");
  EXPECT_TRUE(fs::is_fifo(fifo));
  common::removeWrittenOutputs();
  EXPECT_TRUE(fs::is_fifo(fifo));  // not taken away as a written output

  const fs::path real = dir.path() / "real.csv", link = dir.path() / "link.csv";
  common::writeTextAtomically(real, "old");
  fs::create_symlink(real, link);
  common::writeTextAtomically(link, "new");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(real), "new");
  // a link to a file not there yet: the file is made, the link kept
  const fs::path dangling = dir.path() / "dangling.csv";
  fs::create_symlink("sub/later.csv", dangling);
  common::writeTextAtomically(dangling, "made");
  EXPECT_TRUE(fs::is_symlink(dangling));
  EXPECT_EQ(slurp(dir.path() / "sub" / "later.csv"), "made");
  common::removeWrittenOutputs();
}

// ---- the commands, interrupted midway
// ------------------------------------------------------------

/// Starts the command, signals it after `after`, and checks what is left in `out`: no temporary,
/// and every JSON output that is there parses. A machine fast enough to finish the command first
/// (the H100 machine's generate, with CUDA, took < 600 ms) is tried again with a quarter of the
/// wait, down to 10 ms (still after the start: the command is then interrupted early).
void interruptMidway(const std::vector<std::string>& args, std::chrono::milliseconds after,
                     int sig) {
  int code = 0;
  std::string err;
  for (auto wait = after; code != 128 + sig && wait >= std::chrono::milliseconds(10);
       wait /= 4) {
    const TempDir dir;
    const pid_t pid = start(dir, args);
    std::this_thread::sleep_for(wait);
    kill(pid, sig);
    code = finish(pid);
    err = slurp(dir.path() / "stderr.txt");
    const auto left = filesUnder(dir.path() / "out");
    for (const auto& name : left) {
      EXPECT_FALSE(isTemporary(name)) << name << " left after " << args[0] << " got signal " << sig;
      if (fs::path(name).extension() == ".json")
        EXPECT_TRUE(nlohmann::json::accept(slurp(dir.path() / "out" / name))) << name;
    }
  }
  // Interrupted midway: killed by the signal (the work outlasts the wait), nothing partial left,
  // and it says so (a run killed by `timeout` ended its log as if it had stopped on its own).
  EXPECT_EQ(code, 128 + sig) << err;
  EXPECT_NE(
      err.find(std::string("fieldpath: interrupted by ") + (sig == SIGINT ? "SIGINT" : "SIGTERM")),
      std::string::npos)
      << err;
}

TEST(Interrupted, GenerateLeavesNoPartialFile) {
  interruptMidway({"generate", kImpeller.string(), "--out", "out"}, std::chrono::milliseconds(600),
                  SIGINT);
}

// A run killed where no handler runs (SIGKILL, the out-of-memory killer) between its renames
// left its new path.cl beside the earlier run's path.apt and report.json, a set that reads
// complete (a helper's): the earlier files go when the work starts. Looked at the moment the new
// path.cl appears (the first rename): the earlier report.json is gone already.
TEST(Killed, AGenerateKilledBetweenItsRenamesLeavesNoEarlierFile) {
  const TempDir dir;
  for (const char* name : {"path.cl", "path.apt", "angles.csv", "report.json"})
    dir.write(std::string("out/") + name, "earlier\n");
  const pid_t pid = start(dir, {"generate", kImpeller.string(), "--out", "out"});
  const fs::path path_cl = dir.path() / "out" / "path.cl";
  std::string report_then = "(path.cl never appeared)";
  for (int ms = 0; ms < 60000; ++ms) {
    std::error_code ec;
    if (fs::exists(path_cl, ec) && slurp(path_cl).rfind("earlier", 0) != 0) {
      report_then = slurp(dir.path() / "out" / "report.json");
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  kill(pid, SIGKILL);
  finish(pid);
  ASSERT_NE(report_then, "(path.cl never appeared)") << slurp(dir.path() / "stderr.txt");
  EXPECT_EQ(report_then.find("earlier"), std::string::npos) << report_then;
  for (const auto& name : filesUnder(dir.path() / "out"))
    if (!isTemporary(name)) EXPECT_NE(slurp(dir.path() / "out" / name), "earlier\n") << name;
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

}  // namespace
}  // namespace fieldpath
