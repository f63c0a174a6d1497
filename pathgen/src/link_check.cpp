/// pathgen/link_check.h: the links of a path against the part.
#include "fieldpath/pathgen/link_check.h"

#include <algorithm>
#include <span>
#include <vector>

#include "fieldpath/pathgen/generate.h"  // kClearanceMeshTolMm

namespace fieldpath::pathgen {

namespace {

/// The tip's travel (mm) at the pass's end of a move out of (into) it that is left out: there the
/// ball leaves (reaches) the surface it cuts. Past it a ball leaving at up to 78° to the surface's
/// normal is clear of it by more than the tool mesh's chordal tolerance (0.1 cos 78° > 0.02).
constexpr double kPassContactMm = 0.1;

/// The motion a → b against the part but for its first kPassContactMm of tip travel
/// (`from_start`) or its last (a pure turn, with no tip travel, is left out whole): counted in
/// `out` as motion `index`.
void checkPartOfMove(const ClearanceChecker& part, const geometry::Posture& a,
                     const geometry::Posture& b, bool from_start, std::size_t index,
                     LinkPartResult& out) {
  const double travel_mm = (b.tip_mm - a.tip_mm).norm();
  if (!(travel_mm > kPassContactMm)) return;
  const double skip = kPassContactMm / travel_mm;
  const std::vector<geometry::Posture> piece =
      from_start ? std::vector<geometry::Posture>{geometry::alongMotion(a, b, skip), b}
                 : std::vector<geometry::Posture>{a, geometry::alongMotion(a, b, 1.0 - skip)};
  const MotionResult m = part.checkMotions(piece, MotionRequest{});  // required 0: touching
  // Counted, but not in the links' minimum: it starts 0.1 mm off the cut surface by design.
  out.motions += 1;
  if (m.colliding) {
    ++out.colliding_motions;
    out.first_colliding_motion = std::min(out.first_colliding_motion, index);
  }
}

}  // namespace

LinkPartResult checkLinksAgainstPart(const ClearanceChecker& part, const geometry::PathFile& path) {
  LinkPartResult out;
  const auto& all = path.postures;
  auto same = [&](std::size_t i, std::size_t j) { return geometry::samePose(all[i], all[j]); };
  for (geometry::PathBlock block : path.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Link) continue;
    // A link posture where the pass beside it starts or ends (links.retract: 0) is that pass's:
    // the ball cuts there.
    if (block.begin > 0 && block.begin < block.end && same(block.begin, block.begin - 1)) ++block.begin;
    if (block.end < all.size() && block.begin < block.end && same(block.end - 1, block.end)) --block.end;
    if (block.size() == 0) continue;
    // The moves out of the pass before and into the pass after (a retract along a tool axis
    // leaning over a wall of the part drove the ball into it), but where the ball cuts.
    if (block.begin > 0)
      checkPartOfMove(part, all[block.begin - 1], all[block.begin], true, block.begin - 1, out);
    if (block.end < all.size())
      checkPartOfMove(part, all[block.end - 1], all[block.end], false, block.end - 1, out);
    const std::span<const geometry::Posture> postures(all.data() + block.begin, block.size());
    const ClearanceResult c = part.check(postures);
    out.postures += c.postures;
    out.min_clearance_mm = std::min(out.min_clearance_mm, c.min_clearance_mm);
    out.colliding_postures += c.colliding;
    if (c.colliding && out.first_colliding_posture == LinkPartResult::npos)
      out.first_colliding_posture = block.begin + c.first_colliding;
    if (block.size() < 2) continue;
    MotionRequest request;  // touching is what counts here: required 0
    request.posture_clearance_mm = c.clearance_mm;
    const MotionResult m = part.checkMotions(postures, request);
    out.motions += m.motions;
    out.min_clearance_mm = std::min(out.min_clearance_mm, m.min_clearance_mm);
    out.colliding_motions += m.colliding;
    if (m.colliding)
      out.first_colliding_motion =
          std::min(out.first_colliding_motion, block.begin + m.first_colliding);
  }
  return out;
}

std::optional<LinkPartResult> checkHolderAgainstPart(const geometry::ToolSpec& tool,
                                                     const geometry::HolderProfile& holder,
                                                     const geometry::TriangleMesh& part,
                                                     std::span<const geometry::Posture> postures) {
  const geometry::TriangleMesh holder_mesh = geometry::holderMesh(tool, holder, kClearanceMeshTolMm);
  if (holder_mesh.triangles.empty() || postures.empty()) return std::nullopt;
  const ClearanceChecker holder_part(holder_mesh, std::span(&part, 1), kClearanceMeshTolMm);
  LinkPartResult out;
  const ClearanceResult c = holder_part.check(postures, {});
  out.postures = c.postures;
  out.min_clearance_mm = c.min_clearance_mm;
  out.colliding_postures = c.colliding;
  out.first_colliding_posture = c.first_colliding;
  MotionRequest request;  // touching is what counts: required 0
  request.posture_clearance_mm = c.clearance_mm;
  const MotionResult m = holder_part.checkMotions(postures, request);
  out.motions = m.motions;
  out.min_clearance_mm = std::min(out.min_clearance_mm, m.min_clearance_mm);
  out.colliding_motions = m.colliding;
  out.first_colliding_motion = m.first_colliding;
  return out;
}

}  // namespace fieldpath::pathgen
