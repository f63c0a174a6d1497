#pragma once
/// Which points lie inside the closed shells of a mesh, and which of its shells are solids and
/// which voids. FCL measures distances between surfaces, so a tool wholly inside a closed
/// obstacle (or an obstacle wholly inside the tool's holder) touches no triangle and reads as
/// clear: the clearance checker asks these shells too; `orientClosedShells` winds each shell as
/// its kind (a solid's outward, a void's inward) for the Z-buffer, which reads a facet's winding.
#include <cstddef>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::geometry {

class ClosedShells {
 public:
  /// The closed, consistently wound shells of `mesh` (closedShells); open ones have no inside and
  /// are left out. Each shell's kind is read from its nesting and its winding relative to the
  /// shell it lies in (wholly: every vertex inside or on it), so that a mesh whose every facet is
  /// flipped reads as the same part:
  /// - a shell in no other is a solid, whichever way it is wound (a solid exported inside out),
  ///   but for one wound inward inside the box of an open shell that nearly closes (a cavity of a
  ///   part left open: its winding is all there is to tell), whose inside counts for nothing;
  /// - a shell in another (the smallest that holds it) is, in a solid, a void when wound the other
  ///   way and a body overlapping it when wound the same way (as assemblies overlap); in a void,
  ///   an island whichever way it is wound (air in air means nothing).
  explicit ClosedShells(const TriangleMesh& mesh);

  /// Whether p lies inside the part: inside more solids' shells than voids' (the union of the
  /// solids less their voids), each shell's inside by the parity of the crossings of the vertical
  /// ray from p upward, each triangle's projection taking the points of its edges by the top-left
  /// rule (so that a ray through an edge or a vertex is counted once).
  bool contains(const Eigen::Vector3d& p) const;
  /// A vertex of each shell: a shell wholly inside a solid has them all inside.
  const std::vector<Eigen::Vector3d>& anchors() const { return anchors_; }
  bool empty() const { return shells_.empty(); }

  std::size_t size() const { return shells_.size(); }
  /// Shell s's triangles (indices into the mesh).
  const std::vector<int>& triangles(std::size_t s) const { return shells_[s].triangles; }
  /// Shell s's enclosed volume as wound (mm³): < 0 wound inward.
  double volumeMm3(std::size_t s) const { return shells_[s].volume_mm3; }
  /// +1 a solid, -1 a void.
  int sign(std::size_t s) const { return shells_[s].sign; }

 private:
  struct Shell {
    std::vector<int> triangles;
    Eigen::AlignedBox3d box;
    int nx = 1, ny = 1;
    double cell_x = 1, cell_y = 1;
    std::vector<std::vector<int>> cells;  ///< per xy cell: the triangles whose box meets it
    double volume_mm3 = 0.0;              ///< signed: < 0 wound inward
    int sign = 1;                         ///< -1: a void
    /// What its inside adds to a point's winding: its sign, but 0 for a void of an open shell
    /// (air around which no closed shell counts).
    int weight = 1;
  };
  static double surfaceTolMm(const Shell& shell);
  const std::vector<int>& cellAt(const Shell& shell, const Eigen::Vector3d& p) const;
  /// The crossings of the vertical ray from p upward with `shell`'s triangles.
  int crossings(const Shell& shell, const Eigen::Vector3d& p) const;
  /// Whether p lies on `shell`'s surface, within `tol_mm`.
  bool onSurface(const Shell& shell, const Eigen::Vector3d& p, double tol_mm) const;
  /// Whether shell `inner` lies wholly in shell `outer`: every vertex inside or on it, one inside.
  bool within(const Shell& inner, const Shell& outer) const;
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<Shell> shells_;
  std::vector<Eigen::Vector3d> anchors_;
};

/// The open shells of `mesh` that nearly enclose a volume: their open edges short against their
/// area (length / sqrt(area) under 3: a box with a face missing 1.8, a hemisphere 2.5, a bore's
/// wall longer than 2.8 radii; a flat disc 3.5, a square sheet 4, the mesh example's hub 4.8).
/// A solid exported with facets missing, rather than a sheet; triangle indices per shell.
std::vector<std::vector<int>> nearlyClosedOpenShells(const TriangleMesh& mesh);

}  // namespace fieldpath::geometry
