/// The voxel build's large arrays (field/src/huge_pages.h): mapped 2 MiB-aligned with the kernel
/// told to back them with huge pages (the VmFlags of the mapping say "hg"), holding what is
/// written, and the small ones from the heap, 64-byte aligned.
#include <cstdint>
#include <fstream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "huge_pages.h"

using namespace fieldpath::field;

namespace {

/// The VmFlags line of the mapping of /proc/self/smaps that holds address p ("" if none).
std::string vmFlagsAt(const void* p) {
  std::ifstream smaps("/proc/self/smaps");
  std::string line;
  const auto at = reinterpret_cast<std::uintptr_t>(p);
  bool inside = false;
  while (std::getline(smaps, line)) {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-') {
      inside = lo <= at && at < hi;
      continue;
    }
    if (inside && line.rfind("VmFlags:", 0) == 0) return line;
  }
  return "";
}

}  // namespace

TEST(HugePages, MappedArraysAreAlignedAdvisedAndHoldTheirValues) {
  const std::size_t bytes = (std::size_t{5} << 20) + 123;  // 2.x huge pages, not a multiple
  auto* p = static_cast<std::uint32_t*>(detail::mapHuge(bytes));
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % (std::size_t{2} << 20), 0u);
  const std::size_t n = bytes / sizeof(std::uint32_t);
  for (std::size_t i = 0; i < n; ++i) p[i] = std::uint32_t(i * 2654435761u);
  std::size_t wrong = 0;
  for (std::size_t i = 0; i < n; ++i) wrong += p[i] != std::uint32_t(i * 2654435761u);
  EXPECT_EQ(wrong, 0u);
  const std::string flags = vmFlagsAt(p);
  if (flags.empty()) GTEST_SKIP() << "no /proc/self/smaps here";
  EXPECT_NE(flags.find(" hg"), std::string::npos) << flags;  // madvise(MADV_HUGEPAGE) took
  detail::unmapHuge(p, bytes);
}

TEST(HugePages, ArraysSmallOrLargeHoldTheirValues) {
  // Whichever way this machine takes them (hugePagesEnabled: 8 threads or more, or the
  // FIELDPATH_HUGE_PAGES switch), both sizes round-trip and the small one is 64-byte aligned.
  for (std::size_t n : {std::size_t{1000}, kHugeMinBytes / sizeof(double) + 7}) {
    HugeArray<double> a(n);
    EXPECT_EQ(a.size(), n);
    for (std::size_t i = 0; i < n; ++i) a[i] = 0.5 * double(i);
    double sum = 0.0;
    for (std::size_t i = 0; i < n; ++i) sum += a[i];
    EXPECT_EQ(sum, 0.25 * double(n) * double(n - 1));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.data()) % 64, 0u);
    UninitVector<float> v;
    v.resize(n);
    v[n - 1] = 3.0f;
    v.resize(2 * n);  // reallocates: the old element moves
    EXPECT_EQ(v[n - 1], 3.0f);
  }
}
