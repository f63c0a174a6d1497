/// The voxel field's build: the nodes of each level from the samples (the CPU block build,
/// the CUDA build, or the per-node reference) and the refinement's levels (voxel_grid.h; which
/// leaves a level has: voxel_leaves.cpp; the error estimate: voxel_refine.cpp; the queries:
/// voxel_field.cpp).
#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

#include <openvdb/tools/Prune.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_scan.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/common/phase_trace.h"
#include "fieldpath/common/short_number.h"
#include "node_block.h"
#include "plane_ratio.h"
#include "voxel_grid.h"

namespace fieldpath::field {

using namespace voxel;

namespace voxel {
namespace {

using common::PhaseTrace;

/// What the node values of every level are made from.
struct NodeBuilder {
  const DirectField::Index& index;
  const VoxelRequest& request;
  bool ratio;
  double band_in_mm, reach_mm, over_mm, near_mm;
  PlaneLaw law;
  FieldBackend backend;                ///< Cpu, Cuda or Reference (resolved)
  std::optional<SampleTable> table;    ///< the cell list (all but Reference)
  mutable double nodes_seconds = 0.0;  ///< node evaluation, all levels

  /// The constants of the block and CUDA builds at voxel size h.
  NodeJob jobAt(double h) const {
    const FieldParams& params = index.params;
    NodeJob job;
    job.h_mm = h;
    job.law.r0 = params.r0_mm;
    job.law.r0_sq = params.r0_mm * params.r0_mm;
    job.law.inv_r0 = 1.0 / params.r0_mm;
    job.law.r_min = params.r_min_mm;
    job.law.r_min_sq = params.r_min_mm * params.r_min_mm;
    job.law.inv_r_min = 1.0 / params.r_min_mm;
    job.law.gain = params.gain;
    job.law.plane_scale = law.scale;
    job.law.face_reach = kThinReachSteps * params.sample_step_mm;
    job.rules.ratio = ratio;
    job.rules.band_in_mm = band_in_mm;
    job.rules.reach_mm = reach_mm;
    job.rules.over_mm = over_mm;
    job.rules.near_mm = near_mm;
    job.rules.has_region = bool(request.region_mm);
    for (int a = 0; a < 3; ++a) {
      job.rules.region_lo[a] = request.region_mm ? request.region_mm->min()[a] : 0.0;
      job.rules.region_hi[a] = request.region_mm ? request.region_mm->max()[a] : 0.0;
    }
    return job;
  }

  /// Computes the nodes of `origins` (leaves of a level of size h): all of a leaf's nodes, or
  /// those on in `only`. Returns the level's grids (inactive nodes pruned from the value grid).
  /// Progress between batches, from this thread only.
  std::pair<Grid::Ptr, FloatGrid::Ptr> build(double h, const std::vector<openvdb::Coord>& origins,
                                             const openvdb::MaskGrid* only,
                                             const std::function<void(double)>& progress) const {
    auto grid = Grid::create(openvdb::Vec3s(0.0f));
    grid->setTransform(openvdb::math::Transform::createLinearTransform(h));
    grid->setName(ratio ? "plane_ratio" : "force");
    grid->setVectorType(openvdb::VEC_INVARIANT);
    FloatGrid::Ptr closeness;
    if (ratio) {
      closeness = FloatGrid::create(0.0f);
      closeness->setTransform(grid->transform().copy());
      closeness->setName("plane_closeness");
    }
    PhaseTrace trace;
    auto start = std::chrono::steady_clock::now();
    // The tasks from the origins; on the GPU the nodes are started now and computed while the
    // host makes the leaves below (their values are stored when both are done).
    std::vector<LeafTask> tasks;
    if (backend != FieldBackend::Reference) tasks = tasksOf(origins, only);
    trace.lap("  tasks");
    std::optional<kernel::CudaNodeBuild> gpu;
    if (backend == FieldBackend::Cuda) gpu.emplace(cellTableOf(*table), jobAt(h), tasks);
    if (gpu) trace.lap("  device started");
    const double started_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    // The leaves made (allocated and filled) in parallel, then added to the trees.
    std::vector<Leaf*> leaves(origins.size());
    std::vector<FloatLeaf*> float_leaves(ratio ? origins.size() : 0);
    std::vector<std::unique_ptr<Leaf>> made(origins.size());
    std::vector<std::unique_ptr<FloatLeaf>> made_float(ratio ? origins.size() : 0);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origins.size()), [&](const auto& range) {
      for (std::size_t l = range.begin(); l != range.end(); ++l) {
        made[l] = std::make_unique<Leaf>(origins[l], openvdb::Vec3s(0.0f), false);
        leaves[l] = made[l].get();
        if (ratio) {
          made_float[l] = std::make_unique<FloatLeaf>(origins[l], 0.0f, false);
          float_leaves[l] = made_float[l].get();
        }
      }
    });
    trace.lap("  leaves made");
    addLeaves(made, grid->tree());
    if (ratio) addLeaves(made_float, closeness->tree());
    trace.lap("  leaves added");
    start = std::chrono::steady_clock::now();
    if (backend == FieldBackend::Reference)
      buildReference(h, leaves, float_leaves, only, progress);
    else
      buildBlocks(h, leaves, float_leaves, tasks, gpu ? &*gpu : nullptr, progress);
    nodes_seconds +=
        started_s + std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    trace.lap("  nodes and store");
    openvdb::tools::pruneInactive(grid->tree());
    trace.lap("  prune");
    // (closeness keeps its leaves: its inactive nodes hold values, those beyond open edges.)
    return {grid, closeness};
  }

  /// Writes a leaf's computed nodes (those of `mask`) into its value and closeness leaves.
  static void store(const std::uint64_t (&mask)[8], const kernel::NodeValue* values, Leaf& leaf,
                    FloatLeaf* float_leaf) {
    for (int word = 0; word < 8; ++word) {
      std::uint64_t bits = mask[word];
      while (bits) {
        const int offset = word * 64 + __builtin_ctzll(bits);
        bits &= bits - 1;
        const kernel::NodeValue& v = values[offset];
        if (v.flags & kernel::kCloseSet) {
          if (v.flags & kernel::kCloseOn)
            float_leaf->setValueOn(openvdb::Index(offset), v.closeness);
          else
            float_leaf->setValueOff(openvdb::Index(offset), v.closeness);
        }
        if (v.flags & kernel::kNodeOn)
          leaf.setValueOn(openvdb::Index(offset), openvdb::Vec3s(v.v[0], v.v[1], v.v[2]));
      }
    }
  }

  /// The leaves' tasks: every node, or those on in `only`.
  static std::vector<LeafTask> tasksOf(const std::vector<openvdb::Coord>& origins,
                                       const openvdb::MaskGrid* only) {
    std::vector<LeafTask> tasks(origins.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, origins.size()), [&](const auto& range) {
      std::optional<openvdb::MaskGrid::ConstAccessor> wanted;
      if (only) wanted.emplace(only->getConstAccessor());
      for (std::size_t l = range.begin(); l != range.end(); ++l) {
        LeafTask& t = tasks[l];
        const openvdb::Coord& o = origins[l];
        for (int a = 0; a < 3; ++a) t.origin[a] = o[a];
        const auto* mask_leaf = wanted ? wanted->probeConstLeaf(o) : nullptr;
        for (int word = 0; word < 8; ++word)
          t.mask[word] = !wanted     ? ~std::uint64_t{0}
                         : mask_leaf ? mask_leaf->getValueMask().getWord<std::uint64_t>(word)
                                     : 0;
      }
    });
    return tasks;
  }

  /// The block builds: on the GPU (all leaves at once, started by the caller: `gpu`) or on the
  /// CPU leaf by leaf.
  void buildBlocks(double h, const std::vector<Leaf*>& leaves,
                   const std::vector<FloatLeaf*>& float_leaves, const std::vector<LeafTask>& tasks,
                   kernel::CudaNodeBuild* gpu, const std::function<void(double)>& progress) const {
    const NodeJob job = jobAt(h);
    if (gpu) {
      const kernel::NodeValues values = gpu->finish();
      std::vector<std::size_t> first(tasks.size() + 1, 0);
      for (std::size_t l = 0; l < tasks.size(); ++l) {
        std::size_t n = 0;
        for (std::uint64_t word : tasks[l].mask) n += std::size_t(__builtin_popcountll(word));
        first[l + 1] = first[l] + n;
      }
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, tasks.size()), [&](const auto& range) {
        kernel::NodeValue buffer[Leaf::SIZE];
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
          std::size_t at = first[l];
          for (int word = 0; word < 8; ++word)
            for (std::uint64_t bits = tasks[l].mask[word]; bits; bits &= bits - 1)
              buffer[word * 64 + __builtin_ctzll(bits)] = values[at++];
          store(tasks[l].mask, buffer, *leaves[l], ratio ? float_leaves[l] : nullptr);
        }
      });
      if (progress) progress(1.0);
      return;
    }
    const std::size_t batches =
        std::max<std::size_t>(1, std::min<std::size_t>(20, leaves.size() / 64));
    const ObstacleSamples& samples = index.samples;
    // A thread's scratch lives through the build (ranges are often one leaf: made per range,
    // its sample sets and 2048 answers were allocated and zeroed per leaf).
    tbb::enumerable_thread_specific<BlockScratch> scratches;
    for (std::size_t batch = 0; batch < batches; ++batch) {
      const std::size_t begin = leaves.size() * batch / batches;
      const std::size_t end = leaves.size() * (batch + 1) / batches;
      tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1), [&](const auto& range) {
        BlockScratch& scratch = scratches.local();
        kernel::NodeValue buffer[Leaf::SIZE];
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
          buildLeafNodes(*table, samples, job, tasks[l], scratch, buffer);
          store(tasks[l].mask, buffer, *leaves[l], ratio ? float_leaves[l] : nullptr);
        }
      });
      if (progress) progress(double(batch + 1) / double(batches));
    }
  }

  /// The per-node reference build (FieldBackend::Reference): a probe through the point index
  /// for each node against the samples gathered for its leaf.
  void buildReference(double h, const std::vector<Leaf*>& leaves,
                      const std::vector<FloatLeaf*>& float_leaves, const openvdb::MaskGrid* only,
                      const std::function<void(double)>& progress) const {
    const ObstacleSamples& samples = index.samples;
    const FieldParams& params = index.params;
    const std::size_t batches =
        std::max<std::size_t>(1, std::min<std::size_t>(20, leaves.size() / 64));
    for (std::size_t batch = 0; batch < batches; ++batch) {
      const std::size_t begin = leaves.size() * batch / batches;
      const std::size_t end = leaves.size() * (batch + 1) / batches;
      tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, 1), [&](const auto& range) {
        auto searcher = index.searcher();
        std::optional<openvdb::MaskGrid::ConstAccessor> wanted;
        if (only) wanted.emplace(only->getConstAccessor());
        std::vector<std::size_t> near;
        for (std::size_t l = range.begin(); l != range.end(); ++l) {
          Leaf& leaf = *leaves[l];
          const openvdb::Coord o = leaf.origin();
          const Vec3 lo = Vec3(o.x(), o.y(), o.z()) * h;
          const Vec3 hi = lo + Vec3::Constant((kLeafDim - 1) * h);
          // Samples within reach of the leaf's nodes, gathered once; the surface rule's second
          // sum, at a point lifted off the wall (rare: nodes within r_min or inside), searches
          // the index.
          near.clear();
          index.forEachInBox(searcher, lo.array() - reach_mm, hi.array() + reach_mm,
                             [&](std::size_t j) { near.push_back(j); });
          for (auto it = leaf.beginValueAll(); it; ++it) {
            const openvdb::Coord ijk = it.getCoord();
            if (wanted && !wanted->isValueOn(ijk)) continue;
            const Vec3 x(ijk.x() * h, ijk.y() * h, ijk.z() * h);
            if (request.region_mm && !request.region_mm->contains(x)) continue;
            auto for_each_near = [&](const Vec3& center, double radius, auto&& fn) {
              if (center == x && radius <= reach_mm)  // `near` holds those within reach
                for (std::size_t j : near) fn(j);
              else
                index.forEachNear(searcher, center, radius, fn);
            };
            const detail::Probe p =
                detail::probe(x, for_each_near, samples.points_mm, samples.normals, samples.weights,
                              index.far_face, params, reach_mm);
            if (p.nearest < 0 || (p.height_mm < -band_in_mm && overSurface(p, over_mm))) continue;
            Vec3 value;
            if (ratio) {
              const RatioNode node =
                  planeRatio(p, x, samples.points_mm[p.nearest], samples.normals[p.nearest], law,
                             params.gain, over_mm, near_mm, [&](const Vec3& at) {
                               return index.fieldAt(searcher, at).value_or(Vec3::Zero());
                             });
              // The closeness grid's active mask carries `over` (see ratioHolds).
              const float closeness_mm = float(params.r0_mm - node.s_mm);
              if (node.over)
                float_leaves[l]->setValueOn(it.pos(), closeness_mm);
              else
                float_leaves[l]->setValueOff(it.pos(), closeness_mm);
              value = node.g;
            } else {
              if (!p.force) continue;
              value = *p.force;
            }
            it.setValue(openvdb::Vec3s(float(value.x()), float(value.y()), float(value.z())));
            it.setValueOn();
          }
        }
      });
      if (progress) progress(double(batch + 1) / double(batches));
    }
  }
};

/// Auto: the GPU when one is there (and the program has CUDA), else the CPU.
FieldBackend resolveBackend(FieldBackend wanted) {
  if (wanted == FieldBackend::Auto)
    wanted = kernel::cudaNodeBuildAvailable() ? FieldBackend::Cuda : FieldBackend::Cpu;
  if (wanted == FieldBackend::Cuda && !kernel::cudaNodeBuildAvailable())
    throw common::InputError(
        "field.backend: cuda, but this program was built without CUDA or no GPU is present");
  if (wanted == FieldBackend::Cuda) common::requireCudaContext();
  return wanted;
}

}  // namespace

BuiltLevels buildLevels(const DirectField& direct, const VoxelRequest& request,
                        std::optional<Level> level0) {
  BuiltLevels built;
  const DirectField::Index& index = direct.index();
  const ObstacleSamples& samples = index.samples;
  const FieldParams& params = index.params;
  const double h = request.voxel_size_mm;
  checkVoxelSize(h);
  const StoredQuantity stored = request.stored;
  const bool ratio = stored == StoredQuantity::PlaneRatio;
  const double tolerance = request.refine_tolerance;
  const int refine_levels = request.refine_levels;
  if (!(tolerance >= 0.0) || !std::isfinite(tolerance))
    throw common::InputError("field.refine_tolerance: must be >= 0 (got " +
                             std::to_string(tolerance) + ")");
  // A node spacing past r0 cannot hold a field that lives within r0 of the surfaces: at 10 and
  // 20 mm (r0 5) the paths collided more than the nominal one, from 50 mm the field was zero.
  if (h > params.r0_mm)
    throw common::InputError("field.voxel_size (or --voxel): " + common::shortNumber(h) +
                             " mm is coarser than field.r0 (" + std::to_string(params.r0_mm) +
                             " mm): the grid cannot hold a field that ends within r0 of the "
                             "surfaces; use at most r0 (r0 / 10 for an accurate one)");
  if (refine_levels < 0 || refine_levels > 6)
    throw common::InputError("field.refine_levels: must be in [0, 6] (got " +
                             std::to_string(refine_levels) + ")");
  if (tolerance > 0.0 && request.interpolation == Interpolation::Quadratic)
    throw common::InputError(
        "field.refine_tolerance: refinement is trilinear only (field.interpolation: quadratic)");
  // Sideways reach of a sample (sub-triangle centroids: within 0.87 step of any surface point);
  // closer to the surface than about one spacing the samples' field is not yet a plane's.
  NodeBuilder builder{index,
                      request,
                      ratio,
                      insideBandMm(params, request),
                      reachMm(params, request),
                      params.sample_step_mm,
                      request.plane_near_mm.value_or((tolerance > 0.0 ? kRefinedNearFactor : 2.0) *
                                                     params.r_min_mm),
                      PlaneLaw(params, weightPerMm2(samples, params)),
                      resolveBackend(request.backend),
                      std::nullopt};
  PhaseTrace trace;
  if (builder.backend != FieldBackend::Reference)
    builder.table.emplace(samples, index.far_face, params.r0_mm);
  trace.lap("cell list");
  const double reach_mm = builder.reach_mm;

  // What the run's meshes, samples and postures leave (common::memoryLeftBytes), or the request's.
  const double limit_bytes =
      request.max_memory_bytes ? double(request.max_memory_bytes) : common::memoryLeftBytes();
  // Refuses `bytes` (of `nodes`) over the limit.
  auto refuseBytes = [&](const std::string& what, double nodes, double bytes,
                         const std::string& advice = "use a coarser voxel size") {
    if (bytes <= limit_bytes) return;
    throw common::InputError(
        "voxel field at h = " + common::shortNumber(h) + " mm: " + what + " " +
        std::to_string(static_cast<long long>(nodes)) + " nodes (" + mib(bytes) + "), over " +
        (request.max_memory_bytes
             ? "the limit of " + mib(limit_bytes)
             : "what is left (" + mib(limit_bytes) + ")" + common::memoryLimitText()) +
        "; " + advice);
  };
  auto refuse = [&](const std::string& what, double nodes, double bytes_per_node,
                    const std::string& advice, double list_bytes) {
    refuseBytes(what, nodes, nodes * bytes_per_node + list_bytes, advice);
  };
  const std::string refine_advice =
      "raise field.refine_tolerance or lower field.refine_levels (or a coarser voxel size)";
  // The plane ratio adds a float to the Vec3f of a node.
  const double value_bytes = ratio ? 16.0 : 12.0;
  // Progress: level 0 takes the whole bar without refinement, half of it with.
  const double level0_share = tolerance > 0.0 ? 0.5 : 1.0;
  std::vector<Level>& levels = built.levels;
  if (level0) {  // built already (a job's uniform grid, refined near its path)
    built.stats.estimated_nodes = level0->grid->activeVoxelCount();
    levels.push_back(std::move(*level0));
  } else {
    // Said in the summary; refused on the leaves below (the nodes within two coarse cells of a
    // sample are 1.1-1.9 times those built: refused on them, a grid of 0.84 GB at its peak was
    // refused under a limit of 2.5 GB).
    built.stats.estimated_nodes = estimateVoxelNodes(samples, params, request);
    trace.lap("estimate");

    // Candidate leaves (8³ nodes): those within reach of a sample, inside the region; refused
    // on the bytes of the level they make (every candidate made before the prune), the search
    // stopped once more than the limit holds.
    const Eigen::AlignedBox3d reach = reachBox(samples, params, request);
    const double per_leaf = levelBytesPerLeaf(ratio);
    const LeafCandidates found = candidateLeaves(
        samples, reach, h, reach_mm,
        std::size_t(std::min(limit_bytes / per_leaf, double(std::size_t(-1) >> 8))));
    const std::vector<openvdb::Coord>& origins = found.origins;
    trace.lap("candidate leaves");
    if (found.more) {  // refused: at_least * per_leaf is over the limit
      const double at_least = static_cast<double>(found.at_least);
      refuseBytes("candidate leaves hold more than", at_least * Leaf::SIZE,
                  std::max(at_least * per_leaf, std::nextafter(limit_bytes, HUGE_VAL)));
    }
    refuseBytes("candidate leaves hold", static_cast<double>(origins.size()) * Leaf::SIZE,
                levelBytesBound(origins, ratio));

    levels.emplace_back();
    levels[0].h_mm = h;
    std::tie(levels[0].grid, levels[0].closeness) = builder.build(
        h, origins, nullptr,
        [&](double f) { common::report(request.progress, level0_share * f, "field"); });
    trace.lap("level 0 nodes");
    makeBlocks(levels[0], ratio);
    trace.lap("level 0 blocks");
  }
  std::optional<PlaneLaw> law;
  if (ratio) law = builder.law;

  // Refinement: estimate each candidate cell's error from its nodes, split those that miss.
  VoxelStats& stats = built.stats;
  if (tolerance > 0.0 && refine_levels > 0) {
    const double floor = kRefineFloorFraction * builder.law.at(2.0 * params.r_min_mm);
    fillBlocks(levels[0]);  // cellsWithValues reads every block (the rest read through locate)
    CellList cells = cellsWithValues(levels[0]);
    trace.lap("cells with values");
    const auto refine_start = std::chrono::steady_clock::now();
    const double nodes_before = builder.nodes_seconds;
    for (int l = 0; l < refine_levels && !cells.empty(); ++l) {
      const double hl = levels[l].h_mm;
      Level& level = levels[std::size_t(l)];
      const CellErrors errors(level, law, floor);
      trace.lap("node errors");
      // Each cell's error and, for those that miss, their bit in the level's `refined` (cells
      // share a block's words: atomic ors); then the split cells' ranks (a parallel prefix
      // sum) and, at those ranks, the split cells and their halves, in the cells' order. No
      // list is zeroed first: each entry is written once, in parallel.
      UninitVector<std::uint8_t> split(cells.size());  // 1: split
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size()), [&](const auto& range) {
        auto acc = level.block_of->getConstUnsafeAccessor();
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          const openvdb::Coord ijk = cells[c].coord();
          const Vec3 x = (Vec3(ijk.x(), ijk.y(), ijk.z()) + Vec3::Constant(0.5)) * hl;
          CellRef where;
          split[c] = (!request.region_mm || request.region_mm->contains(x)) &&
                     (!request.refine_mask || request.refine_mask->contains(x)) &&
                     errors.cellError(ijk, acc) > tolerance && locate(level, acc, x, where);
          if (split[c])
            std::atomic_ref<std::uint64_t>(
                level.refined[where.block * kCellWords + (where.cell >> 6)])
                .fetch_or(std::uint64_t{1} << (where.cell & 63), std::memory_order_relaxed);
        }
      });
      stats.tested_cells += cells.size();
      UninitVector<std::size_t> rank(cells.size());  // split cells before c
      const std::size_t splits = tbb::parallel_scan(
          tbb::blocked_range<std::size_t>(0, cells.size()), std::size_t{0},
          [&](const tbb::blocked_range<std::size_t>& range, std::size_t sum, bool is_final) {
            for (std::size_t c = range.begin(); c != range.end(); ++c) {
              if (is_final) rank[c] = sum;
              sum += split[c];
            }
            return sum;
          },
          std::plus<std::size_t>());
      // Refused before the split lists (8 cells a split) and the new nodes are made: at least 8
      // new nodes a split cell (the whole build reached 21 GB before the refusal below).
      double levels_nodes = 0.0;  // the levels built so far
      for (const Level& level : levels) levels_nodes += double(level.grid->activeVoxelCount());
      // With the cell lists beside them: the cells tested (a split byte and a rank each), the
      // split cells and their halves (a 1 G limit was passed by 15 % without them).
      const double cell_bytes = double(sizeof(CellIjk));
      const double list_bytes = double(cells.size()) * (cell_bytes + 1.0 + sizeof(std::size_t)) +
                                9.0 * double(splits) * cell_bytes;
      refuse("refined level " + std::to_string(l + 1) + " makes at least",
             levels_nodes + 8.0 * double(splits), kVoxelBytesPerNode * value_bytes / 12.0,
             refine_advice, list_bytes);
      CellList split_cells(splits), next_cells(8 * splits);
      tbb::parallel_for(tbb::blocked_range<std::size_t>(0, cells.size()), [&](const auto& range) {
        for (std::size_t c = range.begin(); c != range.end(); ++c) {
          if (!split[c]) continue;
          split_cells[rank[c]] = cells[c];
          const CellIjk fine{2 * cells[c].x, 2 * cells[c].y, 2 * cells[c].z};
          for (int h8 = 0; h8 < 8; ++h8)
            next_cells[8 * rank[c] + std::size_t(h8)] = {
                fine.x + (h8 >> 2), fine.y + ((h8 >> 1) & 1), fine.z + (h8 & 1)};
        }
      });
      stats.refined_cells += splits;
      trace.lap("cell errors, split cells");
      const openvdb::MaskGrid::Ptr fine_nodes = nodesOfHalves(split_cells);
      trace.lap("nodes of halves");
      if (next_cells.empty()) break;
      std::vector<openvdb::Coord> fine_origins;
      for (auto leaf = fine_nodes->tree().cbeginLeaf(); leaf; ++leaf)
        fine_origins.push_back(leaf->origin());
      // All levels so far as they hold and the new one from its leaves.
      const double built_nodes = levels_nodes + double(fine_nodes->activeVoxelCount());
      double held_bytes = list_bytes + levelBytesBound(fine_origins, ratio);
      for (const Level& level : levels) held_bytes += double(level.memUsage());
      refuseBytes("refined level " + std::to_string(l + 1) + " makes", built_nodes, held_bytes,
                  refine_advice);
      Level fine;
      fine.h_mm = 0.5 * hl;
      const double share_begin = level0_share + (1.0 - level0_share) * l / refine_levels;
      const double share_end = level0_share + (1.0 - level0_share) * (l + 1) / refine_levels;
      std::tie(fine.grid, fine.closeness) =
          builder.build(fine.h_mm, fine_origins, fine_nodes.get(), [&](double f) {
            common::report(request.progress, share_begin + (share_end - share_begin) * f, "field");
          });
      trace.lap("level " + std::to_string(l + 1) + " nodes");
      fine.grid->setName(fine.grid->getName() + "_level" + std::to_string(l + 1));
      if (fine.closeness) fine.closeness->setName("plane_closeness_level" + std::to_string(l + 1));
      matchCoarserLevels(fine, levels, ratio);
      trace.lap("hanging nodes");
      makeBlocks(fine, ratio);
      trace.lap("blocks");
      stats.refined_nodes += fine.grid->activeVoxelCount();
      levels.push_back(std::move(fine));
      cells = std::move(next_cells);
    }
    // The refinement's own work: error estimates, split cells, hanging nodes, blocks.
    stats.refine_seconds =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - refine_start).count() -
        (builder.nodes_seconds - nodes_before);
  }

  built.law = law;
  built.stats.backend = builder.backend == FieldBackend::Cuda        ? "cuda"
                        : builder.backend == FieldBackend::Reference ? "reference"
                                                                     : "cpu";
  built.stats.nodes_seconds = builder.nodes_seconds;
  return built;
}

}  // namespace voxel
}  // namespace fieldpath::field
