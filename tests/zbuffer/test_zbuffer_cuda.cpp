/// CPU vs CUDA: the same heights to the last bit (same float code, no FMA, order-independent
/// minimum). Skips with a message where no GPU is present (CI).
#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/tool_mesh.h"

namespace fieldpath::zbuffer {
namespace {

std::vector<Posture> randomPostures(int count, unsigned seed, double extent) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<Posture> p;
  for (int k = 0; k < count; ++k) {
    double i = 0, j = 0, kk = 1;
    if (k % 3 == 1) {
      i = 0.7 * u(rng);
      j = 0.7 * u(rng);
    }
    if (k % 7 == 2) {
      i = u(rng);
      j = u(rng);
      kk = 1e-3;
    }
    if (k % 11 == 3) {
      i = 1e-9;
    }
    const double n = std::sqrt(i * i + j * j + kk * kk);
    p.push_back({{float(extent * u(rng)), float(extent * u(rng)), float(u(rng))},
                 {float(i / n), float(j / n), float(kk / n)}});
  }
  return p;
}

/// A zigzag path over a wavy surface, consecutive postures 0.05 mm apart (what the group kernel
/// takes in groups of 8), vertical or tilted along and across the path.
std::vector<Posture> pathPostures(int count, double extent, bool tilted) {
  std::vector<Posture> p;
  const int passes = 12;
  for (int k = 0; k < count; ++k) {
    const int pass = k * passes / count;
    const double u = double(k * passes % count) / count;
    const double x = -extent + 2 * extent * (pass % 2 ? 1 - u : u);
    const double y = -extent + 2 * extent * (pass + 0.5) / passes;
    const double z = 0.5 * std::sin(x / 3) * std::cos(y / 4);
    double i = 0, j = 0, kk = 1;
    if (tilted) {
      i = 0.3 * std::sin(x / 5);
      j = 0.2 + 0.1 * std::cos(y / 3);
    }
    const double n = std::sqrt(i * i + j * j + kk * kk);
    p.push_back({{float(x), float(y), float(z)}, {float(i / n), float(j / n), float(kk / n)}});
  }
  return p;
}

void expectSameBits(const Grid& g, const Tool& tool, const std::vector<Posture>& postures,
                    Engine engine, EngineTuning tuning = {}) {
  SimulationRequest req;
  req.tuning = tuning;
  req.grid = g;
  req.tool = tool;
  req.stock_mm = 5.f;
  req.engine = engine;
  req.backend = Backend::Cpu;
  const auto cpu = simulate(req, postures);
  req.backend = Backend::Cuda;
  req.block_postures = 1000;  // several blocks
  const auto gpu = simulate(req, postures);
  ASSERT_EQ(cpu.heights_mm.size(), gpu.heights_mm.size());
  std::size_t differ = 0;
  for (std::size_t i = 0; i < cpu.heights_mm.size(); ++i)
    differ += std::memcmp(&cpu.heights_mm[i], &gpu.heights_mm[i], 4) != 0;
  EXPECT_EQ(differ, 0u) << "lines whose CPU and CUDA heights differ in any bit";
  EXPECT_GT(cpu.lines_lowered, 0u);
}

class CpuVsCuda : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!cudaAvailable())
      GTEST_SKIP()
          << "no CUDA device (cudaGetDeviceCount failed or found none): CPU vs CUDA not run";
  }
};

TEST_F(CpuVsCuda, AnalyticToolsBitIdentical) {
  const Grid g = Grid::fromRegion(-20, -20, 20, 20, 256, 256);
  const auto p = randomPostures(5000, 1, 18);
  expectSameBits(g, Tool::ball(2, 8), p, Engine::Fast);
  expectSameBits(g, Tool::torus(3, 1, 12), p, Engine::Fast);
  expectSameBits(g, Tool::flat(1.5, 6), p, Engine::Fast);
  // Shorter than their end's height: cut at their flat top (tool_entry.h cutAtTop).
  expectSameBits(g, Tool::ball(2, 2), p, Engine::Fast);
  expectSameBits(g, Tool::torus(3, 1.5, 2), p, Engine::Fast);
}

TEST_F(CpuVsCuda, MeshToolBitIdenticalFastAndCoarse) {
  const Grid g = Grid::fromRegion(-20, -20, 20, 20, 200, 200);
  const auto p = randomPostures(2000, 2, 18);
  const Tool mesh = Tool::fromMesh(analyticToolMesh(Tool::torus(3, 1, 12), 48, 8));
  expectSameBits(g, mesh, p, Engine::Fast);
  expectSameBits(g, mesh, p, Engine::Coarse);
}

// Spindle angles (the 7th column) turn a mesh tool on both backends the same, bit for bit.
TEST_F(CpuVsCuda, SpindleAnglesBitIdentical) {
  const Grid g = Grid::fromRegion(-20, -20, 20, 20, 200, 200);
  auto p = randomPostures(2000, 5, 18);
  for (std::size_t k = 0; k < p.size(); ++k) {
    const double angle = 0.37 * double(k % 17) - 3.0;
    p[k].spindle_cos = float(std::cos(angle));
    p[k].spindle_sin = float(std::sin(angle));
  }
  const Tool mesh = Tool::fromMesh(analyticToolMesh(Tool::torus(3, 1, 12), 7, 4));
  expectSameBits(g, mesh, p, Engine::Fast);
  expectSameBits(g, mesh, p, Engine::Coarse);
}

TEST_F(CpuVsCuda, EveryTuningVariantBitIdentical) {
  // Small footprints (thread per posture) and large ones (warp per posture) in one run: a fine
  // ball over a coarse grid, tilted postures reach far; each variant of the GPU engine must give
  // the CPU reference's bits.
  const Grid g = Grid::fromRegion(-20, -20, 20, 20, 96, 96);
  const auto p = randomPostures(4000, 4, 18);
  const Tool small_mesh = Tool::fromMesh(analyticToolMesh(Tool::ball(0.8, 6), 32, 31));
  for (int variant = 0; variant < 32; ++variant) {
    EngineTuning t;
    t.vertical_bins = variant & 1;
    t.lowest_first = variant & 2;
    t.small_threads = variant & 4;
    t.overlap_upload = variant & 8;
    t.tile_skip = variant & 16;
    t.refresh_postures = variant % 3 == 0 ? 64 : 0;  // many refreshes between the chunks
    t.pinned_staging = variant % 5 != 1;
    t.tile_shift = 2 + variant % 4;
    t.prepass_stride = variant % 3 == 1 ? 0 : 2 + variant % 7;
    t.capsule_floor = variant % 7 != 3;
    t.group_postures = variant % 4 == 3 ? 0 : (variant % 2 ? 16 : 8);
    t.live_tiles = variant % 6 != 5;
    SCOPED_TRACE("variant " + std::to_string(variant));
    expectSameBits(g, small_mesh, p, Engine::Fast, t);
    if (variant % 4 == 2) expectSameBits(g, Tool::ball(0.8, 6), p, Engine::Fast, t);
  }
}

TEST_F(CpuVsCuda, PathsCutInGroupsBitIdentical) {
  // Large footprints along a path: the warps cut 8 consecutive postures together (and fall back
  // to one at a time where a group is scattered); with and without groups and the prepass.
  const Grid g = Grid::fromRegion(-20, -20, 20, 20, 200, 200);
  const Tool mesh_ball = Tool::fromMesh(analyticToolMesh(Tool::ball(3, 10), 32, 31));
  const Tool mesh_torus = Tool::fromMesh(analyticToolMesh(Tool::torus(3, 1, 12), 48, 8));
  for (bool tilted : {false, true}) {
    const auto p = pathPostures(6000, 16, tilted);
    for (int variant = 0; variant < 4; ++variant) {
      EngineTuning t;
      t.group_postures = variant == 1 ? 0 : (variant == 3 ? 16 : (variant == 2 ? 32 : 8));
      t.prepass_stride = variant == 2 ? 0 : 16;
      t.tile_skip = variant != 3;
      t.live_tiles = variant != 2;
      SCOPED_TRACE(std::string(tilted ? "tilted" : "vertical") + " variant " +
                   std::to_string(variant));
      expectSameBits(g, mesh_ball, p, Engine::Fast, t);
      expectSameBits(g, Tool::ball(3, 10), p, Engine::Fast, t);
      if (variant == 0) expectSameBits(g, mesh_torus, p, Engine::Fast, t);
    }
  }
}

TEST_F(CpuVsCuda, ZoomWithFewPosturesBitIdentical) {
  const Grid g = Grid::fromRegion(-1, -1, 1, 1, 512, 512);  // ~4 µm lines
  const auto p = randomPostures(300, 3, 2);
  expectSameBits(g, Tool::ball(2, 8), p, Engine::Fast);
  expectSameBits(g, Tool::fromMesh(analyticToolMesh(Tool::ball(2, 8), 79, 78)), p, Engine::Fast);
}

}  // namespace
}  // namespace fieldpath::zbuffer
