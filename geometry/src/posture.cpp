#include "fieldpath/geometry/posture.h"

#include <cmath>

namespace fieldpath::geometry {

Eigen::Matrix3d rotationFromZ(const Vec3& axis) {
  const Vec3 a = axis.normalized();
  const double i = a.x(), j = a.y(), k = a.z();
  // f·i², f·i·j, f·j² with f = 1/(1+k), computed without cancellation on either hemisphere:
  // for k < 0, f = (1-k)/(i²+j²), applied to the unit horizontal direction (i, j)/hypot(i, j) so
  // that tiny i, j (axis within 1e-160 of -z) neither underflow nor overflow.
  double fii, fij, fjj;
  if (k >= 0.0) {
    const double f = 1.0 / (1.0 + k);
    fii = f * i * i, fij = f * i * j, fjj = f * j * j;
  } else {
    const double h = std::hypot(i, j);
    if (h == 0.0) return Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();  // rotation by π about x
    const double ci = i / h, cj = j / h;
    fii = (1.0 - k) * ci * ci, fij = (1.0 - k) * ci * cj, fjj = (1.0 - k) * cj * cj;
  }
  Eigen::Matrix3d r;
  r << 1.0 - fii, -fij, i,  //
      -fij, 1.0 - fjj, j,   //
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

Posture alongMotion(const Posture& a, const Posture& b, double t) {
  Posture p;
  p.tip_mm = (1 - t) * a.tip_mm + t * b.tip_mm;
  Vec3 axis = (1 - t) * a.axis + t * b.axis;
  if (axis.norm() < 1e-9) axis = a.axis.unitOrthogonal();
  p.axis = axis.normalized();
  return p;
}

}  // namespace fieldpath::geometry
