#pragma once
/// The world box that tool + holder can reach along a job's passes: the region the voxel field is
/// built in (generate, study). Outside it the voxels do not answer (field::RegionField gives the
/// exact field there, counted).
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/dynamics/params.h"
#include "fieldpath/geometry/posture.h"
#include "fieldpath/pathgen/passes.h"

namespace fieldpath::pathgen {

/// The tool + holder `nodes` (tool frame, mm) placed at pass stations every few mm, at the nominal
/// axis (lead `lead_rad`, tilt 0) and at the lead/tilt limits of `dyn`, each alone and both
/// together (the dynamics holds lead and tilt at their limits independently); the box of them
/// padded by the distance between those stations and `pad_mm`.
Eigen::AlignedBox3d reachBox(const std::vector<Pass>& passes, const std::vector<Vec3>& nodes,
                             double ball_radius_mm, const dynamics::DynamicsParams& dyn,
                             double lead_rad, double pad_mm);

/// The padding of the reach box a voxel job builds its field over (`pad_mm` above): two voxels,
/// so that the trilinear stencil of a point within reach has its nodes however the box falls.
inline double voxelRegionPadMm(double voxel_size_mm) { return 2.0 * voxel_size_mm; }

}  // namespace fieldpath::pathgen
