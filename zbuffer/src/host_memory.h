#pragma once
/// Large host arrays of the Z-buffer (heights of a 10000² grid: 400 MB). Their pages are faulted in
/// on first touch, which on the GPU machine's VM costs ~0.6 ms per MB with 4 KB pages (400 MB
/// zeroed: 250 ms); transparent huge pages cut it 3× (83 ms; bench/results/zbuffer-h100.md, run
/// 30). The kernel gives them where it is set to "madvise" (there) or "always".
#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <vector>

namespace fieldpath::zbuffer::detail {

/// An empty vector with room for n elements, its memory advised to use huge pages (advice only:
/// nothing depends on it being taken). Fill it with assign() or resize().
template <class T>
std::vector<T> reserveHuge(std::size_t n) {
  std::vector<T> v;
  v.reserve(n);
#ifdef MADV_HUGEPAGE
  constexpr std::uintptr_t kHuge = std::uintptr_t{2} << 20;
  const auto data = reinterpret_cast<std::uintptr_t>(v.data());  // reserved, not yet sized
  const auto begin = (data + kHuge - 1) & ~(kHuge - 1);
  const auto end = (data + n * sizeof(T)) & ~(kHuge - 1);
  if (n * sizeof(T) >= 4 * kHuge && end > begin)
    madvise(reinterpret_cast<void*>(begin), end - begin, MADV_HUGEPAGE);
#endif
  return v;
}

}  // namespace fieldpath::zbuffer::detail
