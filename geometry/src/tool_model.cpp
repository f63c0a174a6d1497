#include "fieldpath/geometry/tool_model.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <string>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/memory.h"
#include "fieldpath/common/short_number.h"

namespace fieldpath::geometry {
namespace {

using common::InputError;
using Vec2 = Eigen::Vector2d;  ///< meridian half-plane: (rho = distance from the axis, z), mm

constexpr double kPi = std::numbers::pi;
/// Sizes beyond which a tolerance or spacing is taken as a mistake (memory, not accuracy).
constexpr double kMaxTriangles = 2e7;
/// Bytes a triangle of the tool mesh costs in `tool`: the mesh, its check (closed, area, volume:
/// the edges' map) and its STL; measured 414 B (`tool` at --tol 1e-5 and 3e-6: 1.30 M and 4.26 M
/// triangles, 587 and 1757 MiB), rounded up.
constexpr double kBytesPerToolTriangle = 448.0;
constexpr double kMaxNodes = 2e7;

/// One piece of a revolved profile: a straight segment, or a circular arc about `centre` from
/// `start_rad` to `end_rad` (counter-clockwise in the (rho, z) plane). `from`/`to` are exact end
/// points, so the tip and the top lie exactly on the axis.
struct ProfileSegment {
  Vec2 from, to;
  bool is_arc = false;
  Vec2 centre = Vec2::Zero();
  double radius_mm = 0, start_rad = 0, end_rad = 0;
  NodePart part = NodePart::Tool;

  double length() const { return is_arc ? radius_mm * (end_rad - start_rad) : (to - from).norm(); }
  /// Point at parameter t in [0, 1].
  Vec2 at(double t) const {
    if (t <= 0) return from;
    if (t >= 1) return to;
    if (!is_arc) return from + t * (to - from);
    const double a = start_rad + t * (end_rad - start_rad);
    return centre + radius_mm * Vec2(std::cos(a), std::sin(a));
  }
  /// Outward unit normal at parameter t. The profile runs tip → top with the solid on its left,
  /// so outward is the travel direction turned clockwise.
  Vec2 normal(double t) const {
    if (is_arc) return (at(t) - centre).normalized();
    const Vec2 d = (to - from).normalized();
    return Vec2(d.y(), -d.x());
  }
  double distance(const Vec2& q) const {
    if (is_arc) {
      const Vec2 d = q - centre;
      const double a = std::atan2(d.y(), d.x());
      if (a >= start_rad && a <= end_rad) return std::abs(d.norm() - radius_mm);
      return std::min((q - from).norm(), (q - to).norm());
    }
    const Vec2 d = to - from;
    const double t = std::clamp((q - from).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (q - (from + t * d)).norm();
  }
};

using Profile = std::vector<ProfileSegment>;

ProfileSegment line(Vec2 from, Vec2 to, NodePart part = NodePart::Tool) {
  ProfileSegment s;
  s.from = from;
  s.to = to;
  s.part = part;
  return s;
}

/// Quarter arc of the cutting corner: from the bottom (angle -π/2) to the side (angle 0).
ProfileSegment cornerArc(Vec2 centre, double radius_mm) {
  ProfileSegment s;
  s.is_arc = true;
  s.centre = centre;
  s.radius_mm = radius_mm;
  s.start_rad = -kPi / 2;
  s.end_rad = 0.0;
  s.from = Vec2(centre.x(), centre.y() - radius_mm);
  s.to = Vec2(centre.x() + radius_mm, centre.y());
  return s;
}

/// Tip → side of the shank up to (R, top_z): cutting end then shank cylinder. No top.
Profile toolSide(const ToolSpec& tool, double top_z_mm) {
  const double big_r = tool.radius_mm;
  Profile p;
  switch (tool.shape) {
    case ToolShape::Ball:
      p.push_back(cornerArc(Vec2(0.0, big_r), big_r));
      break;
    case ToolShape::Torus: {
      const double r = tool.corner_radius_mm;
      if (big_r - r > 0) p.push_back(line(Vec2(0.0, 0.0), Vec2(big_r - r, 0.0)));
      p.push_back(cornerArc(Vec2(big_r - r, r), r));
      break;
    }
    case ToolShape::Flat:
      p.push_back(line(Vec2(0.0, 0.0), Vec2(big_r, 0.0)));
      break;
  }
  const double side_start_z = cornerRadius(tool);
  if (top_z_mm > side_start_z) p.push_back(line(Vec2(big_r, side_start_z), Vec2(big_r, top_z_mm)));
  return p;
}

/// The holder's outline (rho, z) joined with the tool: below the tool top L the union of the two
/// solids is at least the shank radius R, so the outline is widened to R there (crossings of
/// rho = R and of z = L become points of their own).
std::vector<Vec2> holderOutline(const ToolSpec& tool, const HolderProfile& holder) {
  const double big_r = tool.radius_mm, len = tool.length_mm;
  std::vector<Vec2> raw;
  for (std::size_t i = 0; i < holder.size(); ++i) {
    const Vec2 b(holder[i].radius_mm, holder[i].z_mm);
    if (i > 0) {
      const Vec2 a = raw.back();
      std::vector<std::pair<double, Vec2>> cuts;
      if (a.y() < len && b.y() > len) {
        const double t = (len - a.y()) / (b.y() - a.y());
        cuts.push_back({t, Vec2(a.x() + t * (b.x() - a.x()), len)});
      }
      if ((a.x() - big_r) * (b.x() - big_r) < 0) {
        const double t = (big_r - a.x()) / (b.x() - a.x());
        const double z = a.y() + t * (b.y() - a.y());
        if (z < len) cuts.push_back({t, Vec2(big_r, z)});
      }
      std::sort(cuts.begin(), cuts.end(),
                [](const auto& u, const auto& v) { return u.first < v.first; });
      for (const auto& cut : cuts) raw.push_back(cut.second);
    }
    raw.push_back(b);
  }
  std::vector<Vec2> outline;
  for (std::size_t i = 0; i < raw.size(); ++i) {
    const Vec2& u = raw[i];
    if (u.y() > len) {
      outline.push_back(u);
      continue;
    }
    outline.emplace_back(std::max(u.x(), big_r), u.y());
    // Leaving the tool's top upwards at a radius below R: step in along z = L first.
    if (u.y() == len && u.x() < big_r && i + 1 < raw.size() && raw[i + 1].y() > len)
      outline.push_back(u);
  }
  return outline;
}

/// The whole closed profile from the tip to the top on the axis: tool side, then either the flat
/// top at L, or the outline of tool and holder joined (holderOutline) and the top face.
Profile fullProfile(const ToolSpec& tool, const HolderProfile& holder) {
  const double big_r = tool.radius_mm, len = tool.length_mm;
  if (holder.empty()) {
    Profile p = toolSide(tool, len);
    p.push_back(line(p.back().to, Vec2(0.0, len)));
    return p;
  }
  validateHolderOnTool(tool, holder);
  // The shank runs up to the first station, also past L into a holder that starts above the tool.
  // Past L it does not cut: holder surface (checked against the part as the holder is; as tool
  // surface a shank 1 mm into an overhang above L went unseen, `check` ok: a reviewer's case).
  Profile p = toolSide(tool, std::min(holder.front().z_mm, len));
  if (holder.front().z_mm > len)
    p.push_back(line(p.back().to, Vec2(big_r, holder.front().z_mm), NodePart::Holder));
  // Pieces on the shank cylinder below L are tool surface; the rest is holder.
  const auto add = [&](Vec2 to) {
    const Vec2 from = p.back().to;
    if ((to - from).norm() == 0) return;
    const bool on_shank = from.x() == big_r && to.x() == big_r && to.y() <= len;
    p.push_back(line(from, to, on_shank ? NodePart::Tool : NodePart::Holder));
  };
  for (const Vec2& q : holderOutline(tool, holder)) add(q);
  const double holder_top_mm = holder.back().z_mm;
  if (holder_top_mm < len) {  // a collar round the shank: the tool goes on above it
    add(Vec2(big_r, holder_top_mm));
    add(Vec2(big_r, len));
    p.push_back(line(p.back().to, Vec2(0.0, len)));
  } else {
    add(Vec2(0.0, holder_top_mm));
  }
  return p;
}

/// Angular step (rad) whose chord on a circle of `radius_mm` stays within `sagitta_mm`.
double angularStep(double radius_mm, double sagitta_mm) {
  if (sagitta_mm >= radius_mm) return kPi / 2;
  return 2.0 * std::acos(1.0 - sagitta_mm / radius_mm);
}

double parseNumberField(std::string_view token, std::string_view what, std::string_view text) {
  // Blanks around a number are a list's spacing (`40:6 ,55:6`), not part of it.
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.front())))
    token.remove_prefix(1);
  while (!token.empty() && std::isspace(static_cast<unsigned char>(token.back())))
    token.remove_suffix(1);
  double value = 0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (token.empty() || ec != std::errc() || end != token.data() + token.size() ||
      !std::isfinite(value))
    throw InputError(std::string(what) + " '" + std::string(text) + "': '" + std::string(token) +
                     "' is not a finite number");
  return value;
}

std::vector<std::string_view> split(std::string_view text, char separator) {
  std::vector<std::string_view> parts;
  for (std::size_t start = 0;;) {
    const auto end = text.find(separator, start);
    parts.push_back(
        text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

}  // namespace

ToolSpec parseToolSpec(std::string_view text) {
  const auto fields = split(text, ':');
  const std::string_view name = fields[0];
  ToolSpec tool;
  std::size_t needed;
  if (name == "ball") {
    tool.shape = ToolShape::Ball;
    needed = 2;
  } else if (name == "torus") {
    tool.shape = ToolShape::Torus;
    needed = 3;
  } else if (name == "flat") {
    tool.shape = ToolShape::Flat;
    needed = 2;
  } else {
    throw InputError("tool shape '" + std::string(text) +
                     "': expected ball:R[:L], torus:R:r[:L] or flat:R[:L]");
  }
  if (fields.size() != needed && fields.size() != needed + 1)
    throw InputError("tool shape '" + std::string(text) + "': expected " +
                     (needed == 3 ? "torus:R:r[:L]" : std::string(name) + ":R[:L]"));
  tool.radius_mm = parseNumberField(fields[1], "tool shape", text);
  tool.corner_radius_mm = needed == 3 ? parseNumberField(fields[2], "tool shape", text) : 0.0;
  tool.length_mm = fields.size() > needed ? parseNumberField(fields[needed], "tool shape", text)
                                          : 4.0 * tool.radius_mm;
  try {
    validateToolSpec(tool);
  } catch (const InputError& e) {
    throw InputError("tool shape '" + std::string(text) + "': " + e.what());
  }
  return tool;
}

HolderProfile parseHolderProfile(std::string_view text) {
  HolderProfile holder;
  if (text.empty()) return holder;
  for (std::string_view station : split(text, ',')) {
    const auto zr = split(station, ':');
    if (zr.size() != 2)
      throw InputError("holder '" + std::string(text) + "': station '" + std::string(station) +
                       "' is not z:r");
    holder.push_back(
        {parseNumberField(zr[0], "holder", text), parseNumberField(zr[1], "holder", text)});
  }
  try {
    validateHolderProfile(holder);
  } catch (const InputError& e) {
    throw InputError("holder '" + std::string(text) + "': " + e.what());
  }
  return holder;
}

namespace {
/// Tools and holders longer or wider than this (mm) are no spindle's: refused as typos before
/// they size meshes, node sets and reach boxes.
constexpr double kMaxToolSizeMm = 1e4;

using common::shortNumber;
}  // namespace

void validateToolSpec(const ToolSpec& tool) {
  if (!std::isfinite(tool.radius_mm) || !(tool.radius_mm > 0))
    throw InputError("tool radius must be > 0");
  if (tool.radius_mm < 1e-3)  // below this the meshes and tolerances are rounding noise
    throw InputError("tool radius " + shortNumber(tool.radius_mm) +
                     " mm is below 0.001 mm (no cutter is that small)");
  for (const double v : {tool.radius_mm, tool.length_mm, tool.corner_radius_mm})
    if (std::abs(v) > kMaxToolSizeMm)
      throw InputError("tool size " + shortNumber(v) + " mm is beyond " +
                       shortNumber(kMaxToolSizeMm) + " mm (no spindle takes it)");
  if (tool.shape == ToolShape::Torus &&
      !(tool.corner_radius_mm > 0 && tool.corner_radius_mm <= tool.radius_mm))
    throw InputError("corner_radius " + shortNumber(tool.corner_radius_mm) +
                     " mm must be in (0, radius " + shortNumber(tool.radius_mm) + " mm]");
  const double end_mm = cornerRadius(tool);
  if (!std::isfinite(tool.length_mm) || !(tool.length_mm > 0))
    throw InputError("tool length must be > 0 mm");
  if (!(tool.length_mm >= end_mm))
    throw InputError("tool length must cover the cutting end (>= " + shortNumber(end_mm) + " mm)");
}

void validateHolderOnTool(const ToolSpec& tool, const HolderProfile& holder) {
  if (!holder.empty() && !(holder.front().z_mm > cornerRadius(tool)))
    throw InputError("holder starts at z " + shortNumber(holder.front().z_mm) +
                     " mm, not above the cutting end of the tool (" +
                     shortNumber(cornerRadius(tool)) + " mm)");
}

void validateHolderProfile(const HolderProfile& holder) {
  for (std::size_t i = 0; i < holder.size(); ++i) {
    const HolderStation& s = holder[i];
    if (!std::isfinite(s.z_mm) || !std::isfinite(s.radius_mm) || !(s.radius_mm > 0))
      throw InputError("station " + std::to_string(i + 1) + ": z must be finite and radius > 0");
    if (std::abs(s.z_mm) > kMaxToolSizeMm || s.radius_mm > kMaxToolSizeMm)
      throw InputError("station " + std::to_string(i + 1) + ": " + shortNumber(s.z_mm) + ":" +
                       shortNumber(s.radius_mm) + " is beyond " + shortNumber(kMaxToolSizeMm) +
                       " mm (no spindle takes it)");
    if (i > 0 && !(s.z_mm > holder[i - 1].z_mm) &&
        !(s.z_mm == holder[i - 1].z_mm && s.radius_mm != holder[i - 1].radius_mm))
      throw InputError("station " + std::to_string(i + 1) + " (z " + shortNumber(s.z_mm) +
                       "): z must increase (equal z only for a step to another radius)");
  }
  if (holder.size() == 1) throw InputError("a holder needs at least two stations");
  if (!holder.empty() && !(holder.back().z_mm > holder.front().z_mm))
    throw InputError("holder has no height");
}

namespace {

/// toolMesh, or (`only` given) the bands of the profile pieces of that part alone: an open mesh.
TriangleMesh revolvedMesh(const ToolSpec& tool, const HolderProfile& holder, double chord_tol_mm,
                          const NodePart* only) {
  validateToolSpec(tool);
  validateHolderProfile(holder);
  if (!std::isfinite(chord_tol_mm) || !(chord_tol_mm > 0))
    throw InputError("chordal tolerance must be a finite number > 0 mm");
  const Profile profile = fullProfile(tool, holder);

  // A triangle spanning a profile step and a circumferential step deviates from the surface by
  // about the sum of both sagittas (to leading order), so with arcs in the profile each gets under
  // half the tolerance; straight profiles (cylinders, cones, planes) have only the circumferential
  // one.
  const bool has_arcs =
      std::any_of(profile.begin(), profile.end(), [](const ProfileSegment& s) { return s.is_arc; });
  const double sagitta_mm = (has_arcs ? 0.45 : 0.9) * chord_tol_mm;

  // Refuse tolerances that would not fit in memory (bad input must not crash or hang).
  double max_rho_mm = 0, rings = 0;
  for (const auto& s : profile) {
    max_rho_mm = std::max({max_rho_mm, s.from.x(), s.to.x()});
    rings += s.is_arc ? (s.end_rad - s.start_rad) / angularStep(s.radius_mm, sagitta_mm) + 1 : 1;
  }
  const double triangles_estimate = 2 * rings * (2 * kPi / angularStep(max_rho_mm, sagitta_mm) + 8);
  if (triangles_estimate > kMaxTriangles)
    throw InputError(
        "chordal tolerance " + shortNumber(chord_tol_mm) + " mm is too fine: about " +
        std::to_string(static_cast<long long>(triangles_estimate)) + " triangles (limit " +
        std::to_string(static_cast<long long>(kMaxTriangles)) + ")");

  // Profile points from the tip to the top; arcs subdivided, straight pieces left whole.
  std::vector<Vec2> points{profile.front().from};
  std::vector<NodePart> band_part;  // of the band between points k and k + 1
  for (const auto& s : profile) {
    const int pieces =
        s.is_arc ? std::max(1, static_cast<int>(std::ceil((s.end_rad - s.start_rad) /
                                                          angularStep(s.radius_mm, sagitta_mm))))
                 : 1;
    for (int i = 1; i <= pieces; ++i) {
      points.push_back(s.at(static_cast<double>(i) / pieces));
      band_part.push_back(s.part);
    }
  }

  // One ring of vertices per profile point, vertex j at angle 2πj/N. A ring's N keeps the chord
  // sagitta within budget at the largest radius of the ring and its neighbours, so the triangles
  // on either side of it do too; rings on the axis are one vertex. Smaller rings get fewer
  // vertices, which keeps the triangles near the tip well shaped.
  const std::size_t count = points.size();
  std::vector<int> first(count), sectors(count);
  double triangles = 0.0;  // the zip below makes n_lo + n_hi of them a band
  for (std::size_t k = 0; k < count; ++k) {
    const double rho_mm = points[k].x();
    if (rho_mm == 0.0) {
      sectors[k] = 1;
    } else {
      const double widest_mm = std::max({rho_mm, points[k - 1].x(), points[k + 1].x()});
      sectors[k] =
          std::max(8, static_cast<int>(std::ceil(2 * kPi / angularStep(widest_mm, sagitta_mm))));
    }
    if (k > 0) triangles += sectors[k - 1] + sectors[k];
  }
  // Against --max-memory: 4.3 M triangles took `tool` to 1.76 GiB under a limit of 43M (a memory
  // sweep's). Passing: a job's tool mesh is small, and held by what uses it.
  common::requireMemory(
      "chordal tolerance " + shortNumber(chord_tol_mm) + " mm", kBytesPerToolTriangle * triangles,
      shortNumber(triangles) + " triangles of the tool and holder", common::MemoryUse::kPassing);
  TriangleMesh mesh;
  for (std::size_t k = 0; k < count; ++k) {
    first[k] = static_cast<int>(mesh.vertices.size());
    const double rho_mm = points[k].x(), z_mm = points[k].y();
    if (rho_mm == 0.0) {
      mesh.vertices.emplace_back(0.0, 0.0, z_mm);
      continue;
    }
    for (int j = 0; j < sectors[k]; ++j) {
      const double a = 2 * kPi * j / sectors[k];
      mesh.vertices.emplace_back(rho_mm * std::cos(a), rho_mm * std::sin(a), z_mm);
    }
  }
  // Zip neighbouring rings together by angle: advance on the ring whose next vertex comes first.
  // Outward orientation: the profile runs upwards with the solid on its left.
  for (std::size_t k = 0; k + 1 < count; ++k) {
    if (only && band_part[k] != *only) continue;
    const int n_lo = sectors[k], n_hi = sectors[k + 1];
    const auto lo = [&](int i) { return first[k] + i % n_lo; };
    const auto hi = [&](int j) { return first[k + 1] + j % n_hi; };
    for (int i = 0, j = 0; i < n_lo || j < n_hi;) {
      // next lower angle 2π(i+1)/n_lo <= next upper angle 2π(j+1)/n_hi, compared exactly
      const bool advance_lo = i < n_lo && (j == n_hi || static_cast<long>(i + 1) * n_hi <=
                                                            static_cast<long>(j + 1) * n_lo);
      if (advance_lo) {
        if (n_lo > 1) mesh.triangles.emplace_back(lo(i), lo(i + 1), hi(j));
        ++i;
      } else {
        if (n_hi > 1) mesh.triangles.emplace_back(lo(i), hi(j + 1), hi(j));
        ++j;
      }
    }
  }
  return mesh;
}

}  // namespace

TriangleMesh toolMesh(const ToolSpec& tool, const HolderProfile& holder, double chord_tol_mm) {
  return revolvedMesh(tool, holder, chord_tol_mm, nullptr);
}

TriangleMesh holderMesh(const ToolSpec& tool, const HolderProfile& holder, double chord_tol_mm) {
  const NodePart holder_part = NodePart::Holder;
  return revolvedMesh(tool, holder, chord_tol_mm, &holder_part);
}

std::vector<SurfaceNode> surfaceNodes(const ToolSpec& tool, const HolderProfile& holder,
                                      double spacing_mm) {
  validateToolSpec(tool);
  validateHolderProfile(holder);
  if (!std::isfinite(spacing_mm) || !(spacing_mm > 0))
    throw InputError("node spacing must be a finite number > 0 mm");
  const Profile profile = fullProfile(tool, holder);

  double nodes_estimate = 0;
  for (const auto& s : profile)
    nodes_estimate +=
        (s.length() / spacing_mm + 2) * (2 * kPi * std::max(s.from.x(), s.to.x()) / spacing_mm + 2);
  if (nodes_estimate > kMaxNodes)
    throw InputError("node spacing " + std::to_string(spacing_mm) + " mm is too fine: about " +
                     std::to_string(static_cast<long long>(nodes_estimate)) + " nodes");

  std::vector<SurfaceNode> nodes;
  const auto addRing = [&](const ProfileSegment& s, double t, int ring_index) {
    const Vec2 q = s.at(t), n = s.normal(t);
    if (q.x() == 0.0) {
      nodes.push_back({Vec3(0.0, 0.0, q.y()), Vec3(0.0, 0.0, n.y()), s.part});
      return;
    }
    // An even count: with either stagger the ring is its own mirror across x = 0 and y = 0 (the
    // dynamics place x along the feed: a ring of 25 held a lone node nearest a wall on one side).
    const int count = 2 * std::max(1, static_cast<int>(std::ceil(kPi * q.x() / spacing_mm)));
    const double phase = 0.5 * (ring_index % 2);  // staggered rings cover the surface more evenly
    for (int j = 0; j < count; ++j) {
      const double a = 2 * kPi * (j + phase) / count;
      const Vec3 radial(std::cos(a), std::sin(a), 0.0);
      nodes.push_back({Vec3(q.x() * radial.x(), q.x() * radial.y(), q.y()),
                       Vec3(n.x() * radial.x(), n.x() * radial.y(), n.y()).normalized(), s.part});
    }
  };
  int ring_index = 0;
  for (const auto& s : profile) {
    const int pieces = std::max(1, static_cast<int>(std::ceil(s.length() / spacing_mm)));
    for (int i = 0; i < pieces; ++i) addRing(s, static_cast<double>(i) / pieces, ring_index++);
  }
  addRing(profile.back(), 1.0, ring_index);
  return nodes;
}

double toolSurfaceDistance(const ToolSpec& tool, const Vec3& point_tool_frame_mm) {
  return toolSurfaceDistance(tool, {}, point_tool_frame_mm);
}

double toolSurfaceDistance(const ToolSpec& tool, const HolderProfile& holder,
                           const Vec3& point_tool_frame_mm) {
  const Profile profile = fullProfile(tool, holder);
  const Vec2 q(std::hypot(point_tool_frame_mm.x(), point_tool_frame_mm.y()),
               point_tool_frame_mm.z());
  double distance_mm = std::numeric_limits<double>::infinity();
  for (const auto& s : profile) distance_mm = std::min(distance_mm, s.distance(q));
  return distance_mm;
}

}  // namespace fieldpath::geometry
