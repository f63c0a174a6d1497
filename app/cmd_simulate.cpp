/// fieldpath simulate: Z-buffer machining simulation of a path (DESIGN.md command line).
/// Fast as a process, not only as a kernel (issue 13): the path is read on all cores while the
/// tool is prepared (and the CUDA context created) on another thread; with --region the engine
/// cuts each chunk as soon as it is parsed; the outputs are written concurrently, each
/// atomically; simulate.json says where the time went.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_parse.h"
#include "commands.h"
#include "cutter_note.h"
#include "errors.h"
#include "estimates.h"
#include "fieldpath/common/atomic_file.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/mesh_io.h"
#include "fieldpath/zbuffer/outputs.h"
#include "fieldpath/zbuffer/simulator.h"
#include "json_text.h"
#include "posture_stream.h"
#include "progress.h"
#include "scene_mesh.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

namespace zb = zbuffer;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

const char* const kOutputNames[] = {"npy", "json", "stl", "png"};

/// "npy,json,stl,png" (any subset, any order) → the set; one line naming the bad item otherwise.
/// ", every 3rd line, each the lowest of its block" where surface.stl keeps fewer lines than the
/// grid has (writeSurfaceStl's default 2048 a side), else "".
std::string stlStrideNote(const zbuffer::Grid& grid) {
  const int k = std::max((grid.nx + 2047) / 2048, (grid.ny + 2047) / 2048);
  if (k <= 1) return "";
  const std::string nth = k == 2 ? "2nd" : k == 3 ? "3rd" : std::to_string(k) + "th";
  return ", every " + nth + " line and the last, each the lowest of those it stands for";
}

std::set<std::string> parseOutputs(const std::string& text) {
  std::set<std::string> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const auto comma = std::min(text.find(',', pos), text.size());
    const std::string item = text.substr(pos, comma - pos);
    if (std::find(std::begin(kOutputNames), std::end(kOutputNames), item) ==
        std::end(kOutputNames))
      throw InputError("--outputs '" + text + "': '" + item +
                       "' is not one of npy, json, stl, png");
    if (!out.insert(item).second)
      throw InputError("--outputs '" + text + "': '" + item + "' named twice");
    pos = comma + 1;
  }
  // heights.npy comes with its grid (DESIGN: heights.json beside it; `view --surface` reads
  // both): `--outputs npy` wrote the array alone, a helper's finding.
  if (out.count("npy")) out.insert("json");
  return out;
}

/// Peak resident memory of this process so far (MiB).
double peakRssMib() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_maxrss) / 1024.0;  // KiB on Linux
}

/// A number for JSON: finite, or null.
nlohmann::json finiteOrNull(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

/// How far the tool reaches up its axis from the tip, mm (a mesh tool: its highest vertex).
double toolLength(const zb::Tool& tool) {
  if (tool.kind != zb::ToolKind::Mesh) return tool.length_mm;
  double top = 0.0;
  for (const auto& v : tool.mesh.vertices) top = std::max(top, double(v.z));
  return top;
}

/// Lines whose cut lies beneath the top layer of `part` (an underside of it above the cut:
/// zbuffer::partUnderCut, as `check` reads them): a helper's tool under a mushroom's cap showed
/// the cap cut from 30 to 12.6 mm, silently.
std::size_t linesBeneathTheTopLayer(const geometry::TriangleMesh& part, const zb::Grid& grid,
                                    const std::vector<float>& heights_mm) {
  const zb::ToolMesh m = toZbuffer(part);
  const std::vector<float> top = zb::partTop(grid, m.vertices, m.triangles);
  constexpr float kLayerMm = 0.005f;  // the check's default gouge tolerance: no thinner layer
  if (!zb::anyCutUnderTop(top, heights_mm, kLayerMm)) return 0;
  std::vector<std::uint8_t> open(part.triangles.size(), 0);
  for (const std::vector<int>& shell : geometry::openShells(part))
    for (const int k : shell) open[static_cast<std::size_t>(k)] = 1;
  const zb::PartUnderCut under =
      zb::partUnderCut(grid, m.vertices, m.triangles, top, heights_mm, open, kLayerMm);
  return static_cast<std::size_t>(std::count(under.beneath.begin(), under.beneath.end(), 1));
}

}  // namespace

void addSimulateCommand(CLI::App& app, const GlobalOptions& global) {
  auto* cmd = app.add_subcommand("simulate",
                                 "Z-buffer machining simulation of a path: heights.npy (+ .json), "
                                 "surface.stl, heights.png, simulate.json and a summary");
  struct Options {
    std::string tool, path, grid = "1024x1024", region, part, backend = "auto", out;
    std::string outputs = "npy,json,stl,png";
    double stock_mm = std::numeric_limits<double>::quiet_NaN();
    std::size_t block_postures = 0;
  };
  auto o = std::make_shared<Options>();
  cmd->add_option("--tool", o->tool,
                  "Mesh file (tip at origin, axis +z) or ball:R[:L] | torus:R:r[:L] | flat:R[:L]")
      ->required();
  cmd->add_option("--path", o->path,
                  "Path file: .cl (x y z i j k per line), APT (.apt/.cls) or .npy (N×6/7 "
                  "float32/64)")
      ->required();
  cmd->add_option("--grid", o->grid, "Lines NXxNY")->capture_default_str();
  cmd->add_option("--region", o->region,
                  "x0,y0,x1,y1 mm (default: where the tool can cut, the tips' XY range and a "
                  "tilted axis up to the stock's top, plus the tool radius); given, the path is "
                  "cut while it is read");
  auto* stock =
      cmd->add_option("--stock", o->stock_mm, "Stock top plane z, mm (default: the highest tip)")
          ->check(numberFromTo(-common::kMaxCoordinateMm, common::kMaxCoordinateMm, "mm"));
  cmd->add_option("--part", o->part, "Part mesh whose top is the initial surface")->excludes(stock);
  cmd->add_option("--backend", o->backend,
                  "auto (the CPU where it would finish before the GPU has started, else the "
                  "GPU) | cpu | cuda")
      ->capture_default_str();
  cmd->add_option("--outputs", o->outputs,
                  "Which of npy (heights.npy, with heights.json: its grid), json (heights.json), "
                  "stl (surface.stl), png (heights.png) to write; simulate.json is always written "
                  "(those left out that an "
                  "earlier run wrote in --out are removed)")
      ->capture_default_str();
  cmd->add_option("--block", o->block_postures,
                  "Postures per chunk read and cut together (default: 4 MB of text); the heights "
                  "do not depend on it")
      ->check(CLI::Range(std::size_t{1}, std::size_t{1} << 40));
  cmd->add_option("--out", o->out, "Output directory")->required();

  cmd->callback([o, &global] {
    const auto start = Clock::now();
    // Everything the user typed is checked before any work.
    zb::SimulationRequest req;
    req.backend = zb::backendFromName(o->backend, "--backend");
    const std::set<std::string> outputs = parseOutputs(o->outputs);
    const fs::path out = o->out;
    common::checkOutputDirectory(out, "--out");  // before the work, not after
    common::claimOutputs(
        out, {"heights.npy", "heights.json", "surface.stl", "heights.png", "simulate.json"},
        {o->path, o->part});
    const auto [nx, ny] = parseGrid(o->grid);
    if (outputs.count("stl") && (nx < 2 || ny < 2))  // (1x1 wrote an STL of no triangles)
      throw InputError("--grid '" + o->grid +
                       "': surface.stl needs 2 lines each way (or --outputs without stl)");
    std::vector<double> region;
    if (!o->region.empty()) region = parseNumbers(o->region, "--region", 4);
    req.tool = parseTool(o->tool);

    // The path is read on all cores; beside it, the tool and the device get ready.
    geometry::PathReadOptions read_options;
    if (o->block_postures > 0) read_options.chunk_bytes = o->block_postures * 40;  // ~40 B a line
    // Until cut, the postures are held as floats (all of them where the reading runs ahead of the
    // cutting): refused before anything is read when that cannot fit.
    const double postures_estimate = estimatePostures(o->path);
    constexpr std::size_t kPostureBytes = sizeof(geometry::CompactPosture);
    static_assert(kPostureBytes == sizeof(zb::Posture), "read and cut postures alike");
    // With the file itself: it is mapped, and its pages read stay resident (a 975 k posture .cl
    // refused at 94M after reaching 125 MiB: a memory sweep's).
    std::error_code size_error;
    const double file_bytes = double(std::filesystem::file_size(o->path, size_error));
    common::requireMemory(
        "--path " + o->path,
        postures_estimate * double(kPostureBytes) + (size_error ? 0.0 : file_bytes),
        "about " + std::to_string(std::llround(postures_estimate)) + " postures of " +
            std::to_string(kPostureBytes) + " bytes, and the file mapped");
    const common::FileStamp path_stamp = common::fileStamp(o->path);
    PostureStream stream(o->path, read_options);
    // The part (--part) read beside the path: its top bounds the default region.
    std::optional<geometry::TriangleMesh> part;
    double part_top_z = -HUGE_VAL;
    if (!o->part.empty()) {
      // As a scene's part is read: mended, its shells wound outward (the top is a closed
      // shell's up-facing side; an overhang's underside its down-facing one).
      part = loadSceneMesh(o->part);
      for (const auto& v : part->vertices) part_top_z = std::max(part_top_z, double(v.z()));
    }
    // A first cut's surface.stl as the next one's --part, into the same --out: refused before the
    // work (its writing over the input is refused anyway, after it).
    for (const auto& [key, name] : {std::pair{"npy", "heights.npy"},
                                    {"json", "heights.json"},
                                    {"stl", "surface.stl"},
                                    {"png", "heights.png"},
                                    {"", "simulate.json"}})
      if (!*key || outputs.count(key)) common::refuseOutputsOverInputs(out, {name}, "--out");
    const bool streamed = !region.empty();
    bool have_grid = false;
    const auto makeGrid = [&] {
      if (have_grid) return;
      have_grid = true;
      if (streamed) {
        try {
          req.grid = zb::Grid::fromRegion(region[0], region[1], region[2], region[3], nx, ny);
        } catch (const InputError& e) {
          throw InputError("--region '" + o->region + "': " + e.what());
        }
        return;
      }
      stream.waitAll();  // the default region needs every tip
      // Where the tool can cut: its axis up to the stock's top (--stock, the part's top, else
      // the highest tip) reaches beside the tips when tilted.
      double top_z = !std::isnan(o->stock_mm) ? o->stock_mm : stream.bounds().zmax;
      if (part) top_z = part_top_z;
      // (Every point of the tool lies within `margin` of its axis: those below the top, of the
      // axis below top + margin.)
      const double margin = zb::toolReach(req.tool);
      const TipBounds b = stream.cutBounds(toolLength(req.tool), top_z + margin);
      req.grid = zb::Grid::fromRegion(b.xmin - margin, b.ymin - margin, b.xmax + margin,
                                      b.ymax + margin, nx, ny);
    };

    // auto: the CPU where it would be done before the GPU is ready (a small path), decided
    // before any CUDA call. Without --region a small path is read first to know its grid.
    std::string choice = zb::backendName(req.backend);
    if (req.backend == zb::Backend::Auto) {
      if (streamed || postures_estimate <= 5e6) {
        makeGrid();
        double cpu_s = 0;
        if (zb::cpuFinishesFirst(req.tool, req.grid, postures_estimate, &cpu_s)) {
          req.backend = zb::Backend::Cpu;
          choice = "auto: cpu (estimated " + std::to_string(cpu_s).substr(0, 5) +
                   " s, less than the GPU takes to start)";
        } else {
          choice = "auto: the GPU where there is one (the CPU estimated " +
                   std::to_string(cpu_s).substr(0, 5) + " s, more than the GPU takes to start)";
        }
      } else {
        choice = "auto: the GPU where there is one (over 5e6 postures)";
      }
    }
    // The GPU's context held on this thread, before the grid is sized (prepare's thread made it
    // while this one sized the grid: a diff review's).
    if (req.backend != zb::Backend::Cpu && zb::cudaAvailable()) common::requireCudaContext();
    const auto prepare_start = Clock::now();
    // The first CUDA call (the driver's start, ~0.1 s) is made here too, not before the reading.
    std::future<double> prepared = std::async(std::launch::async, [&req, prepare_start] {
      if (req.backend == zb::Backend::Cuda && !zb::cudaAvailable())
        throw InputError("--backend cuda: no CUDA device available (built without CUDA or no GPU)");
      zb::prepare(req.tool, req.backend);
      return secondsSince(prepare_start);
    });
    makeGrid();
    if (part)  // held, then the grid beside it: the part's top a line and its mesh (the file
               // read passed): an accepted limit ran 1.26 times over without it (a diff review's)
      common::requireMemory(
          "--part " + o->part,
          8.0 * double(req.grid.lineCount()) + 64.0 * double(part->triangles.size()),
          "the stock from its top: " + std::to_string(req.grid.lineCount()) + " lines");
    try {  // before allocating anything grid-sized
      zb::checkGridFits(req.grid);
    } catch (const InputError& e) {
      throw InputError((streamed ? "--region " + o->region : std::string("--grid")) + ": " +
                       e.what());  // (the grid's own text names its lines)
    }

    if (part) {
      const zb::ToolMesh m = toZbuffer(*part);
      req.initial_heights_mm = zb::stockFromPart(req.grid, m.vertices, m.triangles);
    } else if (!std::isnan(o->stock_mm)) {
      req.stock_mm = static_cast<float>(o->stock_mm);
    } else {
      // the highest tip: known before the cut only when the whole path was read first
      if (streamed) stream.waitAll();
      req.stock_mm = static_cast<float>(stream.bounds().zmax);
    }
    req.progress = makeProgressLine(global.quiet);
    // The postures cut over those there are (counted when the whole file was read first, else
    // estimated from its size): the engine reports within a chunk too (a file of one or two
    // chunks showed 0 %, then 50 % after 35 s).
    req.expected_postures =
        streamed ? static_cast<std::size_t>(std::max(1.0, postures_estimate)) : stream.postures();
    const double prepare_s = prepared.get();

    const zb::SimulationResult res = zb::simulateBlocks(req, [&stream] { return stream.next(); });
    stream.waitAll();  // an error after the last chunk (e.g. no postures at all)
    if (res.postures == 0) throw InputError(o->path + ": no postures");
    // An APT file's CUTTER / TLDATA against --tool, as generate and check say it of the scene's
    // (an adversary's 8 mm cutter was cut as a 6 mm ball in silence). Not a mesh tool's.
    if (req.tool.kind != zb::ToolKind::Mesh) {
      geometry::ToolSpec spec;
      spec.shape = req.tool.kind == zb::ToolKind::Ball    ? geometry::ToolShape::Ball
                   : req.tool.kind == zb::ToolKind::Torus ? geometry::ToolShape::Torus
                                                          : geometry::ToolShape::Flat;
      spec.radius_mm = req.tool.radius_mm;
      spec.corner_radius_mm = req.tool.corner_radius_mm;
      spec.length_mm = req.tool.length_mm;
      const std::vector<std::string> notes =
          cutterNotes(spec, stream.toolRecords(), "--tool", /*compare_length=*/false);
      if (!notes.empty()) endProgressLine();
      for (const std::string& note : notes) std::fprintf(stderr, "note: %s\n", note.c_str());
    }
    // Heights from the bytes read: a path rewritten in place meanwhile (not cut short: that is
    // SIGBUS's) mixed both files' postures, exit 0 (a helper's).
    common::requireUnchanged(o->path, path_stamp, "simulated");

    // The outputs, concurrently; each lands atomically under its name.
    const auto write_start = Clock::now();
    fs::create_directories(out);
    std::size_t stl_triangles = 0;
    std::vector<std::future<void>> writing;
    const auto write = [&writing](auto job) {
      writing.push_back(std::async(std::launch::async, job));
    };
    // The earlier run's set goes first and the grid's description comes after the heights: a
    // run killed while writing (SIGKILL, the OOM killer) left a new heights.json beside the old
    // heights.npy, a grid read onto heights it does not describe.
    common::removeStaleOutputs(
        out, {"heights.npy", "heights.json", "surface.stl", "heights.png", "simulate.json"});
    if (outputs.count("npy"))
      write([&] { zb::writeHeightsNpy(out / "heights.npy", req.grid, res.heights_mm); });
    if (outputs.count("stl"))
      write([&] {
        stl_triangles = zb::writeSurfaceStl(out / "surface.stl", req.grid, res.heights_mm);
      });
    if (outputs.count("png"))
      write([&] { zb::writeReliefPng(out / "heights.png", req.grid, res.heights_mm); });
    for (auto& w : writing) w.wait();
    for (auto& w : writing) w.get();  // the first failure, after every writer stopped
    if (outputs.count("json")) zb::writeHeightsJson(out / "heights.json", req.grid);
    for (const auto& [key, name] : {std::pair{"npy", "heights.npy"},
                                    {"json", "heights.json"},
                                    {"stl", "surface.stl"},
                                    {"png", "heights.png"}})
      if (!outputs.count(key)) common::removeStaleOutputs(out, {name});
    const double write_s = secondsSince(write_start);

    const auto [lo, hi] = std::minmax_element(res.heights_mm.begin(), res.heights_mm.end());
    {
      // The Z-buffer cuts in single precision (the postures are read as floats, as the GPU takes
      // them): far from the origin every position rounds to a float's step. At 9e5 mm the same
      // raster cut 37.6 um off its cut at the origin, while a note said the heights were exact
      // (a helper's finding). Said with the step, whatever the outputs.
      const zb::Grid& g = req.grid;
      const double far_mm = std::max(
          {std::abs(g.x0_mm), std::abs(g.y0_mm), std::abs(g.x0_mm + g.nx * g.dx_mm),
           std::abs(g.y0_mm + g.ny * g.dy_mm), std::abs(double(*lo)), std::abs(double(*hi))});
      if (far_mm > common::kFloatExactMm)
        std::fprintf(stderr,
                     "note: the path and the grid lie up to %.4g mm from the origin; the Z-buffer "
                     "cuts in single precision, in steps of %.2g mm there, so the heights (and "
                     "heights.npy, surface.stl: floats too) may be off by about that: place the "
                     "job near the origin for micron figures\n",
                     far_mm, common::floatStepMm(far_mm));
    }
    const double read_s = stream.readSeconds(), total_s = secondsSince(start);
    const double per_s = res.seconds > 0 ? double(res.postures) / res.seconds : 0.0;
    std::error_code size_ec;
    const double path_mb = double(fs::file_size(o->path, size_ec)) / 1e6;
    nlohmann::json report = {
        {"path", o->path},
        // Which file it was, for `generate` into this folder: its simulation of the path it
        // replaces is removed with it (an old heights.npy stood beside a new path.cl).
        {"path_digest", common::fileDigest(o->path)},
        {"path_megabytes", size_ec ? nlohmann::json(nullptr) : nlohmann::json(path_mb)},
        {"postures", res.postures},
        {"postures_culled", res.postures_culled},
        {"grid",
         {{"nx", req.grid.nx},
          {"ny", req.grid.ny},
          {"origin_mm", {req.grid.x0_mm, req.grid.y0_mm}},
          {"spacing_mm", {req.grid.dx_mm, req.grid.dy_mm}}}},
        {"lines_lowered", res.lines_lowered},
        {"heights_mm", {{"min", finiteOrNull(*lo)}, {"max", finiteOrNull(*hi)}}},
        // What the lines no pass cut still hold (`view` greys them): the stock plane, exactly
        // as the heights store it (float), or the part's top (--part).
        // The part's digest: `view` tells whether it is its scene's part (the name is relative to
        // where simulate ran).
        {"stock",
         part ? nlohmann::json{{"part", o->part}, {"part_digest", common::fileDigest(o->part)}}
              : nlohmann::json{{"plane_mm", double(req.stock_mm)}}},
        {"backend", zb::backendName(res.backend)},
        {"backend_asked", choice},
        {"streamed", streamed},
        {"seconds",
         {{"read", read_s},
          {"prepare", prepare_s},
          {"cut", res.seconds},
          {"write", write_s},
          {"total", total_s}}},
        {"note",
         "read and prepare run side by side; with --region (streamed) the cut overlaps the read"},
        {"postures_per_second", finiteOrNull(per_s)},
        {"read_megabytes_per_second",
         finiteOrNull(size_ec || read_s <= 0 ? NAN : path_mb / read_s)},
        {"peak_memory_mib", peakRssMib()}};
    common::writeTextAtomically(out / "simulate.json", jsonText(report));
    common::commitOutputs();  // a summary lost from here takes none of them away

    std::printf("postures        %zu (%zu culled: cannot lower any line)\n", res.postures,
                res.postures_culled);
    std::printf(
        "grid            %dx%d lines, spacing %.6g x %.6g mm, region %.6g,%.6g,%.6g,%.6g mm\n",
        req.grid.nx, req.grid.ny, req.grid.dx_mm, req.grid.dy_mm, req.grid.x0_mm, req.grid.y0_mm,
        req.grid.x0_mm + req.grid.nx * req.grid.dx_mm,
        req.grid.y0_mm + req.grid.ny * req.grid.dy_mm);
    std::printf("lines touched   %zu of %zu (%.1f%%)\n", res.lines_lowered, req.grid.lineCount(),
                100.0 * double(res.lines_lowered) / double(req.grid.lineCount()));
    std::printf("heights         %.6g .. %.6g mm\n", double(*lo) + 0.0, double(*hi) + 0.0);
    std::printf("time            %.3f s simulation (%.3g postures/s); read %.3f s, prepare %.3f s, "
                "write %.3f s, total %.3f s%s\n",
                res.seconds, per_s, read_s, prepare_s, write_s, total_s,
                streamed ? " (cut while reading)" : "");
    std::printf("memory          %.0f MiB peak\n", peakRssMib());
    std::printf("backend         %s\n", zb::backendName(res.backend));
    std::string names;
    for (const char* name : kOutputNames) {
      if (!outputs.count(name)) continue;
      const std::string file = std::string(name) == "npy"    ? "heights.npy"
                               : std::string(name) == "json" ? "heights.json"
                               : std::string(name) == "stl"
                                   ? "surface.stl (" + std::to_string(stl_triangles) +
                                         " triangles" + stlStrideNote(req.grid) + ")"
                                   : "heights.png";
      names += file + ", ";
    }
    std::printf("outputs         %s/{%ssimulate.json}\n", out.string().c_str(), names.c_str());
    // Nothing cut is most often the stock where the path already is (a newcomer's raster on a
    // floor read "0 lines touched" without a word, twice).
    if (res.lines_lowered == 0)
      std::fprintf(stderr,
                   "warning: no line was cut: the tool never goes below the initial surface (%s); "
                   "a finishing path runs on the finished part, so its stock lies above: give "
                   "--stock Z above the path's lowest tips%s\n",
                   part                       ? "the top of --part"
                   : !std::isnan(o->stock_mm) ? "--stock"
                                              : "the stock at the highest tip, the default",
                   // A user read "nothing cut" on the part as "no gouge": the moves between
                   // postures are not stamped (a chord over a convex part gouged 141 um).
                   part ? " instead of --part (simulate stamps the postures, not the moves "
                          "between them: `fieldpath check` finds a move's gouge)"
                        : "");
    // From the part's top a finishing path lowers only the lines where it enters the part: a
    // CAM engineer's raster changed 0.2 % of them and read as the path's surface, scallops and
    // all (they stand above the part, where the stock already is).
    if (part && res.lines_lowered > 0 && res.lines_lowered < req.grid.lineCount() / 20)
      std::fprintf(stderr,
                   "note: %.2g %% of the lines were cut: the heights start on --part's top, so "
                   "only where the tool went under the part shows (its gouges); the cusps between "
                   "passes show cut from a stock above the path (--stock Z), or measured by "
                   "`fieldpath check`\n",
                   100.0 * double(res.lines_lowered) / double(req.grid.lineCount()));
    if (part && res.lines_lowered > 0)
      if (const std::size_t n = linesBeneathTheTopLayer(*part, req.grid, res.heights_mm); n > 0)
        std::fprintf(stderr,
                     "warning: %zu lines were cut beneath the top layer of --part (the tool "
                     "passed under an overhang, or through the part): a line keeps its lowest "
                     "cut, so the surface there shows the layer above cut through; `fieldpath "
                     "check` measures such lines against the part under the layer\n",
                     n);
  });
}

}  // namespace fieldpath::app
