#pragma once
/// The cutter against the part, exactly (`check`, `generate`, `view`; DESIGN.md "Links and
/// motion"). The Z-buffer's lines are vertical and a spacing apart: a shank driven into a wall of
/// the part by less than a spacing can fall between them (0.02 mm into a wall at the default
/// 0.05 mm went unseen). Here the cutter, shrunk all round by the gouge tolerance, is tested
/// against the part's triangles (and, for a closed part, its inside) at every posture and at
/// stamps along every motion: a ball tool as its ball and its shank, FCL's sphere and cylinder
/// (exact surfaces, not tessellated); a torus tool as its corner (the slab over its disc, FCL's
/// cylinder; the ring around it, the part's triangles there each measured from the disc by GJK)
/// and its shank.
#include <cstddef>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/common/progress.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/pathgen/clearance.h"  // ObstacleModel, prepareObstacle

namespace fieldpath::pathgen {

/// Depth under the part that counts as a gouge by default, mm (`check --gouge-tol`, in µm). The
/// part is a mesh: where it is concave its facets lie above the true surface by up to its chordal
/// error, so an exact cut reads as a shallow entry.
inline constexpr double kGougeToleranceMm = 0.005;
/// The depth of the deepest entry is found to this, mm (bisection on the shrink).
inline constexpr double kGougeDepthResolutionMm = 1e-4;

struct CutterPartResult {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t stamps = 0;        ///< postures and motion stamps tested
  double tolerance_mm = 0;       ///< the shrink: entries shallower than this are not counted
  double step_mm = 0;            ///< stamps along a motion: no point of the tool moves farther
  double between_stamps_mm = 0;  ///< how much deeper an entry may be between two stamps
  std::size_t gouging_postures = 0, gouging_motions = 0;
  std::size_t first_gouging_posture = npos, first_gouging_motion = npos;
  /// The deepest entry of the cutter into the part over the stamps, mm (to
  /// kGougeDepthResolutionMm; at most the cutter's radius: a cutter wholly inside a closed part
  /// reads its radius); 0 when no stamp enters deeper than the tolerance.
  double max_depth_mm = 0;
  std::size_t deepest = npos;      ///< posture index, or motion index (from posture i to i + 1)
  bool deepest_on_motion = false;  ///< whether `deepest` is a motion
  /// Every gouging posture and motion (path indices, ascending).
  std::vector<std::size_t> posture_contacts, motion_contacts;
  bool gouges() const { return gouging_postures + gouging_motions > 0; }
};

/// The postures and motions that a cutter test found clear of the part at every stamp, kept for
/// the next test of a path changed in places (generate checks its path again after each repair:
/// the cutter's stamps were a fifth of a reversed job's time, most of them tested before). A
/// posture's stamp is itself and a motion's are set by its two ends: the same bits, the same
/// stamps, the same verdicts. Those entering the part are tested again (few, and each then
/// bisected for its depth). Kept for one part, tool and tolerance: another empties it.
class CutterMemo {
 public:
  CutterMemo();
  ~CutterMemo();
  CutterMemo(const CutterMemo&) = delete;
  CutterMemo& operator=(const CutterMemo&) = delete;
  /// Postures and motions given back from it so far, their stamps not tested again.
  std::size_t reused() const;
  /// Drops what the tests since the last call did not use (ClearanceMemo::forgetUnused).
  void forgetUnused();
  struct Impl;  ///< (cutter_part.cpp)
  Impl& impl() { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
};

/// Tests the cutter of `tool` (ball or torus; a flat end's sharp rim is not: nothing tested,
/// stamps 0), shrunk by `tolerance_mm`, against `part` at every posture and along every motion
/// that comes within the cutter's length of the part, with stamps no farther apart than
/// √(2 ρ tolerance) (ρ: the ball's R; a torus's corner r) so that an entry between two stamps is
/// at most a quarter of the tolerance deeper than at them.
CutterPartResult checkCutterAgainstPart(const geometry::ToolSpec& tool,
                                        const geometry::TriangleMesh& part,
                                        std::span<const geometry::Posture> postures,
                                        double tolerance_mm = kGougeToleranceMm,
                                        const common::Progress& progress = {});
/// Requires of the memory ledger (common::requireMemory, passing) the bytes that
/// checkCutterAgainstPart takes to test the postures of `passes` and the motions within each
/// against a part within `part_box`. `generate` asks it before the steering (at the ball centres,
/// the axis held): the steered path's turns and its links only add stamps, so a test refused at
/// the end of the job is refused before its work (33 s of a run were spent before the refusal).
void requireCutterTestMemory(const geometry::ToolSpec& tool, const Eigen::AlignedBox3d& part_box,
                             std::span<const std::vector<geometry::Posture>> passes,
                             double tolerance_mm = kGougeToleranceMm);
/// The same against the part prepared once (prepareObstacle), shared with the other checks; with
/// `memo`, the postures and motions it holds clear are not tested again, and those found clear
/// are put in it.
CutterPartResult checkCutterAgainstPart(const geometry::ToolSpec& tool,
                                        const std::shared_ptr<const ObstacleModel>& part,
                                        std::span<const geometry::Posture> postures,
                                        double tolerance_mm = kGougeToleranceMm,
                                        const common::Progress& progress = {},
                                        CutterMemo* memo = nullptr);

}  // namespace fieldpath::pathgen
