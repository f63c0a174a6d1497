#pragma once
/// Independent double-precision reference for the analytic tools: the lowest point of each convex
/// piece along a vertical line, found from the piece's convex "outside distance" alone (ternary
/// search for its minimum, then bisection for the first root). No closed forms shared with the
/// library.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <optional>

namespace fieldpath::zbuffer::test {

using V3 = std::array<double, 3>;

inline V3 sub(V3 a, V3 b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
inline double dotd(V3 a, V3 b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }
inline double norm(V3 a) { return std::sqrt(dotd(a, a)); }

/// An analytic tool placed at a posture (double): shape R, r, L; tip p; unit axis a.
struct PlacedTool {
  double big_r, r, len;  // r = 0: flat
  V3 tip, axis;

  /// Convex outside distances (<= 0 inside) of the two pieces at world point x.
  double corner(V3 x) const {  // points within r of the disk radius R-r at height r
    const V3 q = sub(x, tip);
    const double s = dotd(q, axis) - r;  // axial offset from the disk plane
    const V3 radial = sub(q, {axis[0] * (s + r), axis[1] * (s + r), axis[2] * (s + r)});
    const double rr = std::max(0.0, norm(radial) - (big_r - r));
    return std::sqrt(rr * rr + s * s) - r;
  }
  double shank(V3 x) const {  // cylinder radius R, axial coordinate in [r, L]
    const V3 q = sub(x, tip);
    const double s = dotd(q, axis);
    const V3 radial = sub(q, {axis[0] * s, axis[1] * s, axis[2] * s});
    return std::max({norm(radial) - big_r, r - s, s - len});
  }
};

/// Lowest z on the vertical line (x, y) where the convex function f(z) <= 0, if any.
inline std::optional<double> firstRoot(const std::function<double(double)>& f, double lo,
                                       double hi) {
  double a = lo, b = hi;
  for (int it = 0; it < 300; ++it) {
    const double m1 = a + (b - a) / 3, m2 = b - (b - a) / 3;
    if (f(m1) <= f(m2))
      b = m2;
    else
      a = m1;
  }
  const double tmin = 0.5 * (a + b);
  if (f(tmin) > 0) return std::nullopt;
  double l = lo, h = tmin;
  if (f(l) <= 0) return l;
  for (int it = 0; it < 200; ++it) {
    const double m = 0.5 * (l + h);
    (f(m) <= 0 ? h : l) = m;
  }
  return h;
}

/// Lowest z of the placed tool on the line (x, y), or nullopt.
inline std::optional<double> lowestZ(const PlacedTool& t, double x, double y) {
  const double span = 4 * (t.len + t.big_r) + 10;
  const double lo = t.tip[2] - span, hi = t.tip[2] + span;
  std::optional<double> best;
  const auto take = [&](std::optional<double> z) {
    if (z && (!best || *z < *best)) best = z;
  };
  take(firstRoot([&](double z) { return t.shank({x, y, z}); }, lo, hi));
  if (t.r > 0) take(firstRoot([&](double z) { return t.corner({x, y, z}); }, lo, hi));
  return best;
}

}  // namespace fieldpath::zbuffer::test
