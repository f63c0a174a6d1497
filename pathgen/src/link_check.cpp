/// pathgen/link_check.h: the links of a path against the part.
#include "fieldpath/pathgen/link_check.h"

#include <algorithm>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "fieldpath/pathgen/generate.h"  // kClearanceMeshTolMm

namespace fieldpath::pathgen {

namespace {

/// How close to the links' true minimum against the part their reported bound is (fraction).
constexpr double kLinkTightenFraction = 0.1;

/// The motion a → b against the shrunk tool, each pose's tip `shrink_mm` up its axis (the shrunk
/// ball's centre is the ball's): counted in `out` as motion `index`.
void checkGrazingMove(const GrazingChecker& grazing, const geometry::Posture& a,
                      const geometry::Posture& b, std::size_t index, LinkPartResult& out,
                      const MotionRequest& request) {
  std::vector<geometry::Posture> move = {a, b};
  for (geometry::Posture& p : move) p.tip_mm += grazing.shrink_mm * p.axis;
  const MotionResult m = grazing.checker.checkMotions(move, request);
  // Counted, but not in the links' minimum (it is the shrunk tool's).
  out.motions += 1;
  if (m.colliding) {
    ++out.colliding_motions;
    out.first_colliding_motion = std::min(out.first_colliding_motion, index);
    out.motion_contacts.push_back(index);
  }
}

/// The colliding entries of `clearance_mm` (per posture or per motion, d <= 0 as the checker
/// counts them), as path indices from `first`, appended to `to`.
void addContacts(const std::vector<double>& clearance_mm, std::size_t first,
                 std::vector<std::size_t>& to) {
  for (std::size_t k = 0; k < clearance_mm.size(); ++k)
    if (clearance_mm[k] <= 0.0) to.push_back(first + k);
}

/// The contact lists ascending, each index once (a grazing move can also be a link's motion).
void sortContacts(LinkPartResult& out) {
  for (std::vector<std::size_t>* list : {&out.posture_contacts, &out.motion_contacts}) {
    std::sort(list->begin(), list->end());
    list->erase(std::unique(list->begin(), list->end()), list->end());
  }
}

}  // namespace

geometry::HolderProfile thinnerHolder(const geometry::HolderProfile& holder, double by_mm) {
  // Thinner by `by` (but never below half its radius: a neck of 0.1 mm under a 0.1 mm graze
  // had no radius left and the job was refused), its top 2 `by` lower: the stations under the
  // new top, and one there on the profile (a last station lowered alone fell under a step at
  // the top, [90, 12], [90, 20]: "z must increase", refused). Its bottom is already `by` up
  // with the shrunk tool's tip.
  auto thinner = [by_mm](double radius_mm) { return std::max(radius_mm - by_mm, 0.5 * radius_mm); };
  geometry::HolderProfile out;
  if (holder.empty()) return out;
  const double top_mm = holder.back().z_mm - 2 * by_mm;
  for (std::size_t i = 0; i < holder.size(); ++i) {
    const geometry::HolderStation& s = holder[i];
    if (s.z_mm < top_mm) {
      out.push_back({s.z_mm, thinner(s.radius_mm)});
      continue;
    }
    if (i > 0 && holder[i - 1].z_mm < top_mm) {  // then s.z_mm > holder[i - 1].z_mm
      const geometry::HolderStation& a = holder[i - 1];
      const double f = (top_mm - a.z_mm) / (s.z_mm - a.z_mm);
      out.push_back({top_mm, thinner(a.radius_mm + f * (s.radius_mm - a.radius_mm))});
    }
    break;
  }
  if (out.size() < 2) out.clear();  // a holder shorter than 2 `by`: none left to graze
  return out;
}

GrazingChecker grazingPartChecker(const geometry::ToolSpec& tool,
                                  const geometry::HolderProfile& holder,
                                  const geometry::TriangleMesh& part) {
  return grazingPartChecker(tool, holder, prepareObstacle(part, "part"));
}

GrazingChecker grazingPartChecker(const geometry::ToolSpec& tool,
                                  const geometry::HolderProfile& holder,
                                  const std::shared_ptr<const ObstacleModel>& part) {
  const double corner_mm = geometry::cornerRadius(tool);
  const double by = std::min(kPassGrazeMm, 0.5 * (corner_mm > 0.0 ? corner_mm : tool.radius_mm));
  // In the shrunk tool's frame (its tip `by` up the axis) every surface lies `by` inside.
  geometry::ToolSpec shrunk = tool;
  shrunk.radius_mm -= by;
  if (shrunk.shape == geometry::ToolShape::Torus) shrunk.corner_radius_mm -= by;
  // Its top `by` under the tool's, but never below its own cutting end (a ball as long as
  // its radius, L < R + by, was refused as too short for its end after the job's work).
  shrunk.length_mm = std::max(shrunk.length_mm - 2 * by, geometry::cornerRadius(shrunk));
  const geometry::HolderProfile thinner = thinnerHolder(holder, by);
  const double tol_mm = clearanceMeshTolMm(shrunk, thinner);
  return {
      ClearanceChecker(geometry::toolMesh(shrunk, thinner, tol_mm), std::span(&part, 1), tol_mm),
      by};
}

LinkPartResult checkLinksAgainstPart(const ClearanceChecker& part, const GrazingChecker& grazing,
                                     const geometry::PathFile& path,
                                     const common::Progress& progress, bool contacts_only,
                                     PartMemo* memo) {
  LinkPartResult out;
  // Touching is what counts: required 0. Contacts only: the lowest piece certified above 0 ends
  // a motion (a slack of its whole nearest sample).
  MotionRequest grazing_request;
  if (contacts_only) grazing_request.tighten_fraction = 1.0;
  if (memo) grazing_request.memo = &memo->grazing;
  ClearanceRequest posture_request;
  if (memo) posture_request.memo = &memo->links;
  const auto& all = path.postures;
  // Said link by link (~12 ms each: 1320 passes' links took 16 s without a word, a helper's).
  const double links = static_cast<double>(path.count(geometry::PathBlock::Kind::Link));
  double links_done = 0.0;
  auto same = [&](std::size_t i, std::size_t j) { return geometry::samePose(all[i], all[j]); };
  for (geometry::PathBlock block : path.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Link) continue;
    common::report(progress, links_done++ / std::max(1.0, links), "links vs part");
    // A link posture where the pass beside it starts or ends (a path written with no retract) is
    // that pass's: the ball cuts there.
    if (block.begin > 0 && block.begin < block.end && same(block.begin, block.begin - 1))
      ++block.begin;
    if (block.end < all.size() && block.begin < block.end && same(block.end - 1, block.end))
      --block.end;
    if (block.size() == 0) continue;
    // The moves out of the pass before and into the pass after (a retract along a tool axis
    // leaning over a fin of the part drove the ball into it): they may graze what the ball cuts.
    if (block.begin > 0)
      checkGrazingMove(grazing, all[block.begin - 1], all[block.begin], block.begin - 1, out,
                       grazing_request);
    if (block.end < all.size())
      checkGrazingMove(grazing, all[block.end - 1], all[block.end], block.end - 1, out,
                       grazing_request);
    const std::span<const geometry::Posture> postures(all.data() + block.begin, block.size());
    const ClearanceResult c = part.check(postures, posture_request);
    out.postures += c.postures;
    out.min_clearance_mm = std::min(out.min_clearance_mm, c.min_clearance_mm);
    out.colliding_postures += c.colliding;
    if (c.colliding && out.first_colliding_posture == LinkPartResult::npos)
      out.first_colliding_posture = block.begin + c.first_colliding;
    addContacts(c.clearance_mm, block.begin, out.posture_contacts);
    if (block.size() < 2) continue;
    MotionRequest request;  // touching is what counts here: required 0
    request.posture_clearance_mm = c.clearance_mm;
    if (memo) request.memo = &memo->links;
    // Its minimum told to within 10 % (a lower bound), not 1 %: a link 10 mm over a concave part
    // whose axis turns took ~150 distance queries a motion to tell 9.88 mm to 0.1 mm, and a
    // helper's 439 links on a concave cylinder did not finish in 300 s.
    request.tighten_fraction = contacts_only ? 1.0 : kLinkTightenFraction;
    const MotionResult m = part.checkMotions(postures, request);
    out.motions += m.motions;
    out.min_clearance_mm = std::min(out.min_clearance_mm, m.min_clearance_mm);
    out.colliding_motions += m.colliding;
    if (m.colliding)
      out.first_colliding_motion =
          std::min(out.first_colliding_motion, block.begin + m.first_colliding);
    addContacts(m.clearance_mm, block.begin, out.motion_contacts);
  }
  sortContacts(out);
  return out;
}

std::optional<LinkPartResult> checkHolderAgainstPart(const geometry::ToolSpec& tool,
                                                     const geometry::HolderProfile& holder,
                                                     const geometry::TriangleMesh& part,
                                                     std::span<const geometry::Posture> postures) {
  if (holder.empty() || postures.empty()) return std::nullopt;
  return checkHolderAgainstPart(tool, holder, prepareObstacle(part, "part"), postures);
}

std::optional<LinkPartResult> checkHolderAgainstPart(
    const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
    const std::shared_ptr<const ObstacleModel>& part, std::span<const geometry::Posture> postures,
    const common::Progress& progress, ClearanceMemo* memo) {
  const double tol_mm = clearanceMeshTolMm(tool, holder);
  const geometry::TriangleMesh holder_mesh = geometry::holderMesh(tool, holder, tol_mm);
  if (holder_mesh.triangles.empty() || postures.empty()) return std::nullopt;
  const ClearanceChecker holder_part(holder_mesh, std::span(&part, 1), tol_mm);
  LinkPartResult out;
  ClearanceRequest only_min;  // the holder's minimum and contacts are reported, not each posture's
  only_min.exact_min_only = true;
  const ClearanceResult c =
      holder_part.check(postures, only_min, common::scaled(progress, 0, 0.3, ""));
  out.postures = c.postures;
  out.min_clearance_mm = c.min_clearance_mm;
  out.colliding_postures = c.colliding;
  out.first_colliding_posture = c.first_colliding;
  MotionRequest request;  // touching is what counts: required 0
  request.posture_clearance_mm = c.clearance_mm;
  request.memo = memo;
  const MotionResult m =
      holder_part.checkMotions(postures, request, common::scaled(progress, 0.3, 1.0, ""));
  out.motions = m.motions;
  out.min_clearance_mm = std::min(out.min_clearance_mm, m.min_clearance_mm);
  out.colliding_motions = m.colliding;
  out.first_colliding_motion = m.first_colliding;
  addContacts(c.clearance_mm, 0, out.posture_contacts);
  addContacts(m.clearance_mm, 0, out.motion_contacts);
  return out;
}

PartContacts checkAgainstPart(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                              const geometry::TriangleMesh& part, const geometry::PathFile& path,
                              double gouge_tolerance_mm, const common::Progress& progress) {
  // The part's tree and shells once, for the four checks (a 1 M-triangle part took four builds
  // of ~8 s and ~300 B a triangle each, without a progress line).
  common::report(progress, 0.0, "part");
  return checkAgainstPart(tool, holder, prepareObstacle(part, "part"), path, gouge_tolerance_mm,
                          progress);
}

PartContacts checkAgainstPart(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder,
                              const std::shared_ptr<const ObstacleModel>& model,
                              const geometry::PathFile& path, double gouge_tolerance_mm,
                              const common::Progress& progress, double ball_exact_below_mm,
                              PartMemo* memo) {
  PartContacts out;  // its progress from 0.2 (0 to 0.2: the model's preparation, above)
  if (memo) memo->useFor(model, tool, holder, gouge_tolerance_mm);
  common::report(progress, 0.2, "links vs part");
  const double tol_mm = clearanceMeshTolMm(tool, holder);
  const ClearanceChecker whole(geometry::toolMesh(tool, holder, tol_mm), std::span(&model, 1),
                               tol_mm);
  if (path.count(geometry::PathBlock::Kind::Link) > 0)
    out.links =
        checkLinksAgainstPart(whole, grazingPartChecker(tool, holder, model), path,
                              common::scaled(progress, 0.2, 0.3, "links vs part"), false, memo);
  if (tool.shape == geometry::ToolShape::Ball) {
    // Every pass posture's ball told nearer or farther than the far-from-part distance (a pass
    // beside the part is not hidden by one on it), the least exact under the range asked.
    const double far_mm = farFromPartMm(tool.radius_mm);
    std::vector<Vec3> centres;
    for (const geometry::PathBlock& block : path.blocks)
      if (block.kind == geometry::PathBlock::Kind::Pass)
        for (std::size_t i = block.begin; i < block.end; ++i)
          centres.push_back(geometry::ballCentre(path.postures[i], tool.radius_mm));
    std::vector<double> each;
    if (!centres.empty()) {
      BallResult balls = whole.ballClearance(
          centres, {tool.radius_mm, std::max(kReachesPartMm, ball_exact_below_mm), far_mm, true});
      out.ball_part_mm = balls.min_mm;
      each = std::move(balls.each_mm);
    }
    out.far.pass_postures = each.size();
    std::size_t k = 0, pass = 0;
    for (const geometry::PathBlock& block : path.blocks) {
      if (block.kind != geometry::PathBlock::Kind::Pass) continue;
      double nearest_mm = std::numeric_limits<double>::infinity();
      for (std::size_t i = block.begin; i < block.end; ++i, ++k) {
        nearest_mm = std::min(nearest_mm, each[k]);
        out.far.postures += each[k] >= far_mm;
      }
      if (block.size() == 0) continue;
      ++pass;
      if (nearest_mm >= far_mm) {
        if (out.far.passes.empty()) out.far.first_posture = block.begin;
        out.far.passes.push_back(pass);
      }
    }
  }
  out.holder = checkHolderAgainstPart(tool, holder, model, path.postures,
                                      common::scaled(progress, 0.3, 0.6, "holder vs part"),
                                      memo ? &memo->holder : nullptr);
  if (tool.shape != geometry::ToolShape::Flat)
    out.cutter = checkCutterAgainstPart(tool, model, path.postures, gouge_tolerance_mm,
                                        common::scaled(progress, 0.6, 1.0, "cutter vs part"),
                                        memo ? &memo->cutter : nullptr);
  return out;
}

void PartMemo::forgetUnused() {
  links.forgetUnused();
  grazing.forgetUnused();
  holder.forgetUnused();
  cutter.forgetUnused();
}

void PartMemo::useFor(const std::shared_ptr<const ObstacleModel>& part,
                      const geometry::ToolSpec& tool, const geometry::HolderProfile& profile,
                      double tolerance_mm) {
  const auto same_station = [](const geometry::HolderStation& a, const geometry::HolderStation& b) {
    return a.z_mm == b.z_mm && a.radius_mm == b.radius_mm;
  };
  if (part == part_ && tool.shape == tool_.shape && tool.radius_mm == tool_.radius_mm &&
      tool.corner_radius_mm == tool_.corner_radius_mm && tool.length_mm == tool_.length_mm &&
      std::equal(profile.begin(), profile.end(), holder_.begin(), holder_.end(), same_station) &&
      tolerance_mm == tolerance_mm_)
    return;
  links.clear();
  grazing.clear();
  holder.clear();  // (the cutter's memo checks its own: part, tool and tolerance)
  part_ = part;
  tool_ = tool;
  holder_ = profile;
  tolerance_mm_ = tolerance_mm;
}

PartContacts::Marks PartContacts::marks(std::size_t n) const {
  Marks out{std::vector<std::uint8_t>(n, 0), std::vector<std::uint8_t>(n, 0)};
  const auto mark = [&out, n](const std::vector<std::size_t>& postures,
                              const std::vector<std::size_t>& motions) {
    for (std::size_t i : postures)
      if (i < n) out.posture[i] = 1;
    for (std::size_t i : motions)
      if (i < n) out.motion[i] = 1;
  };
  for (const std::optional<LinkPartResult>* r : {&links, &holder})
    if (*r) mark((*r)->posture_contacts, (*r)->motion_contacts);
  if (cutter) mark(cutter->posture_contacts, cutter->motion_contacts);
  return out;
}

}  // namespace fieldpath::pathgen
