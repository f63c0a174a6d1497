/// bench_field: the repulsive field on two twisted walls of the seed's impeller size (walls.h).
/// Prints, as markdown tables: the voxel build (time, nodes against the dense box, memory) per
/// voxel size; the evaluation rates of the voxel samplers beside the indexed direct sum and the
/// brute-force peer, at random points of the band and at the nodes of a tool moving down the
/// channel; the relative error of each voxel variant against the direct field at random points of
/// the band, by distance from the walls. Times are medians of repeated runs in this process; the
/// rates are given per wall-clock second and per CPU second (the machine is shared: CPU seconds
/// are what this process got, so "per CPU-s × cores" is what idle cores would give).
///   bench_field [--repeats N] [--points N] [--threads N] [--sample-step MM] [--quick]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <tuple>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "fieldpath/common/stats.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/metrics.h"
#include "fieldpath/field/voxel_field.h"
#include "walls.h"

using namespace fieldpath;
using field::Vec3;

namespace {

/// Wall and CPU (whole process) seconds of one run.
struct Times {
  double wall_s, cpu_s;
};

Times measure(const std::function<void()>& work) {
  timespec c0, c1;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c0);
  const auto start = std::chrono::steady_clock::now();
  work();
  const double wall =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &c1);
  return {wall, (c1.tv_sec - c0.tv_sec) + 1e-9 * (c1.tv_nsec - c0.tv_nsec)};
}

using common::median;

/// Medians of wall and CPU seconds over repeated runs.
Times medianTimes(int repeats, const std::function<void()>& work) {
  std::vector<double> wall, cpu;
  for (int r = 0; r < repeats; ++r) {
    const Times t = measure(work);
    wall.push_back(t.wall_s);
    cpu.push_back(t.cpu_s);
  }
  return {median(wall), median(cpu)};
}

struct BandPoints {
  std::vector<Vec3> points;
  std::vector<double> distance_mm;  ///< to the nearest sample
};

/// Random points of the band: in the region, on the channel side of the walls, 0.5 mm to
/// r0 - 0.5 mm from the nearest sample.
BandPoints bandPoints(const field::ObstacleSamples& s, const field::FieldParams& p,
                      const Eigen::AlignedBox3d& region, std::size_t count) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> ux(region.min().x(), region.max().x()),
      uy(region.min().y(), region.max().y()), uz(region.min().z(), region.max().z());
  BandPoints out;
  while (out.points.size() < count) {
    const Vec3 x(ux(rng), uy(rng), uz(rng));
    double best = HUGE_VAL;
    std::size_t nearest = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double d2 = (x - s.points_mm[j]).squaredNorm();
      if (d2 < best) best = d2, nearest = j;
    }
    const double d = std::sqrt(best);
    if (d >= 0.5 && d <= p.r0_mm - 0.5 &&
        (x - s.points_mm[nearest]).dot(s.normals[nearest]) > 0.0) {
      out.points.push_back(x);
      out.distance_mm.push_back(d);
    }
  }
  return out;
}

/// Nodes of a ball-end tool (R 3 mm, 40 mm long, ≈500 nodes, tool frame: tip at the origin,
/// axis +z) for a tip moving down the middle of the channel: `postures` batches of nodes, each
/// evaluated as one call, as the dynamics does.
std::vector<std::vector<Vec3>> toolNodeBatches(int postures, double tip_y_mm = 0.0) {
  std::vector<Vec3> tool;
  const double radius = 3.0;
  for (int i = 0; i <= 8; ++i)  // hemisphere, rings of latitude
    for (int j = 0; j < 24; ++j) {
      const double lat = 0.5 * M_PI * i / 8, lon = 2 * M_PI * j / 24;
      tool.emplace_back(radius * std::sin(lat) * std::cos(lon),
                        radius * std::sin(lat) * std::sin(lon), radius * (1 - std::cos(lat)));
      if (i == 0) break;
    }
  for (int k = 1; k <= 14; ++k)  // shank rings up to 40 mm
    for (int j = 0; j < 24; ++j) {
      const double lon = 2 * M_PI * j / 24;
      tool.emplace_back(radius * std::cos(lon), radius * std::sin(lon), radius + 37.0 * k / 14);
    }
  std::vector<std::vector<Vec3>> batches;
  for (int p = 0; p < postures; ++p) {
    const Vec3 tip(-44.0 + 88.0 * p / std::max(1, postures - 1), tip_y_mm, 2.0);
    std::vector<Vec3> nodes;
    for (const Vec3& n : tool) nodes.push_back(tip + n);
    batches.push_back(std::move(nodes));
  }
  return batches;
}

std::string loadAverage() {
  std::FILE* f = std::fopen("/proc/loadavg", "r");
  char text[64] = "?";
  if (f) {
    if (!std::fgets(text, sizeof text, f)) text[0] = 0;
    std::fclose(f);
  }
  std::string s(text);
  return s.substr(0, s.find(' ', s.find(' ', s.find(' ') + 1) + 1));
}

/// Points where a voxel field is compared with the direct one, as the study (app/study.h) does:
/// relative error where the point is in free space at least `clearance` from the walls and
/// |F_d| is at least 1 % of the set's largest |F_d|. The walls are open sheets: free space is
/// their channel side (η > 0 above the nearest sample) and beyond their edges; the distance to
/// a wall is η where the point is over it (the nearest sample less than `over_mm` sideways),
/// else the distance to the nearest sample.
struct ErrorSet {
  std::string name;
  std::vector<Vec3> points;
  std::vector<Vec3> exact;
  std::vector<char> counted;
};

ErrorSet errorSet(std::string name, std::vector<Vec3> points, const field::DirectField& direct,
                  double clearance_mm, double over_mm) {
  ErrorSet set{std::move(name), std::move(points), {}, {}};
  set.exact.resize(set.points.size());
  direct.evaluate(set.points, set.exact);
  const auto& s = direct.samples();
  double max_ref = 0.0;
  std::vector<char> clear(set.points.size());
  for (std::size_t i = 0; i < set.points.size(); ++i) {
    double best = HUGE_VAL;
    std::size_t nearest = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double d2 = (set.points[i] - s.points_mm[j]).squaredNorm();
      if (d2 < best) best = d2, nearest = j;
    }
    const double eta = (set.points[i] - s.points_mm[nearest]).dot(s.normals[nearest]);
    const bool over = best - eta * eta <= over_mm * over_mm;
    clear[i] = over ? eta >= clearance_mm : std::sqrt(best) >= clearance_mm;
    if (clear[i]) max_ref = std::max(max_ref, set.exact[i].norm());
  }
  for (std::size_t i = 0; i < set.points.size(); ++i)
    set.counted.push_back(clear[i] && set.exact[i].norm() >= 0.01 * max_ref && max_ref > 0.0);
  return set;
}

field::FieldError setError(const ErrorSet& set, const field::ForceField& f) {
  std::vector<Vec3> approx(set.points.size()), a, r;
  f.evaluate(set.points, approx);
  for (std::size_t i = 0; i < approx.size(); ++i)
    if (set.counted[i]) a.push_back(approx[i]), r.push_back(set.exact[i]);
  return field::relativeError(a, r, 0.0);
}

std::vector<Vec3> segment(const Vec3& a, const Vec3& b, double step_mm) {
  const int n = std::max(2, static_cast<int>(std::ceil((b - a).norm() / step_mm)) + 1);
  std::vector<Vec3> points;
  for (int i = 0; i < n; ++i) points.push_back(a + (b - a) * (double(i) / (n - 1)));
  return points;
}

/// The study's lines on the walls: a, along the channel r0/2 off the +y wall at mid height;
/// b, across the channel wall to wall at x = 22.5 (the walls turned ±7.5°), mid height; c, across
/// the channel 2 mm above the walls' top edges (x = 22.5: the open edges, both sides of them);
/// and the nodes of a tool moving down the channel 14 mm off its axis (its shank grazes the +y
/// wall where it leans in).
std::vector<ErrorSet> errorSets(const field::DirectField& direct, double r0_mm, double over_mm) {
  using bench::wallNormal, bench::wallPoint;
  const double v = 0.5 * bench::kHeight, x = 22.5;
  std::vector<Vec3> a;
  for (int i = 0; i <= 1760; ++i) {
    const double xi = -44.0 + 88.0 * i / 1760;
    a.push_back(wallPoint(1, xi, v) + 0.5 * r0_mm * wallNormal(1, xi, v));
  }
  const Vec3 top_l = wallPoint(-1, x, bench::kHeight), top_r = wallPoint(1, x, bench::kHeight);
  std::vector<Vec3> tool;
  for (const auto& batch : toolNodeBatches(200, 14.0))
    tool.insert(tool.end(), batch.begin(), batch.end());
  return {errorSet("line a", std::move(a), direct, 0.5, over_mm),
          errorSet("line b", segment(wallPoint(-1, x, v), wallPoint(1, x, v), 0.05), direct, 0.5,
                   over_mm),
          errorSet("line c (edges)",
                   segment(Vec3(x, -30, top_l.z() + 2), Vec3(x, 30, top_r.z() + 2), 0.05), direct,
                   0.5, over_mm),
          errorSet("tool nodes", std::move(tool), direct, 0.5, over_mm)};
}

const char* storedName(field::StoredQuantity s) {
  return s == field::StoredQuantity::PlaneRatio ? "plane ratio" : "force";
}

}  // namespace

int main(int argc, char** argv) {
  int repeats = 5;
  std::size_t n_points = 200000;
  bool quick = false;
  int threads = 0;              // 0: TBB's default
  double sample_step_mm = 2.0;  // the walls' 3.6 mm triangles split in 4: ≈1.3 mm apart
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--repeats") && i + 1 < argc)
      repeats = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--points") && i + 1 < argc)
      n_points = std::strtoul(argv[++i], nullptr, 10);
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--sample-step") && i + 1 < argc)
      sample_step_mm = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--quick"))
      quick = true, repeats = 1, n_points = 20000;
    else {
      std::fprintf(stderr,
                   "usage: bench_field [--repeats N] [--points N] [--threads N] [--sample-step MM] "
                   "[--quick]\n");
      return 1;
    }
  }
  std::optional<tbb::global_control> limit;
  if (threads > 0) limit.emplace(tbb::global_control::max_allowed_parallelism, threads);
  const int cores = threads > 0 ? threads : tbb::info::default_concurrency();

  field::FieldParams params;  // r0 5, r_min 0.25, area weights
  params.sample_step_mm = sample_step_mm;
  const auto walls = bench::twistedWalls();
  const Eigen::AlignedBox3d region = bench::wallsRegion();
  const field::ObstacleSamples samples =
      field::sampleObstacles(walls, params.sample_step_mm, params.weights);
  std::printf(
      "# bench_field: two twisted walls, %zu samples (sample_step %.1f mm, %.0f mm²), region %.0f "
      "cm³, "
      "r0 %.1f mm, r_min %.2f mm, %d threads, medians of %d runs, load average at start %s\n\n",
      samples.size(), params.sample_step_mm, samples.area_mm2, region.volume() / 1000.0,
      params.r0_mm, params.r_min_mm, cores, repeats, loadAverage().c_str());

  const field::DirectField direct(samples, params);
  const field::BruteForceField brute(samples, params);

  // ---- build ------------------------------------------------------------------------------
  std::printf("## Voxel build (trilinear; only the reachable region is built)\n\n");
  std::printf(
      "| h (mm) | build wall (s) | build CPU (s) | estimate | active nodes | region box nodes | "
      "active / box | memory (MiB) |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (double h : {2.0, 1.0, 0.5, 0.25}) {
    if (quick && h < 0.5) continue;
    field::VoxelRequest request;
    request.voxel_size_mm = h;
    request.region_mm = region;
    field::VoxelStats stats;
    const Times t =
        medianTimes(repeats, [&] { stats = field::VoxelField(direct, request).stats(); });
    const Vec3 nodes = (region.sizes() / h).array().floor() + 1.0;
    const double box_nodes = nodes.prod();
    std::printf("| %.2f | %.3f | %.3f | %zu | %zu | %.0f | %.2f %% | %.1f |\n", h, t.wall_s,
                t.cpu_s, stats.estimated_nodes, stats.active_nodes, box_nodes,
                100.0 * stats.active_nodes / box_nodes, stats.memory_bytes / 1048576.0);
  }

  // ---- rates ------------------------------------------------------------------------------
  const BandPoints band = bandPoints(samples, params, region, n_points);
  const std::vector<Vec3>& points = band.points;
  std::vector<Vec3> exact(points.size()), forces(points.size());
  direct.evaluate(points, exact);
  const std::size_t n_brute = std::min<std::size_t>(points.size(), 20000);
  const std::span<const Vec3> brute_points(points.data(), n_brute);
  const auto batches = toolNodeBatches(quick ? 40 : 400);
  std::size_t n_tool = 0;
  for (const auto& b : batches) n_tool += b.size();
  auto evaluateBatches = [&](const field::ForceField& f) {
    std::vector<Vec3> out(batches.front().size());
    for (const auto& b : batches) f.evaluate(b, out);
  };

  struct Rate {
    std::string name;
    double wall_per_s, cpu_per_s;
  };
  std::vector<Rate> random_rates, tool_rates;
  auto rate = [](const std::string& name, std::size_t n, const Times& t) {
    return Rate{name, n / t.wall_s, n / t.cpu_s};
  };
  std::vector<Vec3> brute_forces(n_brute);
  random_rates.push_back(rate("brute force (every sample)", n_brute, medianTimes(repeats, [&] {
                                brute.evaluate(brute_points, brute_forces);
                              })));
  random_rates.push_back(rate("direct (PointIndexGrid, r0)", points.size(),
                              medianTimes(repeats, [&] { direct.evaluate(points, forces); })));
  tool_rates.push_back(rate("direct (PointIndexGrid, r0)", n_tool,
                            medianTimes(repeats, [&] { evaluateBatches(direct); })));

  // ---- voxel variants: rates and errors -----------------------------------------------------
  const std::vector<std::pair<double, double>> buckets{
      {0.5, 1.0}, {1.0, 2.0}, {2.0, 4.5}, {0.5, 4.5}};
  const std::vector<ErrorSet> sets = errorSets(direct, params.r0_mm, params.sample_step_mm);
  std::vector<std::string> error_rows, set_rows;
  for (double h :
       quick ? std::vector<double>{1.0, 0.5} : std::vector<double>{2.0, 1.0, 0.5, 0.25}) {
    for (auto stored : {field::StoredQuantity::Force, field::StoredQuantity::PlaneRatio}) {
      for (auto interpolation :
           {field::Interpolation::Trilinear, field::Interpolation::Quadratic}) {
        field::VoxelRequest request;
        request.voxel_size_mm = h;
        request.region_mm = region;
        request.interpolation = interpolation;
        request.stored = stored;
        const field::VoxelField voxel(direct, request);
        char name[96];
        std::snprintf(name, sizeof name, "voxel h %.2f %s %s", h, storedName(stored),
                      interpolation == field::Interpolation::Trilinear ? "trilinear" : "quadratic");
        random_rates.push_back(rate(name, points.size(),
                                    medianTimes(repeats, [&] { voxel.evaluate(points, forces); })));
        tool_rates.push_back(
            rate(name, n_tool, medianTimes(repeats, [&] { evaluateBatches(voxel); })));
        std::string row = std::string("| ") + name;
        for (const auto& [lo, hi] : buckets) {
          std::vector<Vec3> a, b;
          for (std::size_t i = 0; i < points.size(); ++i)
            if (band.distance_mm[i] >= lo && band.distance_mm[i] < hi)
              a.push_back(forces[i]), b.push_back(exact[i]);
          const field::FieldError e = field::relativeError(a, b, 0.0);
          char cell[64];
          std::snprintf(cell, sizeof cell, " | %.1e / %.1e", e.max_relative, e.rms_relative);
          row += cell;
        }
        error_rows.push_back(row + " |");
        char head[160];
        std::snprintf(head, sizeof head, "| %s | %zu | %.3f", name, voxel.stats().active_nodes,
                      voxel.stats().build_seconds);
        row = head;
        for (const ErrorSet& set : sets) {
          const field::FieldError e = setError(set, voxel);
          char cell[64];
          std::snprintf(cell, sizeof cell, " | %.2f / %.2f", 100 * e.max_relative,
                        100 * e.rms_relative);
          row += cell;
        }
        set_rows.push_back(row + " |");
      }
    }
  }

  auto printRates = [&](const char* title, const std::vector<Rate>& rates, const Rate& brute_rate,
                        const Rate& direct_rate) {
    std::printf("\n## %s\n\n", title);
    std::printf(
        "| evaluator | M/s (wall) | M per CPU-s | × %d cores | × brute force | × direct |\n",
        cores);
    std::printf("|---|---|---|---|---|---|\n");
    for (const Rate& r : rates)
      std::printf("| %s | %.3f | %.3f | %.2f | %.1f | %.2f |\n", r.name.c_str(), r.wall_per_s / 1e6,
                  r.cpu_per_s / 1e6, cores * r.cpu_per_s / 1e6, r.cpu_per_s / brute_rate.cpu_per_s,
                  r.cpu_per_s / direct_rate.cpu_per_s);
  };
  printRates(
      ("Evaluation at " + std::to_string(points.size()) +
       " random points of the band (brute force on the first " + std::to_string(n_brute) + ")")
          .c_str(),
      random_rates, random_rates[0], random_rates[1]);
  printRates(("Evaluation at the nodes of a tool moving down the channel (" +
              std::to_string(batches.size()) + " postures × " +
              std::to_string(batches.front().size()) + " nodes, one call a posture)")
                 .c_str(),
             tool_rates, random_rates[0], tool_rates[0]);

  const field::FieldError brute_error =
      field::relativeError(brute_forces, std::span<const Vec3>(exact.data(), n_brute), 0.0);
  std::printf(
      "\n## Relative error against the direct field at the random band points (max / RMS), by "
      "distance to the nearest sample\n\n");
  std::printf("brute force against direct: max %.1e, RMS %.1e (rounding only)\n\n",
              brute_error.max_relative, brute_error.rms_relative);
  std::printf(
      "| variant | 0.5-1 mm | 1-2 mm | 2-4.5 mm | all (0.5-4.5 mm) |\n|---|---|---|---|---|\n");
  for (const auto& row : error_rows) std::printf("%s\n", row.c_str());

  std::printf(
      "\n## Relative error (%%, max / RMS) on the study's sets: points >= 0.5 mm from every "
      "sample where |F_direct| >= 1 %% of the set's largest (app/study.h's definition)\n\n");
  std::printf("| variant | active nodes | build s (last run)");
  for (const ErrorSet& set : sets) {
    std::size_t n = 0;
    for (char c : set.counted) n += c;
    std::printf(" | %s (%zu pts)", set.name.c_str(), n);
  }
  std::printf(" |\n|---|---|---");
  for (std::size_t i = 0; i < sets.size(); ++i) std::printf("|---");
  std::printf("|\n");
  for (const auto& row : set_rows) std::printf("%s\n", row.c_str());
  return 0;
}
