#pragma once
/// Scratch folders, files and runs of `fieldpath` for the app tests.
#include <array>
#include <sstream>
#include <string>

#include "run_fieldpath.h"

namespace fieldpath::app::test {

using fieldpath::test::Outcome;
using fieldpath::test::runFieldpath;
using fieldpath::test::slurp;
using fieldpath::test::TempDir;

/// ASCII STL of the square [-a, a]² at height z, normal +z.
inline std::string squareStl(double a, double z = 0.0) {
  auto v = [z](double x, double y) {
    return "   vertex " + std::to_string(x) + " " + std::to_string(y) + " " + std::to_string(z) +
           "\n";
  };
  auto facet = [](const std::string& a, const std::string& b, const std::string& c) {
    return " facet normal 0 0 1\n  outer loop\n" + a + b + c + "  endloop\n endfacet\n";
  };
  return "solid square\n" + facet(v(-a, -a), v(a, -a), v(a, a)) +
         facet(v(-a, -a), v(a, a), v(-a, a)) + "endsolid square\n";
}

/// ASCII STL of the closed box [x0, x1] × [y0, y1] × [z0, z1], outward normals.
inline std::string boxStl(double x0, double y0, double z0, double x1, double y1, double z1) {
  const double x[2] = {x0, x1}, y[2] = {y0, y1}, z[2] = {z0, z1};
  auto v = [&](int i, int j, int k) {
    std::ostringstream s;
    s << "   vertex " << x[i] << ' ' << y[j] << ' ' << z[k] << '\n';
    return s.str();
  };
  // Each face as four corners, counter-clockwise seen from outside.
  const int faces[6][4][3] = {{{0, 0, 0}, {0, 1, 0}, {1, 1, 0}, {1, 0, 0}},   // z0
                              {{0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}},   // z1
                              {{0, 0, 0}, {1, 0, 0}, {1, 0, 1}, {0, 0, 1}},   // y0
                              {{0, 1, 0}, {0, 1, 1}, {1, 1, 1}, {1, 1, 0}},   // y1
                              {{0, 0, 0}, {0, 0, 1}, {0, 1, 1}, {0, 1, 0}},   // x0
                              {{1, 0, 0}, {1, 1, 0}, {1, 1, 1}, {1, 0, 1}}};  // x1
  std::string text = "solid box\n";
  for (const auto& f : faces)
    for (const auto& t : {std::array<int, 3>{0, 1, 2}, std::array<int, 3>{0, 2, 3}}) {
      text += " facet normal 0 0 0\n  outer loop\n";
      for (int c : t) text += v(f[c][0], f[c][1], f[c][2]);
      text += "  endloop\n endfacet\n";
    }
  return text + "endsolid box\n";
}

/// A small impeller job (part of one channel, three passes, a coarse solver): generate, study
/// and view in seconds.
inline constexpr const char* kSmallImpellerScene = R"(obstacles:
  - impeller: { u_range: [0.55, 0.8], passes_v: [0.3, 0.7], chord_tol: 0.5 }
guide: { impeller: hub }
tool: { shape: ball, radius: 3, length: 40 }
holder: [[40, 6], [55, 6], [55, 12], [90, 12]]
clearance: 0.5
dynamics: { max_tilt_deg: 45, max_lead_deg: 45, rtol: 1.0e-4, atol: 1.0e-7 }
path: { passes: 3, step: 2.0 }
)";

}  // namespace fieldpath::app::test
