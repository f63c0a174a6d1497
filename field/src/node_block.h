#pragma once
/// Internal to field/ (no OpenVDB): the samples as a cell list in structure-of-arrays form, and
/// the node values of one leaf of voxel nodes computed together (the CPU block build) or of many
/// leaves on the GPU (node_build_cuda.cu). node_kernel.h holds the per-node math for both.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fieldpath/field/sampling.h"
#include "node_cuda.h"
#include "node_lanes.h"

namespace fieldpath::field {

/// The samples sorted by cell of a uniform grid (edge >= r0 / 2, at most kMaxCellsPerAxis a
/// side), in SoA form; `id` is the sample's index in ObstacleSamples.
struct SampleTable {
  static constexpr int kMaxCellsPerAxis = 160;
  std::vector<double> x, y, z, nx, ny, nz, w;
  std::vector<std::int32_t> id;
  std::vector<std::uint8_t> far_face;        ///< farFaces' flags in this table's order
  std::vector<std::uint8_t> far_face_by_id;  ///< ... and in ObstacleSamples' order
  std::vector<std::int32_t> cell_start;  ///< per cell (x-major, z fastest), then the end
  double lo[3] = {0, 0, 0};              ///< world corner of cell (0, 0, 0), mm
  double cell_mm = 1.0;
  int dim[3] = {0, 0, 0};

  /// `far_face`: farFaces(samples, ...), in the samples' order.
  SampleTable(const ObstacleSamples& samples, const std::vector<std::uint8_t>& far_face,
              double r0_mm);
  std::size_t size() const { return x.size(); }
  kernel::SampleSpan span(int begin, int end) const {
    return {x.data() + begin, y.data() + begin, z.data() + begin, nx.data() + begin,
            ny.data() + begin, nz.data() + begin, w.data() + begin, id.data() + begin,
            end - begin, begin};
  }
};

using kernel::LeafTask;
using kernel::NodeJob;

/// The table as the kernels' plain pointers.
kernel::CellTable cellTableOf(const SampleTable& table);

/// Samples in structure-of-arrays form, sized for `count` of them (the CPU block build's
/// gathered sets).
struct SampleSet {
  std::vector<double> x, y, z, nx, ny, nz, w;
  std::vector<std::int32_t> id;
  int count = 0;
  /// The seven double arrays in SampleSpan's order (x, y, z, nx, ny, nz, w).
  std::array<std::vector<double>*, 7> doubles() { return {&x, &y, &z, &nx, &ny, &nz, &w}; }
  /// Room for n samples and 8 more (the lanes' whole-vector stores; count unchanged).
  void reserveFor(std::size_t n) {
    n += 8;
    for (std::vector<double>* v : doubles())
      if (v->size() < n) v->resize(n);
    if (id.size() < n) id.resize(n);
  }
  kernel::SampleSpan span() const {
    return {x.data(), y.data(), z.data(), nx.data(), ny.data(), nz.data(), w.data(), id.data(),
            count, 0};
  }
};

/// kernel::nodeValue asks a node's neighbourhood for at most this many sums: probe's first and
/// lifted ones, and again for the plane ratio's probe of the point lifted near_mm over the surface.
constexpr int kMaxNodeSums = 4;

/// A sum a node asks for (kernel::Hood::sum's arguments), answered with other nodes' in lanes.
struct SumRequest {
  double at[3];     ///< mm
  double radius;    ///< every sample within it is asked for (the terms stop at r0)
  double best_sq;   ///< the nearest is sought within sqrt(best_sq) when `track`
  bool track;
  int node;         ///< offset in the leaf
  /// Every sample within this of `at` may count (its terms or its nearest).
  double reach() const { return std::max(radius, track ? std::sqrt(best_sq) : 0.0); }
};

/// Per-thread scratch of the CPU block build: the samples gathered for the leaf (within reach
/// of its box), for a round's lifted points where they leave that box, and those picked from
/// them for a brick of nodes or a batch of points (its core and its ring, in the same pass);
/// the sums answered per node (kMaxNodeSums a node), the requests pending.
struct BlockScratch {
  SampleSet block, lifted;
  lanes::Picks core, ring;
  std::vector<kernel::Accum> answers;        ///< node · kMaxNodeSums + k
  std::array<std::uint8_t, 512> answered{};  ///< sums answered per node
  std::array<std::vector<SumRequest>, 2> requests;  ///< a round's tracked, untracked sums
  std::vector<int> pending, next;
};

/// The values of a leaf's masked nodes (out[offset], 512 of them; unmasked ones untouched):
/// the samples within reach of the leaf gathered once; a 2 x 2 x 2 brick's first sums together,
/// the nodes in the vector lanes, over the samples near the brick; then, in rounds, every node's
/// value made from the sums it has, the sums still asked for (the points the surface rule and the
/// plane ratio lift a node to) answered 8 points at a time over the samples near them. Same
/// values as the per-node reference build up to the order of the sums.
void buildLeafNodes(const SampleTable& table, const ObstacleSamples& samples, const NodeJob& job,
                    const LeafTask& leaf, BlockScratch& scratch, kernel::NodeValue* out);

}  // namespace fieldpath::field
