#pragma once
/// Internal to field/ (no OpenVDB): the samples as a cell list in structure-of-arrays form, and
/// the node values of one leaf of voxel nodes computed together (the CPU block build) or of many
/// leaves on the GPU (node_build_cuda.cu). node_kernel.h holds the per-node math for both.
#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fieldpath/field/sampling.h"
#include "node_cuda.h"

namespace fieldpath::field {

/// The samples sorted by cell of a uniform grid (edge >= r0 / 2, at most kMaxCellsPerAxis a
/// side), in SoA form; `id` is the sample's index in ObstacleSamples.
struct SampleTable {
  static constexpr int kMaxCellsPerAxis = 160;
  std::vector<double> x, y, z, nx, ny, nz, w;
  std::vector<std::int32_t> id;
  std::vector<std::int32_t> cell_start;  ///< per cell (x-major, z fastest), then the end
  double lo[3] = {0, 0, 0};              ///< world corner of cell (0, 0, 0), mm
  double cell_mm = 1.0;
  int dim[3] = {0, 0, 0};

  explicit SampleTable(const ObstacleSamples& samples, double r0_mm);
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
  std::array<const std::vector<double>*, 7> doubles() const {
    return {&x, &y, &z, &nx, &ny, &nz, &w};
  }
  /// Room for n samples and 8 more (the lanes' whole-vector stores; count unchanged).
  void reserveFor(std::size_t n) {
    n += 8;
    for (std::vector<double>* v : doubles())
      if (v->size() < n) v->resize(n);
    if (id.size() < n) id.resize(n);
  }
  /// Appends the samples of `more` (room for them made beforehand: reserveFor).
  void append(const SampleSet& more) {
    const auto from = more.doubles();
    const auto to = doubles();
    for (int k = 0; k < 7; ++k)
      std::copy(from[k]->begin(), from[k]->begin() + more.count, to[k]->begin() + count);
    std::copy(more.id.begin(), more.id.begin() + more.count, id.begin() + count);
    count += more.count;
  }
  kernel::SampleSpan span() const {
    return {x.data(), y.data(), z.data(), nx.data(), ny.data(), nz.data(), w.data(), id.data(),
            count, 0};
  }
};

/// Per-thread scratch of the CPU block build: the samples gathered for the leaf (within reach
/// of its box) and for one row (its core, then its ring, gathered apart in the same pass).
struct BlockScratch {
  SampleSet block, row, ring;
};

/// The values of a leaf's masked nodes (out[offset], 512 of them; unmasked ones untouched):
/// the samples within reach of the leaf gathered once, then every node summed against them in
/// vector loops (the points a node's surface rule lifts it to read the same samples when they
/// fall inside the gathered box, the cell list otherwise). Same values as the per-node
/// reference build up to the order of the sums.
void buildLeafNodes(const SampleTable& table, const ObstacleSamples& samples, const NodeJob& job,
                    const LeafTask& leaf, BlockScratch& scratch, kernel::NodeValue* out);

}  // namespace fieldpath::field
