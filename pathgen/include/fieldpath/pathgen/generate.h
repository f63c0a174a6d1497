#pragma once
/// The whole job of `fieldpath generate` on the impeller, as a library call (the CLI, the tests and
/// the benchmark share it): passes → field (direct or voxels) → steered tool axis per pass →
/// exact clearance of every posture.
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/common/progress.h"
#include "fieldpath/dynamics/params.h"
#include "fieldpath/field/params.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/params.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::field {
class VoxelField;
}

namespace fieldpath::pathgen {

/// BruteForce: every obstacle point for every node (seed 004's direct method; the study's timing
/// peer).
enum class FieldMode { Voxel, Direct, BruteForce };

/// The two names of a FieldMode, written once: `id` as report.json and study.csv write it,
/// `label` for tables and plots (the study prefixes a voxel variant's size and settings).
struct FieldModeNames {
  const char* id;
  const char* label;
};

constexpr FieldModeNames fieldModeNames(FieldMode mode) {
  switch (mode) {
    case FieldMode::Voxel:
      return {"voxel", "voxel"};
    case FieldMode::Direct:
      return {"direct", "direct"};
    case FieldMode::BruteForce:
      return {"brute_force", "brute force"};
  }
  return {"?", "?"};
}

struct GenerateRequest {
  ImpellerParams impeller;
  /// Obstacles besides the impeller's two blades (world frame, mm), e.g. scene `- mesh:` entries.
  std::vector<geometry::TriangleMesh> extra_obstacles;
  PathParams path;
  field::FieldParams field;
  dynamics::DynamicsParams dynamics;
  geometry::ToolSpec tool;
  geometry::HolderProfile holder;
  double clearance_mm =
      0.5;  ///< required min distance tool + holder ↔ obstacles (reported against)
  FieldMode mode = FieldMode::Voxel;
  /// Nominal path: the axis stays on the nominal angles (no field, no dynamics).
  bool nominal = false;
  /// Hand the voxel field the path was steered by back in GenerateResult::voxels (the study
  /// measures its error without building it a second time).
  bool keep_voxels = false;
  common::Progress progress;  ///< "field", "pass k/n", "clearance"
};

/// One output posture with what the dynamics and the clearance check say about it.
struct GeneratedPosture {
  int pass = 0;       ///< 0-based
  double s_mm = 0.0;  ///< arc length along the pass
  double lead_rad = 0.0, tilt_rad = 0.0;
  double moment = 0.0;        ///< |M| of the field about the ball centre (0 for the nominal path)
  double clearance_mm = 0.0;  ///< exact (FCL) nearest distance to the obstacles; 0 if colliding
  geometry::Posture posture;
};

/// Seconds per stage (steady clock).
struct StageTimes {
  double setup_s = 0, field_s = 0, steering_s = 0, clearance_s = 0, total_s = 0;
};

struct GenerateResult {
  std::vector<GeneratedPosture> postures;  ///< all passes, in order
  std::vector<Pass> passes;
  ClearanceResult clearance;
  StageTimes times;
  std::size_t obstacle_points = 0;  ///< field samples
  std::size_t tool_nodes = 0;       ///< tool + holder nodes of the moment
  std::size_t tool_triangles = 0;   ///< of the clearance mesh
  std::size_t voxel_nodes = 0;      ///< active nodes (voxel mode)
  std::size_t voxel_memory_bytes = 0;
  /// The voxel field of the path (voxel mode with GenerateRequest::keep_voxels), else null.
  std::shared_ptr<const field::VoxelField> voxels;
  Eigen::AlignedBox3d reach_box_mm;  ///< region of the voxels: what tool + holder can reach
  double path_length_mm = 0;         ///< sum of the pass lengths (ball centre)
  double max_tilt_deg = 0, max_lead_deg = 0;  ///< largest |angle| on the path
  long solver_steps = 0, rhs_evals = 0, jacobian_evals = 0, error_test_failures = 0,
       convergence_failures = 0;
};

/// Tool + holder nodes for the moments: spacing from the tool size so that a seed-like tool and
/// holder get ≈ 500 nodes.
double defaultNodeSpacingMm(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder);

/// Runs the job. Throws common::InputError for bad settings (naming the key), for a pass whose
/// ball comes closer to a blade than `clearance` ("pass 2 (v = ...): ... channel narrower than the
/// ball"), and when the dynamics leaves its limits (naming the pass and arc length).
GenerateResult generateImpellerPath(const GenerateRequest& request);

/// The obstacles of a job: the impeller's blades (0 = left, 1 = right), then the extra ones.
std::vector<geometry::TriangleMesh> obstacleMeshes(
    const Impeller& impeller, const std::vector<geometry::TriangleMesh>& extra = {});

/// Chordal tolerance of the tool + holder mesh used for the exact clearance, mm.
inline constexpr double kClearanceMeshTolMm = 0.02;

}  // namespace fieldpath::pathgen
