#pragma once
/// Exact evaluation of eq. 1 (law.h): the indexed direct sum and the brute-force reference peer.
#include <cstdint>
#include <memory>
#include <vector>

#include "fieldpath/field/force_field.h"
#include "fieldpath/field/params.h"
#include "fieldpath/field/sampling.h"

namespace fieldpath::field {

/// The exact sum over the samples within r0 of each query point, found through a radius search
/// (OpenVDB PointIndexGrid, hidden in the .cpp); parallel over query points (TBB).
class DirectField final : public ForceField {
 public:
  /// Throws common::InputError for bad params (r0 <= 0, r_min outside (0, r0), non-finite gain)
  /// or samples whose vectors differ in size.
  DirectField(ObstacleSamples samples, const FieldParams& params);
  ~DirectField() override;
  DirectField(DirectField&&) noexcept;
  DirectField& operator=(DirectField&&) noexcept;

  void evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const override;

  const ObstacleSamples& samples() const;
  const FieldParams& params() const;

  struct Index;  ///< the point index (OpenVDB), defined in field/src
  const Index& index() const { return *index_; }

 private:
  std::unique_ptr<Index> index_;
};

/// Every sample for every query point (the seed's direct method): the reference peer of
/// benchmarks. Parallel over query points.
class BruteForceField final : public ForceField {
 public:
  BruteForceField(ObstacleSamples samples, const FieldParams& params);
  void evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const override;

 private:
  ObstacleSamples samples_;
  FieldParams params_;
  std::vector<std::uint8_t> far_face_;  ///< farFaces (law.h's thin-wall rule)
};

/// Throws common::InputError naming the key (field.r0, field.r_min, ...) if `params` is invalid.
void validate(const FieldParams& params);

}  // namespace fieldpath::field
