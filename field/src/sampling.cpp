#include "fieldpath/field/sampling.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "fieldpath/common/errors.h"

namespace fieldpath::field {

ObstacleSamples sampleObstacles(std::span<const geometry::TriangleMesh> meshes, double step_mm,
                                Weights weights) {
  if (!(step_mm > 0.0) || !std::isfinite(step_mm))
    throw common::InputError("field.sample_step: must be > 0 (got " + std::to_string(step_mm) +
                             ")");
  ObstacleSamples out;
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const auto& mesh = meshes[m];
    for (const auto& v : mesh.vertices)
      if (!v.allFinite())
        throw common::InputError("obstacle " + std::to_string(m + 1) + ": non-finite vertex");
    for (const auto& t : mesh.triangles) {
      const int nv = static_cast<int>(mesh.vertices.size());
      if (t.minCoeff() < 0 || t.maxCoeff() >= nv) continue;
      const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
      const Vec3 cross = (b - a).cross(c - a);
      const double area = 0.5 * cross.norm();
      if (!(area > 0.0)) continue;
      const Vec3 normal = cross.normalized();
      const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
      const int n = std::max(1, static_cast<int>(std::ceil(std::max(std::sqrt(area) / step_mm,
                                                                    longest / (1.5 * step_mm)))));
      // Sub-triangles of the n×n split in barycentric steps e1 = (b-a)/n, e2 = (c-a)/n: "up" ones
      // have centroid a + (i + 1/3) e1 + (j + 1/3) e2 (i + j <= n-1), "down" ones
      // a + (i + 2/3) e1 + (j + 2/3) e2 (i + j <= n-2). All have area / n².
      const Vec3 e1 = (b - a) / n, e2 = (c - a) / n;
      const double w = weights == Weights::Area ? area / (double(n) * n) : 1.0;
      for (int i = 0; i < n; ++i)
        for (int j = 0; i + j < n; ++j) {
          out.add(a + (i + 1.0 / 3.0) * e1 + (j + 1.0 / 3.0) * e2, normal, w);
          if (i + j <= n - 2) out.add(a + (i + 2.0 / 3.0) * e1 + (j + 2.0 / 3.0) * e2, normal, w);
        }
      out.area_mm2 += area;
    }
  }
  return out;
}

}  // namespace fieldpath::field
