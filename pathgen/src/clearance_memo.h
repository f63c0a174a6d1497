#pragma once
/// Internal to pathgen/: what a ClearanceMemo keeps (clearance.h), read and filled by
/// ClearanceChecker's check and checkMotions.
#include <array>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <utility>

#include "fieldpath/geometry/posture.h"
#include "fieldpath/pathgen/clearance.h"

namespace fieldpath::pathgen {

namespace memo_detail {

/// The bits of doubles, as a key (no two different values alike, -0 and 0 apart).
template <std::size_t N>
struct BitsHash {
  std::size_t operator()(const std::array<std::uint64_t, N>& key) const {
    std::uint64_t h = 1469598103934665603ull;  // FNV-1a over the words
    for (const std::uint64_t w : key) h = (h ^ w) * 1099511628211ull;
    return static_cast<std::size_t>(h);
  }
};

inline void putBits(std::uint64_t* out, const geometry::Posture& p) {
  for (int k = 0; k < 3; ++k) {
    out[k] = std::bit_cast<std::uint64_t>(p.tip_mm[k]);
    out[3 + k] = std::bit_cast<std::uint64_t>(p.axis[k]);
  }
}

}  // namespace memo_detail

struct ClearanceMemo::Impl {
  using PostureKey = std::array<std::uint64_t, 6>;
  /// Two postures, their clearances (given, or measured) and the six numbers of the request:
  /// all that a motion's bound depends on.
  using MotionKey = std::array<std::uint64_t, 20>;
  struct Posture {
    double distance_mm;
    int obstacle;
    std::uint32_t used;  ///< the generation that last put or gave it back
  };
  struct Motion {
    double bound_mm;
    bool touched;
    std::size_t samples;
    std::uint32_t used;
  };
  std::unordered_map<PostureKey, Posture, memo_detail::BitsHash<6>> postures;
  std::unordered_map<MotionKey, Motion, memo_detail::BitsHash<20>> motions;
  std::size_t reused = 0;
  std::uint32_t generation = 0;  ///< forgetUnused's count

  static PostureKey key(const geometry::Posture& p) {
    PostureKey k;
    memo_detail::putBits(k.data(), p);
    return k;
  }
  static MotionKey key(const geometry::Posture& a, const geometry::Posture& b, double a_mm,
                       double b_mm, const std::array<double, 6>& request) {
    MotionKey k;
    memo_detail::putBits(k.data(), a);
    memo_detail::putBits(k.data() + 6, b);
    k[12] = std::bit_cast<std::uint64_t>(a_mm);
    k[13] = std::bit_cast<std::uint64_t>(b_mm);
    for (std::size_t i = 0; i < request.size(); ++i)
      k[14 + i] = std::bit_cast<std::uint64_t>(request[i]);
    return k;
  }
};

}  // namespace fieldpath::pathgen
