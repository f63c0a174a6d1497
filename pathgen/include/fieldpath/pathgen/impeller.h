#pragma once
/// The parametric impeller channel ("veine", seed 004 Fig. 2): a hub (the guide surface, machined
/// by the ball end) between two twisted blade walls (ruled surfaces, the obstacles), narrowing
/// along its length. World frame, mm: x along the channel, y across it (left blade at low y), z up.
///
/// Hub: S(u, v), u ∈ [0, 1] along the channel, v ∈ [0, 1] across it (0 = foot of the left blade,
/// 1 = foot of the right one). It is also a smooth height field z = h(x, y), so the Z-buffer can be
/// compared with it:
///   x = L u,  y = y_c(u) + η w(u),  η = 2v - 1,  y_c(u) = bend u²,
///   w(u) = (width_in + (width_out - width_in) u) / 2,  h = rise u² - dish (1 - η²).
/// Blades: ruled surfaces B(u, t) = F(u) + t H d(u), t ∈ [0, 1], F the foot curve S(u, 0 | 1),
/// d(u) = cos λ(u) e_z + sin λ(u) m(u), m the horizontal normal of the foot pointing into the
/// channel, λ linear in u from lean_in to lean_out (the twist); λ > 0 overhangs the channel.
#include <array>
#include <string>
#include <vector>

#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::pathgen {

using geometry::Vec3;

/// Scene `impeller: {...}` keys (examples/impeller/scene.yaml documents them). Defaults, once,
/// here, equal to the example scene: sized like seed 004's case (7 passes ≈ 513 mm, blades
/// sampled at 1 mm into 5100 points).
struct ImpellerParams {
  double length_mm = 72.0;        ///< `length`: channel length along x
  double width_in_mm = 34.0;      ///< `width_in`: hub width between the blade feet at u = 0
  double width_out_mm = 22.0;     ///< `width_out`: at u = 1 (the channel narrows)
  double bend_mm = 10.0;          ///< `bend`: centreline y offset at u = 1 (y_c = bend u²)
  double hub_rise_mm = 12.0;      ///< `hub_rise`: hub height at u = 1 on the centreline (+ dish)
  double hub_dish_mm = 1.0;       ///< `hub_dish`: hub centre below its edges (concave across)
  double blade_height_mm = 16.5;  ///< `blade_height`: ruling length, foot to tip
  /// `lean_left_deg: [in, out]`: left blade lean at u = 0 and u = 1 (> 0 over the channel).
  std::array<double, 2> lean_left_deg = {4.0, 24.0};
  /// `lean_right_deg: [in, out]`: right blade lean (> 0 over the channel, < 0 away from it).
  std::array<double, 2> lean_right_deg = {-8.0, 9.0};
  /// `passes_v: [first, last]`: v of the first and last pass (evenly spread in between).
  std::array<double, 2> passes_v = {0.25, 0.82};
  /// `u_range: [start, end]`: the part of the channel the passes cover.
  std::array<double, 2> u_range = {0.0, 1.0};
  double chord_tol_mm = 0.01;  ///< `chord_tol`: meshes within this of the surfaces
};

/// The evaluated impeller: surfaces, their derivatives and meshes. A value type.
class Impeller {
 public:
  /// Throws common::InputError naming the `impeller.<key>` for a non-finite, non-positive or
  /// out-of-range value and for blades that cross (their gap across the channel ≤ 0 anywhere).
  explicit Impeller(const ImpellerParams& params);

  const ImpellerParams& params() const { return params_; }

  /// Hub point S(u, v), mm.
  Vec3 hub(double u, double v) const;
  /// Unit hub normal at S(u, v), pointing up (out of the material).
  Vec3 hubNormal(double u, double v) const;
  /// Hub height h(x, y), mm; defined (extrapolated) beyond the blades too.
  double hubHeight(double x_mm, double y_mm) const;
  /// Hub parameters (u, v) of the point above (x, y): the inverse of S in plan.
  std::array<double, 2> hubUV(double x_mm, double y_mm) const;
  /// Unit hub normal at (x, y), from the gradient of h.
  Vec3 hubNormalAt(double x_mm, double y_mm) const;
  /// Blade point B(u, t); side 0 = left (v = 0), 1 = right (v = 1).
  Vec3 blade(int side, double u, double t) const;
  /// Unit normal of the blade, pointing into the channel (the side the tool is on).
  Vec3 bladeNormal(int side, double u, double t) const;
  /// Smallest gap between the blades measured across the channel (foot or tip), and its u.
  double minGapMm(double* at_u = nullptr) const;

  /// Meshes within chord_tol of the surfaces (see impeller.cpp for the sampling bound).
  /// Hub: normals up. Blades: open sheets, normals into the channel.
  geometry::TriangleMesh hubMesh() const;
  geometry::TriangleMesh bladeMesh(int side) const;
  /// Triangles of hubMesh() + both bladeMesh(), computed without making them (for the memory
  /// estimate made before any mesh is allocated).
  std::size_t meshTriangleCount() const;

 private:
  ImpellerParams params_;
  double halfWidth(double u) const;
  double leanRad(int side, double u) const;
  /// Horizontal unit normal of the foot curve of `side`, pointing into the channel.
  Vec3 footInward(int side, double u) const;
};

}  // namespace fieldpath::pathgen
