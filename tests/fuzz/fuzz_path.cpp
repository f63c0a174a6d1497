/// libFuzzer target: the path readers (`.cl`, APT CLDATA, `.npy`), one binary per format
/// (FIELDPATH_FUZZ_FORMAT 0, 1, 2). The first byte picks the reading options (threads, chunk
/// size), so that the chunked parallel reading is fuzzed at its chunk boundaries too: the result
/// must not depend on them (checked against a whole-file read).
#include <cstdlib>

#include "fieldpath/common/errors.h"
#include "fieldpath/geometry/cl_file.h"
#include "fuzz_support.h"

#ifndef FIELDPATH_FUZZ_FORMAT
#define FIELDPATH_FUZZ_FORMAT 0
#endif

namespace {

using namespace fieldpath;

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
    return bits;
  } catch (const common::InputError& e) {
    return std::string("error: ") + e.what();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const char* ext[] = {"path.cl", "path.apt", "path.npy"};
  const auto file = fuzz::writeScratch(ext[FIELDPATH_FUZZ_FORMAT], fuzz::view(data + 1, size - 1));
  geometry::PathReadOptions small;
  // Two threads for one input in 64, picked by a hash of the whole input: TBB's workers spin
  // after each parallel call (95 % of fuzz_cl's time on a busy 2-core machine), and a choice by
  // the first byte was learnt by the fuzzer (the threaded branch is new coverage: 59 % of the
  // corpus took it). The chunks (1..32 bytes: many boundaries) are cut and joined the same way on
  // one thread.
  std::uint32_t hash = 2166136261u;  // FNV-1a
  for (std::size_t i = 0; i < size; ++i) hash = (hash ^ data[i]) * 16777619u;
  small.threads = hash % 64 == 0 ? 2 : 1;
  small.chunk_bytes = 1 + (data[0] >> 3);
  const std::string chunked = outcome(file, small);
  const std::string whole = outcome(file, geometry::PathReadOptions{1, std::size_t{1} << 30});
  if (chunked != whole) std::abort();  // the reading options changed the result
  return 0;
}
