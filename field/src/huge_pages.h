#pragma once
/// Internal to field/: large arrays of the voxel build in transparent huge pages. A refined
/// build writes ~0.5-1 GB of fresh memory (node values, blocks, node errors); in 4 KiB pages that
/// is ~230 000 page faults, which 16 threads take one at a time (the refinement's host work on the
/// GPU machine was page-fault bound: 0.27 s of 0.43 s). Arrays of at least kHugeMinBytes are mapped
/// 2 MiB-aligned and madvise(MADV_HUGEPAGE)d: a fault then maps 2 MiB. Plain C++ (no OpenVDB),
/// so that node_cuda.h can use it too.
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

namespace fieldpath::field {

/// Smallest array given huge pages (one huge page: smaller ones gain nothing).
constexpr std::size_t kHugeMinBytes = std::size_t{2} << 20;

/// Threads from which huge pages pay. Measured (bench/results/field.md, "huge pages"): on the
/// GPU machine's 16 cores they cut a refined CUDA build 0.35 -> 0.30 s (faults 228k -> 138k); on
/// the 2-core VM the faults are not contended and the kernel's compaction for 2 MiB pages made
/// the refinement slower (0.45 -> 0.52-0.72 s).
constexpr unsigned kHugeMinThreads = 8;

/// Whether large arrays get huge pages: FIELDPATH_HUGE_PAGES=0 or 1 if set, else on machines of
/// at least kHugeMinThreads hardware threads (read once).
bool hugePagesEnabled();

namespace detail {
/// The two ways hugeAlloc takes memory (tests call them directly: the switch is read once a
/// process). mapHuge: whole 2 MiB pages, 2 MiB-aligned, madvised to huge pages.
void* mapHuge(std::size_t bytes);
void unmapHuge(void* p, std::size_t bytes) noexcept;
}  // namespace detail

/// `bytes` of uninitialised memory (zero-filled by the OS where mapped), 64-byte aligned at
/// least; throws std::bad_alloc. Free with hugeFree(p, bytes), the same `bytes`.
void* hugeAlloc(std::size_t bytes);
void hugeFree(void* p, std::size_t bytes) noexcept;

/// A std::allocator that takes large arrays from hugeAlloc and leaves trivially constructible
/// elements uninitialised on resize (every user writes them in parallel where it reads them:
/// zeroing first was 0.1 s a refined level, serial, on the GPU machine's 16 cores).
template <class T>
struct UninitAllocator {
  using value_type = T;
  UninitAllocator() = default;
  template <class U>
  UninitAllocator(const UninitAllocator<U>&) noexcept {}
  T* allocate(std::size_t n) { return static_cast<T*>(hugeAlloc(n * sizeof(T))); }
  void deallocate(T* p, std::size_t n) noexcept { hugeFree(p, n * sizeof(T)); }
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible_v<U>) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <class U>
  bool operator==(const UninitAllocator<U>&) const noexcept { return true; }
  template <class U>
  bool operator!=(const UninitAllocator<U>&) const noexcept { return false; }
};
template <class T>
using UninitVector = std::vector<T, UninitAllocator<T>>;

/// An uninitialised array of n T (trivial T) from hugeAlloc, freed with it.
template <class T>
class HugeArray {
  static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_destructible_v<T>);

 public:
  HugeArray() = default;
  explicit HugeArray(std::size_t n)
      : data_(static_cast<T*>(hugeAlloc(n * sizeof(T))), Free{n * sizeof(T)}), size_(n) {}
  T& operator[](std::size_t i) { return data_.get()[i]; }
  const T& operator[](std::size_t i) const { return data_.get()[i]; }
  T* data() { return data_.get(); }
  std::size_t size() const { return size_; }

 private:
  struct Free {
    std::size_t bytes = 0;
    void operator()(T* p) const noexcept { hugeFree(p, bytes); }
  };
  std::unique_ptr<T, Free> data_{nullptr, Free{}};
  std::size_t size_ = 0;
};

}  // namespace fieldpath::field
