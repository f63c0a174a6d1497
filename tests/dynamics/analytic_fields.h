#pragma once
/// Small analytic ForceFields and test scenes for the dynamics tests and benchmark: closed-form
/// references independent of field/ (whose direct and voxel fields are tested on their own).
#include <cmath>
#include <functional>
#include <memory>
#include <numbers>
#include <vector>

#include "fieldpath/dynamics/steering.h"
#include "fieldpath/field/force_field.h"

namespace fieldpath::dynamics::testing {

using geometry::Vec3;

/// Eq. 1 integrated over an infinite plane with area weights: at distance d from the plane
/// (r_min < d < r0) the field is |F| = π·gain·(r0 - d)² / (d·r0²) along the plane normal; held at
/// its r_min value below r_min (and inside the wall, d < 0, so an entered node is pushed out); 0
/// beyond r0.
struct PlaneField final : field::ForceField {
  Vec3 point_mm = Vec3::Zero();
  Vec3 normal = Vec3::UnitY();  ///< unit, from the wall into free space
  double r0_mm = 5.0, r_min_mm = 0.25, gain = 1.0;

  PlaneField(const Vec3& point, const Vec3& unit_normal, double gain_)
      : point_mm(point), normal(unit_normal.normalized()), gain(gain_) {}

  double magnitude(double d_mm) const {
    if (d_mm >= r0_mm) return 0.0;
    const double d = std::max(d_mm, r_min_mm);
    return std::numbers::pi * gain * (r0_mm - d) * (r0_mm - d) / (d * r0_mm * r0_mm);
  }
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    for (std::size_t i = 0; i < points.size(); ++i)
      forces[i] = magnitude((points[i] - point_mm).dot(normal)) * normal;
  }
};

/// The sum of several fields (a channel = two facing planes).
struct SumField final : field::ForceField {
  std::vector<std::shared_ptr<const field::ForceField>> parts;
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    std::vector<Vec3> part(points.size());
    for (Vec3& f : forces) f.setZero();
    for (const auto& p : parts) {
      p->evaluate(points, part);
      for (std::size_t i = 0; i < points.size(); ++i) forces[i] += part[i];
    }
  }
};

/// A wall with a step: `before` where x < step_x_mm, `after` elsewhere (discontinuous in x).
struct StepField final : field::ForceField {
  std::shared_ptr<const field::ForceField> before, after;
  double step_x_mm = 0.0;
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    for (std::size_t i = 0; i < points.size(); ++i)
      forces[i] = (points[i].x() < step_x_mm ? before : after)->at(points[i]);
  }
};

/// Voxel-like sampling of another field on a lattice of spacing h (mm): trilinear interpolation of
/// the 8 surrounding lattice values, or the nearest lattice value (piecewise constant).
struct LatticeField final : field::ForceField {
  std::shared_ptr<const field::ForceField> exact;
  double h_mm = 2.0;
  bool nearest = false;
  void evaluate(std::span<const Vec3> points, std::span<Vec3> forces) const override {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 g = points[i] / h_mm;
      if (nearest) {
        forces[i] = exact->at(g.array().round().matrix() * h_mm);
        continue;
      }
      const Vec3 base = g.array().floor().matrix();
      const Vec3 w = g - base;
      Vec3 sum = Vec3::Zero();
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner(base.x() + (c & 1), base.y() + ((c >> 1) & 1), base.z() + ((c >> 2) & 1));
        const double weight = ((c & 1) ? w.x() : 1 - w.x()) * (((c >> 1) & 1) ? w.y() : 1 - w.y()) *
                              (((c >> 2) & 1) ? w.z() : 1 - w.z());
        sum += weight * exact->at(corner * h_mm);
      }
      forces[i] = sum;
    }
  }
};

/// Ball-end tool and shank as rings of `per_ring` nodes (tool frame, tip at 0, axis +z): ball rings
/// every `dz_mm` from the tip, then shank rings up to `length_mm`. Each ring has a node at angle 0,
/// so the set is symmetric under y → -y. R = 3, L = 40, dz = 1, 12 per ring gives ≈ 500 nodes.
inline std::vector<Vec3> ringNodes(double radius_mm = 3.0, double length_mm = 40.0,
                                   double dz_mm = 1.0, int per_ring = 12) {
  std::vector<Vec3> nodes{Vec3::Zero()};
  for (double z = dz_mm; z <= length_mm + 1e-9; z += dz_mm) {
    const double r = z < radius_mm
                         ? std::sqrt(radius_mm * radius_mm - (radius_mm - z) * (radius_mm - z))
                         : radius_mm;
    for (int k = 0; k < per_ring; ++k) {
      const double phi = 2.0 * std::numbers::pi * k / per_ring;
      nodes.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
  }
  return nodes;
}

/// A straight pass along +x on the plane z = 0 (normal +z), ball centre at height R, starting at
/// x0.
inline Pass straightPass(double length_mm, double radius_mm = 3.0, double x0_mm = 0.0) {
  return Pass{length_mm, [=](double s_mm) {
                PassFrame f;
                f.centre_mm = Vec3(x0_mm + s_mm, 0.0, radius_mm);
                f.feed = Vec3::UnitX();
                f.normal = Vec3::UnitZ();
                return f;
              }};
}

}  // namespace fieldpath::dynamics::testing
