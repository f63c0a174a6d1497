#pragma once
/// Internal to pathgen/ (ClearanceChecker): which points lie inside the closed shells of a mesh.
/// FCL measures distances between surfaces, so a tool wholly inside a closed obstacle (or an
/// obstacle wholly inside the tool's holder) touches no triangle and reads as clear: the
/// checker asks these shells too.
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/geometry/mesh.h"

namespace fieldpath::pathgen {

class ClosedShells {
 public:
  /// The closed, consistently wound shells of `mesh` (geometry::closedShells); open ones have
  /// no inside and are left out.
  explicit ClosedShells(const geometry::TriangleMesh& mesh);

  /// Whether p lies inside the part: inside more solids' shells than voids' (a shell wound
  /// inward inside another is a void), each shell's inside by the parity of the crossings of the
  /// vertical ray from p upward, each triangle's projection taking the points of its edges by
  /// the top-left rule (so that a ray through an edge or a vertex is counted once).
  bool contains(const Eigen::Vector3d& p) const;
  /// A vertex of each shell: a shell wholly inside a solid has them all inside.
  const std::vector<Eigen::Vector3d>& anchors() const { return anchors_; }
  bool empty() const { return shells_.empty(); }

 private:
  struct Shell {
    Eigen::AlignedBox3d box;
    int nx = 1, ny = 1;
    double cell_x = 1, cell_y = 1;
    std::vector<std::vector<int>> cells;  ///< per xy cell: the triangles whose box meets it
    double volume_mm3 = 0.0;              ///< signed: < 0 wound inward
    int sign = 1;                         ///< -1: a void (wound inward, inside a solid)
  };
  /// The crossings of the vertical ray from p upward with `shell`'s triangles.
  int crossings(const Shell& shell, const Eigen::Vector3d& p) const;
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Eigen::Vector3i> triangles_;
  std::vector<Shell> shells_;
  std::vector<Eigen::Vector3d> anchors_;
};

}  // namespace fieldpath::pathgen
