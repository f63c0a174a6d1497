/// libFuzzer target: the path readers (`.cl`, APT CLDATA, `.npy`), one binary per format
/// (FIELDPATH_FUZZ_FORMAT 0, 1, 2). The first byte picks the reading options (threads, chunk
/// size), so that the chunked parallel reading is fuzzed at its chunk boundaries too: the result
/// must not depend on them (checked against a whole-file read).
#include <cstdint>
#include <cstdlib>

#include <tbb/global_control.h>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fuzz_support.h"

#ifndef FIELDPATH_FUZZ_FORMAT
#define FIELDPATH_FUZZ_FORMAT 0
#endif

namespace {

using namespace fieldpath;

// TBB held to the calling thread: the readers' parallel loops then run their chunks in order here.
// Spinning TBB workers took 95 % of the time on a busy 2-core machine (inputs of several chunks
// start them; the readers' line count, splitAtLines, did whatever PathReadOptions::threads said
// until it took the same thread count). The chunk cutting and joining checked here are the same on
// one thread; their concurrency is TSan's (scripts/sanitize.sh tsan).
const tbb::global_control one_thread(tbb::global_control::max_allowed_parallelism, 1);

geometry::PathFile readAs(const std::filesystem::path& file, const geometry::PathReadOptions& o) {
  switch (FIELDPATH_FUZZ_FORMAT) {
    case 1:
      return geometry::readAptPath(file, o);
    case 2:
      return geometry::readNpyPath(file, o);
    default:
      return geometry::readClPath(file, o);
  }
}

/// "ok" + the postures' bits, or "error: " + the message.
std::string outcome(const std::filesystem::path& file, const geometry::PathReadOptions& o) {
  try {
    const geometry::PathFile path = readAs(file, o);
    std::string bits = "ok";
    for (const auto& p : path.postures) {
      bits.append(reinterpret_cast<const char*>(p.tip_mm.data()), 3 * sizeof(double));
      bits.append(reinterpret_cast<const char*>(p.axis.data()), 3 * sizeof(double));
    }
    for (const auto& b : path.blocks)
      bits += std::to_string(b.begin) + "-" + std::to_string(b.end) + ";";
    for (const auto& c : path.cutters) {  // APT's CUTTER records, in mm
      bits.append(reinterpret_cast<const char*>(&c.diameter_mm), sizeof(double));
      bits.append(reinterpret_cast<const char*>(&c.corner_mm), sizeof(double));
      bits += std::to_string(c.line) + ";";
    }
    return bits;
  } catch (const common::InputError& e) {
    return std::string("error: ") + e.what();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fieldpath::common::releaseHeldMemory();  // each input a run of its own (--max-memory)
  if (size < 1) return 0;
  const char* ext[] = {"path.cl", "path.apt", "path.npy"};
  const auto file = fuzz::writeScratch(ext[FIELDPATH_FUZZ_FORMAT], fuzz::view(data + 1, size - 1));
  geometry::PathReadOptions small;
  // The arena path (threads = 2, run on this thread) for one input in 64, picked by a hash of
  // the whole input (a choice by the first byte was learnt by the fuzzer: new coverage); chunks
  // of 1..32 bytes: many boundaries.
  std::uint32_t hash = 2166136261u;  // FNV-1a
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 16777619u;
  small.threads = hash % 64 == 0 ? 2 : 1;
  small.chunk_bytes = 1 + (data[0] >> 3);
  const std::string chunked = outcome(file, small);
  const std::string whole = outcome(file, geometry::PathReadOptions{1, std::size_t{1} << 30});
  if (chunked != whole) std::abort();  // the reading options changed the result
  return 0;
}
