/// Path-file reading speed (issue 13): the parallel chunked readers against the serial getline
/// reader they replaced (kept here, verbatim in what it does per line, as the in-run peer), on
/// files the user gives (e.g. those of `bench_zbuffer --write-cases`). Each variant's postures are
/// compared with the peer's, bit for bit (compact floats), before any timing.
///
///   bench_path_read [--reps N] FILE...
/// Prints a markdown table: file, MB, postures, median ms and MB/s of each variant, speed-up. The
/// scans are timed as simulate uses them: postures handed over by chunk, not gathered.
#include <atomic>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "fieldpath/common/stats.h"
#include "fieldpath/geometry/cl_file.h"

namespace fs = std::filesystem;
using namespace fieldpath::geometry;

namespace {

/// The serial `.cl` reader of before issue 13: getline, split into tokens, from_chars, one
/// posture and one line number pushed per line (markers and errors left out: the good path).
std::vector<Posture> serialRead(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::vector<Posture> postures;
  std::vector<std::size_t> lines;
  std::string text;
  for (std::size_t line = 1; std::getline(in, text); ++line) {
    std::string_view content(text);
    if (const auto hash = content.find('#'); hash != std::string_view::npos)
      content = content.substr(0, hash);
    std::vector<std::string_view> tokens;
    std::size_t i = 0;
    while (i < content.size()) {
      while (i < content.size() && std::isspace(static_cast<unsigned char>(content[i]))) ++i;
      const std::size_t start = i;
      while (i < content.size() && !std::isspace(static_cast<unsigned char>(content[i]))) ++i;
      if (i > start) tokens.push_back(content.substr(start, i - start));
    }
    if (tokens.size() < 6) continue;
    double v[7];
    for (std::size_t c = 0; c < tokens.size() && c < 7; ++c)
      std::from_chars(tokens[c].data(), tokens[c].data() + tokens[c].size(), v[c]);
    Posture p;
    p.tip_mm = Vec3(v[0], v[1], v[2]);
    const Vec3 axis(v[3], v[4], v[5]);
    const double length = axis.norm();
    p.axis = std::abs(length - 1.0) <= 8 * 2.2e-16 ? axis : Vec3(axis / length);
    postures.push_back(p);
    lines.push_back(line);
  }
  return postures;
}

template <class F>
double medianMs(int reps, F&& f) {
  return 1e3 * fieldpath::common::medianSeconds(reps, std::forward<F>(f));
}

std::vector<CompactPosture> scanAll(const fs::path& file) {
  std::vector<std::vector<CompactPosture>> chunks;
  PostureChunkSink sink;
  sink.begin = [&](std::size_t n) { chunks.resize(n); };
  sink.chunk = [&](std::size_t i, std::span<const CompactPosture> p) {
    chunks[i].assign(p.begin(), p.end());
  };
  scanPathFile(file, {}, sink);
  std::vector<CompactPosture> all;
  for (auto& c : chunks) all.insert(all.end(), c.begin(), c.end());
  return all;
}

/// The postures counted as scanPathFile hands them over (what simulate's stream does before the
/// engine takes them): the timed scan, with `threads` workers (0: all).
std::size_t scanCount(const fs::path& file, unsigned threads) {
  std::atomic<std::size_t> n{0};
  PostureChunkSink sink;
  sink.begin = [](std::size_t) {};
  sink.chunk = [&](std::size_t, std::span<const CompactPosture> p) { n += p.size(); };
  PathReadOptions options;
  options.threads = threads;
  scanPathFile(file, options, sink);
  return n;
}

bool sameCompact(const std::vector<CompactPosture>& a, const std::vector<Posture>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const CompactPosture c = compact(b[i]);
    if (std::memcmp(&c, &a[i], sizeof c) != 0) return false;
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  int reps = 5;
  std::vector<fs::path> files;
  for (int i = 1; i < argc; ++i) {
    if (std::string(argv[i]) == "--reps" && i + 1 < argc)
      reps = std::max(1, std::atoi(argv[++i]));
    else
      files.push_back(argv[i]);
  }
  if (files.empty()) {
    std::fprintf(stderr, "usage: bench_path_read [--reps N] FILE...\n");
    return 1;
  }
  std::printf("%u hardware threads, median of %d runs (page cache warm)\n\n",
              std::thread::hardware_concurrency(), reps);
  std::printf(
      "| file | MB | postures | serial getline ms (peer) | readPathFile 1 thread ms | "
      "readPathFile all ms | scanPathFile 1 thread ms | scanPathFile all ms | MB/s (scan all) | "
      "speed-up scan all / peer | same postures "
      "|\n|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const fs::path& file : files) {
    const double mb = double(fs::file_size(file)) / 1e6;
    const bool cl = pathFormatOf(file) == PathFormat::Cl;
    PathReadOptions one;
    one.threads = 1;
    const PathFile reference = readPathFile(file, one);
    bool same = sameCompact(scanAll(file), reference.postures);
    if (cl) same = same && sameCompact(scanAll(file), serialRead(file));
    const double peer = cl ? medianMs(reps, [&] { serialRead(file); }) : NAN;
    const double serial = medianMs(reps, [&] { readPathFile(file, one); });
    const double all = medianMs(reps, [&] { readPathFile(file); });
    const double scan1 = medianMs(reps, [&] { scanCount(file, 1); });
    const double scan = medianMs(reps, [&] { scanCount(file, 0); });
    std::printf("| %s | %.1f | %zu | %.0f | %.0f | %.0f | %.0f | %.0f | %.0f | %.1f× | %s |\n",
                file.filename().c_str(), mb, reference.postures.size(), peer, serial, all, scan1,
                scan, mb / (scan / 1e3), peer / scan, same ? "yes" : "NO");
    std::fflush(stdout);
  }
  return 0;
}
