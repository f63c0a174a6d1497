#include "fieldpath/zbuffer/tool_mesh.h"

#include <cmath>
#include <numbers>

#include "fieldpath/common/errors.h"

namespace fieldpath::zbuffer {

namespace {

/// Closes a ring of n vertices with n-2 triangles, cutting ears off every other vertex round after
/// round (no long fan from one vertex: well-shaped triangles except the last few).
void closePolygon(std::vector<std::array<std::uint32_t, 3>>& tris, std::uint32_t first, int n,
                  bool facing_down) {
  std::vector<std::uint32_t> poly(n);
  for (int j = 0; j < n; ++j) poly[j] = first + static_cast<std::uint32_t>(j);
  const auto add = [&](std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    if (facing_down)
      tris.push_back({a, c, b});
    else
      tris.push_back({a, b, c});
  };
  while (poly.size() > 3) {
    const std::size_t m = poly.size();
    std::vector<std::uint32_t> next;
    std::size_t k = 0;
    for (; k + 2 < m || (m % 2 == 0 && k + 1 < m); k += 2) {
      add(poly[k], poly[k + 1], poly[(k + 2) % m]);
      next.push_back(poly[k]);
    }
    for (; k < m; ++k) next.push_back(poly[k]);
    poly = std::move(next);
  }
  if (poly.size() == 3) add(poly[0], poly[1], poly[2]);
}

}  // namespace

ToolMesh revolveProfile(const std::vector<std::pair<double, double>>& profile,
                        int segments_around) {
  const int n = segments_around;
  if (n < 3 || profile.size() < 2)
    throw common::InputError("revolveProfile: need >= 3 segments around and >= 2 profile points");
  ToolMesh mesh;
  std::vector<std::uint32_t> ring_start;  // first vertex of each profile point (pole: one vertex)
  for (const auto& [rho, z] : profile) {
    ring_start.push_back(static_cast<std::uint32_t>(mesh.vertices.size()));
    if (rho == 0.0) {
      mesh.vertices.push_back({0.f, 0.f, static_cast<float>(z)});
      continue;
    }
    for (int j = 0; j < n; ++j) {
      const double th = 2.0 * std::numbers::pi * j / n;
      mesh.vertices.push_back({static_cast<float>(rho * std::cos(th)),
                               static_cast<float>(rho * std::sin(th)), static_cast<float>(z)});
    }
  }
  auto& tris = mesh.triangles;
  const auto ring = [&](std::size_t k, int j) {
    return ring_start[k] + static_cast<std::uint32_t>(j % n);
  };
  const std::size_t last = profile.size() - 1;
  const bool bottom_pole = profile.front().first == 0.0, top_pole = profile.back().first == 0.0;
  if (!bottom_pole) closePolygon(tris, ring_start[0], n, true);
  for (std::size_t k = 0; k < last; ++k) {
    const bool lo_pole = profile[k].first == 0.0, hi_pole = profile[k + 1].first == 0.0;
    for (int j = 0; j < n; ++j) {
      if (lo_pole) {
        tris.push_back({ring_start[k], ring(k + 1, j + 1), ring(k + 1, j)});
      } else if (hi_pole) {
        tris.push_back({ring_start[k + 1], ring(k, j), ring(k, j + 1)});
      } else {
        tris.push_back({ring(k, j), ring(k, j + 1), ring(k + 1, j + 1)});
        tris.push_back({ring(k, j), ring(k + 1, j + 1), ring(k + 1, j)});
      }
    }
  }
  if (!top_pole)
    for (int j = 1; j + 1 < n; ++j)
      tris.push_back({ring(last, 0), ring(last, j), ring(last, j + 1)});
  return mesh;
}

ToolMesh analyticToolMesh(const Tool& tool, int segments_around, int segments_arc) {
  const double big_r = tool.radius_mm, r = tool.corner_radius_mm, len = tool.length_mm;
  std::vector<std::pair<double, double>> profile;
  if (tool.kind == ToolKind::Flat) {
    profile = {{big_r, 0.0}, {big_r, len}};
  } else if (tool.kind == ToolKind::Ball || tool.kind == ToolKind::Torus) {
    const double rho = big_r - r;
    profile.push_back({rho, 0.0});
    for (int k = 1; k <= segments_arc; ++k) {
      const double phi = -0.5 * std::numbers::pi + 0.5 * std::numbers::pi * k / segments_arc;
      profile.push_back({k == segments_arc ? big_r : rho + r * std::cos(phi),
                         k == segments_arc ? r : r + r * std::sin(phi)});
    }
    profile.push_back({big_r, len});
  } else {
    throw common::InputError("analyticToolMesh: the tool is already a mesh");
  }
  profile.push_back({0.0, len});
  if (tool.kind != ToolKind::Ball) profile.pop_back();  // flat polygon on top: 2n·rings - 4
  return revolveProfile(profile, segments_around);
}

double analyticToolMeshError(const Tool& tool, int segments_around, int segments_arc) {
  const double d_theta = 2.0 * std::numbers::pi / segments_around;
  const double d_phi = 0.5 * std::numbers::pi / std::max(1, segments_arc);
  const double r = tool.kind == ToolKind::Flat ? 0.0 : tool.corner_radius_mm;
  // Sagitta around the axis plus sagitta along the corner arc, each over a full step (generous).
  return tool.radius_mm * (1.0 - std::cos(d_theta)) + r * (1.0 - std::cos(d_phi));
}

}  // namespace fieldpath::zbuffer
