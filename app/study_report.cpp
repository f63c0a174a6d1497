/// The study's outputs: study.csv, study.md, lines.csv, tilt.csv and their plots (split from
/// study.cpp, which runs the variants).
#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string_view>

#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/output_signals.h"
#include "fieldpath/field/law.h"
#include "fieldpath/geometry/units.h"
#include "study.h"
#include "study_assets.h"
#include "study_text.h"

namespace fieldpath::app {

using namespace study_detail;
using geometry::kRadToDeg;
namespace {

std::string fixed(double value, int decimals) {
  if (!std::isfinite(value)) return "–";
  std::ostringstream s;
  s << std::fixed << std::setprecision(decimals) << value;
  return s.str();
}

/// Why trilinear voxels miss: the worst relative error of linear interpolation (what trilinear
/// does along one axis) across an infinite plane wall of the area-weighted field (law.h
/// planeFieldMagnitude, held r_min off the wall and even about it, as the surface rule does),
/// over heights d in [d_min, r0) where |F| >= kErrorFloorFraction · |F(d_min)|, worst over the
/// grid's offset to the wall. `times_distance`: the nodes store F·d and the query divides by its
/// exact d (a smoother stored quantity).
double planeInterpolationError(double h_mm, double d_min_mm, const field::FieldParams& params,
                               bool times_distance) {
  auto height = [&](double d) { return params.r_min_mm + std::abs(d - params.r_min_mm); };
  auto force = [&](double d) { return field::planeFieldMagnitude(height(d), params); };
  auto stored = [&](double d) { return times_distance ? force(d) * height(d) : force(d); };
  const double floor = kErrorFloorFraction * force(d_min_mm);
  constexpr int kOffsets = 16, kPoints = 2000;
  double worst = 0.0;
  for (int o = 0; o < kOffsets; ++o) {
    const double offset = h_mm * o / kOffsets;
    for (int i = 0; i < kPoints; ++i) {
      const double d = d_min_mm + (params.r0_mm - d_min_mm) * i / kPoints;
      const double exact = force(d);
      if (exact < floor || exact <= 0.0) continue;
      const double k = std::floor((d - offset) / h_mm);
      const double d0 = offset + k * h_mm, w = (d - d0) / h_mm;
      const double value = (1 - w) * stored(d0) + w * stored(d0 + h_mm);
      const double approx = times_distance ? value / height(d) : value;
      worst = std::max(worst, std::abs(approx - exact) / exact);
    }
  }
  return worst;
}

/// An error's value where it counted points, else NaN (written "–" or an empty cell): a line of
/// no points, or a field of gain 0, read "0.000 %" and its targets "met" (a study sweep's).
double counted(const field::FieldError& error, double value) {
  return error.count > 0 ? value : std::numeric_limits<double>::quiet_NaN();
}
double maxOf(const field::FieldError& e) { return counted(e, e.max_relative); }
double rmsOf(const field::FieldError& e) { return counted(e, e.rms_relative); }

/// Largest relative force error of a row over both lines and the nodes, fraction; NaN where none
/// of them counted a point.
double maxForceError(const StudyRow& row) {
  double worst = std::numeric_limits<double>::quiet_NaN();
  for (const field::FieldError* e :
       {&row.line_a.relative, &row.line_b.relative, &row.nodes.relative})
    if (e->count > 0)
      worst = std::isnan(worst) ? e->max_relative : std::max(worst, e->max_relative);
  return worst;
}

std::string csvText(const StudyResult& r) {
  std::ostringstream s;
  s << "variant,mode,voxel_mm,interpolation,stored,refine_tolerance_pct,levels,status,active_"
       "nodes,refined_nodes,dense_box_nodes,voxel_memory_mb,"
       "field_s,path_s,clearance_s,total_s,speedup_vs_brute,speedup_vs_direct,"
       "path_speedup_vs_direct,"
       "line_a_max_pct,line_a_rms_pct,line_b_max_pct,line_b_rms_pct,nodes_max_pct,nodes_rms_pct,"
       "max_force_error_pct,nodes_max_scaled_pct,moment_max_pct,moment_rms_pct,tilt_max_deg,tilt_"
       "rms_deg,tilt_middle_max_deg,"
       "min_clearance_mm,"
       "colliding,max_tilt_deg,solver_steps,rhs_evals\n";
  for (const StudyRow& row : r.rows) {
    const StudyVariant& v = row.variant;
    s << v.name() << ',' << pathgen::fieldModeNames(v.mode).id << ','
      << (v.isVoxel() ? number(v.voxel.voxel_size_mm) : "0") << ','
      << (v.isVoxel() ? interpolationName(v.voxel.interpolation) : "exact") << ','
      << (v.isVoxel() ? storedName(v.voxel.stored) : "exact") << ','
      << number(100 * v.voxel.refine_tolerance) << ',' << row.levels << ','
      << (row.failure.empty() ? "ok" : "failed") << ',' << row.active_nodes << ','
      << row.refined_nodes << ',' << row.dense_box_nodes << ','
      << number(row.voxel_memory_bytes / 1e6) << ',' << number(row.times.field_s) << ','
      << number(row.times.steering_s) << ',' << number(row.times.clearance_s) << ','
      << number(row.total_s) << ',' << number(row.speedup_vs_brute) << ','
      << number(row.speedup_vs_direct) << ',' << number(row.path_speedup_vs_direct) << ','
      << number(100 * maxOf(row.line_a.relative)) << ',' << number(100 * rmsOf(row.line_a.relative))
      << ',' << number(100 * maxOf(row.line_b.relative)) << ','
      << number(100 * rmsOf(row.line_b.relative)) << ',' << number(100 * maxOf(row.nodes.relative))
      << ',' << number(100 * rmsOf(row.nodes.relative)) << ',' << number(100 * maxForceError(row))
      << ',' << number(100 * counted(row.nodes.relative, row.nodes.max_scaled)) << ','
      << number(100 * maxOf(row.moment.relative)) << ',' << number(100 * rmsOf(row.moment.relative))
      << ',' << number(row.tilt_max_deg) << ',' << number(row.tilt_rms_deg) << ','
      << number(row.tilt_middle_max_deg) << ',' << number(row.min_clearance_mm) << ','
      << row.colliding << ',' << number(row.max_tilt_deg) << ',' << row.solver_steps << ','
      << row.rhs_evals << '\n';
  }
  return s.str();
}

std::string linesText(const StudyResult& r) {
  std::ostringstream s;
  s << "line,variant,t_mm,wall_distance_mm,direct_force,variant_force,relative_error\n";
  for (const StudyLine* line : {&r.line_a, &r.line_b})
    for (std::size_t v = 0; v < r.rows.size(); ++v) {
      if (!r.rows[v].variant.isVoxel()) continue;
      for (std::size_t i = 0; i < line->t_mm.size(); ++i)
        s << line->name << ',' << r.rows[v].variant.name() << ',' << number(line->t_mm[i], 6) << ','
          << number(line->wall_distance_mm[i], 5) << ',' << number(line->direct_magnitude[i], 6)
          << ',' << number(line->magnitude[v][i], 6) << ',' << number(line->relative_error[v][i], 5)
          << '\n';
    }
  return s.str();
}

std::string tiltText(const StudyResult& r) {
  std::ostringstream s;
  s << "variant,pass,s_mm,tilt_deg\n";
  for (std::size_t v = 0; v < r.rows.size(); ++v)
    for (std::size_t i = 0; i < r.tilt_deg[v].size() && i < r.tilt_s_mm.size(); ++i)
      s << r.rows[v].variant.name() << ',' << r.middle_pass + 1 << ',' << number(r.tilt_s_mm[i], 6)
        << ',' << number(r.tilt_deg[v][i], 6) << '\n';
  return s.str();
}

/// Seed 004 published figures by voxel size (Tables 1 and 2).
struct Published {
  double h_mm, nodes, field_s, total_s, force_pct, tilt_deg;
};
constexpr Published kPublished[] = {{2.0, 121e3, 32, 88, 15, 0.7},
                                    {1.0, 784e3, 138, 194, 5, 0.5},
                                    {0.5, 5389e3, 971, 1027, 1, 0.3}};
constexpr double kPublishedDirectS = 3396;
constexpr double kPublishedPathS = 56;
/// Issue 7 targets: max force error and tilt difference by voxel size (half the seed's).
struct Target {
  double h_mm, force_pct, tilt_deg;
};
constexpr Target kTargets[] = {{2.0, 7.5, 0.35}, {1.0, 2.5, 0.25}, {0.5, 0.5, 0.1}};

/// `study --backend A,B`: each voxel variant's builds in one group, times against the group's
/// first build (issue 15: old and new build side by side, field + path totals). Empty without.
std::string buildsSideBySide(const StudyResult& r) {
  std::vector<std::string> groups;
  for (const StudyRow& row : r.rows)
    if (row.variant.isVoxel() && row.variant.named_backend &&
        std::find(groups.begin(), groups.end(), row.variant.nameWithoutBackend()) == groups.end())
      groups.push_back(row.variant.nameWithoutBackend());
  if (groups.empty()) return {};
  std::ostringstream s;
  s << "\n## Node builds side by side (`--backend`)\n\n"
    << "The same variant built by each backend (`reference`: the per-node build of before issue"
    << " 15; `cpu`: the block build; `cuda`: the GPU's), in this run; × is the first build's time"
    << " over this one's (> 1: faster). Same node values to float rounding: the errors agree.\n\n"
    << "| variant | build | active nodes | field s | path s | total s | field × | total × |"
       " max force error % | tilt diff max ° "
       "|\n|---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const std::string& group : groups) {
    const StudyRow* first = nullptr;
    for (const StudyRow& row : r.rows) {
      if (!row.variant.isVoxel() || !row.variant.named_backend ||
          row.variant.nameWithoutBackend() != group)
        continue;
      if (!first) first = &row;
      s << "| " << group << " | " << backendName(row.variant.voxel.backend) << " | "
        << row.active_nodes << " | " << fixed(row.times.field_s, 3) << " | "
        << fixed(row.times.steering_s, 3) << " | " << fixed(row.total_s, 3) << " | "
        << fixed(first->times.field_s / row.times.field_s, 2) << " | "
        << fixed(first->total_s / row.total_s, 2) << " | " << fixed(100 * maxForceError(row), 3)
        << " | " << fixed(row.tilt_max_deg, 4) << " |\n";
    }
  }
  return s.str();
}

std::string markdownText(const StudyResult& r, const std::string& command_line,
                         const std::string& machine) {
  std::ostringstream s;
  std::time_t now = std::time(nullptr);
  char date[64];
  std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
  s << "# Voxel-size study (seed 004 Tables 1–2, Figs. 5–6)\n\n"
    << "- date: " << date << "\n- machine: " << machine << "\n- command: `" << command_line
    << "`\n\n"
    << "Job: " << r.postures << " postures on " << fixed(r.path_length_mm, 1)
    << " mm of path, middle pass " << r.middle_pass + 1 << " plotted; " << r.tool_nodes
    << " tool + holder nodes; " << r.obstacle_points << " obstacle points (blades sampled every "
    << r.field.sample_step_mm << " mm; seed 004: 1 mm, 5100 points); voxel region (what tool"
    << " + holder can reach) " << fixed(r.reach_box_cm3, 0) << " cm³; r0 = " << r.field.r0_mm
    << " mm, r_min = " << r.field.r_min_mm << " mm, clearance = " << r.clearance_mm << " mm.\n\n"
    << "## Definitions\n\n"
    << "- **Relative force error** at a point x: `|F_v(x) - F_d(x)| / |F_d(x)|`, F_d the indexed"
    << " direct field (exact eq. 1), counted where `|F_d(x)| >= " << kErrorFloorFraction * 100
    << " % of max |F_d|` over the same set (line or nodes) and, on the lines, x is at least"
    << " `clearance` from every obstacle (FCL) and inside the region tool + holder can reach."
    << " Why: the field fades to 0 at r0, where any relative error is meaningless and the nodes"
    << " add nothing to the moment; points closer to a wall than `clearance` or out of reach are"
    << " never occupied by a valid path (and the voxels exist only in reach). `nodes scaled` is "
       "`|ΔF| / max |F_d|` over"
    << " all nodes (no floor), the error relative to the largest force on the tool.\n"
    << "- **Moment error**: the same relative error of the field's moment on the tool about the"
    << " ball centre, `τ = Σ (x_i - C) × F(x_i)` over the tool + holder nodes, per posture of the"
    << " direct path (floor 1 % of the largest |τ_d|): the force *acting on the tool* (seed 004"
    << " Table 2's wording), where node errors partly cancel.\n"
    << "- **Max force error** of a variant: the largest relative error over line a, line b and the"
    << " nodes.\n"
    << "- **Refined near its path** (`--refine-region path`, what `generate` does): the passes"
    << " steered on the uniform grid first, cells split only within 1.5 voxels of where that"
    << " path's nodes went; such a variant is measured as its job reads the field: its voxels"
    << " within half a voxel of those nodes, the exact field beyond (so its lines' errors are"
    << " those of the points near the path). **Everywhere** (`reach`): split wherever the error"
    << " asks, in the region tool + holder can reach.\n"
    << "- **Line a**: " << r.line_a.description << " (" << r.line_a.t_mm.size() << " points, "
    << fixed(r.line_a.t_mm.back(), 1) << " mm). **Line b**: " << r.line_b.description << " ("
    << r.line_b.t_mm.size() << " points, " << fixed(r.line_b.t_mm.back(), 1) << " mm).\n"
    << "- **Nodes**: the " << r.tool_nodes << " tool + holder nodes at every posture of the direct"
    << " path (" << r.node_points << " points).\n"
    << "- **Times** (steady clock, this run): field = obstacle sampling + index (+ voxel build);"
    << " path = steering of every pass; total = field + path (the seed's *temps total*); the FCL"
    << " clearance check of each path is listed apart (the same work for every variant).\n"
    << "- Times are medians of " << r.repeats << " run(s) of each variant.\n"
    << "- **Tilt difference**: `|θ_tilt,v - θ_tilt,d|` at every posture of every pass.\n\n";

  s << "## Table 1: cost\n\n"
    << "| variant | active nodes | of them refined | dense-box nodes | memory MB | field s |"
       " path s | total s | × vs brute | × vs direct (total) | × vs direct (path only) |"
       " clearance s | solver steps | RHS evals |\n"
    << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const StudyRow& row : r.rows)
    s << "| " << row.variant.name() << " | " << row.active_nodes << " | " << row.refined_nodes
      << " | " << row.dense_box_nodes << " | " << fixed(row.voxel_memory_bytes / 1e6, 1) << " | "
      << fixed(row.times.field_s, 3) << " | " << fixed(row.times.steering_s, 3) << " | "
      << fixed(row.total_s, 3) << " | " << fixed(row.speedup_vs_brute, 1) << " | "
      << fixed(row.speedup_vs_direct, 2) << " | " << fixed(row.path_speedup_vs_direct, 2) << " | "
      << fixed(row.times.clearance_s, 2) << " | " << row.solver_steps << " | " << row.rhs_evals
      << " |\n";
  s << "\n**Published (seed 004 Table 1; Matlab on a Xeon E5-1620 @ 3.6 GHz, other hardware, "
       "5100 obstacle points, 500 tool nodes, 660 cm³):**\n\n"
    << "| method | voxel nodes | field s | path s | total s |\n|---|---:|---:|---:|---:|\n"
    << "| direct | – | – | " << kPublishedDirectS << " | " << kPublishedDirectS << " |\n";
  for (const Published& p : kPublished)
    s << "| voxel " << p.h_mm << " mm | " << fixed(p.nodes / 1e3, 0) << "e3 | " << p.field_s
      << " | " << kPublishedPathS << " (2 mm) | " << p.total_s << " |\n";

  s << buildsSideBySide(r);
  s << "\n## Table 2: what it breaks (errors in %, tilt in degrees)\n\n"
    << "| variant | line a max | line a rms | line b max | line b rms | nodes max | nodes rms |"
       " nodes scaled max | max force error | moment max | moment rms | tilt diff max ° |"
       " tilt diff rms ° | tilt diff max °, middle pass | min clearance mm | colliding |\n"
    << "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const StudyRow& row : r.rows)
    s << "| " << row.variant.name() << " | " << fixed(100 * maxOf(row.line_a.relative), 3) << " | "
      << fixed(100 * rmsOf(row.line_a.relative), 3) << " | "
      << fixed(100 * maxOf(row.line_b.relative), 3) << " | "
      << fixed(100 * rmsOf(row.line_b.relative), 3) << " | "
      << fixed(100 * maxOf(row.nodes.relative), 3) << " | "
      << fixed(100 * rmsOf(row.nodes.relative), 3) << " | "
      << fixed(100 * counted(row.nodes.relative, row.nodes.max_scaled), 3) << " | "
      << fixed(100 * maxForceError(row), 3) << " | " << fixed(100 * maxOf(row.moment.relative), 3)
      << " | " << fixed(100 * rmsOf(row.moment.relative), 3) << " | " << fixed(row.tilt_max_deg, 4)
      << " | " << fixed(row.tilt_rms_deg, 4) << " | " << fixed(row.tilt_middle_max_deg, 4) << " | "
      << (underClearance(row, r.clearance_mm) ? "**" + fixed(row.min_clearance_mm, 3) + " (under " +
                                                    fixed(r.clearance_mm, 3) + ")**"
                                              : fixed(row.min_clearance_mm, 3))
      << " | " << row.colliding << " |\n";
  s << "\n**Published (seed 004 Table 2; Matlab, linear interpolation, other hardware):**\n\n"
    << "| voxel | force variation | tilt difference |\n|---|---:|---:|\n";
  for (const Published& p : kPublished)
    s << "| " << p.h_mm << " mm | up to " << p.force_pct << " % | up to " << p.tilt_deg << "° |\n";

  // Where the line errors are: max relative error by distance to the nearest wall.
  const double bands[] = {r.clearance_mm, 1.0, 2.0, r.field.r0_mm};
  s << "\n**Where** (max relative error %, both lines, by distance d to the nearest wall, mm; the"
       " samples are "
    << r.field.sample_step_mm << " mm apart):\n\n| variant |";
  for (int b = 0; b + 1 < 4; ++b) s << " " << bands[b] << " ≤ d < " << bands[b + 1] << " |";
  s << "\n|---|---:|---:|---:|\n";
  for (std::size_t v = 0; v < r.rows.size(); ++v) {
    if (!r.rows[v].variant.isVoxel()) continue;
    s << "| " << r.rows[v].variant.name() << " |";
    for (int b = 0; b + 1 < 4; ++b) {
      double worst = std::numeric_limits<double>::quiet_NaN();  // "–": no point counted there
      for (const StudyLine* line : {&r.line_a, &r.line_b})
        for (std::size_t i = 0; i < line->t_mm.size(); ++i) {
          const double d = line->wall_distance_mm[i], e = line->relative_error[v][i];
          if (d >= bands[b] && d < bands[b + 1] && std::isfinite(e))
            worst = std::isnan(worst) ? e : std::max(worst, e);
        }
      s << " " << fixed(100 * worst, 3) << " |";
    }
    s << "\n";
  }

  // Targets of issue 7, best variant per voxel size, uniform and refined apart.
  s << "\n## Targets (issue 7)\n\n"
    << "Per voxel size and grid (uniform, or refined where its error estimate exceeds the"
    << " tolerance), the variant with the least max force error and the one with the least tilt"
    << " difference (variants whose path failed are left out).\n\n"
    << "| voxel | grid | least force error | max force error % (target) | met |"
       " least tilt difference | tilt diff max ° (target) | met |\n"
    << "|---|---|---|---:|---|---|---:|---|\n";
  for (const Target& t : kTargets)
    for (const bool refined : {false, true}) {
      const StudyRow *force = nullptr, *tilt = nullptr;
      for (const StudyRow& row : r.rows) {
        if (!row.variant.isVoxel() || !row.failure.empty() ||
            std::abs(row.variant.voxel.voxel_size_mm - t.h_mm) > 1e-9 ||
            (row.variant.voxel.refine_tolerance > 0.0) != refined)
          continue;
        if (!force || maxForceError(row) < maxForceError(*force) ||
            (std::isnan(maxForceError(*force)) && !std::isnan(maxForceError(row))))
          force = &row;
        if (!tilt || row.tilt_max_deg < tilt->tilt_max_deg) tilt = &row;
      }
      if (!force) continue;
      const bool force_met = 100 * maxForceError(*force) <= t.force_pct;  // (NaN: not measured)
      const bool tilt_met = tilt->tilt_max_deg <= t.tilt_deg;
      s << "| " << t.h_mm << " mm | " << (refined ? "refined" : "uniform") << " | "
        << force->variant.name() << " | " << fixed(100 * maxForceError(*force), 3) << " (≤ "
        << t.force_pct << ") | "
        << (force_met                           ? "yes"
            : std::isnan(maxForceError(*force)) ? "**not measured**"
                                                : "**no**")
        << " | " << tilt->variant.name() << " | " << fixed(tilt->tilt_max_deg, 4) << " (≤ "
        << t.tilt_deg << ") | " << (tilt_met ? "yes" : "**no**") << " |\n";
    }
  // Speed: path only (the field built once per part, seed 004 Table 1 keeps it apart) and total.
  const StudyRow *by_path = nullptr, *by_total = nullptr;
  std::size_t accurate_under = 0;  // at <= 1 %, their path under the clearance
  for (const StudyRow& row : r.rows) {
    if (!row.variant.isVoxel() || !row.failure.empty() || !(maxForceError(row) <= 0.01)) continue;
    if (underClearance(row, r.clearance_mm)) {
      ++accurate_under;
      continue;
    }
    if (!by_path || row.path_speedup_vs_direct > by_path->path_speedup_vs_direct) by_path = &row;
    if (!by_total || row.speedup_vs_direct > by_total->speedup_vs_direct) by_total = &row;
  }
  s << "\nSpeed at ≤ 1 % max force error (target: the voxel path ≥ 10× the indexed direct path"
    << " in the same run; variants whose path went under the clearance are left out): ";
  if (by_path)
    s << "path only, best " << by_path->variant.name() << ": "
      << fixed(by_path->path_speedup_vs_direct, 2) << "× ("
      << (by_path->path_speedup_vs_direct >= 10 ? "met" : "**not met**")
      << "); total (field build + path), best " << by_total->variant.name() << ": "
      << fixed(by_total->speedup_vs_direct, 2) << "× ("
      << (by_total->speedup_vs_direct >= 10 ? "met" : "**not met**") << ").\n";
  else if (accurate_under > 0)
    s << accurate_under << " voxel variant" << (accurate_under == 1 ? " reaches" : "s reach")
      << " 1 %, " << (accurate_under == 1 ? "its path" : "their paths")
      << " under the clearance (**not met**).\n";
  else
    s << "no voxel variant reaches 1 % (**not met**).\n";
  for (const StudyRow& row : r.rows)
    if (!row.failure.empty())
      s << "\n**" << row.variant.name() << "**: no path (" << row.failure
        << "); its force errors are measured all the same, its times and angles are not.\n";
  // Why: the closed form of a plane wall, interpolated along its normal.
  std::vector<double> sizes;
  for (const StudyRow& row : r.rows)
    if (row.variant.isVoxel() &&
        std::find(sizes.begin(), sizes.end(), row.variant.voxel.voxel_size_mm) == sizes.end())
      sizes.push_back(row.variant.voxel.voxel_size_mm);
  s << "\n## Why stored force misses the targets (closed form: a plane wall)\n\n"
    << "Across a plane wall the field is `π·gain·(r0 - d)² / (d·r0²)` (law.h): it rises like 1/d"
    << " towards the wall and fades like (r0 - d)² at r0, so with r0 = " << r.field.r0_mm
    << " mm a voxel of 1–2 mm spans most of its range. The worst relative error of linear"
    << " interpolation along the normal (trilinear does this along each axis), over heights d ≥"
    << " d_min where |F| ≥ " << kErrorFloorFraction * 100 << " % of |F(d_min)|, worst over"
    << " the grid's offset to the wall (%):\n\n"
    << "| voxel | stored F, d ≥ clearance (" << r.clearance_mm
    << " mm) | stored F, d ≥ 1 mm |"
       " stored F, d ≥ r0/2 | stored F·d, d ≥ clearance |\n|---|---:|---:|---:|---:|\n";
  for (double h : sizes)
    s << "| " << h << " mm | "
      << fixed(100 * planeInterpolationError(h, r.clearance_mm, r.field, false), 1) << " | "
      << fixed(100 * planeInterpolationError(h, 1.0, r.field, false), 1) << " | "
      << fixed(100 * planeInterpolationError(h, 0.5 * r.field.r0_mm, r.field, false), 1) << " | "
      << fixed(100 * planeInterpolationError(h, r.clearance_mm, r.field, true), 1) << " |\n";
  s << "\nThe 1-D error of linear interpolation of f is about h²/8·|f''|/f; for the 1/d rise that"
    << " is h²/(4 d²): reaching 7.5 / 2.5 / 0.5 % at the clearance needs h ≈ "
    << fixed(2 * r.clearance_mm * std::sqrt(0.075), 2) << " / "
    << fixed(2 * r.clearance_mm * std::sqrt(0.025), 2) << " / "
    << fixed(2 * r.clearance_mm * std::sqrt(0.005), 2)
    << " mm near the walls; towards r0 the (r0 - d)² fade adds its own error (the d ≥ r0/2"
    << " column, whose floor reaches further out). Quadratic sampling does not help where a cell"
    << " spans the 1/d rise: it overshoots. What does: a stored quantity that is smooth across"
    << " the wall, the force recovered at the query. F·d with d exact (last column) is not"
    << " enough; `plane_ratio` (field::StoredQuantity::PlaneRatio) stores the signed equivalent"
    << " plane height s and G = F / P(s), P the plane law, and returns P(s~)·G~: exact for a"
    << " plane at any h (0 in this table), so what remains in the `plane_ratio` rows above is the"
    << " walls' curvature and twist, the second wall, and the lumpy field of the discrete samples"
    << " within about one sample spacing of a wall.\n";
  s << "\nFiles: study.csv (this table), lines.csv (Fig. 5 data), tilt.csv (Fig. 6 data), "
       "speed_vs_error.png, force_error_lines.png, tilt_along_path.png.\n";
  return s.str();
}

}  // namespace

void writeStudy(const StudyResult& result, const std::filesystem::path& dir,
                const std::string& command_line, const std::string& machine) {
  common::writeTextAtomically(dir / "study.csv", csvText(result));
  common::writeTextAtomically(dir / "lines.csv", linesText(result));
  common::writeTextAtomically(dir / "tilt.csv", tiltText(result));
  common::writeTextAtomically(
      dir / "study.md",
      markdownText(result, command_line, machine.empty() ? machineDescription() : machine));
}

bool plotStudy(const std::filesystem::path& dir, std::string* message) {
  auto fail = [&](const std::string& why) {
    if (message) *message = why;
    return false;
  };
  // Debian's python3 (where python3-matplotlib goes), else the one on PATH; the script on its
  // standard input and the folder as an argument of its own:
  // no shell (a folder named with a quote ran what followed it) and no script file to find (the
  // program looked for a developer's checkout). Its stderr is kept for the message: a traceback
  // is not printed under --quiet.
  // A plotter killed with an interrupted run leaves its temporary (`.NAME.png.XXXX.tmp.png`,
  // hidden); the folder is this run's (locked: claimOutputs), so any such is a dead one's.
  std::error_code listed;
  for (std::filesystem::directory_iterator it(dir, listed), end; !listed && it != end;
       it.increment(listed)) {
    const std::string name = it->path().filename().string();
    for (const char* png : {"speed_vs_error.png", "force_error_lines.png", "tilt_along_path.png"})
      if (name.starts_with("." + std::string(png) + ".") && name.ends_with(".tmp.png")) {
        std::error_code ignored;
        std::filesystem::remove(it->path(), ignored);
      }
  }
  int to_python[2], from_python[2];
  if (::pipe2(to_python, O_CLOEXEC) != 0) return fail("pictures not made: no pipe to python3");
  if (::pipe2(from_python, O_CLOEXEC) != 0) {
    ::close(to_python[0]), ::close(to_python[1]);
    return fail("pictures not made: no pipe from python3");
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_adddup2(&actions, to_python[0], STDIN_FILENO);
  posix_spawn_file_actions_adddup2(&actions, from_python[1], STDOUT_FILENO);
  posix_spawn_file_actions_adddup2(&actions, from_python[1], STDERR_FILENO);
  const std::string folder = dir.string();
  char* argv[] = {const_cast<char*>("python3"), const_cast<char*>("-"),
                  const_cast<char*>(folder.c_str()), nullptr};
  pid_t pid = 0;
  const char* const debian = "/usr/bin/python3";
  const int spawned = ::access(debian, X_OK) == 0
                          ? ::posix_spawn(&pid, debian, &actions, nullptr, argv, environ)
                          : ::posix_spawnp(&pid, "python3", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned == 0) common::detail::output_helper.store(pid);  // a signal ends it with the run
  ::close(to_python[0]);
  ::close(from_python[1]);
  if (spawned != 0) {
    ::close(to_python[1]), ::close(from_python[0]);
    return fail("pictures not made: no python3 (" + std::string(std::strerror(spawned)) + ")");
  }
  // The script (a few kB) fits in the pipe's buffer: written whole before its output is read.
  const std::string_view script = study_assets::kPlotStudyPy;
  // python3 gone early: EPIPE, not SIGPIPE. The whole sigaction is put back (signal() dropped
  // the cleanup handler's SA_RESETHAND: a later SIGPIPE re-raised itself for ever, a reviewer's).
  struct sigaction ignore {
  }, old_pipe{};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  ::sigaction(SIGPIPE, &ignore, &old_pipe);
  for (std::size_t done = 0; done < script.size();) {
    const ssize_t n = ::write(to_python[1], script.data() + done, script.size() - done);
    if (n <= 0 && errno != EINTR) break;
    if (n > 0) done += static_cast<std::size_t>(n);
  }
  ::close(to_python[1]);
  ::sigaction(SIGPIPE, &old_pipe, nullptr);
  std::string output;
  char buffer[4096];
  for (ssize_t n; (n = ::read(from_python[0], buffer, sizeof buffer)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    if (output.size() < (1u << 20)) output.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(from_python[0]);
  int status = -1;  // a failed waitpid (SIGCHLD ignored: ECHILD) is no success
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  common::detail::output_helper.store(0);
  if (status != -1 && WIFEXITED(status) && WEXITSTATUS(status) == 0) return true;
  // The last line python3 wrote says why (an ImportError for a missing matplotlib).
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
  const std::string last = output.substr(output.find_last_of('\n') + 1);
  return fail("pictures not made: " +
              (last.empty() ? "python3 ended with status " + std::to_string(status) : last));
}

}  // namespace fieldpath::app
