/// Large arrays in transparent huge pages (huge_pages.h).
#include "huge_pages.h"

#include <sys/mman.h>

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <thread>

namespace fieldpath::field {

namespace {
constexpr std::size_t kHugePage = std::size_t{2} << 20;

std::size_t roundUp(std::size_t bytes) { return (bytes + kHugePage - 1) & ~(kHugePage - 1); }
}  // namespace

bool hugePagesEnabled() {
  static const bool enabled = [] {
    if (const char* v = std::getenv("FIELDPATH_HUGE_PAGES")) return std::strcmp(v, "0") != 0;
    return std::thread::hardware_concurrency() >= kHugeMinThreads;
  }();
  return enabled;
}

namespace detail {

void* mapHuge(std::size_t bytes) {
  // Map one huge page more than needed, keep the 2 MiB-aligned part, unmap the rest: a huge
  // page needs 2 MiB-aligned virtual addresses.
  const std::size_t size = roundUp(bytes);
  void* raw = mmap(nullptr, size + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS,
                   -1, 0);
  if (raw == MAP_FAILED) throw std::bad_alloc();
  const auto base = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (base + kHugePage - 1) & ~std::uintptr_t(kHugePage - 1);
  if (aligned > base) munmap(raw, aligned - base);
  const std::uintptr_t end = base + size + kHugePage;
  if (end > aligned + size) munmap(reinterpret_cast<void*>(aligned + size), end - (aligned + size));
  void* p = reinterpret_cast<void*>(aligned);
  madvise(p, size, MADV_HUGEPAGE);  // advice only: without THP the pages stay 4 KiB
  return p;
}

void unmapHuge(void* p, std::size_t bytes) noexcept { munmap(p, roundUp(bytes)); }

}  // namespace detail

void* hugeAlloc(std::size_t bytes) {
  if (bytes >= kHugeMinBytes && hugePagesEnabled()) return detail::mapHuge(bytes);
  return ::operator new(bytes ? bytes : 1, std::align_val_t{64});
}

void hugeFree(void* p, std::size_t bytes) noexcept {
  if (!p) return;
  if (bytes >= kHugeMinBytes && hugePagesEnabled())
    detail::unmapHuge(p, bytes);
  else
    ::operator delete(p, std::align_val_t{64});
}

}  // namespace fieldpath::field
