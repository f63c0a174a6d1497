// `--max-memory` bounds a run, not each of its items: what the run holds (the program, its
// meshes, samples, field and postures) is counted against every later estimate (a memory sweep:
// items each under the limit took the mesh example to 4 times it).
#include <fcntl.h>
#include <spawn.h>
#include <sys/resource.h>
#include <sys/wait.h>

#include <cstdint>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fieldpath/common/memory.h"
#include "run_fieldpath.h"

extern char** environ;

namespace {

using fieldpath::common::HeldMemory;
using fieldpath::common::InputError;
using fieldpath::common::MemoryUse;
using fieldpath::common::requireMemory;
using fieldpath::test::TempDir;

constexpr double kMiB = 1024.0 * 1024.0;

/// The process-wide limit and ledger, set for one test and cleared after it.
struct LimitForTheTest {
  explicit LimitForTheTest(double bytes) {
    fieldpath::common::releaseHeldMemory();
    fieldpath::common::setMemoryLimitBytes(static_cast<std::size_t>(bytes));
  }
  ~LimitForTheTest() {
    fieldpath::common::setMemoryLimitBytes(0);
    fieldpath::common::releaseHeldMemory();
  }
};

std::string refusal(const std::string& what, double bytes, MemoryUse use = MemoryUse::kKept) {
  try {
    requireMemory(what, bytes, "", use);
  } catch (const InputError& e) {
    return e.what();
  }
  return {};
}

TEST(MemoryLimit, KeptEstimatesAddUpAndPassingOnesDoNot) {
  const LimitForTheTest limit(100 * kMiB);
  EXPECT_EQ(refusal("meshes", 60 * kMiB), "");
  // 60 held + 50 > 100: each alone fits, together they do not.
  const std::string over = refusal("field", 50 * kMiB);
  EXPECT_NE(over.find("field: needs about 50 MiB of memory, limit 100 MiB (--max-memory), of "
                      "which the run holds 60 MiB (meshes 60 MiB)"),
            std::string::npos)
      << over;
  EXPECT_EQ(refusal("a file read", 35 * kMiB, MemoryUse::kPassing), "");
  EXPECT_EQ(refusal("postures", 35 * kMiB), "");  // 60 + 35: the file read was not held
  EXPECT_NE(refusal("more", 10 * kMiB), "");      // 95 + 10
  EXPECT_EQ(refusal("less", 5 * kMiB, MemoryUse::kPassing), "");
}

TEST(MemoryLimit, AnObjectHoldsItsBytesWhileItLives) {
  const LimitForTheTest limit(100 * kMiB);
  {
    HeldMemory field("the voxel field", 70 * kMiB);
    EXPECT_NE(refusal("grid", 40 * kMiB, MemoryUse::kPassing).find("the voxel field 70 MiB"),
              std::string::npos);
    HeldMemory moved = std::move(field);
    EXPECT_NE(refusal("grid", 40 * kMiB, MemoryUse::kPassing), "");  // held once, by `moved`
  }
  EXPECT_EQ(refusal("grid", 40 * kMiB, MemoryUse::kPassing), "");  // given back
  HeldMemory early("early", 30 * kMiB);
  early.release();
  EXPECT_EQ(refusal("grid", 99 * kMiB, MemoryUse::kPassing), "");
}

// The CUDA context's resident memory (measured on an H200: 101-156 MB over the CPU backend's
// peak, in no estimate) is held once, before the GPU is first used; refused naming the backend.
TEST(MemoryLimit, TheCudaContextIsHeldOnce) {
  {
    const LimitForTheTest limit(100 * kMiB);
    try {
      fieldpath::common::requireCudaContext();
      ADD_FAILURE() << "160 MiB under a 100 MiB limit";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("the CUDA backend: needs about 160 MiB"),
                std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("--backend cpu spares it"), std::string::npos);
    }
  }
  const LimitForTheTest limit(1024 * kMiB);
  fieldpath::common::requireCudaContext();
  fieldpath::common::requireCudaContext();
  EXPECT_DOUBLE_EQ(fieldpath::common::memoryHeld().first, 160 * kMiB);
}

/// `fieldpath --quiet ARGS...` in `dir`; its exit code and peak resident memory (KiB, wait4).
struct Peak {
  int exit_code = -1;
  long peak_kib = 0;
};
Peak runMeasured(const TempDir& dir, const std::vector<std::string>& args) {
  std::vector<std::string> argv = {FIELDPATH_EXE, "--quiet"};
  argv.insert(argv.end(), args.begin(), args.end());
  std::vector<char*> pointers;
  for (std::string& a : argv) pointers.push_back(a.data());
  pointers.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string out = (dir.path() / "stdout.txt").string();
  const std::string err = (dir.path() / "stderr.txt").string();
  posix_spawn_file_actions_addopen(&actions, 1, out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  Peak peak;
  if (posix_spawn(&pid, argv[0].c_str(), &actions, nullptr, pointers.data(), environ) == 0) {
    int status = 0;
    rusage usage{};
    if (wait4(pid, &status, 0, &usage) == pid && WIFEXITED(status)) {
      peak.exit_code = WEXITSTATUS(status);
      peak.peak_kib = usage.ru_maxrss;
    }
  }
  posix_spawn_file_actions_destroy(&actions);
  return peak;
}

// The impeller example's run (87 MiB at its peak, 42 of them the program's own): under limits
// its items each kept (the voxel estimate 48 MiB) it had run past them; now a run accepted stays
// under its limit, and one refused says what the run holds.
TEST(MemoryLimit, AnAcceptedRunStaysUnderItsLimit) {
  const TempDir dir;
  const std::string scene = std::string(FIELDPATH_SOURCE_DIR) + "/examples/impeller/scene.yaml";
  int accepted = 0, refused = 0;
  for (int mib : {60, 75, 90, 150}) {
    const Peak run = runMeasured(dir, {"--max-memory", std::to_string(mib) + "M", "generate", scene,
                                       "--out", (dir.path() / "out").string()});
    const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
    if (run.exit_code == 0) {
      ++accepted;
      EXPECT_LE(run.peak_kib, mib * 1024L) << mib << " MiB: ran to " << run.peak_kib << " KiB";
    } else {
      ++refused;
      EXPECT_EQ(run.exit_code, 1) << err;
      EXPECT_NE(err.find("of which the run holds"), std::string::npos) << err;
      EXPECT_NE(err.find("the program"), std::string::npos) << err;
    }
  }
  EXPECT_GE(accepted, 1);
  EXPECT_GE(refused, 2);
  // check's surface at 0.02 mm (5.6 M lines, 228 MiB at its peak): at 200M its grid had been
  // counted at the Z-buffer's 20 B a line and accepted (a diff review's).
  ASSERT_TRUE(std::filesystem::exists(dir.path() / "out/path.cl"));
  for (int mib : {200, 400}) {
    const Peak run =
        runMeasured(dir, {"--max-memory", std::to_string(mib) + "M", "check", scene, "--path",
                          (dir.path() / "out/path.cl").string(), "--spacing", "0.02", "--backend",
                          "cpu", "--out", (dir.path() / "check").string()});
    const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
    EXPECT_EQ(run.exit_code, mib == 200 ? 1 : 0) << err;
    if (run.exit_code == 0)
      EXPECT_LE(run.peak_kib, mib * 1024L) << mib << " MiB: ran to " << run.peak_kib << " KiB";
    else
      EXPECT_NE(err.find("check's surface grid"), std::string::npos) << err;
  }
}

// `tool`'s mesh is counted before it is made, to the triangle (4.3 M of them took it to 1.76 GiB
// under a limit of 43M: a memory sweep's): 1.3 M triangles at --tol 1e-5 (587 MiB).
TEST(MemoryLimit, TheToolMeshIsSizedBeforeItIsMade) {
  const TempDir dir;
  const Peak run = runMeasured(
      dir, {"--max-memory", "300M", "tool", "--shape", "ball:3", "--holder",
            "40:6,55:6,55:12,90:12", "--tol", "1e-5", "--out", (dir.path() / "t.stl").string()});
  const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
  EXPECT_EQ(run.exit_code, 1) << err;
  EXPECT_NE(err.find("chordal tolerance 1e-05 mm: needs about 554 MiB of memory (1.2975e+06 "
                     "triangles of the tool and holder)"),
            std::string::npos)
      << err;
  EXPECT_LT(run.peak_kib, 100 * 1024L);
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "t.stl"));
}

// An STL's triangles are known before it is read (its header's count, an ASCII one's facets):
// counted at 600 B each beside its text, where 16 B a file byte refused an ASCII STL at 4.7
// times its need. The worst case is a soup of separate triangles (every corner its own vertex):
// 200 k of them, 9.5 MiB of binary STL, ran to 155 MiB; an accepted run stays under its limit,
// and 185M, which 16 B a byte refused (195 MiB with the program), is accepted.
TEST(MemoryLimit, AnStlIsSizedByItsTriangles) {
  const TempDir dir;
  const auto soup = dir.path() / "soup.stl";
  {
    std::ofstream out(soup, std::ios::binary);
    const std::string header(80, ' ');
    out.write(header.data(), 80);
    const std::uint32_t count = 200000;
    out.write(reinterpret_cast<const char*>(&count), 4);
    std::mt19937 random(7);
    std::uniform_real_distribution<float> at(0.0f, 100.0f), near(-0.5f, 0.5f);
    for (std::uint32_t i = 0; i < count; ++i) {
      float facet[12] = {0, 0, 1};
      const float x = at(random), y = at(random);
      for (int k = 0; k < 3; ++k) {
        facet[3 + 3 * k] = x + near(random);
        facet[4 + 3 * k] = y + near(random);
        facet[5 + 3 * k] = 0.01f * near(random);
      }
      out.write(reinterpret_cast<const char*>(facet), sizeof facet);
      const std::uint16_t attribute = 0;
      out.write(reinterpret_cast<const char*>(&attribute), 2);
    }
  }
  const auto path = dir.path() / "one.cl";
  std::ofstream(path) << "50 50 10 0 0 1\n51 50 10 0 0 1\n";
  int accepted_at = 0;
  for (int mib : {120, 185}) {
    const Peak run =
        runMeasured(dir, {"--max-memory", std::to_string(mib) + "M", "simulate", "--tool", "ball:3",
                          "--path", path.string(), "--part", soup.string(), "--grid", "16x16",
                          "--out", (dir.path() / "out").string()});
    const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
    if (run.exit_code == 0) {
      if (accepted_at == 0) accepted_at = mib;
      EXPECT_LE(run.peak_kib, mib * 1024L) << mib << " MiB: ran to " << run.peak_kib << " KiB";
    } else {
      EXPECT_EQ(run.exit_code, 1) << err;
      EXPECT_NE(err.find("soup.stl: needs about"), std::string::npos) << err;
      EXPECT_NE(err.find("(200000 triangles"), std::string::npos) << err;
    }
  }
  EXPECT_EQ(accepted_at, 185);
}

// study holds the tool nodes at every posture of the direct path and the lines' points to its
// end: in no estimate, an accepted --max-memory 57M ran to 106 MiB (a study sweep's). Asked
// before any variant runs; an accepted study stays under its limit.
TEST(MemoryLimit, AStudyIsSizedBeforeItsVariantsRun) {
  const TempDir dir;
  const std::string scene = std::string(FIELDPATH_SOURCE_DIR) + "/examples/impeller/scene.yaml";
  for (int mib : {95, 130}) {
    const Peak run =
        runMeasured(dir, {"--max-memory", std::to_string(mib) + "M", "study", scene, "--voxels",
                          "2", "--interp", "trilinear", "--stored", "force", "--no-brute-force",
                          "--line-step", "0.05", "--out", (dir.path() / "study").string()});
    const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
    if (mib == 95) {
      EXPECT_EQ(run.exit_code, 1) << err;
      EXPECT_NE(err.find("study: needs about"), std::string::npos) << err;
      EXPECT_NE(err.find("1035 postures x 596 tool nodes"), std::string::npos) << err;
      EXPECT_LT(run.peak_kib, 95 * 1024L);
    } else {
      EXPECT_EQ(run.exit_code, 0) << err;
      EXPECT_LE(run.peak_kib, mib * 1024L) << "ran to " << run.peak_kib << " KiB";
    }
  }
}

TEST(MemoryLimit, ALimitUnderTheProgramItselfIsRefusedAtOnce) {
  const TempDir dir;
  const Peak run = runMeasured(dir, {"--max-memory", "4M", "convert", "none.cl", "none.npy"});
  const std::string err = fieldpath::test::slurp(dir.path() / "stderr.txt");
  EXPECT_EQ(run.exit_code, 1) << err;
  EXPECT_NE(err.find("--max-memory 4M: under the "), std::string::npos) << err;
  EXPECT_NE(err.find(" the program holds at its start"), std::string::npos) << err;
}

}  // namespace
