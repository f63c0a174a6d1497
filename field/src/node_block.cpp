/// The CPU block build of voxel nodes (node_block.h): the cell list, a leaf's samples gathered,
/// its bricks' sums through the lane kernels (node_lanes.cpp). No OpenVDB.
#include "node_block.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "node_lanes.h"

namespace fieldpath::field {

using kernel::Accum;
using kernel::D3;
using kernel::Law;
using kernel::SampleSpan;

SampleTable::SampleTable(const ObstacleSamples& samples, const std::vector<std::uint8_t>& far,
                         double r0_mm)
    : far_face_by_id(far) {
  if (far.size() != samples.size())
    throw std::logic_error("SampleTable: far-face flags and samples differ in size");
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
    dim[a] =
        std::max(1, std::min(kMaxCellsPerAxis, int(std::floor((hi[a] - lo[a]) / cell_mm)) + 1));
  const std::size_t cells = std::size_t(dim[0]) * dim[1] * dim[2];
  std::vector<std::int32_t> cell_of(n);
  cell_start.assign(cells + 1, 0);
  for (std::size_t j = 0; j < n; ++j) {
    int c[3];
    for (int a = 0; a < 3; ++a)
      c[a] =
          std::clamp(int(std::floor((samples.points_mm[j][a] - lo[a]) / cell_mm)), 0, dim[a] - 1);
    cell_of[j] = (c[0] * dim[1] + c[1]) * dim[2] + c[2];
    ++cell_start[cell_of[j] + 1];
  }
  std::partial_sum(cell_start.begin(), cell_start.end(), cell_start.begin());
  std::vector<std::int32_t> next(cell_start.begin(), cell_start.end() - 1);
  for (auto* v : {&x, &y, &z, &nx, &ny, &nz, &w}) v->resize(n);
  id.resize(n);
  far_face.resize(n);
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
    far_face[at] = far[j];
  }
}

namespace {

using lanes::kLanes;

/// A node's neighbourhood in the staged build (buildLeafNodes): its sums answered in the order
/// kernel::nodeValue asks for them; the first one not answered yet is recorded and the hood
/// pending (nodeValue stops; the node runs again once it is answered).
/// nodeValue asks each sum with a fresh Accum (zero sum, best_sq its search radius²), as the
/// answers were started.
struct ReplayHood {
  const Accum* answers;
  int answered;
  SumRequest* request;
  const ObstacleSamples* samples;
  const kernel::CellTable* cells;  ///< the thin-wall rule's search (rare: far faces read inside)
  const std::uint8_t* far_face;    ///< by sample id
  int asked = 0;
  bool missing = false;

  void sum(D3 c, double radius, bool track, Accum& a) {
    if (asked < answered) {
      a = answers[asked++];
      return;
    }
    *request = SumRequest{{c.x, c.y, c.z}, radius, a.best_sq, track, -1};
    missing = true;
  }
  D3 point(const Accum& a) const {
    const Vec3& p = samples->points_mm[std::size_t(a.best_id)];
    return {p.x(), p.y(), p.z()};
  }
  D3 normal(const Accum& a) const {
    const Vec3& n = samples->normals[std::size_t(a.best_id)];
    return {n.x(), n.y(), n.z()};
  }
  bool farFace(const Accum& a) const { return far_face[a.best_id] != 0; }
  void nearFace(D3 x, D3 q, D3 n, double eta, Accum& a) const {
    kernel::nearFaceIn(*cells, x, q, n, eta, a);
  }
  void round(D3 foot, D3 nj, double reach, kernel::Round& r) const {
    kernel::roundIn(*cells, foot, nj, reach, r);
  }
  bool pending() const { return missing; }
};

/// Copies the samples of the spans it is given that lie in [lo, hi] (mm) to `set`.
struct GatherBox {
  SampleSet* set;
  const double *lo, *hi;
  void operator()(const SampleSpan& span) {
    set->reserveFor(std::size_t(set->count + span.count));
    int& n = set->count;
    for (int j = 0; j < span.count; ++j) {  // written whether in or not: no branch to mispredict
      const double px = span.x[j], py = span.y[j], pz = span.z[j];
      set->x[n] = px;
      set->y[n] = py;
      set->z[n] = pz;
      set->nx[n] = span.nx[j];
      set->ny[n] = span.ny[j];
      set->nz[n] = span.nz[j];
      set->w[n] = span.w[j];
      set->id[n] = span.id[j];
      n += (px >= lo[0]) & (py >= lo[1]) & (pz >= lo[2]) & (px <= hi[0]) & (py <= hi[1]) &
           (pz <= hi[2]);
    }
  }
};

/// The samples of the cell list in [lo, hi] (mm) copied to `set` (its count reset).
void gatherBox(const kernel::CellTable& cells, const double* lo, const double* hi, SampleSet& set) {
  set.count = 0;
  GatherBox gather{&set, lo, hi};
  const D3 centre{0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]), 0.5 * (lo[2] + hi[2])};
  // The box's half diagonal covers it (a superset; the gather filters by the box).
  const double half = 0.5 * std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) +
                                      (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                                      (hi[2] - lo[2]) * (hi[2] - lo[2]));
  kernel::cellSpans(cells, centre, half, gather);
}

/// The sums of up to 8 requests together (SumRequest order, the points in the lanes): the
/// samples of `from` within r0 of the points' bounding box, and the ring out to the largest
/// radius, gathered (`from` holds every sample within that reach of the points); each answer
/// appended to its node's.
void answerBatch(const Law& law, const SampleSpan& from, const SumRequest* r, int n,
                 BlockScratch& scratch) {
  alignas(64) double px[kLanes], py[kLanes], pz[kLanes], init_sq[kLanes];
  lanes::Box box{{HUGE_VAL, HUGE_VAL, HUGE_VAL}, {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL}};
  double reach = 0.0;
  for (int l = 0; l < kLanes; ++l) {
    const SumRequest& q = r[std::min(l, n - 1)];  // the last one again in the lanes past n
    px[l] = q.at[0];
    py[l] = q.at[1];
    pz[l] = q.at[2];
    init_sq[l] = q.track ? q.best_sq : 0.0;
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = std::min(box.lo[a], q.at[a]);
      box.hi[a] = std::max(box.hi[a], q.at[a]);
    }
    reach = std::max(reach, q.reach());
  }
  const double core_sq = law.r0_sq * (1.0 + 1e-12);
  const double reach_sq = reach * reach * (1.0 + 1e-12);
  scratch.core.reserveFor(std::size_t(from.count));
  scratch.ring.reserveFor(std::size_t(from.count));
  scratch.ring.count = 0;
  lanes::gather(from, box, core_sq, reach_sq, scratch.core,
                reach_sq > core_sq ? &scratch.ring : nullptr);
  Accum out[kLanes];
  lanes::laneSums(law, from, scratch.core, scratch.ring, px, py, pz, init_sq, out);
  for (int l = 0; l < n; ++l) {
    Accum a = out[l];
    if (!r[l].track) {  // as an untracked sum leaves it
      a.best_sq = r[l].best_sq;
      a.best_id = -1;
      a.best_at = -1;
    }
    const int node = r[l].node;
    scratch.answers[std::size_t(node) * kMaxNodeSums + scratch.answered[node]++] = a;
  }
}

}  // namespace

kernel::CellTable cellTableOf(const SampleTable& t) {
  kernel::CellTable c;
  c.all = t.span(0, int(t.size()));
  c.cell_start = t.cell_start.data();
  c.far_face = t.far_face.data();
  for (int a = 0; a < 3; ++a) {
    c.lo[a] = t.lo[a];
    c.dim[a] = t.dim[a];
  }
  c.cell_mm = t.cell_mm;
  c.inv_cell = 1.0 / t.cell_mm;
  return c;
}

void buildLeafNodes(const SampleTable& table, const ObstacleSamples& samples, const NodeJob& job,
                    const LeafTask& task, BlockScratch& scratch, kernel::NodeValue* out) {
  const double h = job.h_mm;
  const double reach = std::max(job.rules.reach_mm, job.law.r0);
  const kernel::CellTable cells = cellTableOf(table);
  double box_lo[3], box_hi[3];  // the leaf's nodes' reach
  for (int a = 0; a < 3; ++a) {
    box_lo[a] = task.origin[a] * h - reach;
    box_hi[a] = (task.origin[a] + 7) * h + reach;
  }
  SampleSet& block = scratch.block;
  gatherBox(cells, box_lo, box_hi, block);
  const SampleSpan block_span = block.span();
  scratch.core.reserveFor(std::size_t(block.count));
  scratch.ring.reserveFor(std::size_t(block.count));
  scratch.answers.resize(512 * kMaxNodeSums);
  const double reach_sq = reach * reach * (1.0 + 1e-12);
  const double core_sq = job.law.r0_sq * (1.0 + 1e-12);
  // probe()'s first sum: radius max(reach, r0), the nearest tracked from its square.
  double first_sq = kernel::dmax(job.rules.reach_mm, job.law.r0);
  first_sq *= first_sq;
  alignas(64) double lane_x[kLanes], lane_y[kLanes], lane_z[kLanes], init_sq[kLanes];
  std::fill(init_sq, init_sq + kLanes, first_sq);
  std::vector<int>& pending = scratch.pending;
  pending.clear();
  // Brick by brick (2 x 2 x 2 nodes, one a lane): the first sums over the leaf's samples within
  // reach of the brick, those within r0 (the core: every term) apart from the rest (the ring:
  // only a shell node's nearest), gathered in one pass. Bricks, not rows of 8 along z: the
  // region within r0 of a cube is tighter than of a segment 7 h long (uniform example: 3.31 M
  // samples read against 4.07 M, and the lifted points of a brick's nodes lie closer together).
  for (int brick = 0; brick < 64; ++brick) {
    const int i0 = 2 * (brick >> 4), j0 = 2 * ((brick >> 2) & 3), k0 = 2 * (brick & 3);
    int nodes[kLanes];
    bool any = false;
    for (int l = 0; l < kLanes; ++l) {
      const int i = i0 + (l >> 2), j = j0 + ((l >> 1) & 1), k = k0 + (l & 1);
      const bool on = (task.mask[i] >> (j * 8 + k)) & 1u;
      nodes[l] = on ? (i * 8 + j) * 8 + k : -1;
      any = any || on;
      lane_x[l] = (task.origin[0] + i) * h;
      lane_y[l] = (task.origin[1] + j) * h;
      lane_z[l] = (task.origin[2] + k) * h;
    }
    if (!any) continue;
    const lanes::Box brick_box{{lane_x[0], lane_y[0], lane_z[0]},
                               {lane_x[kLanes - 1], lane_y[kLanes - 1], lane_z[kLanes - 1]}};
    lanes::gather(block_span, brick_box, core_sq, reach_sq, scratch.core, &scratch.ring);
    Accum first[kLanes];
    lanes::laneSums(job.law, block_span, scratch.core, scratch.ring, lane_x, lane_y, lane_z,
                    init_sq, first);
    for (int l = 0; l < kLanes; ++l) {
      if (nodes[l] < 0) continue;
      scratch.answers[std::size_t(nodes[l]) * kMaxNodeSums] = first[l];
      scratch.answered[nodes[l]] = 1;
      pending.push_back(nodes[l]);
    }
  }
  // Rounds: every pending node's value from the sums it has; those that ask for one more wait
  // for the round's requests, answered 8 at a time (in brick order: neighbours' lifted points
  // lie together).
  // The tracked sums and the untracked ones (the surface rule's lifted point) apart: a batch
  // with none tracked skips the nearest (laneSums).
  std::vector<SumRequest>& tracked = scratch.requests[0];
  std::vector<SumRequest>& untracked = scratch.requests[1];
  std::vector<int>& next = scratch.next;
  while (!pending.empty()) {
    tracked.clear();
    untracked.clear();
    next.clear();
    for (const int node : pending) {
      const D3 x{(task.origin[0] + (node >> 6)) * h, (task.origin[1] + ((node >> 3) & 7)) * h,
                 (task.origin[2] + (node & 7)) * h};
      SumRequest request;
      ReplayHood hood{&scratch.answers[std::size_t(node) * kMaxNodeSums],
                      scratch.answered[node],
                      &request,
                      &samples,
                      &cells,
                      table.far_face_by_id.data()};
      const kernel::NodeValue value = kernel::nodeValue(hood, job.law, job.rules, x);
      if (!hood.missing) {
        out[node] = value;
        continue;
      }
      if (scratch.answered[node] >= kMaxNodeSums)
        throw std::logic_error("voxel block build: a node asked for more than " +
                               std::to_string(kMaxNodeSums) + " sums");
      request.node = node;
      (request.track ? tracked : untracked).push_back(request);
      next.push_back(node);
    }
    if (next.empty()) break;
    // The samples the round's points reach: the leaf's where they lie within its box (points
    // lifted less than √3·h off the leaf), gathered from the cell list otherwise.
    double lo[3], hi[3];
    for (int a = 0; a < 3; ++a) {
      lo[a] = HUGE_VAL;
      hi[a] = -HUGE_VAL;
    }
    for (const std::vector<SumRequest>& requests : scratch.requests)
      for (const SumRequest& q : requests)
        for (int a = 0; a < 3; ++a) {
          lo[a] = std::min(lo[a], q.at[a] - q.reach());
          hi[a] = std::max(hi[a], q.at[a] + q.reach());
        }
    bool inside = true;
    for (int a = 0; a < 3; ++a) inside = inside && lo[a] >= box_lo[a] && hi[a] <= box_hi[a];
    if (!inside) gatherBox(cells, lo, hi, scratch.lifted);
    const SampleSpan from = inside ? block_span : scratch.lifted.span();
    for (const std::vector<SumRequest>& requests : scratch.requests)
      for (std::size_t b = 0; b < requests.size(); b += kLanes)
        answerBatch(job.law, from, &requests[b],
                    int(std::min<std::size_t>(kLanes, requests.size() - b)), scratch);
    std::swap(pending, next);
  }
}

}  // namespace fieldpath::field
