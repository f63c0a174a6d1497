#include "fieldpath/field/sampling.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "fieldpath/common/errors.h"

namespace fieldpath::field {
namespace {

/// Pieces of surface smaller than a quarter of a sample's patch (step²), gathered into one sample
/// per cell of side `step` and direction of normal. A CAD export tessellated finer than the step
/// (1 M triangles on 10^4 mm²) gave one sample a triangle, 100× the density asked, and the field
/// took 100× as long (200 s for a probe, a scale sweep's finding); merged, about one sample per
/// step² as for a coarse mesh. A cell's pieces are merged by normal direction (a cell of the
/// normal's cube map, under ~25 deg wide), so the two faces of a wall thinner than the step, the
/// faces at a box's edge and the sectors of a fillet stay apart: the sample keeps the pieces' area
/// (Weights::Area, still an exact partition), their area-weighted centroid and mean normal.
class SmallPieces {
 public:
  explicit SmallPieces(double step_mm) : step_mm_(step_mm) {}

  void add(const Vec3& centroid, const Vec3& normal, double area_mm2) {
    // The normal's cell on the cube map: the face of its largest component, then 4 x 4 on that
    // face (cells under ~25 deg wide): the pieces of a fillet or a thin cylinder merged across
    // a 90 deg sector sat off the surface, and the field 0.3 mm from an R 1.5 cylinder swung
    // 17.8 deg off radial (a reviewer's case).
    int axis = 0;
    normal.cwiseAbs().maxCoeff(&axis);
    const double along = std::abs(normal[axis]);
    const auto cell = [along](double c) {
      return std::clamp(static_cast<int>(std::floor((c / along + 1.0) * 2.0)), 0, 3);
    };
    const int direction =
        ((2 * axis + (normal[axis] < 0.0 ? 1 : 0)) * 4 + cell(normal[(axis + 1) % 3])) * 4 +
        cell(normal[(axis + 2) % 3]);
    // Cells counted in double and clamped: a step of 1e-300 mm would overflow the integers.
    const auto index = [this](double c) {
      return static_cast<std::int64_t>(std::clamp(std::floor(c / step_mm_), -4e18, 4e18));
    };
    const Key key{index(centroid.x()), index(centroid.y()), index(centroid.z()), direction};
    const auto [it, fresh] = index_.try_emplace(key, merged_.size());
    if (fresh) merged_.push_back({});
    Merged& m = merged_[it->second];
    m.moment += area_mm2 * centroid;
    m.normal += area_mm2 * normal;
    m.area += area_mm2;
  }

  /// The merged samples, in the order their cells were first met (deterministic).
  void appendTo(ObstacleSamples& out, Weights weights) const {
    for (const Merged& m : merged_)
      out.add(m.moment / m.area, m.normal.normalized(), weights == Weights::Area ? m.area : 1.0);
  }

 private:
  struct Key {
    std::int64_t x, y, z;
    int direction;
    bool operator==(const Key&) const = default;
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = static_cast<std::uint64_t>(k.direction);
      for (const std::int64_t c : {k.x, k.y, k.z})
        h = (h ^ static_cast<std::uint64_t>(c)) * 0x9E3779B97F4A7C15ull;
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  struct Merged {
    Vec3 moment = Vec3::Zero(), normal = Vec3::Zero();
    double area = 0.0;
  };
  double step_mm_;
  std::unordered_map<Key, std::size_t, KeyHash> index_;
  std::vector<Merged> merged_;
};

/// One point at the centroid of each piece of triangle (a, b, c) halved at its longest edge until
/// every edge is at most 1.5 steps: points proportional to its length, not to its length squared.
void sampleSliver(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal, double step_mm,
                  Weights weights, ObstacleSamples& out, SmallPieces& small, int depth = 0) {
  const double ab = (b - a).norm(), bc = (c - b).norm(), ca = (a - c).norm();
  const double longest = std::max({ab, bc, ca});
  if (longest <= 1.5 * step_mm || depth >= 40) {
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (isSmallPiece(area, step_mm))
      small.add((a + b + c) / 3.0, normal, area);
    else
      out.add((a + b + c) / 3.0, normal, weights == Weights::Area ? area : 1.0);
    return;
  }
  if (longest == ab) {
    const Vec3 m = 0.5 * (a + b);
    sampleSliver(a, m, c, normal, step_mm, weights, out, small, depth + 1);
    sampleSliver(m, b, c, normal, step_mm, weights, out, small, depth + 1);
  } else if (longest == bc) {
    const Vec3 m = 0.5 * (b + c);
    sampleSliver(a, b, m, normal, step_mm, weights, out, small, depth + 1);
    sampleSliver(a, m, c, normal, step_mm, weights, out, small, depth + 1);
  } else {
    const Vec3 m = 0.5 * (c + a);
    sampleSliver(a, b, m, normal, step_mm, weights, out, small, depth + 1);
    sampleSliver(m, b, c, normal, step_mm, weights, out, small, depth + 1);
  }
}

}  // namespace

int triangleSplits(const Vec3& a, const Vec3& b, const Vec3& c, double step_mm) {
  const double area = 0.5 * (b - a).cross(c - a).norm();
  const double longest = std::max({(b - a).norm(), (c - b).norm(), (a - c).norm()});
  // In double and clamped before the cast: a step of 1e-300 mm would overflow an int.
  return static_cast<int>(std::clamp(
      std::ceil(std::max(std::sqrt(area) / step_mm, longest / (1.5 * step_mm))), 1.0, 1e9));
}

ObstacleSamples sampleObstacles(std::span<const geometry::TriangleMesh> meshes, double step_mm,
                                Weights weights) {
  if (!(step_mm > 0.0) || !std::isfinite(step_mm))
    throw common::InputError("field.sample_step: must be > 0 (got " + std::to_string(step_mm) +
                             ")");
  ObstacleSamples out;
  SmallPieces small(step_mm);
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    const auto& mesh = meshes[m];
    for (const auto& v : mesh.vertices)
      if (!v.allFinite())
        throw common::InputError("obstacle " + std::to_string(m + 1) + ": non-finite vertex");
    // A triangle written again the same way round is sampled once (each copy pushed).
    const std::vector<char> repeated = geometry::repeatedFacets(mesh);
    for (std::size_t i = 0; i < mesh.triangles.size(); ++i) {
      const auto& t = mesh.triangles[i];
      const int nv = static_cast<int>(mesh.vertices.size());
      if (t.minCoeff() < 0 || t.maxCoeff() >= nv || repeated[i]) continue;
      const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
      const Vec3 cross = (b - a).cross(c - a);
      const double area = 0.5 * cross.norm();
      if (!(area > 0.0)) continue;
      const Vec3 normal = cross.normalized();
      const int n = triangleSplits(a, b, c, step_mm);
      if (double(n) * n > 2.0 * std::max(1.0, area / (step_mm * step_mm))) {
        // A sliver (CAD tessellations are full of them): the n×n split would put n² points on
        // little area. Halve it at its longest edge instead, until no edge exceeds 1.5 steps.
        sampleSliver(a, b, c, normal, step_mm, weights, out, small);
        out.area_mm2 += area;
        continue;
      }
      if (n == 1 && isSmallPiece(area, step_mm)) {
        small.add((a + b + c) / 3.0, normal, area);
        out.area_mm2 += area;
        continue;
      }
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
  small.appendTo(out, weights);
  return out;
}

namespace {

/// The samples in cells of side `cell_mm` (hashed): forNear(i, radius, fn) calls fn(j) for every
/// other sample j within radius (at most cell_mm) of sample i.
class SampleCells {
 public:
  SampleCells(const ObstacleSamples& samples, double cell_mm)
      : samples_(samples), cell_mm_(cell_mm) {
    for (std::size_t i = 0; i < samples.size(); ++i)
      cells_[keyOf(cellOf(samples.points_mm[i]))].push_back(i);
  }
  template <class Fn>
  void forNear(std::size_t i, double radius, Fn&& fn) const {
    const double within_sq = radius * radius;
    const Vec3& p = samples_.points_mm[i];
    std::vector<const Members*> near;
    neighbours(cellOf(p), near);
    for (const Members* members : near)
      for (const std::size_t j : *members)
        if (j != i && (samples_.points_mm[j] - p).squaredNorm() <= within_sq) fn(j);
  }

  using Members = std::vector<std::size_t>;
  /// The occupied cells: each one's coordinates and samples.
  std::vector<std::pair<Eigen::Vector3i, const Members*>> occupied() const {
    std::vector<std::pair<Eigen::Vector3i, const Members*>> out;
    out.reserve(cells_.size());
    for (const auto& [key, members] : cells_)
      out.emplace_back(cellOf(samples_.points_mm[members.front()]), &members);
    return out;
  }
  /// The samples of the 27 cells round cell c (those occupied).
  void neighbours(const Eigen::Vector3i& c, std::vector<const Members*>& out) const {
    out.clear();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells_.find(keyOf(c + Eigen::Vector3i(dx, dy, dz)));
          if (it != cells_.end()) out.push_back(&it->second);
        }
  }

 private:
  Eigen::Vector3i cellOf(const Vec3& p) const {
    return Eigen::Vector3i(int(std::floor(p.x() / cell_mm_)), int(std::floor(p.y() / cell_mm_)),
                           int(std::floor(p.z() / cell_mm_)));
  }
  static std::uint64_t keyOf(const Eigen::Vector3i& c) {
    return (std::uint64_t(std::uint32_t(c.x()) & 0x1fffff) << 42) |
           (std::uint64_t(std::uint32_t(c.y()) & 0x1fffff) << 21) |
           std::uint64_t(std::uint32_t(c.z()) & 0x1fffff);
  }
  const ObstacleSamples& samples_;
  double cell_mm_;
  std::unordered_map<std::uint64_t, Members> cells_;
};

}  // namespace

std::vector<std::uint8_t> farFaces(const ObstacleSamples& samples, double reach_mm) {
  std::vector<std::uint8_t> far(samples.size(), 0);
  if (!(reach_mm > 0.0) || samples.size() < 2) return far;
  // Cell by cell in parallel (each writes its own samples' flags), its 27 neighbours looked up
  // once for its samples, each sample's search stopped at its first such neighbour: 500 k
  // samples (the impeller at 0.1 mm) took 3.4 s one by one.
  const SampleCells cells(samples, reach_mm);
  const auto occupied = cells.occupied();
  const double reach_sq = reach_mm * reach_mm;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, occupied.size(), 16),
                    [&](const auto& range) {
                      std::vector<const SampleCells::Members*> near;
                      for (std::size_t c = range.begin(); c != range.end(); ++c) {
                        cells.neighbours(occupied[c].first, near);
                        for (const std::size_t k : *occupied[c].second) {
                          const Vec3& q = samples.points_mm[k];
                          const Vec3& n = samples.normals[k];
                          auto faces = [&] {
                            for (const SampleCells::Members* members : near)
                              for (const std::size_t j : *members) {
                                const Vec3 d = samples.points_mm[j] - q;
                                if (j != k && d.squaredNorm() <= reach_sq &&
                                    samples.normals[j].dot(n) < 0.0 && d.dot(n) < 0.0)
                                  return true;
                              }
                            return false;
                          };
                          far[k] = faces() ? 1 : 0;
                        }
                      }
                    });
  return far;
}

ThinWall thinnestWall(const ObstacleSamples& samples, double within_mm) {
  ThinWall thinnest;
  if (!(within_mm > 0.0) || samples.size() < 2) return thinnest;
  // Samples in cells of side 1.5 within_mm (a sample's split steps up to 1.5 steps apart: the
  // samples beside one on its face are sought that far): a pair lies in neighbouring cells.
  const double cell_mm = 1.5 * within_mm;
  const SampleCells cells(samples, cell_mm);
  auto forNear = [&](std::size_t i, double radius, auto&& fn) { cells.forNear(i, radius, fn); };
  // A sample's wall: the least depth behind its face of a sample facing the other way (normals
  // within 18° of opposite), each behind the other's face.
  std::vector<double> depth(samples.size(), HUGE_VAL);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Vec3& n = samples.normals[i];
    forNear(i, within_mm, [&](std::size_t j) {
      const Vec3 d = samples.points_mm[j] - samples.points_mm[i];
      if (n.dot(samples.normals[j]) >= -0.95) return;
      const double behind = -d.dot(n);
      if (behind > 0.0 && d.dot(samples.normals[j]) > 0.0) depth[i] = std::min(depth[i], behind);
    });
  }
  // A wall, not a crease nor a rounded edge (whose opposite faces meet, or part, within a
  // step: their depth changes across it, however long the edge): every sample within 1.5 steps on
  // the same face (within 18°), three at least, finds the same depth within a fifth.
  for (std::size_t i = 0; i < samples.size(); ++i) {
    if (!(depth[i] < thinnest.thickness_mm)) continue;
    int alike = 0;
    bool unlike = false;
    forNear(i, cell_mm, [&](std::size_t j) {
      if (samples.normals[i].dot(samples.normals[j]) <= 0.95) return;
      if (std::abs(depth[j] - depth[i]) <= 0.2 * depth[i])
        ++alike;
      else
        unlike = true;
    });
    if (alike >= 3 && !unlike) thinnest = {depth[i], samples.points_mm[i]};
  }
  return thinnest;
}

}  // namespace fieldpath::field
