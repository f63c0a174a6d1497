#pragma once
/// Tool and holder as revolved profiles → closed meshes and surface nodes, in the tool frame
/// (tip at the origin, axis +z, mm). See tool.h for the descriptions.
#include <string_view>
#include <vector>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/tool.h"

namespace fieldpath::geometry {

/// "ball:R[:L]" | "torus:R:r[:L]" | "flat:R[:L]" (mm); L defaults to 4R. Throws common::InputError.
ToolSpec parseToolSpec(std::string_view text);

/// "z0:r0,z1:r1,..." (mm, z from the tip, increasing; equal z only for a step; r > 0). Empty text
/// → empty profile.
/// Throws common::InputError.
HolderProfile parseHolderProfile(std::string_view text);

/// Throws common::InputError if the tool is not meshable (R <= 0, r outside (0, R] for a torus,
/// L below the cutting end, non-finite values).
void validateToolSpec(const ToolSpec& tool);
/// Throws common::InputError unless there are >= 2 stations, z increases (equal only for a step)
/// and every radius is finite and > 0.
void validateHolderProfile(const HolderProfile& holder);
/// Throws common::InputError unless the holder (if any) starts above the tool's cutting end.
void validateHolderOnTool(const ToolSpec& tool, const HolderProfile& holder);

/// Closed, outward-oriented mesh of tool body (cutting end + cylindrical shank to L) and holder,
/// every point within `chord_tol_mm` of the analytic surface. Angular steps come from the sagitta
/// formula; the tip lies on the axis with no degenerate triangles there. The holder (may be empty)
/// and the tool make one solid (their union): a holder starting above L is reached by the shank
/// running on; one starting below L (the shank inside it) is widened to at least R up to L; one
/// ending below L is a collar with the shank and the top at L above it. The first station must lie
/// above the cutting end. Throws common::InputError for bad tool, holder or tolerance.
TriangleMesh toolMesh(const ToolSpec& tool, const HolderProfile& holder, double chord_tol_mm);

enum class NodePart { Tool, Holder };

/// The holder's surface alone as toolMesh makes it (the pieces of the profile above the shank that
/// are not tool surface: it never cuts), an open mesh; empty when there is no holder.
TriangleMesh holderMesh(const ToolSpec& tool, const HolderProfile& holder, double chord_tol_mm);

/// A point on the surface of tool or holder (tool frame, mm) with its outward unit normal.
struct SurfaceNode {
  Vec3 position_mm;
  Vec3 normal;
  NodePart part;
};

/// Nodes spread over the revolved surface about `spacing_mm` apart (along the profile and around
/// the axis), including the tip, and the flat top (tool only) or the holder's end faces. Each ring
/// has an even count: the set is its own mirror across the planes x = 0 and y = 0.
std::vector<SurfaceNode> surfaceNodes(const ToolSpec& tool, const HolderProfile& holder,
                                      double spacing_mm);

/// |distance| (mm) from a point in the tool frame to the analytic surface of the tool body
/// (cutting end, shank cylinder and flat top at L).
double toolSurfaceDistance(const ToolSpec& tool, const Vec3& point_tool_frame_mm);
/// |distance| (mm) to the analytic surface of tool and holder joined as toolMesh joins them.
double toolSurfaceDistance(const ToolSpec& tool, const HolderProfile& holder,
                           const Vec3& point_tool_frame_mm);

}  // namespace fieldpath::geometry
