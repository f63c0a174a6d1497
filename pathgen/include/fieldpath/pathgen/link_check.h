#pragma once
/// The links of a path against the machined part (DESIGN.md "Links and motion"): links are rapid
/// moves, so the tool + holder must not touch the part anywhere on them. The obstacles are checked
/// for every posture and motion by ClearanceChecker; the part is not an obstacle (the ball cuts
/// it during a pass), so the links are checked against it here.
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/cutter_part.h"

namespace fieldpath::pathgen {

struct LinkPartResult {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  std::size_t postures = 0;  ///< link postures checked
  std::size_t motions = 0;   ///< motions between two link postures checked
  std::size_t colliding_postures = 0, colliding_motions = 0;
  std::size_t first_colliding_posture = npos;  ///< index in the path
  std::size_t first_colliding_motion = npos;   ///< motion i: posture i → i + 1
  /// Lower bound of tool + holder ↔ part over the checked postures and motions, mm.
  double min_clearance_mm = std::numeric_limits<double>::infinity();
  /// Every colliding posture and motion (path indices, ascending): what `view` colours and
  /// `check`'s clearance.csv marks.
  std::vector<std::size_t> posture_contacts, motion_contacts;
  bool collides() const { return colliding_postures + colliding_motions > 0; }
};

/// How deep (mm) the moves out of and into a pass may graze the part: they start or end where
/// the ball cuts, and slide along a wall the ball finishes (tangent to it all the way up).
inline constexpr double kPassGrazeMm = 0.1;

/// What the part's checks (checkAgainstPart) keep from one check of a path for the next: generate
/// checks its path again after each repair, and most of it was checked before, bit for bit. One
/// memo a checker: the tool + holder at the links, the grazing moves, the holder; and the cutter.
/// Kept for one part, tool, holder and gouge tolerance: checkAgainstPart empties it for another.
class PartMemo {
 public:
  ClearanceMemo links, grazing, holder;
  CutterMemo cutter;
  /// Postures and motions given back so far, not measured or tested again.
  std::size_t reused() const {
    return links.reused() + grazing.reused() + holder.reused() + cutter.reused();
  }
  /// Drops what the checks since the last call did not use (ClearanceMemo::forgetUnused).
  void forgetUnused();
  /// Empties the memos where the part, tool, holder or tolerance is not the one they were filled
  /// for.
  void useFor(const std::shared_ptr<const ObstacleModel>& part, const geometry::ToolSpec& tool,
              const geometry::HolderProfile& profile, double tolerance_mm);

 private:
  std::shared_ptr<const ObstacleModel> part_;  // held: another model at its address is another
  geometry::ToolSpec tool_;
  geometry::HolderProfile holder_;
  double tolerance_mm_ = -1.0;
};

/// The checker of the moves out of and into passes (checkLinksAgainstPart): tool and holder
/// shrunk by `shrink_mm` all round (kPassGrazeMm, or half the corner radius of a smaller tool)
/// against the part; its poses have the tip `shrink_mm` up the axis (the ball's centre kept).
struct GrazingChecker {
  ClearanceChecker checker;
  double shrink_mm;
};
GrazingChecker grazingPartChecker(const geometry::ToolSpec& tool,
                                  const geometry::HolderProfile& holder,
                                  const geometry::TriangleMesh& part);
/// The grazing checker's holder: `by_mm` thinner (at most half of each radius), its top 2 by_mm
/// lower (cut on the profile); empty where less than two stations are left.
geometry::HolderProfile thinnerHolder(const geometry::HolderProfile& holder, double by_mm);
/// The same against the part prepared once (prepareObstacle).
GrazingChecker grazingPartChecker(const geometry::ToolSpec& tool,
                                  const geometry::HolderProfile& holder,
                                  const std::shared_ptr<const ObstacleModel>& part);

/// Every posture of the path's link blocks and every motion between two of them, against
/// `part` (a ClearanceChecker of the tool + holder whose only obstacle is the part mesh), and
/// the motions from a pass's last posture into its link and from a link into the next pass's
/// first posture against `grazing` (grazingPartChecker): they start or end where the ball cuts
/// the part, so they may touch it, not enter it by more than kPassGrazeMm (a retract along an
/// axis leaning over a fin of the part did). Link postures at a pass's first or last posture
/// (a path written with no retract) are that pass's. `progress` after each link.
/// `contacts_only`: each motion refined only until it is certified clear or touches (its bound
/// then loose): what a way being chosen needs (rerouteLinkEnds: 53 ms a way told to 10 %).
/// `memo`: its `links` and `grazing` memos used and filled (the same checkers each time).
LinkPartResult checkLinksAgainstPart(const ClearanceChecker& part, const GrazingChecker& grazing,
                                     const geometry::PathFile& path,
                                     const common::Progress& progress = {},
                                     bool contacts_only = false, PartMemo* memo = nullptr);

/// The holder (geometry::holderMesh) against the part at every posture and every motion of the
/// path, passes and links. The holder never cuts: touching the part anywhere is a crash, also
/// where the ball cuts (a holder swinging into a wall of the part beside the pass, which the
/// Z-buffer of the ball's region never sees). Counted in the same fields as the links'; nothing
/// (nullopt) when there is no holder.
std::optional<LinkPartResult> checkHolderAgainstPart(const geometry::ToolSpec& tool,
                                                     const geometry::HolderProfile& holder,
                                                     const geometry::TriangleMesh& part,
                                                     std::span<const geometry::Posture> postures);
/// The same against the part prepared once (prepareObstacle), reporting to `progress`; `memo`
/// for its motions (its postures are measured for the minimum only: not kept).
std::optional<LinkPartResult> checkHolderAgainstPart(
    const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
    const std::shared_ptr<const ObstacleModel>& part, std::span<const geometry::Posture> postures,
    const common::Progress& progress = {}, ClearanceMemo* memo = nullptr);

/// What a path must not do to the part, as generate, check and view all check it: its links
/// (checkLinksAgainstPart, when it has link blocks), its holder (checkHolderAgainstPart, when
/// there is one), each nullopt when not checked, and its cutter entering the part deeper than
/// the gouge tolerance (checkCutterAgainstPart; a flat end: nullopt).
/// Where a ball end mill's passes keep the ball farther than farFromPartMm from the part: they cut
/// nothing there (a part turned 90 deg under a raster: 22 of 31 passes beside it read `ok`; a
/// path in inches over the impeller's hub hovered over a sliver of it: a units adversary's).
struct FarFromPart {
  /// The passes (the path's pass blocks, numbered from 1) far at every posture, and the first
  /// posture of the first of them.
  std::vector<std::size_t> passes;
  std::size_t first_posture = 0;
  std::size_t postures = 0;       ///< the pass postures far from the part
  std::size_t pass_postures = 0;  ///< of these
};

struct PartContacts {
  std::optional<LinkPartResult> links, holder;
  std::optional<CutterPartResult> cutter;
  /// A ball end mill: the least distance (mm) from its ball at the passes' postures to the part,
  /// exact under kReachesPartMm (a lower bound above it): whether the tool reaches the part
  /// where the Z-buffer, looking down, may see no line (a wall finished with a tilted ball).
  std::optional<double> ball_part_mm;
  /// A ball end mill: where its ball stays farther than farFromPartMm from the part.
  FarFromPart far;
  /// Per posture of a path of n: 1 where the links, the holder or the cutter touch the part there
  /// (posture) or on the motion to the next (motion), from the results' contact lists.
  struct Marks {
    std::vector<std::uint8_t> posture, motion;
  };
  Marks marks(std::size_t n) const;
};
/// The ball within this of the part (mm) reaches it: the mesh's chord on a fine part.
inline constexpr double kReachesPartMm = 0.05;
PartContacts checkAgainstPart(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                              const geometry::TriangleMesh& part, const geometry::PathFile& path,
                              double gouge_tolerance_mm = kGougeToleranceMm,
                              const common::Progress& progress = {});
/// The same with the part's model already prepared (prepareObstacle): generate checks its path
/// again after each repair and the repairs check against the part too, one model for them all.
/// `ball_exact_below_mm`: ball_part_mm exact under it (kReachesPartMm at least). `memo`: what
/// the checks before it (of the same tool, holder and part) found, used and filled; the results
/// are those of a check without it.
PartContacts checkAgainstPart(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                              const std::shared_ptr<const ObstacleModel>& part,
                              const geometry::PathFile& path,
                              double gouge_tolerance_mm = kGougeToleranceMm,
                              const common::Progress& progress = {},
                              double ball_exact_below_mm = kReachesPartMm,
                              PartMemo* memo = nullptr);

}  // namespace fieldpath::pathgen
