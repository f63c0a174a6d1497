#pragma once
/// Indexed triangle meshes (mm). Orientation: counter-clockwise seen from outside (outward
/// normals).
#include <cstddef>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace fieldpath::geometry {

struct TriangleMesh {
  std::vector<Eigen::Vector3d> vertices;   ///< mm
  std::vector<Eigen::Vector3i> triangles;  ///< vertex indices, CCW from outside
};

/// Counts of what is wrong with a mesh (nothing is repaired). Edges are undirected vertex-index
/// pairs.
struct MeshReport {
  std::size_t vertices = 0;
  std::size_t triangles = 0;
  std::size_t non_finite_vertices = 0;
  std::size_t degenerate_triangles = 0;  ///< repeated index, index out of range, or zero area
  std::size_t open_edges = 0;            ///< used by one triangle
  std::size_t non_manifold_edges = 0;    ///< used by more than two triangles
  std::size_t inconsistent_edges = 0;    ///< two triangles traverse it the same way
  /// Closed and consistently oriented: non-empty, no open, non-manifold or inconsistent edge,
  /// no degenerate triangle, every vertex finite.
  bool closed() const;
  /// One line, e.g. "1200 vertices, 2396 triangles, closed".
  std::string summary() const;
};

MeshReport validateMesh(const TriangleMesh& mesh);
/// Whether triangle (a, b, c) has no area: twice its area at most 1e-6 of its longest edge
/// squared (its height under 1e-6 of that edge; a float STL's points sit off their edge by
/// ~1e-7 of their size). Such a triangle is no surface for the shells' inside tests (it may touch
/// a solid without opening it) and a segment for the distances (FCL's tests need a normal).
bool hasNoArea(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c);

/// Total triangle area, mm².
double meshArea(const TriangleMesh& mesh);
/// Signed enclosed volume (divergence theorem), mm³; positive for outward orientation of a closed
/// mesh.
double meshVolume(const TriangleMesh& mesh);

/// The closed, consistently wound shells of `mesh` (connected sets of triangles, joined through
/// their vertices, whose every edge is used as often one way as the other: once each way, or
/// twice where two bodies of one file share a face or an edge), as triangle indices. A triangle
/// written again the same way round is left out (the surface is there once).
std::vector<std::vector<int>> closedShells(const TriangleMesh& mesh);
/// The other shells (triangles joined through their vertices): open sheets, or not closed.
std::vector<std::vector<int>> openShells(const TriangleMesh& mesh);

/// What repairShells mended.
struct ShellRepair {
  std::size_t slivers_removed = 0;  ///< triangles of no area (height <= 1e-6 of their size)
  std::size_t edges_split = 0;      ///< T-junctions: an open edge split at a vertex lying on it
  std::size_t facets_turned = 0;    ///< wound against their neighbours in a closed shell
  std::size_t open_edges_before = 0, open_edges_after = 0;
  /// The T-junction search passed its budget (a triangle soup's every edge is open): nothing
  /// mended.
  bool search_given_up = false;
  bool any() const { return slivers_removed + edges_split + facets_turned > 0; }
};

/// Mends the export defects that leave a solid's shell open or inconsistent, so that its inside
/// is known: slivers of no area are left out, an open edge with open-edge vertices lying on it (a
/// T-junction) is split at them, and in a closed shell the facets wound against the most of
/// their neighbours are turned. The surface is the same. Left as it is where that closes nothing
/// (a sheet), where the mesh is closed already, or where the search would be a soup's.
ShellRepair repairShells(TriangleMesh& mesh);

/// The triangles written again the same way round (the same three points in the same cyclic
/// order, whatever their indices), marked 1 past their first: the surface is there once, and the
/// field sums each copy's samples (a cube written twice pushed twice as hard). The mesh keeps them:
/// two bodies of a file sharing a face each need it to be closed (left out, a tool inside one
/// read clear: a review's). Those written the other way round (a sheet's two sides) are not.
std::vector<char> repeatedFacets(const TriangleMesh& mesh);

/// Winds every closed, consistently wound shell (a connected set of triangles whose every edge is
/// used twice, once each way) as its kind (ClosedShells: from its nesting and its winding against
/// the shell it lies in): a solid's shell outward, a void's inward. CAD exports with the normals
/// flipped, the whole mesh or one body, read the same part. Returns how many shells it turned.
/// Open or inconsistent shells are left as they are (their inside is not defined: their winding
/// is all there is to tell a box with a face missing from a pocket).
std::size_t orientClosedShells(TriangleMesh& mesh);

}  // namespace fieldpath::geometry
