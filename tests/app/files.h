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

}  // namespace fieldpath::app::test
