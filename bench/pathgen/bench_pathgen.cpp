/// bench_pathgen: the impeller job end to end (seed 004 Tab. 1 and Tab. 2).
///   1. In process, per field variant (direct, voxels 2 / 1 / 0.5 mm, nominal): median stage times
///      over repeated runs, ratio to the direct field measured in the same run, and the error of
///      each variant against the direct (exact) field: largest tilt/lead difference per posture.
///   2. The `fieldpath generate` program as a user runs it (--voxel 0.5 and --direct): median wall
///      time and peak resident memory (getrusage of the child) over repeated runs.
/// Usage: bench_pathgen [--scene FILE] [--bin FIELDPATH] [--repeats N] [--brute]
/// Results of record: bench/results/pathgen.md.
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "fieldpath/common/stats.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/generate.h"
#include "job.h"
#include "scene.h"

using namespace fieldpath;

namespace {

using fieldpath::geometry::kRadToDeg;

using common::median;

struct Variant {
  std::string name;
  pathgen::FieldMode mode;
  double voxel_mm = 0;
  bool nominal = false;
};

struct Row {
  Variant variant;
  pathgen::GenerateResult last;
  double field_s = 0, steering_s = 0, clearance_s = 0, total_s = 0;
};

/// Runs `fieldpath ARGS...` `repeats` times; returns the median wall seconds and the largest peak
/// RSS (MiB) of the child.
std::pair<double, double> runProgram(const std::vector<std::string>& args, int repeats) {
  std::vector<double> wall;
  double peak_mib = 0;
  for (int r = 0; r < repeats; ++r) {
    std::fflush(nullptr);  // or the child's exit would print our buffered table again
    const auto start = std::chrono::steady_clock::now();
    const pid_t pid = fork();
    if (pid == 0) {
      std::vector<char*> argv;
      for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      if (!freopen("/dev/null", "w", stdout)) _exit(127);
      execv(argv[0], argv.data());
      _exit(127);
    }
    int status = 0;
    rusage usage{};
    wait4(pid, &status, 0, &usage);
    wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
    if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
      std::fprintf(stderr, "bench_pathgen: %s failed\n", args[0].c_str());
      std::exit(2);
    }
    peak_mib = std::max(peak_mib, usage.ru_maxrss / 1024.0);  // ru_maxrss: KiB on Linux
  }
  return {median(wall), peak_mib};
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene_file = std::string(FIELDPATH_SOURCE_DIR) + "/examples/impeller/scene.yaml";
  std::string bin = FIELDPATH_BIN;
  int repeats = 5;
  bool brute = false;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scene" && i + 1 < argc)
      scene_file = argv[++i];
    else if (a == "--bin" && i + 1 < argc)
      bin = argv[++i];
    else if (a == "--repeats" && i + 1 < argc)
      repeats = std::max(1, std::atoi(argv[++i]));
    else if (a == "--brute")
      brute = true;
    else {
      std::fprintf(
          stderr,
          "usage: bench_pathgen [--scene FILE] [--bin FIELDPATH] [--repeats N] [--brute]\n");
      return 1;
    }
  }
  const app::Scene scene = app::loadScene(scene_file);
  const pathgen::GenerateRequest job = app::sceneJob(scene);

  std::vector<Variant> variants = {{"direct", pathgen::FieldMode::Direct},
                                   {"voxel 2 mm", pathgen::FieldMode::Voxel, 2.0},
                                   {"voxel 1 mm", pathgen::FieldMode::Voxel, 1.0},
                                   {"voxel 0.5 mm", pathgen::FieldMode::Voxel, 0.5},
                                   {"nominal", pathgen::FieldMode::Direct, 0, true}};
  if (brute) variants.insert(variants.begin() + 1, {"brute force", pathgen::FieldMode::BruteForce});

  std::vector<Row> rows;
  for (const Variant& v : variants) {
    pathgen::GenerateRequest request = job;
    request.mode = v.mode;
    request.nominal = v.nominal;
    if (v.voxel_mm > 0) request.field.voxel.voxel_size_mm = v.voxel_mm;
    std::vector<double> field, steering, clearance, total;
    Row row{v, {}};
    const int n = v.mode == pathgen::FieldMode::BruteForce ? 1 : repeats;
    for (int r = 0; r < n; ++r) {
      row.last = pathgen::generatePath(request);
      field.push_back(row.last.times.field_s);
      steering.push_back(row.last.times.steering_s);
      clearance.push_back(row.last.times.clearance_s);
      total.push_back(row.last.times.total_s);
    }
    row.field_s = median(field);
    row.steering_s = median(steering);
    row.clearance_s = median(clearance);
    row.total_s = median(total);
    rows.push_back(std::move(row));
  }

  const Row& direct = rows.front();
  std::printf(
      "impeller: %zu postures on %zu passes, %.1f mm; %zu obstacle points, %zu tool+holder "
      "nodes; %d repeats (median), %u hardware threads\n\n",
      direct.last.postures.size(), direct.last.passes.size(), direct.last.path_length_mm,
      direct.last.obstacle_points, direct.last.tool_nodes, repeats,
      std::max(1u, std::thread::hardware_concurrency()));
  std::printf(
      "| variant | voxel nodes | field s | steering s | clearance s | total s | total / direct "
      "| max |Δtilt| deg | max |Δlead| deg | max tilt deg | min clearance mm | colliding |\n");
  std::printf("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (const Row& row : rows) {
    double dtilt = 0, dlead = 0;
    for (size_t i = 0; i < row.last.postures.size() && i < direct.last.postures.size(); ++i) {
      dtilt = std::max(dtilt,
                       std::abs(row.last.postures[i].tilt_rad - direct.last.postures[i].tilt_rad));
      dlead = std::max(dlead,
                       std::abs(row.last.postures[i].lead_rad - direct.last.postures[i].lead_rad));
    }
    std::printf(
        "| %s | %zu | %.3f | %.3f | %.3f | %.3f | %.2f | %.3f | %.3f | %.2f | %.3f | %zu |\n",
        row.variant.name.c_str(), row.last.voxel_nodes, row.field_s, row.steering_s,
        row.clearance_s, row.total_s, row.total_s / direct.total_s, dtilt * kRadToDeg,
        dlead * kRadToDeg, row.last.max_tilt_deg, row.last.clearance.min_clearance_mm,
        row.last.clearance.colliding);
  }

  std::printf(
      "\nend to end, `fieldpath generate` (process wall time incl. start-up and writing "
      "outputs):\n\n");
  std::printf("| command | median wall s | peak RSS MiB | wall / direct |\n|---|---:|---:|---:|\n");
  const std::string out = "/tmp/bench_pathgen_" + std::to_string(getpid());
  const auto [direct_s, direct_mib] =
      runProgram({bin, "--quiet", "generate", scene_file, "--direct", "--out", out}, repeats);
  const auto [voxel_s, voxel_mib] =
      runProgram({bin, "--quiet", "generate", scene_file, "--voxel", "0.5", "--out", out}, repeats);
  std::printf("| generate --direct | %.3f | %.1f | 1.00 |\n", direct_s, direct_mib);
  std::printf("| generate --voxel 0.5 | %.3f | %.1f | %.2f |\n", voxel_s, voxel_mib,
              voxel_s / direct_s);
  std::error_code ec;
  std::filesystem::remove_all(out, ec);
  return 0;
}
