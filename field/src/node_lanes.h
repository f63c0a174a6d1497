#pragma once
/// Internal to field/ (no OpenVDB): the CPU block build's sums in vector lanes (node_lanes.cpp),
/// used by node_block.cpp. Each runs AVX-512 where the CPU has it, a generic lane loop (or
/// nothing, rowFirstSums) elsewhere; the terms are kernel::addTerm's (node_kernel.h).
#include <cstdint>

#include "node_block.h"
#include "node_kernel.h"

namespace fieldpath::field::lanes {

constexpr int kLanes = 8;

/// The first `lanes` per-lane nearest samples merged into a (ties: lowest id).
void mergeNearest(const double* best, const std::int64_t* best_id, const std::int64_t* best_at,
                  kernel::Accum& a, int lanes = kLanes);

/// Eq. 1 at `at` over the samples of `n` spans (a superset of those within r0: the terms filter
/// by distance), the nearest tracked if `track` (from a.best_sq; ties: lowest id).
void accumulateLanes(const kernel::Law& L, const kernel::SampleSpan* spans, int n, kernel::D3 at,
                     bool track, kernel::Accum& a);
void accumulateLanes(const kernel::Law& L, const kernel::SampleSpan& s, kernel::D3 at,
                     bool track, kernel::Accum& a);

/// An axis-aligned box (mm; a row's segment when x0 = x1 and y0 = y1).
struct Box {
  double lo[3], hi[3];
};

/// The samples of `from` within sqrt(near_sq) of `box` (squared distance d² <= near_sq) copied
/// to `near`, and if `far` those with near_sq < d² <= far_sq to `far`, in their order (counts
/// set; both sized for all of `from`: SampleSet::reserveFor).
void gather(const kernel::SampleSpan& from, const Box& box, double near_sq, double far_sq,
            SampleSet& near, SampleSet* far);

/// The first sums (kernel::probe's) of a row's 8 nodes at (x, y, node_z[k]) at once, the nodes
/// in the lanes: every sample of `core` (those within r0 of the row's segment) read once for the
/// 8, eq. 1 summed for those within r0, the nearest within sqrt(init_sq) tracked (ties: lowest
/// id); then, for nodes with no sample within r0, the nearest among `ring` (the rest of the
/// row's reach). False (nothing made) without AVX-512.
bool rowFirstSums(const kernel::Law& L, const kernel::SampleSpan& core,
                  const kernel::SampleSpan& ring, double x, double y, const double* node_z,
                  double init_sq, kernel::Accum* out);

}  // namespace fieldpath::field::lanes
