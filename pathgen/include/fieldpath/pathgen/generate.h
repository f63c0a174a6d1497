#pragma once
/// The whole job of `fieldpath generate`, as a library call (the CLI, the study, the tests and the
/// benchmark share it): passes (from the impeller or a nominal path) → field (direct or voxels) →
/// steered tool axis per pass → links → exact clearance of every posture and motion.
#include <algorithm>
#include <cstddef>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/common/progress.h"
#include "fieldpath/dynamics/params.h"
#include "fieldpath/field/params.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/impeller.h"
#include "fieldpath/pathgen/link_check.h"
#include "fieldpath/pathgen/links.h"
#include "fieldpath/pathgen/params.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::field {
class VoxelField;
class CellMask;
}  // namespace fieldpath::field

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
  /// The passes, from their source: impellerPasses() (useImpeller) or nominalPasses().
  std::vector<Pass> passes;
  /// Surfaces that repel and that nothing may touch (world frame, mm).
  std::vector<geometry::TriangleMesh> obstacles;
  /// The machined surface (never repels): counted for the links' travel plane.
  std::optional<geometry::TriangleMesh> part;
  PathParams path;  ///< lead_deg (the passes are already made)
  LinkParams links;
  field::FieldParams field;
  dynamics::DynamicsParams dynamics;
  geometry::ToolSpec tool;
  geometry::HolderProfile holder;
  double clearance_mm =
      0.5;  ///< required min distance tool + holder ↔ obstacles (reported against)
  FieldMode mode = FieldMode::Voxel;
  /// Nominal path: the axis stays on the nominal angles (no field, no dynamics).
  bool nominal = false;
  /// Skip the links and the motion check (the study compares the passes' postures only).
  bool passes_only = false;
  /// Hand the voxel field the path was steered by back in GenerateResult::voxels (the study
  /// measures its error without building it a second time).
  bool keep_voxels = false;
  /// Steer the passes one after the other on this thread (default: in parallel on all cores;
  /// the same output bit for bit).
  bool serial_passes = false;
  common::Progress progress;  ///< "field", "pass k/n", "clearance", "motions"
};

/// One output posture of a pass with what the dynamics and the clearance check say about it.
struct GeneratedPosture {
  int pass = 0;       ///< 0-based
  double s_mm = 0.0;  ///< arc length along the pass
  double lead_rad = 0.0, tilt_rad = 0.0;
  double moment = 0.0;        ///< |M| of the field about the ball centre (0 for the nominal path)
  double clearance_mm = 0.0;  ///< exact (FCL) nearest distance to the obstacles; 0 if colliding
  bool limited = false;       ///< an angle limit held here (dynamics.on_limit: clamp)
  std::size_t output = 0;     ///< index of this posture in GenerateResult::path
  geometry::Posture posture;
};

/// Seconds per stage (steady clock).
struct StageTimes {
  double setup_s = 0, field_s = 0, steering_s = 0, clearance_s = 0, total_s = 0;
  /// Of field_s: refinement near the path's first steps (the uniform grid, the passes steered
  /// on it, the cells their nodes went through).
  double near_path_s = 0;
};

/// Passes whose ball comes no nearer the part than this anywhere (mm) never finish it: a path in
/// another frame or units (an inch CAM file over a part in mm), or for another part.
inline double farFromPartMm(double ball_radius_mm) { return std::max(5.0, 2.0 * ball_radius_mm); }

struct GenerateResult {
  std::vector<GeneratedPosture> postures;  ///< the passes' postures, in order
  std::vector<Pass> passes;
  /// The output path: passes joined by links (blocks), postures flagged where a limit held.
  geometry::PathFile path;
  ClearanceResult clearance;  ///< of every posture of `path` (links included)
  MotionResult motions;       ///< of every motion of `path`
  /// The links against the part (when the job has one and links): rapid moves must not touch it.
  std::optional<LinkPartResult> link_part;
  /// The holder against the part at every posture and motion (when the job has a part and a
  /// holder): it never cuts, so touching is a crash.
  std::optional<LinkPartResult> holder_part;
  /// The cutter against the part, exactly (when the job has a part and a ball or torus tool):
  /// entries deeper than kGougeToleranceMm.
  std::optional<CutterPartResult> cutter_part;
  /// A ball end mill and a part: the least distance (mm) from the passes' balls to the part,
  /// exact under farFromPartMm (a lower bound above it).
  std::optional<double> ball_part_mm;
  FarFromPart far_from_part;  ///< (a ball end mill and a part) PartContacts::far
  double safe_z_mm = 0.0;     ///< the links' travel plane
  /// A given links.safe_z below this (mm) lets the links pass within the checks' own margin of
  /// `clearance` (the tool mesh's chordal tolerance, the motions' resolution): they may read as
  /// under it though clear. 0 when safe_z is `auto` (always above it) or there are no links.
  double safe_z_proven_mm = 0.0;
  std::size_t link_postures = 0;
  std::size_t limited_postures = 0;                   ///< where dynamics.on_limit held an angle
  std::size_t limited_colliding = 0;                  ///< of those, colliding ones
  std::size_t first_limited = ClearanceResult::npos;  ///< index into `postures`
  /// Passes started from the axis settled at their start (dynamics.start: settled, or auto where
  /// the nominal start posture was within `clearance`), by Pass::index.
  std::vector<int> settled_starts;
  /// Passes whose start, settled (or nominal), still came within `clearance` and that started
  /// from the clear axis nearest the nominal one instead (itself where clear, else
  /// kClearStartStepDeg apart within the angle limits), by Pass::index.
  std::vector<int> turned_starts;
  /// Passes steered with their corners held (dynamics::SteeringRequest::hold_corners): the axis
  /// turning with the feed came under `clearance` there and holding its direction through the
  /// corners kept more, or it swung over kNoteAxisTurnDeg in a step and holding it kept the
  /// clearance and turned less. By Pass::index.
  std::vector<int> corners_held;
  /// Passes steered from their end to their start (dynamics/reversed_pass.h): steered from
  /// their start they collided or came under `clearance` (the causal axis meets the side of an
  /// obstacle the pass reaches first late: an impeller's passes reversed collided), and steered
  /// from the end the pass checked better. Written in the pass's order. By Pass::index.
  std::vector<int> steered_from_end;
  /// Passes steered from their end that checked better alone, not kept: the path linked to them
  /// was checked worse (pathFaults), and their own links and moves into and out of them
  /// (faultsAround), or the path without the others' that did, still so.
  std::size_t steered_from_end_undone = 0;
  /// Passes that were to start settled but could not (no damping, the solver failing at rest):
  /// they start from the nominal axis, or where that lies within `clearance` the clear axis
  /// nearest it (turned_starts). By Pass::index, why.
  struct SettleFailure {
    int pass = 0;
    std::string why;
  };
  std::vector<SettleFailure> settle_failures;
  /// Passes whose integrator failed and that were steered again with dynamics.rtol and atol
  /// loosened (to at least 1e-3 and 1e-6): one line each, the pass, CVODE's words, the tolerances.
  std::vector<std::string> loosened_solver;
  /// Passes whose ball (its centre is held: only the axis turns) comes within `clearance` of an
  /// obstacle without touching it: no axis can clear that, so the job goes on and the path is
  /// marked under the required clearance (it refused the whole job over 0.0001 mm of a mesh's
  /// rounding). A ball that touches an obstacle is refused (the pass runs through it).
  struct BallUnderClearance {
    int pass = 0;       ///< Pass::index
    std::string label;  ///< the pass and its line
    double s_mm = 0, clearance_mm = 0;
    int obstacle = 0;  ///< 0-based
  };
  std::vector<BallUnderClearance> balls_under_clearance;
  /// Passes that collided steered (with the obstacles, or the holder or the cutter with the
  /// part) and are written with their nominal axes, which clear them at every posture and motion
  /// (the part never repels: steering away from an obstacle can drive the holder into it); and
  /// passes that came under the required clearance steered, written with nominal axes that come
  /// less near the obstacles at every posture and motion than the steered pass's nearest.
  struct KeptNominal {
    int pass = 0;                       ///< Pass::index
    std::string label;                  ///< the pass and its line
    /// Postures of the steered pass that collided there or on the move to the pass's next.
    std::size_t steered_colliding = 0;
    /// Postures of the steered pass that came under the required clearance there or on the move
    /// to the pass's next, without colliding.
    std::size_t steered_under = 0;
  };
  std::vector<KeptNominal> kept_nominal;
  /// Passes whose nominal axes cleared them but were not kept: the path linked to them was
  /// checked worse than the steered one (pathFaults), and is not written.
  std::size_t kept_nominal_undone = 0;
  /// Link ends taken off the pass's axis (DESIGN's way: up and down the axis): where the link
  /// along the axis collided or came under the required clearance, a way up from the pass
  /// nearer the vertical, the axis held, that came clearer (a pass settled at 34 deg tilt in a
  /// channel: its link came down the leaning axis through the channel's wall). rerouteLinkEnds.
  struct RoutedLinkEnd {
    int pass = 0;               ///< Pass::index
    std::string label;          ///< the pass and its line
    bool into = true;           ///< the way into the pass (else out of it)
    geometry::Vec3 way;         ///< unit, the climb from the retract up to the travel plane
    bool retract_along_axis = false;  ///< the retract along the axis (else along `way` too)
    double retract_mm = 0.0;          ///< its length (links.retract, or shorter: LinkEndWay)
    geometry::Vec3 sideways_mm = geometry::Vec3::Zero();  ///< a move sideways before the climb
    /// The climb's length along `way` before straight up (infinite: to the travel plane).
    double climb_mm = std::numeric_limits<double>::infinity();
    double off_axis_deg = 0.0;  ///< the way's angle from the axis
    /// Collisions (postures and motions, obstacles and part) of the way along the axis (the way
    /// taken has none), and the least clearance of the obstacles (mm) of both, from the pass's
    /// posture (its own clearance not counted) to the travel plane.
    std::size_t axis_collisions = 0;
    double axis_min_mm = 0.0, taken_min_mm = 0.0;
  };
  std::vector<RoutedLinkEnd> routed_link_ends;
  /// Link ends a way off the axis cleared, not kept: the path linked that way was checked worse
  /// (pathFaults) than the one along the axes.
  std::size_t routed_link_ends_undone = 0;
  /// Link ends that collide or come under the clearance every straight way up tried (a pass deep
  /// under an overhang): "the way into pass 2 (nominal.cl:44)".
  std::vector<std::string> unfreed_link_ends;
  StageTimes times;
  std::size_t obstacle_points = 0;  ///< field samples
  std::size_t tool_nodes = 0;       ///< tool + holder nodes of the moment
  std::size_t tool_triangles = 0;   ///< of the clearance mesh
  std::size_t voxel_nodes = 0;      ///< active nodes (voxel mode)
  std::size_t voxel_memory_bytes = 0;
  /// Field evaluations (node positions) of the steering that fell outside where the voxels
  /// answer (the reach box; refined near the path: near the first path's nodes) and were
  /// answered by the exact sum (voxel mode).
  std::size_t voxel_outside_points = 0;
  /// Open obstacle sheets whose normals faced away from the passes, turned to face them before
  /// sampling (the field pushes along the normals).
  std::size_t turned_sheets = 0;
  /// The voxel field of the path (voxel mode with GenerateRequest::keep_voxels), else null.
  std::shared_ptr<const field::VoxelField> voxels;
  /// With `voxels`, refined near the path: the cells the voxels answer in (CellMask::inCore),
  /// the exact field beyond (as the steering read them: field::RegionField); else null.
  std::shared_ptr<const field::CellMask> refine_mask;
  Eigen::AlignedBox3d reach_box_mm;  ///< region of the voxels: what tool + holder can reach
  double path_length_mm = 0;         ///< sum of the pass lengths (ball centre)
  double max_tilt_deg = 0, max_lead_deg = 0;  ///< largest |angle| on the path
  long solver_steps = 0, rhs_evals = 0, jacobian_evals = 0, error_test_failures = 0,
       convergence_failures = 0;
};

/// Tool + holder nodes for the moments: spacing from the tool size so that a seed-like tool and
/// holder get ≈ 500 nodes.
double defaultNodeSpacingMm(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder);

/// Runs the job: field, steering pass by pass, links, clearance of every posture and motion.
/// Throws common::InputError for bad settings (naming the key), for a pass whose ball comes
/// closer to an obstacle than `clearance` ("pass 2 (...): ... narrower than the ball"), and,
/// with dynamics.on_limit: fail, when the dynamics leaves its limits (naming the pass and arc
/// length).
GenerateResult generatePath(const GenerateRequest& request);

/// The impeller's two blades (0 = left, 1 = right).
std::vector<geometry::TriangleMesh> bladeMeshes(const Impeller& impeller);

/// The grid of (lead, tilt) searched for a clear start, degrees (GenerateResult::turned_starts).
inline constexpr double kClearStartStepDeg = 5.0;

/// Chordal tolerance of the tool + holder mesh used for the exact clearance, mm, at most
/// (clearanceMeshTolMm).
inline constexpr double kClearanceMeshTolMm = 0.02;

/// The chordal tolerance of the tool + holder mesh of the exact clearance, mm: kClearanceMeshTolMm,
/// or 1/150 of the smallest radius of tool and holder where that is less (the same relative
/// error as a 3 mm ball at 0.02 mm: a 0.1 mm micro ball at 0.02 read every clearance 0.02 mm short,
/// a required 0.02 mm failed at every posture, a helper's). The checks subtract it.
inline double clearanceMeshTolMm(const geometry::ToolSpec& tool,
                                 const geometry::HolderProfile& holder) {
  double smallest = tool.radius_mm;
  if (tool.shape == geometry::ToolShape::Torus)
    smallest = std::min(smallest, tool.corner_radius_mm);
  for (const geometry::HolderStation& s : holder) smallest = std::min(smallest, s.radius_mm);
  return smallest > 0.0 ? std::min(kClearanceMeshTolMm, smallest / 150.0) : kClearanceMeshTolMm;
}

}  // namespace fieldpath::pathgen
