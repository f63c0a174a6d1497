#include <mutex>
#include <string>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/short_number.h"
#include "point_index.h"

namespace fieldpath::field {

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

void validate(const FieldParams& p) {
  auto bad = [](const std::string& key, const std::string& why, double got) {
    throw common::InputError("field." + key + ": " + why + " (got " + std::to_string(got) + ")");
  };
  if (!(p.r0_mm > 0.0) || !std::isfinite(p.r0_mm)) bad("r0", "must be > 0", p.r0_mm);
  if (!(p.r_min_mm > 0.0) || !(p.r_min_mm < p.r0_mm))
    bad("r_min", "must be in (0, r0)", p.r_min_mm);
  if (!std::isfinite(p.gain)) bad("gain", "must be finite", p.gain);
  if (!(p.sample_step_mm > 0.0) || !std::isfinite(p.sample_step_mm))
    bad("sample_step", "must be > 0", p.sample_step_mm);
  // Samples r0 apart or more leave gaps between their balls that no field covers (the voxel
  // grid, built within r0 of a sample's surface rule, read 0 beside a triangle of one sample).
  if (!(p.sample_step_mm < p.r0_mm))
    bad("sample_step",
        "must be under field.r0 (" + common::shortNumber(p.r0_mm) +
            " mm): samples farther apart leave gaps no field covers",
        p.sample_step_mm);
  if (!(p.voxel.voxel_size_mm > 0.0) || !std::isfinite(p.voxel.voxel_size_mm))
    bad("voxel_size", "must be > 0", p.voxel.voxel_size_mm);
}

namespace {

void checkSamples(const ObstacleSamples& s) {
  if (s.normals.size() != s.size() || s.weights.size() != s.size())
    throw common::InputError("obstacle samples: points, normals and weights differ in size");
}

}  // namespace

DirectField::DirectField(ObstacleSamples samples, const FieldParams& params)
    : index_(std::make_unique<Index>()) {
  validate(params);
  checkSamples(samples);
  initializeOpenVdb();
  index_->samples = std::move(samples);
  index_->params = params;
  index_->far_face = farFaces(index_->samples, kThinReachSteps * params.sample_step_mm);
  index_->positions.points = &index_->samples.points_mm;
  index_->transform = openvdb::math::Transform::createLinearTransform(params.r0_mm);
  index_->grid = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(
      index_->positions, *index_->transform);
  // Point, normal, weight (56 B) grown by push_back (x 2) and the point index, rounded up: as
  // app/estimates.h's kBytesPerSample.
  const double bytes = 128.0 * double(index_->samples.size());
  common::requireMemory("the obstacle samples", bytes,
                        std::to_string(index_->samples.size()) + " samples",
                        common::MemoryUse::kPassing);  // against what the run holds now
  index_->held = common::HeldMemory("the obstacle samples", bytes);
}

DirectField::~DirectField() = default;
DirectField::DirectField(DirectField&&) noexcept = default;
DirectField& DirectField::operator=(DirectField&&) noexcept = default;

const ObstacleSamples& DirectField::samples() const { return index_->samples; }
const FieldParams& DirectField::params() const { return index_->params; }

void DirectField::evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const {
  checkSpans(points_mm, forces);
  const Index& index = *index_;
  parallelOverPoints(
      points_mm.size(), [&] { return index.searcher(); },
      [&](std::size_t i, Index::Searcher& s) {
        forces[i] = index.fieldAt(s, points_mm[i]).value_or(Vec3::Zero());
      });
}

BruteForceField::BruteForceField(ObstacleSamples samples, const FieldParams& params)
    : samples_(std::move(samples)), params_(params) {
  validate(params);
  checkSamples(samples_);
  far_face_ = farFaces(samples_, kThinReachSteps * params.sample_step_mm);
}

void BruteForceField::evaluate(std::span<const Vec3> points_mm, std::span<Vec3> forces) const {
  checkSpans(points_mm, forces);
  const std::size_t n = samples_.size();
  auto every = [n](const Vec3&, double, auto&& fn) {
    for (std::size_t j = 0; j < n; ++j) fn(j);
  };
  parallelOverPoints(
      points_mm.size(), [] { return 0; },
      [&](std::size_t i, int&) {
        forces[i] = detail::fieldAt(points_mm[i], every, samples_.points_mm, samples_.normals,
                                    samples_.weights, far_face_, params_)
                        .value_or(Vec3::Zero());
      });
}

}  // namespace fieldpath::field
