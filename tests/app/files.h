#pragma once
/// Scratch folders, files and runs of `fieldpath` for the app tests.
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
