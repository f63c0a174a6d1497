#pragma once
/// Internal to field/: the OpenVDB point index behind DirectField (never include from a public
/// header; each OpenVDB translation unit costs ~15 s and 0.7 GiB to compile).
#include <cstddef>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <openvdb/openvdb.h>
#include <openvdb/tools/PointIndexGrid.h>

#include "fieldpath/common/memory.h"
#include "fieldpath/field/direct_field.h"
#include "fieldpath/field/law.h"

namespace fieldpath::field {

/// OpenVDB PointArray interface over our sample positions (world frame, mm).
struct SamplePositions {
  using PosType = openvdb::Vec3R;
  const std::vector<Vec3>* points = nullptr;
  std::size_t size() const { return points->size(); }
  void getPos(std::size_t n, PosType& xyz) const {
    const Vec3& p = (*points)[n];
    xyz = PosType(p.x(), p.y(), p.z());
  }
};

/// Runs fn(i, state) for every query index, in parallel (TBB) when there are at least
/// `serial_below` of them, with one state per task.
template <class MakeState, class Fn>
void parallelOverPoints(std::size_t n, MakeState&& make_state, Fn&& fn,
                        std::size_t serial_below = 64) {
  if (n < serial_below) {
    auto state = make_state();
    for (std::size_t i = 0; i < n; ++i) fn(i, state);
    return;
  }
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, serial_below / 2 + 1),
                    [&](const auto& range) {
                      auto state = make_state();
                      for (std::size_t i = range.begin(); i != range.end(); ++i) fn(i, state);
                    });
}

inline void checkSpans(std::span<const Vec3> points, std::span<Vec3> forces) {
  if (points.size() != forces.size())
    throw std::invalid_argument("ForceField::evaluate: points and forces differ in size");
}

void initializeOpenVdb();  ///< openvdb::initialize() once per process

struct DirectField::Index {
  ObstacleSamples samples;
  FieldParams params;
  std::vector<std::uint8_t> far_face;  ///< farFaces(samples, kThinReachSteps · sample_step)
  SamplePositions positions;
  openvdb::math::Transform::Ptr transform;  ///< index voxels of r0 (a search visits 3³ of them)
  openvdb::tools::PointIndexGrid::Ptr grid;
  /// The samples' bytes, held against --max-memory while the field lives (a study's variants of
  /// other sample steps are made and dropped).
  common::HeldMemory held;

  using Iterator = openvdb::tools::PointIndexIterator<openvdb::tools::PointIndexTree>;
  using Accessor = openvdb::tree::ValueAccessor<const openvdb::tools::PointIndexTree>;

  /// Per-thread search state.
  struct Searcher {
    Accessor accessor;
    Iterator iterator;
  };
  Searcher searcher() const { return Searcher{grid->getConstAccessor(), {}}; }

  /// Calls fn(j) for every sample j within `radius` of `center` (and some a little beyond).
  template <class Fn>
  void forEachNear(Searcher& s, const Vec3& center, double radius, Fn&& fn) const {
    s.iterator.worldSpaceSearchAndUpdate(openvdb::Vec3d(center.x(), center.y(), center.z()), radius,
                                         s.accessor, positions, *transform, false);
    for (; s.iterator; ++s.iterator) fn(static_cast<std::size_t>(*s.iterator));
  }
  /// Calls fn(j) for every sample j in the world box [lo, hi] (and some a little beyond).
  template <class Fn>
  void forEachInBox(Searcher& s, const Vec3& lo, const Vec3& hi, Fn&& fn) const {
    const openvdb::BBoxd box(openvdb::Vec3d(lo.x(), lo.y(), lo.z()),
                             openvdb::Vec3d(hi.x(), hi.y(), hi.z()));
    s.iterator.worldSpaceSearchAndUpdate(box, s.accessor, positions, *transform);
    for (; s.iterator; ++s.iterator) fn(static_cast<std::size_t>(*s.iterator));
  }

  /// The exact field at x (law.h) through the index.
  std::optional<Vec3> fieldAt(Searcher& s, const Vec3& x_mm) const {
    return detail::fieldAt(
        x_mm, [&](const Vec3& c, double r, auto&& fn) { forEachNear(s, c, r, fn); },
        samples.points_mm, samples.normals, samples.weights, far_face, params);
  }
};

}  // namespace fieldpath::field
