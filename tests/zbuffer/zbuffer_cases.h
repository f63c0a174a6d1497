#pragma once
/// Postures and a tool shared by the Z-buffer CPU tests (test_zbuffer.cpp,
/// test_zbuffer_culling.cpp).
#include <cmath>
#include <cstdint>

#include "fieldpath/zbuffer/simulator.h"
#include "fieldpath/zbuffer/tool_mesh.h"

namespace fieldpath::zbuffer::cases {

/// A posture from a tip and an axis (normalised here), in float as the engine reads it.
inline Posture pose(double x, double y, double z, double i, double j, double k) {
  const double n = std::sqrt(i * i + j * j + k * k);
  return {{float(x), float(y), float(z)}, {float(i / n), float(j / n), float(k / n)}};
}

/// A tool whose bottom is a 4×4 grid of unit squares (two triangles each, diagonals alternating)
/// at z = 0 closed by a pyramid: every vertex and edge of the bottom lies on grid lines.
inline ToolMesh gridBottomTool() {
  ToolMesh m;
  for (int y = -2; y <= 2; ++y)
    for (int x = -2; x <= 2; ++x) m.vertices.push_back({float(x), float(y), 0.f});
  m.vertices.push_back({0.f, 0.f, 3.f});
  const auto v = [](int x, int y) { return std::uint32_t((y + 2) * 5 + (x + 2)); };
  for (int y = -2; y < 2; ++y)
    for (int x = -2; x < 2; ++x) {
      // bottom faces point down: clockwise seen from above
      if ((x + y) % 2 == 0) {
        m.triangles.push_back({v(x, y), v(x + 1, y + 1), v(x + 1, y)});
        m.triangles.push_back({v(x, y), v(x, y + 1), v(x + 1, y + 1)});
      } else {
        m.triangles.push_back({v(x, y), v(x, y + 1), v(x + 1, y)});
        m.triangles.push_back({v(x + 1, y), v(x, y + 1), v(x + 1, y + 1)});
      }
    }
  const std::uint32_t apex = 25;
  for (int k = -2; k < 2; ++k) {
    m.triangles.push_back({v(k, -2), v(k + 1, -2), apex});
    m.triangles.push_back({v(2, k), v(2, k + 1), apex});
    m.triangles.push_back({v(k + 1, 2), v(k, 2), apex});
    m.triangles.push_back({v(-2, k + 1), v(-2, k), apex});
  }
  return m;
}

}  // namespace fieldpath::zbuffer::cases
