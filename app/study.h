#pragma once
/// The voxel-size study of `fieldpath study` (seed 004 Tables 1–2, Figs. 5–6): one impeller job run
/// with every way of computing the field — the brute-force direct sum (the seed's, for its timing),
/// the indexed direct sum (the accuracy reference) and sparse voxels of each size and
/// interpolation — and, per variant, what it costs (nodes, seconds) and what it breaks (force
/// error along two study lines and at the tool + holder nodes along the path, tilt difference,
/// clearance).
///
/// Relative force error at a point x (one definition for lines and nodes):
///   e(x) = |F_v(x) - F_d(x)| / |F_d(x)|,  F_d the indexed direct field (exact eq. 1),
/// counted only where |F_d(x)| >= kErrorFloorFraction · max |F_d| over the same set (line or
/// nodes) and, on the lines, x is at least `clearance` from every obstacle and inside the region
/// tool + holder can reach (the free space a valid path may occupy; voxels exist only there).
/// The floor drops the fringe near r0 where the field fades to zero: there the relative error of
/// any interpolation means nothing, and those nodes add nothing to the moment. The error
/// normalised by the set's max |F_d| (scaled) is reported beside it.
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "fieldpath/common/progress.h"
#include "fieldpath/field/metrics.h"
#include "fieldpath/field/params.h"
#include "fieldpath/pathgen/generate.h"

namespace fieldpath::app {

using geometry::Vec3;

/// Points where |F_d| is below this fraction of the set's max are left out of relative errors.
inline constexpr double kErrorFloorFraction = 0.01;

/// One way of computing the field.
struct StudyVariant {
  pathgen::FieldMode mode = pathgen::FieldMode::Voxel;
  /// Voxel mode only: size, interpolation, what the nodes hold, refinement (a fraction; 0: a
  /// uniform grid) and the levels below the size it may go.
  field::VoxelSettings voxel;

  /// Whether the name says which build made the nodes (StudyRequest::backends given).
  bool named_backend = false;

  bool isVoxel() const { return mode == pathgen::FieldMode::Voxel; }
  /// "brute force", "direct", "voxel 2 mm trilinear force", "voxel 2 mm trilinear plane_ratio
  /// refined 7.5 % to 0.25 mm", "voxel 0.5 mm trilinear plane_ratio [cpu build]" (tables, plots).
  std::string name() const;
  /// name() without the build's part: the variants built by each backend share it.
  std::string nameWithoutBackend() const;
};

struct StudyRequest {
  /// The scene's job (on the parametric impeller); mode, voxel size and interpolation are set per
  /// variant.
  pathgen::GenerateRequest job;
  /// The impeller of the job (the study lines a and b run along and across its channel).
  pathgen::ImpellerParams impeller;
  std::vector<double> voxel_sizes_mm = {2.0, 1.0, 0.5};
  std::vector<field::Interpolation> interpolations = {field::Interpolation::Trilinear,
                                                      field::Interpolation::Quadratic};
  std::vector<field::StoredQuantity> stored = {field::StoredQuantity::Force,
                                               field::StoredQuantity::PlaneRatio};
  /// Per voxel size (same order, same count, or empty): a refinement tolerance (fraction) for
  /// an extra variant of that size, trilinear, for each stored quantity; 0 adds none.
  std::vector<double> refine_tolerances;
  int refine_levels = 2;  ///< levels below the voxel size the refined variants may go
  /// Where each voxel variant's nodes are built (issue 15): every voxel variant runs once per
  /// entry, named with it ("... [reference build]"), e.g. {Reference, Cpu} puts the old
  /// per-node build beside the block build. Empty: once, FieldBackend::Auto, names unchanged.
  std::vector<field::FieldBackend> backends;
  /// Where the refined variants split cells: each refined variant once per entry (near its
  /// path, as `generate` does by default, and/or everywhere in reach).
  std::vector<field::RefineRegion> refine_regions = {field::RefineRegion::Path};
  bool brute_force = true;     ///< run the seed's every-point direct sum (slow on big scenes)
  double line_step_mm = 0.05;  ///< sampling of the study lines
  int repeats = 1;             ///< runs per variant; times are their medians
  common::Progress progress;   ///< "brute force", "direct", "voxel 2 mm ...", "errors"
};

/// Force error of one variant on one point set (relative, see the file comment), as fractions.
struct ForceError {
  field::FieldError relative;  ///< |ΔF| / |F_d| where |F_d| >= floor
  double max_scaled = 0.0;     ///< max |ΔF| / max |F_d| over the set
  double rms_scaled = 0.0;
};

/// One row of study.csv.
struct StudyRow {
  StudyVariant variant;
  /// Why the variant's path could not be made (e.g. the axis left the scene's limits), else "";
  /// its times, tilts and clearance are then NaN, its force errors still measured.
  std::string failure;
  std::size_t active_nodes = 0;     ///< voxel nodes holding a value (0 for direct methods)
  std::size_t dense_box_nodes = 0;  ///< nodes of a dense grid over their bounding box
  std::size_t voxel_memory_bytes = 0;
  std::size_t refined_nodes = 0;   ///< of active_nodes, those of the finer levels
  int levels = 0;                  ///< voxel grid levels built (1: uniform)
  pathgen::StageTimes times;       ///< of generatePath for this variant
  double total_s = 0.0;            ///< field_s + steering_s: what the seed's "temps total" counts
  double speedup_vs_brute = 0.0;   ///< brute total / this total; NaN when brute force was skipped
  double speedup_vs_direct = 0.0;  ///< indexed direct total / this total
  double path_speedup_vs_direct = 0.0;  ///< indexed direct path (steering) / this path
  ForceError line_a, line_b, nodes;
  ForceError moment;  ///< of τ = Σ (x_i - C) × F(x_i) per posture of the direct path
  double tilt_max_deg = 0.0, tilt_rms_deg = 0.0;  ///< |tilt - tilt_direct| over every posture
  double tilt_middle_max_deg = 0.0;  ///< the same over the middle pass (seed 004 Table 2's)
  double min_clearance_mm = 0.0;     ///< FCL, of this variant's path
  std::size_t colliding = 0;
  double max_tilt_deg = 0.0;             ///< largest |tilt| of the path
  long solver_steps = 0, rhs_evals = 0;  ///< CVODE, all passes: a rough field costs steps
};

/// Whether a row's path went under the required clearance or collided (the FCL check of its
/// postures): its speed is no answer (a study named a 2 mm quadratic variant's path at 0.391 mm,
/// required 0.5, beside the others unflagged). False for a row whose path failed (NaN).
inline bool underClearance(const StudyRow& row, double clearance_mm) {
  return row.failure.empty() && (row.colliding > 0 || row.min_clearance_mm < clearance_mm);
}

/// A study line: points, the exact field along it and each variant's field.
struct StudyLine {
  std::string name;  ///< "a" or "b"
  std::string description;
  std::vector<double> t_mm;  ///< arc length from the start
  std::vector<Vec3> points_mm;
  std::vector<double> wall_distance_mm;  ///< to the nearest obstacle (FCL)
  std::vector<double> direct_magnitude;  ///< |F_d|
  /// Per row (same order as StudyResult::rows): |F_v| at each point.
  std::vector<std::vector<double>> magnitude;
  /// Per row: relative error at each point, NaN where it is not counted (floor, clearance).
  std::vector<std::vector<double>> relative_error;
};

struct StudyResult {
  std::vector<StudyRow> rows;  ///< brute force (if run), direct, then voxel variants
  StudyLine line_a, line_b;
  int middle_pass = 0;                        ///< 0-based, the pass of tilt.csv
  std::vector<double> tilt_s_mm;              ///< arc length along the middle pass
  std::vector<std::vector<double>> tilt_deg;  ///< per row, tilt along the middle pass
  std::size_t postures = 0, tool_nodes = 0, obstacle_points = 0, node_points = 0;
  double path_length_mm = 0.0;
  double reach_box_cm3 = 0.0;  ///< volume of the region the voxels cover (direct run's box)
  double clearance_mm = 0.0;
  int repeats = 1;           ///< runs per variant behind each time (medians)
  field::FieldParams field;  ///< r0, r_min, ... of the scene
};

/// Runs every variant. Throws common::InputError for bad settings (empty or non-positive
/// --voxels), and what generatePath throws.
StudyResult runStudy(const StudyRequest& request);

/// Writes study.csv, study.md, lines.csv and tilt.csv into `dir` (each atomically).
/// `command_line` and `machine` are recorded in study.md.
void writeStudy(const StudyResult& result, const std::filesystem::path& dir,
                const std::string& command_line, const std::string& machine);

/// Renders speed_vs_error.png, tilt_along_path.png and force_error_lines.png from the CSVs with
/// scripts/plot_study.py, compiled in and run by python3 (/usr/bin's, else PATH's) + matplotlib,
/// without a shell. Returns false with `message` set if python3 or matplotlib is missing or the
/// script fails (the last line it wrote).
bool plotStudy(const std::filesystem::path& dir, std::string* message);

/// "2,1,0.5" → {2, 1, 0.5}; "trilinear,quadratic" → interpolations. Throw InputError naming `key`.
/// "7.5,2.5,0.5" (percent) → refinement tolerances as fractions, one per voxel size (`sizes`
/// of them); 0 is allowed (no refined variant of that size). Throws InputError naming `key`.
std::vector<double> parseRefineTolerances(const std::string& text, std::size_t sizes,
                                          const std::string& key);
std::vector<double> parseVoxelSizes(const std::string& text, const std::string& key);
std::vector<field::Interpolation> parseInterpolations(const std::string& text,
                                                      const std::string& key);
/// "force,plane_ratio" → what the voxel nodes store. Throws InputError naming `key`.
std::vector<field::StoredQuantity> parseStored(const std::string& text, const std::string& key);
/// "reference,cpu" → voxel node builds (auto, cpu, cuda, reference), each once. Throws
/// InputError naming `key`.
std::vector<field::FieldBackend> parseBackends(const std::string& text, const std::string& key);
/// "path", "reach" or both, comma-separated (study --refine-region); InputError naming `key`.
std::vector<field::RefineRegion> parseRefineRegions(const std::string& text,
                                                    const std::string& key);
/// "auto", "cpu", "cuda", "reference".
const char* backendName(field::FieldBackend backend);

}  // namespace fieldpath::app
