/// pathgen/link_check.h: the links of a path against the part.
#include "fieldpath/pathgen/link_check.h"

#include "fieldpath/pathgen/generate.h"  // kClearanceMeshTolMm

#include <algorithm>
#include <span>

namespace fieldpath::pathgen {

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
    if (m.colliding && out.first_colliding_motion == LinkPartResult::npos)
      out.first_colliding_motion = block.begin + m.first_colliding;
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
