#pragma once
/// Internal to field/ (no OpenVDB): the CPU block build's sums in vector lanes (node_lanes.cpp),
/// used by node_block.cpp: the samples near a box picked (their positions, not copies), and
/// eq. 1 at 8 points at once over the picked samples, the points in the lanes. Each runs
/// AVX-512 where the CPU has it (FIELDPATH_LANES=generic turns it off), a generic loop the
/// compiler vectorises elsewhere; the terms are kernel::addTerm's (node_kernel.h).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "node_kernel.h"

namespace fieldpath::field::lanes {

constexpr int kLanes = 8;

/// An axis-aligned box (mm; a brick of nodes, or the bounding box of a batch of points).
struct Box {
  double lo[3], hi[3];
};

/// Positions of picked samples in a span (gather's output, laneSums' input).
struct Picks {
  std::vector<std::int32_t> at;
  int count = 0;
  /// Room for n picks and 16 more (the lanes' whole-vector stores; count unchanged).
  void reserveFor(std::size_t n) {
    if (at.size() < n + 16) at.resize(n + 16);
  }
};

/// The positions in `from` of its samples within sqrt(near_sq) of `box` (squared distance
/// d² <= near_sq) to `near`, and if `far` of those with near_sq < d² <= far_sq to `far`, in
/// their order (counts set; both sized for all of `from`: Picks::reserveFor).
void gather(const kernel::SampleSpan& from, const Box& box, double near_sq, double far_sq,
            Picks& near, Picks* far);

/// The sums (kernel::probe's) at 8 points at once, point l at (px[l], py[l], pz[l]), the
/// points in the lanes: every sample of `from` that `core` picks (a superset of those within r0
/// of the points) read once for the 8, eq. 1 summed for those within r0, the nearest within
/// sqrt(init_sq[l]) tracked (ties: lowest id; init_sq 0: none tracked); then, for points with
/// no sample within r0, the nearest among those `ring` picks (the rest of their reach).
/// out[l] starts from Accum{} with best_sq = init_sq[l]; best_at stays -1 (the block build
/// finds the nearest by its id).
void laneSums(const kernel::Law& L, const kernel::SampleSpan& from, const Picks& core,
              const Picks& ring, const double* px, const double* py, const double* pz,
              const double* init_sq, kernel::Accum* out);

}  // namespace fieldpath::field::lanes
