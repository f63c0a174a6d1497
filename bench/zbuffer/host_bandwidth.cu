/// Host-side transfer rates of the machine the CUDA backend runs on: memcpy into pinned memory on 1
/// to 16 threads (alone, and beside a thread faulting in a fresh 400 MB array, as the CUDA
/// adapter's output is), host↔device copies pinned, pageable and registered, and the cost of
/// zeroing 400 MB with and without transparent huge pages. It explains the choices of
/// zbuffer/src/cuda_engine.cu (parallelCopy on 4 threads) and zbuffer/src/host_memory.h
/// (reserveHuge); bench/results/zbuffer-h100.md, run 30.
#include <cuda_runtime.h>
#include <omp.h>
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <future>
#include <vector>

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void check(cudaError_t err, const char* what) {
  if (err != cudaSuccess) {
    std::fprintf(stderr, "host_bandwidth: %s: %s\n", what, cudaGetErrorString(err));
    std::exit(1);
  }
}

/// Best of three wall times of f (s).
template <class F>
double best(F f) {
  double b = 1e30;
  for (int r = 0; r < 3; ++r) {
    const double t = now();
    f();
    b = std::min(b, now() - t);
  }
  return b;
}

/// `bytes` into a 32 MB pinned ring in 16 MB pieces, each split over `threads` (as the staging).
void stagedCopy(char* pinned, const char* src, std::size_t bytes, int threads) {
  const std::size_t piece = std::size_t{16} << 20, part = piece / 16;
  for (std::size_t off = 0; off < bytes; off += piece) {
#pragma omp parallel for num_threads(threads) schedule(dynamic)
    for (int k = 0; k < 16; ++k)
      std::memcpy(pinned + off % (2 * piece) + part * k, src + off + part * k, part);
  }
}

}  // namespace

int main() {
  const std::size_t n = std::size_t{96} << 20;  // one block of 4 M postures
  std::vector<char> src(n, 1), dst(n, 2);
  char *pinned = nullptr, *device = nullptr;
  check(cudaMallocHost(&pinned, n), "cudaMallocHost");
  check(cudaMalloc(&device, n), "cudaMalloc");
  std::memset(pinned, 3, n);
  const auto rate = [&](double s) { return double(n) / s / 1e9; };
  std::printf("| measurement | GB/s or ms |\n|---|---:|\n");
  for (int threads : {1, 4, 8, 14, 16})
    std::printf("| memcpy 96 MB pageable → pinned, %d threads | %.1f GB/s |\n", threads,
                rate(best([&] { stagedCopy(pinned, src.data(), n, threads); })));
  for (int threads : {4, 14, 16}) {
    auto faulting = std::async(std::launch::async, [] {
      const double t = now();
      std::vector<float> fresh(std::size_t{100} << 20);
      return now() - t;
    });
    const double t = now();
    stagedCopy(pinned, src.data(), n, threads);
    const double copy = now() - t;
    std::printf("| memcpy 96 MB, %d threads, beside 400 MB being faulted in | %.1f ms |\n", threads,
                copy * 1e3);
    std::printf("| (that 400 MB zeroing) | %.1f ms |\n", faulting.get() * 1e3);
  }
  std::printf(
      "| H2D pinned | %.1f GB/s |\n",
      rate(best([&] { check(cudaMemcpy(device, pinned, n, cudaMemcpyHostToDevice), "H2D"); })));
  std::printf(
      "| H2D pageable | %.1f GB/s |\n",
      rate(best([&] { check(cudaMemcpy(device, src.data(), n, cudaMemcpyHostToDevice), "H2D"); })));
  std::printf(
      "| D2H pinned | %.1f GB/s |\n",
      rate(best([&] { check(cudaMemcpy(pinned, device, n, cudaMemcpyDeviceToHost), "D2H"); })));
  std::printf(
      "| D2H pageable | %.1f GB/s |\n",
      rate(best([&] { check(cudaMemcpy(dst.data(), device, n, cudaMemcpyDeviceToHost), "D2H"); })));
  double t = now();
  check(cudaHostRegister(src.data(), n, 0), "cudaHostRegister");
  std::printf("| cudaHostRegister 96 MB | %.1f ms |\n", (now() - t) * 1e3);
  std::printf(
      "| H2D registered | %.1f GB/s |\n",
      rate(best([&] { check(cudaMemcpy(device, src.data(), n, cudaMemcpyHostToDevice), "H2D"); })));
  check(cudaHostUnregister(src.data()), "cudaHostUnregister");
  {
    t = now();
    std::vector<float> v;
    v.reserve(std::size_t{100} << 20);
    const std::uintptr_t huge = std::uintptr_t{2} << 20;
    const auto begin = (reinterpret_cast<std::uintptr_t>(v.data()) + huge - 1) & ~(huge - 1);
    const auto end = reinterpret_cast<std::uintptr_t>(v.data() + v.capacity()) & ~(huge - 1);
    const int rc = madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
    v.resize(v.capacity());
    std::printf("| 400 MB zeroed after madvise(MADV_HUGEPAGE) (rc %d) | %.1f ms |\n", rc,
                (now() - t) * 1e3);
  }
  t = now();
  { std::vector<float> v(std::size_t{100} << 20); }
  std::printf("| 400 MB zeroed, 4 KB pages | %.1f ms |\n", (now() - t) * 1e3);
  cudaFree(device);
  cudaFreeHost(pinned);
  return 0;
}
