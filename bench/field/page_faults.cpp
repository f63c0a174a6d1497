/// What a fresh page costs on this machine (bench/results/field.md, issue 15 seventh session):
/// 32 MiB mapped and touched page by page, then written again; HUGE=1 madvises it to transparent
/// huge pages first. Standalone (not in the CMake build):
///   g++ -O2 bench/field/page_faults.cpp -o /tmp/page_faults && /tmp/page_faults
#include <sys/mman.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>

int main() {
  using Clock = std::chrono::steady_clock;
  const std::size_t bytes = std::size_t{32} << 20, page = 4096;
  for (int run = 0; run < 3; ++run) {
    const auto t0 = Clock::now();
    char* p = static_cast<char*>(
        mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0));
    if (p == MAP_FAILED) return 1;
    if (std::getenv("HUGE")) madvise(p, bytes, MADV_HUGEPAGE);
    for (std::size_t i = 0; i < bytes; i += page) p[i] = 1;
    const auto t1 = Clock::now();
    std::memset(p, 2, bytes);
    const auto t2 = Clock::now();
    const double fault_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
    std::printf("fault+zero %.2f ms (%.2f us a 4 KiB page), written again %.2f ms\n", fault_ms,
                1e3 * fault_ms / double(bytes / page),
                std::chrono::duration<double, std::milli>(t2 - t1).count());
    munmap(p, bytes);
  }
}
