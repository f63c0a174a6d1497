#pragma once
/// Obstacle meshes → sample points q_j with outward normals and weights (DESIGN.md "The field").
/// The guide surface (the one being machined) is never passed here.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fieldpath/field/params.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/posture.h"

namespace fieldpath::field {

using geometry::Vec3;

/// Sample points of the obstacle surfaces, world frame. All vectors have the same size.
struct ObstacleSamples {
  std::vector<Vec3> points_mm;  ///< q_j, mm
  std::vector<Vec3> normals;    ///< unit, outward (CCW triangles seen from outside)
  std::vector<double> weights;  ///< w_j: the sample's area (mm²) or 1 (Weights::Unit)
  double area_mm2 = 0.0;        ///< total sampled area; 0 if unknown (sizes the voxel estimate)

  std::size_t size() const { return points_mm.size(); }
  void add(const Vec3& point_mm, const Vec3& normal, double weight) {
    points_mm.push_back(point_mm);
    normals.push_back(normal);
    weights.push_back(weight);
  }
};

/// Each triangle is cut into n² similar sub-triangles (n chosen so that a sub-triangle has area
/// <= step² and edges <= 1.5·step); one sample at each sub-triangle's centroid, with the
/// triangle's normal and the sub-triangle's area (Weights::Area, an exact partition of the
/// surface, so the field does not depend on the density) or 1 (Weights::Unit, the seed's sum).
/// Degenerate (zero-area) triangles are skipped. Throws common::InputError for step_mm <= 0 or
/// a non-finite vertex.
ObstacleSamples sampleObstacles(std::span<const geometry::TriangleMesh> meshes, double step_mm,
                                Weights weights);

/// The n of sampleObstacles' n×n split of triangle (a, b, c): sub-triangles of area <= step² and
/// edges <= 1.5·step (>= 1). The memory estimates count samples with it.
int triangleSplits(const Vec3& a, const Vec3& b, const Vec3& c, double step_mm);

/// Whether a piece of surface is under a quarter of a sample's patch (step²): sampleObstacles
/// merges such pieces per cell of side `step` and direction of normal instead of sampling each.
inline bool isSmallPiece(double area_mm2, double step_mm) {
  return area_mm2 < 0.25 * step_mm * step_mm;
}

/// The thinnest wall of a sample set: two samples within `within_mm` of each other whose normals
/// face apart (within 18° of opposite), each behind the other's face, `thickness_mm` their
/// distance along the first one's normal, where every sample beside the first on its face (three at
/// least) finds the same within a fifth (a wall, not a crease or a rounded edge, whose depth
/// changes across a step: a review's 30° wedge, a blade's sharp edge and its nose were called
/// walls). The field's samples see such walls (law.h's thin-wall rule); a voxel grid coarser than
/// twice their thickness interpolates across them between nodes on both faces and pulls a point
/// beside them in (app/scene_notes.cpp names them).
struct ThinWall {
  double thickness_mm = HUGE_VAL;  ///< HUGE_VAL: none found
  Vec3 at_mm = Vec3::Zero();       ///< the first sample of the pair
};
ThinWall thinnestWall(const ObstacleSamples& samples, double within_mm);

/// The far faces of law.h's thin-wall rule, one flag a sample: sample k is one if a sample j
/// within `reach_mm` of it faces away from it (n_j·n_k < 0) from behind its face
/// ((q_j - q_k)·n_k < 0): the far face of a wall thinner than the reach (or of a sharp edge),
/// whose nearest sample to a point beside the near face may be k's. The rule searches for a
/// near face only where the nearest sample is flagged: every evaluator reads these flags.
std::vector<std::uint8_t> farFaces(const ObstacleSamples& samples, double reach_mm);

}  // namespace fieldpath::field
