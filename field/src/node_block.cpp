/// The CPU block build of voxel nodes (node_block.h): the cell list, a leaf's samples gathered,
/// its rows' sums through the lane kernels (node_lanes.cpp). No OpenVDB.
#include "node_block.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "node_lanes.h"

namespace fieldpath::field {

using kernel::Accum;
using kernel::D3;
using kernel::Law;
using kernel::SampleSpan;

SampleTable::SampleTable(const ObstacleSamples& samples, double r0_mm) {
  const std::size_t n = samples.size();
  double hi[3] = {0, 0, 0};
  for (int a = 0; a < 3; ++a) {
    lo[a] = HUGE_VAL;
    hi[a] = -HUGE_VAL;
  }
  for (const Vec3& p : samples.points_mm)
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], p[a]);
      hi[a] = std::max(hi[a], p[a]);
    }
  if (n == 0)
    for (int a = 0; a < 3; ++a) lo[a] = hi[a] = 0.0;
  double extent = 0.0;
  for (int a = 0; a < 3; ++a) extent = std::max(extent, hi[a] - lo[a]);
  cell_mm = std::max(0.5 * r0_mm, extent / (kMaxCellsPerAxis - 1));
  for (int a = 0; a < 3; ++a)
    dim[a] = std::max(1, std::min(kMaxCellsPerAxis, int(std::floor((hi[a] - lo[a]) / cell_mm)) + 1));
  const std::size_t cells = std::size_t(dim[0]) * dim[1] * dim[2];
  std::vector<std::int32_t> cell_of(n);
  cell_start.assign(cells + 1, 0);
  for (std::size_t j = 0; j < n; ++j) {
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] = std::clamp(int(std::floor((samples.points_mm[j][a] - lo[a]) / cell_mm)), 0, dim[a] - 1);
    cell_of[j] = (c[0] * dim[1] + c[1]) * dim[2] + c[2];
    ++cell_start[cell_of[j] + 1];
  }
  std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
  std::vector<std::int32_t> next(cell_start.begin(), cell_start.end() - 1);
  for (auto* v : {&x, &y, &z, &nx, &ny, &nz, &w}) v->resize(n);
  id.resize(n);
  for (std::size_t j = 0; j < n; ++j) {  // stable: ids rise within a cell
    const std::size_t at = std::size_t(next[cell_of[j]]++);
    x[at] = samples.points_mm[j].x();
    y[at] = samples.points_mm[j].y();
    z[at] = samples.points_mm[j].z();
    nx[at] = samples.normals[j].x();
    ny[at] = samples.normals[j].y();
    nz[at] = samples.normals[j].z();
    w[at] = samples.weights[j];
    id[at] = std::int32_t(j);
  }
}

namespace {

using lanes::accumulateLanes;
using lanes::kLanes;
using lanes::mergeNearest;

/// A leaf's neighbourhood: the samples gathered in [box_lo, box_hi] (mm) for sums whose ball
/// lies inside that box, the cell list for the others (points lifted far off the leaf).
struct BlockHood {
  const Law* law;
  SampleSpan block;  ///< the leaf's samples: every one in [box_lo, box_hi]
  double box_lo[3], box_hi[3];
  SampleSpan row;    ///< the row's: every one within row_reach of the row's segment
  double row_x = 0, row_y = 0, row_z0 = 0, row_z1 = 0, row_reach = -1;
  const kernel::CellTable* cells;
  const ObstacleSamples* samples;
  /// The row's nodes' first sums when made together (rowFirstSums512; null otherwise): a sum
  /// with tracking at node k's point (first_z[k]) over first_radius is first[k].
  const Accum* first = nullptr;
  double first_z[kLanes] = {};
  double first_radius = -1;

  /// Gathers the columns' spans, summed together in the lanes (in batches of kSpans).
  struct Visit {
    static constexpr int kSpans = 64;
    const Law* law;
    D3 at;
    bool track;
    Accum* a;
    SampleSpan spans[kSpans];
    int n = 0;
    void operator()(const SampleSpan& s) {
      spans[n++] = s;
      if (n == kSpans) flush();
    }
    void flush() {
      if (n) accumulateLanes(*law, spans, n, at, track, *a);
      n = 0;
    }
  };
  void sum(D3 c, double radius, bool track, Accum& a) {
    if (first && track && radius == first_radius && c.x == row_x && c.y == row_y)
      for (int k = 0; k < kLanes; ++k)
        if (c.z == first_z[k]) {
          a.fx += first[k].fx;
          a.fy += first[k].fy;
          a.fz += first[k].fz;
          const std::int64_t id = first[k].best_id, at = first[k].best_at;
          mergeNearest(&first[k].best_sq, &id, &at, a, 1);
          return;
        }
    // Distance from c to the row's segment (x, y, [z0, z1]).
    const double dz = c.z < row_z0 ? row_z0 - c.z : c.z > row_z1 ? c.z - row_z1 : 0.0;
    const double dx = c.x - row_x, dy = c.y - row_y;
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (d + radius <= row_reach) {
      accumulateLanes(*law, row, c, track, a);
      return;
    }
    const bool inside = c.x - radius >= box_lo[0] && c.y - radius >= box_lo[1] &&
                        c.z - radius >= box_lo[2] && c.x + radius <= box_hi[0] &&
                        c.y + radius <= box_hi[1] && c.z + radius <= box_hi[2];
    if (inside) {
      accumulateLanes(*law, block, c, track, a);
      return;
    }
    Visit v{law, c, track, &a, {}, 0};
    kernel::cellSpans(*cells, c, radius, v);
    v.flush();
  }
  D3 point(const Accum& a) const {
    const Vec3& p = samples->points_mm[std::size_t(a.best_id)];
    return {p.x(), p.y(), p.z()};
  }
  D3 normal(const Accum& a) const {
    const Vec3& n = samples->normals[std::size_t(a.best_id)];
    return {n.x(), n.y(), n.z()};
  }
};

}  // namespace

kernel::CellTable cellTableOf(const SampleTable& t) {
  kernel::CellTable c;
  c.all = t.span(0, int(t.size()));
  c.cell_start = t.cell_start.data();
  for (int a = 0; a < 3; ++a) {
    c.lo[a] = t.lo[a];
    c.dim[a] = t.dim[a];
  }
  c.cell_mm = t.cell_mm;
  c.inv_cell = 1.0 / t.cell_mm;
  return c;
}

void buildLeafNodes(const SampleTable& table, const ObstacleSamples& samples, const NodeJob& job,
                    const LeafTask& leaf, BlockScratch& scratch, kernel::NodeValue* out) {
  const double h = job.h_mm;
  const double reach = std::max(job.rules.reach_mm, job.law.r0);
  BlockHood hood;
  hood.law = &job.law;
  hood.samples = &samples;
  for (int a = 0; a < 3; ++a) {
    hood.box_lo[a] = leaf.origin[a] * h - reach;
    hood.box_hi[a] = (leaf.origin[a] + 7) * h + reach;
  }
  const kernel::CellTable cells = cellTableOf(table);
  hood.cells = &cells;
  // Gather the samples of the box once, in SoA form.
  SampleSet& block = scratch.block;
  block.count = 0;
  const D3 centre{0.5 * (hood.box_lo[0] + hood.box_hi[0]), 0.5 * (hood.box_lo[1] + hood.box_hi[1]),
                  0.5 * (hood.box_lo[2] + hood.box_hi[2])};
  struct Gather {
    SampleSet* s;
    const double *lo, *hi;
    void operator()(const SampleSpan& span) {
      s->reserveFor(std::size_t(s->count + span.count));
      int& n = s->count;
      for (int j = 0; j < span.count; ++j) {
        const double px = span.x[j], py = span.y[j], pz = span.z[j];
        if (px < lo[0] || py < lo[1] || pz < lo[2] || px > hi[0] || py > hi[1] || pz > hi[2])
          continue;
        s->x[n] = px;
        s->y[n] = py;
        s->z[n] = pz;
        s->nx[n] = span.nx[j];
        s->ny[n] = span.ny[j];
        s->nz[n] = span.nz[j];
        s->w[n] = span.w[j];
        s->id[n] = span.id[j];
        ++n;
      }
    }
  } gather{&block, hood.box_lo, hood.box_hi};
  // The box's half diagonal covers it (a superset; the gather filters by the box).
  const double half = std::sqrt(3.0) * 0.5 * (hood.box_hi[0] - hood.box_lo[0]);
  kernel::cellSpans(cells, centre, half, gather);
  hood.block = block.span();
  for (SampleSet* set : {&scratch.row, &scratch.ring})
    set->reserveFor(std::size_t(block.count));
  const double row_reach = reach * (1.0 + 1e-12);
  const double reach_sq = row_reach * row_reach;
  hood.row_reach = reach;
  const double core_sq = job.law.r0_sq * (1.0 + 1e-12);
  // probe()'s first sum: radius max(reach, r0), the nearest tracked from its square.
  double first_sq = kernel::dmax(job.rules.reach_mm, job.law.r0);
  first_sq *= first_sq;
  hood.first_radius = std::sqrt(first_sq);
  for (int k = 0; k < kLanes; ++k) hood.first_z[k] = (leaf.origin[2] + k) * h;
  const double z0 = leaf.origin[2] * h, z1 = (leaf.origin[2] + 7) * h;
  Accum first[kLanes];
  // Row by row (8 nodes along z): the leaf's samples within reach of the row's segment.
  for (int row = 0; row < 64; ++row) {
    const int i = row >> 3, j = row & 7;
    const std::uint64_t bits8 = (leaf.mask[i] >> (j * 8)) & 0xffu;
    if (!bits8) continue;
    hood.row_x = (leaf.origin[0] + i) * h;
    hood.row_y = (leaf.origin[1] + j) * h;
    hood.row_z0 = z0;
    hood.row_z1 = z1;
    // The samples within r0 of the segment first (the core: every term of the row's first
    // sums), then the rest within reach (the ring: only a shell node's nearest), in one pass.
    const lanes::Box segment{{hood.row_x, hood.row_y, z0}, {hood.row_x, hood.row_y, z1}};
    lanes::gather(hood.block, segment, core_sq, reach_sq, scratch.row, &scratch.ring);
    const int core = scratch.row.count;
    scratch.row.append(scratch.ring);
    hood.row = scratch.row.span();
    SampleSpan core_span = hood.row;
    core_span.count = core;
    hood.first = nullptr;
    if (lanes::rowFirstSums(job.law, core_span, kernel::tail(hood.row, core), hood.row_x,
                            hood.row_y, hood.first_z, first_sq, first))
      hood.first = first;
    for (int k = 0; k < 8; ++k) {
      if (!((bits8 >> k) & 1u)) continue;
      const D3 x{hood.row_x, hood.row_y, (leaf.origin[2] + k) * h};
      out[row * 8 + k] = kernel::nodeValue(hood, job.law, job.rules, x);
    }
  }
}

}  // namespace fieldpath::field
