#include "fieldpath/pathgen/impeller.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <sstream>
#include <tuple>

#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/units.h"

namespace fieldpath::pathgen {
namespace {

using common::InputError;

using geometry::kDegToRad;
/// Longest mesh cell side, mm: right triangles of 1 mm legs are sampled once each by the field at
/// a 1 mm step (sampling.h), and FCL's hierarchies stay tight.
constexpr double kMaxEdgeMm = 1.0;

std::string fmt(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

void requireFinite(double value, const char* key) {
  if (!std::isfinite(value))
    throw InputError(std::string("impeller.") + key + ": must be a finite number");
  if (std::abs(value) > common::kMaxCoordinateMm)
    throw InputError(std::string("impeller.") + key + ": " + fmt(value) +
                     " is beyond +-1e6 (mm: outside any machine)");
}

void requirePositive(double value, const char* key) {
  requireFinite(value, key);
  if (value <= 0.0)
    throw InputError(std::string("impeller.") + key + ": must be > 0 (got " + fmt(value) + ")");
}

/// A grid mesh of P(a, b) over [0, 1]² whose linear triangles stay within `tol_mm` of P: the error
/// of linear interpolation on a cell is at most (ha² Maa + 2 ha hb Mab + hb² Mbb) / 8 with M the
/// largest second derivatives (estimated on a fine sample); each term gets a third of the budget.
/// Cells are also at most `max_edge_mm` long (by the chord) so that triangles stay well shaped
/// for the field's sampling. `flip` reverses the winding (the normal is P_a × P_b otherwise).
/// The cells (na, nb) of gridMesh's grid over [0, 1]², from a probe of P's second derivatives and
/// lengths alone (cheap: the size of a mesh is known before it is made).
std::array<int, 2> gridCells(const std::function<Vec3(double, double)>& p, double tol_mm,
                             double max_edge_mm) {
  constexpr int kProbe = 48;
  const double d = 1.0 / kProbe;
  double m_aa = 1e-12, m_bb = 1e-12, m_ab = 1e-12;
  for (int i = 1; i < kProbe; ++i) {
    for (int j = 1; j < kProbe; ++j) {
      const double a = i * d, b = j * d;
      m_aa = std::max(m_aa, ((p(a + d, b) - 2 * p(a, b) + p(a - d, b)) / (d * d)).norm());
      m_bb = std::max(m_bb, ((p(a, b + d) - 2 * p(a, b) + p(a, b - d)) / (d * d)).norm());
      m_ab = std::max(
          m_ab,
          ((p(a + d, b + d) - p(a + d, b - d) - p(a - d, b + d) + p(a - d, b - d)) / (4 * d * d))
              .norm());
    }
  }
  double length_a = 0, length_b = 0;  // longest iso-lines, mm
  for (int j = 0; j <= 4; ++j) {
    double la = 0, lb = 0;
    for (int i = 0; i < kProbe; ++i) {
      la += (p((i + 1) * d, j / 4.0) - p(i * d, j / 4.0)).norm();
      lb += (p(j / 4.0, (i + 1) * d) - p(j / 4.0, i * d)).norm();
    }
    length_a = std::max(length_a, la);
    length_b = std::max(length_b, lb);
  }
  const double budget = tol_mm / 3.0;
  double ha = std::min({1.0, std::sqrt(8.0 * budget / m_aa), max_edge_mm / length_a});
  double hb = std::min({1.0, std::sqrt(8.0 * budget / m_bb), max_edge_mm / length_b});
  const double cross = 2.0 * ha * hb * m_ab / 8.0;
  if (cross > budget) {
    const double shrink = std::sqrt(budget / cross);
    ha *= shrink;
    hb *= shrink;
  }
  constexpr int kMaxCells = 4000;
  const int na = std::clamp(static_cast<int>(std::ceil(1.0 / ha)), 1, kMaxCells);
  const int nb = std::clamp(static_cast<int>(std::ceil(1.0 / hb)), 1, kMaxCells);
  return {na, nb};
}

geometry::TriangleMesh gridMesh(const std::function<Vec3(double, double)>& p, double tol_mm,
                                double max_edge_mm, bool flip) {
  const std::array<int, 2> cells = gridCells(p, tol_mm, max_edge_mm);
  const int na = cells[0], nb = cells[1];  // not a structured binding: clang 14 cannot capture one
  geometry::TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<size_t>(na + 1) * (nb + 1));
  for (int i = 0; i <= na; ++i)
    for (int j = 0; j <= nb; ++j)
      mesh.vertices.push_back(p(static_cast<double>(i) / na, static_cast<double>(j) / nb));
  auto id = [nb](int i, int j) { return i * (nb + 1) + j; };
  mesh.triangles.reserve(2 * static_cast<size_t>(na) * nb);
  for (int i = 0; i < na; ++i) {
    for (int j = 0; j < nb; ++j) {
      int v00 = id(i, j), v10 = id(i + 1, j), v01 = id(i, j + 1), v11 = id(i + 1, j + 1);
      // Split along the shorter diagonal: skewed cells (twisted rulings) keep short edges.
      if ((mesh.vertices[v10] - mesh.vertices[v01]).squaredNorm() <
          (mesh.vertices[v00] - mesh.vertices[v11]).squaredNorm()) {
        // rotate the cell's corner labels so that the split runs v10–v01
        std::tie(v00, v10, v11, v01) = std::make_tuple(v10, v11, v01, v00);
      }
      if (!flip) {
        mesh.triangles.emplace_back(v00, v10, v11);
        mesh.triangles.emplace_back(v00, v11, v01);
      } else {
        mesh.triangles.emplace_back(v00, v11, v10);
        mesh.triangles.emplace_back(v00, v01, v11);
      }
    }
  }
  return mesh;
}

}  // namespace

Impeller::Impeller(const ImpellerParams& params) : params_(params) {
  const ImpellerParams& p = params_;
  requirePositive(p.length_mm, "length");
  requirePositive(p.width_in_mm, "width_in");
  requirePositive(p.width_out_mm, "width_out");
  requireFinite(p.bend_mm, "bend");
  requireFinite(p.hub_rise_mm, "hub_rise");
  requireFinite(p.hub_dish_mm, "hub_dish");
  requirePositive(p.blade_height_mm, "blade_height");
  requirePositive(p.chord_tol_mm, "chord_tol");
  // Far below any machine's accuracy: a smaller tolerance only makes meshes too large to keep.
  if (p.chord_tol_mm < 1e-4)
    throw InputError("impeller.chord_tol: must be >= 0.0001 mm (got " + fmt(p.chord_tol_mm) + ")");
  for (const auto& [key, pair] : {std::pair{"lean_left_deg", p.lean_left_deg},
                                  std::pair{"lean_right_deg", p.lean_right_deg}}) {
    for (double lean : pair) {
      requireFinite(lean, key);
      if (std::abs(lean) >= 75.0)
        throw InputError(std::string("impeller.") + key + ": |lean| must be < 75 deg (got " +
                         fmt(lean) + ")");
    }
  }
  for (double v : p.passes_v) {
    requireFinite(v, "passes_v");
    if (v <= 0.0 || v >= 1.0)
      throw InputError("impeller.passes_v: must lie in (0, 1), between the blade feet (got " +
                       fmt(v) + ")");
  }
  for (double u : p.u_range) {
    requireFinite(u, "u_range");
    if (u < 0.0 || u > 1.0)
      throw InputError("impeller.u_range: must lie in [0, 1] (got " + fmt(u) + ")");
  }
  if (p.u_range[1] < p.u_range[0]) throw InputError("impeller.u_range: end before start");
  if (std::abs(p.hub_dish_mm) > 0.25 * std::min(p.width_in_mm, p.width_out_mm))
    throw InputError("impeller.hub_dish: must stay below a quarter of the channel width");
  double at_u = 0.0;
  const double gap_mm = minGapMm(&at_u);
  if (gap_mm <= 0.0)
    throw InputError("impeller.lean_left_deg/lean_right_deg: the blades cross at u = " + fmt(at_u) +
                     " (gap across the channel " + fmt(gap_mm) + " mm)");
}

double Impeller::halfWidth(double u) const {
  return 0.5 * (params_.width_in_mm + (params_.width_out_mm - params_.width_in_mm) * u);
}

double Impeller::leanRad(int side, double u) const {
  const auto& lean = side == 0 ? params_.lean_left_deg : params_.lean_right_deg;
  return kDegToRad * (lean[0] + (lean[1] - lean[0]) * u);
}

Vec3 Impeller::hub(double u, double v) const {
  const ImpellerParams& p = params_;
  const double eta = 2.0 * v - 1.0;
  return {p.length_mm * u, p.bend_mm * u * u + eta * halfWidth(u),
          p.hub_rise_mm * u * u - p.hub_dish_mm * (1.0 - eta * eta)};
}

double Impeller::hubHeight(double x_mm, double y_mm) const {
  const ImpellerParams& p = params_;
  const double u = x_mm / p.length_mm;
  const double eta = (y_mm - p.bend_mm * u * u) / halfWidth(u);
  return p.hub_rise_mm * u * u - p.hub_dish_mm * (1.0 - eta * eta);
}

std::array<double, 2> Impeller::hubUV(double x_mm, double y_mm) const {
  const double u = x_mm / params_.length_mm;
  const double eta = (y_mm - params_.bend_mm * u * u) / halfWidth(u);
  return {u, 0.5 * (eta + 1.0)};
}

Vec3 Impeller::hubNormalAt(double x_mm, double y_mm) const {
  const ImpellerParams& p = params_;
  const double u = x_mm / p.length_mm;
  const double w = halfWidth(u);
  const double dw_du = 0.5 * (p.width_out_mm - p.width_in_mm);
  const double eta = (y_mm - p.bend_mm * u * u) / w;
  const double deta_dx = (-2.0 * p.bend_mm * u - eta * dw_du) / (w * p.length_mm);
  const double deta_dy = 1.0 / w;
  const double dh_deta = 2.0 * p.hub_dish_mm * eta;
  const double h_x = 2.0 * p.hub_rise_mm * u / p.length_mm + dh_deta * deta_dx;
  const double h_y = dh_deta * deta_dy;
  return Vec3(-h_x, -h_y, 1.0).normalized();
}

Vec3 Impeller::hubNormal(double u, double v) const {
  const Vec3 s = hub(u, v);
  return hubNormalAt(s.x(), s.y());
}

Vec3 Impeller::footInward(int side, double u) const {
  const ImpellerParams& p = params_;
  const double dw_du = 0.5 * (p.width_out_mm - p.width_in_mm);
  const double sign = side == 0 ? -1.0 : 1.0;  // η of the foot
  const Vec3 tangent(p.length_mm, 2.0 * p.bend_mm * u + sign * dw_du, 0.0);
  const Vec3 left_normal = Vec3(-tangent.y(), tangent.x(), 0.0).normalized();  // towards +y
  return side == 0 ? left_normal : Vec3(-left_normal);
}

Vec3 Impeller::blade(int side, double u, double t) const {
  const double lean = leanRad(side, u);
  const Vec3 dir = std::cos(lean) * Vec3::UnitZ() + std::sin(lean) * footInward(side, u);
  return hub(u, side == 0 ? 0.0 : 1.0) + t * params_.blade_height_mm * dir;
}

Vec3 Impeller::bladeNormal(int side, double u, double t) const {
  constexpr double e = 1e-6;
  const Vec3 du = blade(side, u + e, t) - blade(side, u - e, t);
  const Vec3 dt = blade(side, u, t + e) - blade(side, u, t - e);
  Vec3 n = du.cross(dt).normalized();
  if (n.dot(footInward(side, u)) < 0.0) n = -n;
  return n;
}

double Impeller::minGapMm(double* at_u) const {
  constexpr int kSamples = 400;
  double best = std::numeric_limits<double>::infinity();
  for (int i = 0; i <= kSamples; ++i) {
    const double u = static_cast<double>(i) / kSamples;
    const Vec3 across = footInward(0, u);  // left → right, horizontal
    for (double t : {0.0, 1.0}) {          // the gap is linear in t along the rulings
      const double gap = (blade(1, u, t) - blade(0, u, t)).dot(across);
      if (gap < best) {
        best = gap;
        if (at_u) *at_u = u;
      }
    }
  }
  return best;
}

std::size_t Impeller::meshTriangleCount() const {
  std::size_t count = 0;
  const auto add = [&count](const std::array<int, 2>& cells) {
    count += 2 * static_cast<std::size_t>(cells[0]) * static_cast<std::size_t>(cells[1]);
  };
  add(gridCells([this](double u, double v) { return hub(u, v); }, params_.chord_tol_mm,
                kMaxEdgeMm));
  for (int side = 0; side < 2; ++side)
    add(gridCells([this, side](double u, double t) { return blade(side, u, t); },
                  params_.chord_tol_mm, kMaxEdgeMm));
  return count;
}

geometry::TriangleMesh Impeller::hubMesh() const {
  return gridMesh([this](double u, double v) { return hub(u, v); }, params_.chord_tol_mm,
                  kMaxEdgeMm, false);
}

geometry::TriangleMesh Impeller::bladeMesh(int side) const {
  auto surface = [this, side](double u, double t) { return blade(side, u, t); };
  // B_u × B_t points into the channel for the left blade when the winding is kept.
  geometry::TriangleMesh mesh = gridMesh(surface, params_.chord_tol_mm, kMaxEdgeMm, false);
  const auto& tri = mesh.triangles.front();
  const Vec3 n = (mesh.vertices[tri[1]] - mesh.vertices[tri[0]])
                     .cross(mesh.vertices[tri[2]] - mesh.vertices[tri[0]]);
  if (n.dot(bladeNormal(side, 0.0, 0.0)) < 0.0)
    for (auto& t : mesh.triangles) std::swap(t[1], t[2]);
  return mesh;
}

}  // namespace fieldpath::pathgen
