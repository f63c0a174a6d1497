#include "fieldpath/geometry/posture.h"

namespace fieldpath::geometry {

Eigen::Matrix3d rotationFromZ(const Vec3& axis) {
  const Vec3 a = axis.normalized();
  const double i = a.x(), j = a.y(), k = a.z();
  const double s = i * i + j * j;
  double f;  // = 1/(1+k), computed without cancellation on either hemisphere
  if (k >= 0.0) {
    f = 1.0 / (1.0 + k);
  } else if (s > 0.0) {
    f = (1.0 - k) / s;
  } else {
    return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  }
  Eigen::Matrix3d r;
  r << 1.0 - f * i * i, -f * i * j, i,  //
      -f * i * j, 1.0 - f * j * j, j,   //
      -i, -j, k;
  return r;
}

Eigen::Isometry3d toolToWorld(const Posture& posture) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = rotationFromZ(posture.axis);
  t.translation() = posture.tip_mm;
  return t;
}

Posture postureFromTransform(const Eigen::Isometry3d& tool_to_world) {
  Posture p;
  p.tip_mm = tool_to_world.translation();
  p.axis = tool_to_world.linear().col(2).normalized();
  return p;
}

}  // namespace fieldpath::geometry
