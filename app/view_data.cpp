#include "view_data.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <unordered_map>

#include <nlohmann/json.hpp>

#include "errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/geometry/tool_model.h"
#include "fieldpath/geometry/units.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "job.h"
#include "scene.h"
#include "surface_check.h"
#include "to_zbuffer.h"

namespace fieldpath::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string readBytes(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

json readJson(const fs::path& file) {
  try {
    return json::parse(readBytes(file));
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": not valid JSON (" + e.what() + ")");
  }
}

// ------------------------------------------------------------------------------ meshes, tool

Eigen::AlignedBox3d boxOf(const std::vector<ViewMesh>& meshes) {
  Eigen::AlignedBox3d box;
  for (const ViewMesh& m : meshes)
    for (const auto& v : m.mesh.vertices) box.extend(v);
  return box;
}

/// Chordal tolerance of the page's tool mesh: fine enough to look round, small enough to ship.
double displayChordMm(const geometry::ToolSpec& tool) {
  return std::max(0.002, tool.radius_mm / 250.0);
}

// ------------------------------------------------------------------------------ check folder

/// The counts of check.json (the page must agree with them) and the path it checked.
struct CheckJson {
  std::size_t postures = 0, colliding_postures = 0, colliding_motions = 0;
  std::string path;
};

std::size_t count(const json& node, const fs::path& file, const char* key) {
  if (!node.is_number_unsigned())
    throw InputError(file.string() + ": " + key + ": missing or not a count (not check.json?)");
  return node.get<std::size_t>();
}

CheckJson readCheckJson(const fs::path& dir) {
  if (!fs::is_directory(dir)) throw InputError("--check " + dir.string() + ": no such folder");
  const fs::path file = dir / "check.json";
  if (!fs::exists(file))
    throw InputError("--check " + dir.string() +
                     ": no check.json in it (the folder of `fieldpath check --out`)");
  const json j = readJson(file);
  CheckJson c;
  if (!j.is_object()) throw InputError(file.string() + ": not check.json (no object)");
  c.postures = count(j.value("postures", json()), file, "postures");
  const json clearance = j.value("clearance", json::object());
  const json motions = j.value("motions", json::object());
  c.colliding_postures =
      count(clearance.value("colliding_postures", json()), file, "clearance.colliding_postures");
  c.colliding_motions =
      count(motions.value("colliding_motions", json()), file, "motions.colliding_motions");
  if (j.contains("path") && j["path"].is_string()) c.path = j["path"].get<std::string>();
  return c;
}

double parseCell(std::string_view cell, const fs::path& file, std::size_t line, bool empty_ok) {
  if (cell.empty()) {
    if (empty_ok) return kNaN;
    throw InputError(file.string() + ":" + std::to_string(line) + ": an empty number");
  }
  double value = 0;
  const auto [end, ec] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (ec != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value))
    throw InputError(file.string() + ":" + std::to_string(line) + ": '" + std::string(cell) +
                     "' is not a finite number");
  return value;
}

// ------------------------------------------------------------------------------ angles

/// The stations of the scene's passes in a hash grid of cells `cell_mm` wide: the nearest one to
/// a ball centre.
class Stations {
 public:
  Stations(const std::vector<pathgen::Pass>& passes) {
    std::vector<double> steps;
    for (const pathgen::Pass& p : passes)
      for (std::size_t i = 0; i < p.samples.size(); ++i) {
        samples_.push_back(&p.samples[i]);
        if (i > 0) steps.push_back((p.samples[i].centre_mm - p.samples[i - 1].centre_mm).norm());
      }
    double step = 1.0;
    if (!steps.empty()) {
      std::nth_element(steps.begin(), steps.begin() + steps.size() / 2, steps.end());
      step = steps[steps.size() / 2];
    }
    cell_mm_ = std::max(2.0 * step, 0.05);
    for (std::size_t i = 0; i < samples_.size(); ++i)
      cells_[key(cellOf(samples_[i]->centre_mm))].push_back(i);
  }

  /// The nearest station within `max_mm`, or null.
  const pathgen::PassSample* nearest(const geometry::Vec3& c, double max_mm,
                                     double* distance) const {
    const Eigen::Vector3i home = cellOf(c);
    const int rings = static_cast<int>(std::ceil(max_mm / cell_mm_)) + 1;
    const pathgen::PassSample* best = nullptr;
    double best_d = max_mm;
    for (int r = 0; r <= rings; ++r) {
      if (best && (r - 1) * cell_mm_ > best_d) break;
      for (int dx = -r; dx <= r; ++dx)
        for (int dy = -r; dy <= r; ++dy)
          for (int dz = -r; dz <= r; ++dz) {
            if (std::max({std::abs(dx), std::abs(dy), std::abs(dz)}) != r) continue;
            const auto it = cells_.find(key(home + Eigen::Vector3i(dx, dy, dz)));
            if (it == cells_.end()) continue;
            for (std::size_t i : it->second) {
              const double d = (samples_[i]->centre_mm - c).norm();
              if (d <= best_d) best_d = d, best = samples_[i];
            }
          }
    }
    if (distance) *distance = best_d;
    return best;
  }

 private:
  Eigen::Vector3i cellOf(const geometry::Vec3& p) const {
    const auto f = [this](double x) {
      return static_cast<int>(std::clamp(std::floor(x / cell_mm_), -1e6, 1e6));
    };
    return {f(p.x()), f(p.y()), f(p.z())};
  }
  static std::uint64_t key(const Eigen::Vector3i& c) {
    const auto u = [](int v) { return static_cast<std::uint64_t>(v + (1 << 20)) & 0x1fffff; };
    return u(c.x()) | (u(c.y()) << 21) | (u(c.z()) << 42);
  }
  std::vector<const pathgen::PassSample*> samples_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
  double cell_mm_ = 1.0;
};

/// Pass numbers and arc length from the file's blocks; tilt and lead in the frame (f, n, b) of
/// the nearest station of the scene's passes (DESIGN.md "The dynamics": a = sin L f + cos L
/// (cos T n − sin T b)), the frames `generate` steers in.
void computeAngles(const Scene& scene, ViewPath& p) {
  const auto& postures = p.file.postures;
  const std::size_t n = postures.size();
  const double offset = geometry::cornerRadius(scene.tool);
  p.pass.assign(n, 0);
  p.s_mm.assign(n, kNaN);
  p.tilt_deg.assign(n, kNaN);
  p.lead_deg.assign(n, kNaN);
  int pass = 0;
  for (const geometry::PathBlock& block : p.file.blocks) {
    if (block.kind != geometry::PathBlock::Kind::Pass) continue;
    ++pass;
    double s = 0;
    for (std::size_t i = block.begin; i < block.end; ++i) {
      if (i > block.begin)
        s += (geometry::ballCentre(postures[i], offset) -
              geometry::ballCentre(postures[i - 1], offset))
                 .norm();
      p.pass[i] = pass;
      p.s_mm[i] = s;
    }
  }
  std::vector<pathgen::Pass> passes;
  try {
    passes = sceneJob(scene).passes;
  } catch (const InputError& e) {
    p.angles_source = std::string("not known: the scene has no passes (") + e.what() + ")";
    return;
  }
  const Stations stations(passes);
  const double max_mm = std::max(2.0, scene.tool.radius_mm);
  double worst = 0;
  std::size_t found = 0, wanted = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.pass[i] == 0) continue;
    ++wanted;
    const geometry::Vec3 c = geometry::ballCentre(postures[i], offset);
    double d = 0;
    const pathgen::PassSample* at = stations.nearest(c, max_mm, &d);
    if (!at) continue;
    ++found;
    worst = std::max(worst, d);
    const geometry::Vec3& a = postures[i].axis;
    p.lead_deg[i] = std::asin(std::clamp(a.dot(at->feed), -1.0, 1.0)) * geometry::kRadToDeg;
    p.tilt_deg[i] = std::atan2(-a.dot(at->binormal), a.dot(at->normal)) * geometry::kRadToDeg;
  }
  std::ostringstream s;
  s.precision(3);
  s << "in the frames of the scene's passes";
  if (worst < 1e-6)
    s << " (at their stations)";
  else
    s << " (nearest station, up to " << worst << " mm away)";
  if (found < wanted)
    s << "; " << wanted - found << " pass postures have no station within " << max_mm << " mm";
  p.angles_source = s.str();
}

// ------------------------------------------------------------------------------ surface

zbuffer::Grid readGridJson(const fs::path& file) {
  const json j = readJson(file);
  auto pairOf = [&](const char* key) {
    const json v = j.is_object() ? j.value(key, json()) : json();
    if (!v.is_array() || v.size() != 2 || !v[0].is_number() || !v[1].is_number())
      throw InputError(file.string() + ": " + key + ": expected two numbers");
    const double a = v[0].get<double>(), b = v[1].get<double>();
    if (!std::isfinite(a) || !std::isfinite(b))
      throw InputError(file.string() + ": " + key + ": expected two finite numbers");
    return std::array<double, 2>{a, b};
  };
  const auto origin = pairOf("origin"), spacing = pairOf("spacing"), shape = pairOf("shape");
  if (spacing[0] <= 0 || spacing[1] <= 0)
    throw InputError(file.string() + ": spacing: must be > 0");
  if (shape[0] < 1 || shape[1] < 1 || shape[0] > 1e6 || shape[1] > 1e6 ||
      shape[0] != std::floor(shape[0]) || shape[1] != std::floor(shape[1]))
    throw InputError(file.string() + ": shape: expected [ny, nx], whole numbers from 1 to 1e6");
  // A grid beyond any machine (an edited or corrupt .json) is refused like such a path tip.
  const double far = common::kMaxCoordinateMm;
  if (std::abs(origin[0]) > far || std::abs(origin[1]) > far ||
      std::abs(origin[0] + spacing[0] * shape[1]) > far ||
      std::abs(origin[1] + spacing[1] * shape[0]) > far)
    throw InputError(file.string() +
                     ": origin, spacing: the grid reaches beyond 1e6 mm (outside any machine)");
  zbuffer::Grid g;
  g.x0_mm = origin[0];
  g.y0_mm = origin[1];
  g.dx_mm = spacing[0];
  g.dy_mm = spacing[1];
  g.ny = static_cast<int>(shape[0]);
  g.nx = static_cast<int>(shape[1]);
  return g;
}

/// What check.json says of the surface (the colour scale agrees with it), where it is known.
struct SurfaceFigures {
  double gouge_tolerance_um = kGougeToleranceUm;
  double max_scallop_um = NAN, max_gouge_um = NAN;
};

ViewSurface readSurface(const fs::path& dir, const Scene& scene, std::size_t max_lines,
                        const SurfaceFigures& figures, std::vector<std::string>& warnings) {
  const double gouge_tolerance_um = figures.gouge_tolerance_um;
  const std::string where = "--surface " + dir.string();
  if (!fs::is_directory(dir)) throw InputError(where + ": no such folder");
  bool deviation = fs::exists(dir / "deviation.npy");
  const std::string stem = deviation ? "deviation" : "heights";
  if (!fs::exists(dir / (stem + ".npy")))
    throw InputError(where +
                     ": neither deviation.npy (`fieldpath check --out`) nor heights.npy "
                     "(`fieldpath simulate --out`) in it");
  if (!fs::exists(dir / (stem + ".json")))
    throw InputError(where + ": " + stem + ".npy without its grid, " + stem + ".json");
  const zbuffer::Grid source = readGridJson(dir / (stem + ".json"));
  const std::vector<float> values = readGridNpy(dir / (stem + ".npy"), source.ny, source.nx);
  if (deviation && !scene.part)
    throw InputError(where + ": deviation.npy is measured from the part, and the scene " +
                     scene.file.string() + " has no `part`");

  ViewSurface s;
  s.source_lines = source.lineCount();
  s.stride = std::max(
      1, static_cast<int>(std::ceil(
             std::sqrt(double(s.source_lines) / double(std::max<std::size_t>(1, max_lines))))));
  const int k = s.stride;
  s.grid = source;
  s.grid.nx = (source.nx + k - 1) / k;
  s.grid.ny = (source.ny + k - 1) / k;
  s.grid.dx_mm = source.dx_mm * k;
  s.grid.dy_mm = source.dy_mm * k;
  const std::size_t lines = s.grid.lineCount();
  s.height_mm.assign(lines, NAN);
  s.value.assign(lines, NAN);
  std::vector<float> top;
  if (scene.part) {
    const zbuffer::ToolMesh part = toZbuffer(*scene.part);
    top = zbuffer::partTop(s.grid, part.vertices, part.triangles);
  }
  // simulate's stock is a plane (or the part's top): lines still at its highest were never cut.
  float stock = -INFINITY;
  if (!deviation)
    for (float v : values)
      if (std::isfinite(v)) stock = std::max(stock, v);
  constexpr float kUncut = 1e30f;  // value of a block never cut (grey on the page)
  // Block representative: deviation: its deepest gouge if it has one, else its largest scallop
  // (a gouge is never averaged away); heights: the lowest (deepest cut).
  for (int by = 0; by < s.grid.ny; ++by)
    for (int bx = 0; bx < s.grid.nx; ++bx) {
      float lo = INFINITY, hi = -INFINITY;
      for (int iy = by * k; iy < std::min(source.ny, (by + 1) * k); ++iy)
        for (int ix = bx * k; ix < std::min(source.nx, (bx + 1) * k); ++ix) {
          const float v = values[std::size_t(iy) * source.nx + ix];
          if (std::isnan(v)) continue;
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      if (lo > hi) continue;  // every line of the block off the part
      const std::size_t b = std::size_t(by) * s.grid.nx + bx;
      if (deviation) {
        const float dev = lo < -gouge_tolerance_um ? lo : hi;
        s.value[b] = dev;
        s.height_mm[b] = top[b] + dev * 1e-3f;  // NaN where the block centre misses the part
      } else {
        s.height_mm[b] = lo;
        s.value[b] = lo >= stock - 1e-4f ? kUncut : scene.part ? (lo - top[b]) * 1e3f : lo;
      }
    }
  s.deviation = deviation || scene.part.has_value();
  s.uncut_um = deviation ? kStockAllowanceMm * 1e3 - 1.0 : kUncut;
  std::vector<float> finite;
  for (float v : s.value)
    if (std::isfinite(v) && !(s.uncut_um > 0 && v >= s.uncut_um)) finite.push_back(v);
  if (s.deviation) {
    std::vector<float> scallop;
    float lo = 0;
    for (float v : finite) {
      lo = std::min(lo, v);
      if (v > 0) scallop.push_back(v);
    }
    float hi = 10;
    if (!scallop.empty()) {
      const std::size_t at = std::min(scallop.size() - 1, scallop.size() * 99 / 100);
      std::nth_element(scallop.begin(), scallop.begin() + at, scallop.end());
      hi = std::max(hi, scallop[at]);
    }
    s.range[0] = std::min<double>(lo, -gouge_tolerance_um);
    s.range[1] = hi;
    // check's own figures (over the machined band) where it wrote them: the legend agrees.
    if (std::isfinite(figures.max_scallop_um) && figures.max_scallop_um > 0)
      s.range[1] = figures.max_scallop_um;
    if (std::isfinite(figures.max_gouge_um))
      s.range[0] = std::min(-gouge_tolerance_um, -std::abs(figures.max_gouge_um));
  } else if (!finite.empty()) {
    const auto [lo, hi] = std::minmax_element(finite.begin(), finite.end());
    s.range[0] = *lo;
    s.range[1] = *hi > *lo ? *hi : *lo + 1;
  }
  std::ostringstream text;
  text << (deviation    ? "deviation from the part (check)"
           : scene.part ? "simulated heights against the part (simulate)"
                        : "simulated heights (simulate)")
       << ", " << dir.string() << "/" << stem << ".npy: " << source.nx << " x " << source.ny
       << " lines";
  if (k > 1) text << ", shown in blocks of " << k << " x " << k;
  s.source = text.str();
  const bool any =
      std::any_of(s.height_mm.begin(), s.height_mm.end(), [](float h) { return std::isfinite(h); });
  if (!any) warnings.push_back(where + ": no line of the surface lies on the scene's part");
  return s;
}

}  // namespace

// ------------------------------------------------------------------------------ readers

void readClearanceCsv(const fs::path& file, std::size_t postures, std::vector<double>& clearance_mm,
                      std::vector<double>& motion_mm) {
  if (!fs::exists(file))
    throw InputError(file.string() + ": missing (the check folder has check.json without it)");
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::string line;
  const std::string header = "posture,block,pass,clearance_mm,motion_to_next_mm,limited";
  if (!std::getline(in, line) || line != header)
    throw InputError(file.string() + ":1: expected the header '" + header + "'");
  clearance_mm.assign(postures, kNaN);
  motion_mm.assign(postures, kNaN);
  std::size_t row = 0, number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::vector<std::string_view> cells;
    std::string_view rest = line;
    for (std::size_t comma; (comma = rest.find(',')) != std::string_view::npos;) {
      cells.push_back(rest.substr(0, comma));
      rest.remove_prefix(comma + 1);
    }
    cells.push_back(rest);
    if (cells.size() != 6)
      throw InputError(file.string() + ":" + std::to_string(number) + ": expected 6 cells");
    if (row >= postures)
      throw InputError(file.string() + ":" + std::to_string(number) + ": more rows than the " +
                       std::to_string(postures) + " postures of the path");
    if (parseCell(cells[0], file, number, false) != double(row))
      throw InputError(file.string() + ":" + std::to_string(number) + ": posture " +
                       std::string(cells[0]) + " where " + std::to_string(row) + " was expected");
    clearance_mm[row] = parseCell(cells[3], file, number, false);
    motion_mm[row] = parseCell(cells[4], file, number, true);
    ++row;
  }
  if (row != postures)
    throw InputError(file.string() + ": " + std::to_string(row) + " rows for a path of " +
                     std::to_string(postures) + " postures");
}

std::vector<float> readGridNpy(const fs::path& file, int ny, int nx) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be read");
  const auto bad = [&](const std::string& why) { return InputError(file.string() + ": " + why); };
  char magic[10];
  if (!in.read(magic, 10) || std::memcmp(magic, "\x93NUMPY", 6) != 0)
    throw bad("not a NumPy .npy file");
  std::size_t header_len = 0, offset = 10;
  if (magic[6] == 1) {
    header_len = std::uint8_t(magic[8]) | (std::size_t(std::uint8_t(magic[9])) << 8);
  } else if (magic[6] == 2 || magic[6] == 3) {
    char more[2];
    if (!in.read(more, 2)) throw bad("truncated header");
    header_len = std::uint8_t(magic[8]) | (std::size_t(std::uint8_t(magic[9])) << 8) |
                 (std::size_t(std::uint8_t(more[0])) << 16) |
                 (std::size_t(std::uint8_t(more[1])) << 24);
    offset = 12;
  } else {
    throw bad("unknown .npy version " + std::to_string(int(magic[6])));
  }
  if (header_len > 65536) throw bad("header of " + std::to_string(header_len) + " bytes");
  std::string header(header_len, '\0');
  if (!in.read(header.data(), header_len)) throw bad("truncated header");
  if (header.find("'descr': '<f4'") == std::string::npos)
    throw bad("expected float32 ('<f4') values");
  if (header.find("'fortran_order': False") == std::string::npos)
    throw bad("expected C order (fortran_order False)");
  const std::string shape = "'shape': (" + std::to_string(ny) + ", " + std::to_string(nx) + ")";
  if (header.find(shape) == std::string::npos)
    throw bad("expected " + shape + " as its .json says");
  const std::uintmax_t size = fs::file_size(file);
  const std::uintmax_t data = std::uintmax_t(ny) * std::uintmax_t(nx) * 4;
  if (size != offset + header_len + data)
    throw bad(std::to_string(size) + " bytes where the shape needs " +
              std::to_string(offset + header_len + data) + " (truncated or padded)");
  common::requireMemory(file.string(), double(data),
                        std::to_string(ny) + " x " + std::to_string(nx) + " float32");
  std::vector<float> values(std::size_t(ny) * std::size_t(nx));
  if (!in.read(reinterpret_cast<char*>(values.data()), std::streamsize(data)))
    throw bad("truncated data");
  return values;
}

geometry::TriangleMesh decimateMesh(const geometry::TriangleMesh& mesh, std::size_t max_triangles) {
  if (mesh.triangles.size() <= max_triangles || mesh.vertices.empty()) return mesh;
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  const double diag = std::max(box.diagonal().norm(), 1e-9);
  double cell = std::max(
      std::sqrt(2.0 * geometry::meshArea(mesh) / double(std::max<std::size_t>(1, max_triangles))),
      diag * 1e-6);
  geometry::TriangleMesh out;
  for (int attempt = 0; attempt < 60; ++attempt, cell *= 1.15) {
    out = {};
    std::unordered_map<std::uint64_t, int> index;
    std::vector<Eigen::Vector3d> sum;
    std::vector<int> weight, map(mesh.vertices.size());
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
      const Eigen::Vector3d q = ((mesh.vertices[i] - box.min()) / cell).array().floor();
      const std::uint64_t key =
          std::uint64_t(q.x()) | (std::uint64_t(q.y()) << 21) | (std::uint64_t(q.z()) << 42);
      const auto [it, added] = index.emplace(key, int(sum.size()));
      if (added) sum.emplace_back(Eigen::Vector3d::Zero()), weight.push_back(0);
      sum[it->second] += mesh.vertices[i];
      ++weight[it->second];
      map[i] = it->second;
    }
    std::set<std::array<int, 3>> seen;
    for (const auto& t : mesh.triangles) {
      const Eigen::Vector3i m(map[t.x()], map[t.y()], map[t.z()]);
      if (m.x() == m.y() || m.y() == m.z() || m.x() == m.z()) continue;
      std::array<int, 3> sorted{m.x(), m.y(), m.z()};
      std::sort(sorted.begin(), sorted.end());
      if (seen.insert(sorted).second) out.triangles.push_back(m);
    }
    if (out.triangles.size() > max_triangles) continue;
    // Keep the used vertices only, at the mean of their cell.
    std::vector<int> used(sum.size(), -1);
    for (auto& t : out.triangles)
      for (int c = 0; c < 3; ++c) {
        int& u = used[t[c]];
        if (u < 0) {
          u = int(out.vertices.size());
          out.vertices.push_back(sum[t[c]] / weight[t[c]]);
        }
        t[c] = u;
      }
    return out;
  }
  throw std::runtime_error("decimateMesh: no cell size fits " + std::to_string(max_triangles) +
                           " triangles");
}

// ------------------------------------------------------------------------------ gatherView

ViewData gatherView(const ViewRequest& request) {
  ViewData d;
  const Scene scene = loadScene(request.scene);
  d.scene_file = scene.file;
  for (std::size_t i = 0; i < scene.obstacles.size(); ++i) {
    ViewMesh m;
    m.name = i < scene.obstacle_files.size()
                 ? scene.obstacle_files[i].filename().string()
                 : "impeller blade " + std::to_string(i - scene.obstacle_files.size() + 1);
    m.mesh = scene.obstacles[i];
    d.meshes.push_back(std::move(m));
  }
  if (scene.part) {
    ViewMesh m;
    m.name = scene.part_file ? scene.part_file->filename().string() : "impeller hub";
    m.role = ViewMesh::Role::Part;
    m.mesh = *scene.part;
    d.meshes.push_back(std::move(m));
  } else {
    d.notes.push_back("the scene has no `part`");
  }
  d.box = boxOf(d.meshes);
  if (d.box.isEmpty()) throw InputError(scene.file.string() + ": no mesh to show");
  d.tool_spec = scene.tool;
  d.tool = geometry::toolMesh(scene.tool, scene.holder, displayChordMm(scene.tool));
  d.required_mm = scene.clearance_mm;

  // The check folder first: it names the path it checked.
  std::optional<CheckJson> check;
  if (!request.check_dir.empty()) check = readCheckJson(request.check_dir);

  fs::path path_file = request.path;
  if (path_file.empty() && check && !check->path.empty()) {
    if (!fs::exists(check->path))
      throw InputError("--check " + request.check_dir.string() + ": check.json names the path " +
                       check->path + ", which is not there: give --path FILE");
    path_file = check->path;
  }
  if (!path_file.empty()) {
    ViewPath p;
    p.file = geometry::readPathFile(path_file);
    p.what = path_file.string();
    d.path = std::move(p);
  } else if (scene.nominal) {
    ViewPath p;
    p.file = *scene.nominal;
    p.what = scene.nominal->file.string() + " (the scene's path.nominal)";
    d.path = std::move(p);
  } else {
    if (check)
      throw InputError("--check " + request.check_dir.string() +
                       ": check.json names no path: give --path FILE");
    d.missing.push_back(
        "No path: give --path FILE (path.cl of `fieldpath generate`); the scene names no "
        "path.nominal either");
  }

  fs::path surface_dir = request.surface_dir;
  if (surface_dir.empty() && check && fs::exists(request.check_dir / "deviation.npy"))
    surface_dir = request.check_dir;

  if (d.path) {
    ViewPath& p = *d.path;
    const auto& postures = p.file.postures;
    const std::size_t n = postures.size();
    // Per posture here: clearance, motion, s, tilt, lead (double), pass (int), the page's arrays.
    common::requireMemory("view " + p.what, double(n) * 96.0, std::to_string(n) + " postures");

    // Postures far outside the scene: a path for another scene (or another unit).
    const double reach =
        std::max(scene.tool.length_mm, scene.holder.empty() ? 0.0 : scene.holder.back().z_mm);
    const double margin = std::max(reach, 0.25 * d.box.diagonal().norm());
    Eigen::AlignedBox3d near = d.box;
    near.min().array() -= margin;
    near.max().array() += margin;
    for (std::size_t i = 0; i < n; ++i)
      if (!near.contains(postures[i].tip_mm)) {
        if (p.outside++ == 0) p.first_outside = i;
      }
    auto boxText = [&] {
      std::ostringstream s;
      s.precision(4);
      s << "x " << d.box.min().x() << ".." << d.box.max().x() << ", y " << d.box.min().y() << ".."
        << d.box.max().y() << ", z " << d.box.min().z() << ".." << d.box.max().z() << " mm";
      return s.str();
    };
    if (p.outside > 0) {
      std::ostringstream s;
      s.precision(4);
      s << p.outside << " of " << n << " postures lie more than " << margin
        << " mm outside the scene's meshes (" << boxText() << "), the first at posture "
        << p.first_outside << " (" << p.file.where(p.first_outside) << ")";
      if (2 * p.outside > n)
        throw InputError(p.file.file.string() + ": " + s.str() + ": a path for another scene?");
      d.warnings.push_back(s.str());
    }

    if (check) {
      if (check->postures != n)
        throw InputError("--check " + request.check_dir.string() + ": a check of " +
                         std::to_string(check->postures) + " postures (" + check->path + "), but " +
                         p.what + " has " + std::to_string(n) +
                         ": give the folder that `check --path " + p.what + " --out` wrote");
      std::error_code ec;
      if (!check->path.empty() && fs::exists(check->path) && fs::exists(p.file.file) &&
          !fs::equivalent(check->path, p.file.file, ec))
        throw InputError("--check " + request.check_dir.string() + ": the check of " + check->path +
                         ", not of " + p.what);
      readClearanceCsv(request.check_dir / "clearance.csv", n, p.clearance_mm, p.motion_mm);
      p.clearance_source = "check.json of " + request.check_dir.string();
      p.clearance_known = true;
    } else if (scene.obstacles.empty()) {
      p.clearance_mm.assign(n, kNaN);
      p.motion_mm.assign(n, kNaN);
      p.clearance_source = "not known: the scene has no obstacles";
    } else if (n > request.max_clearance_postures) {
      p.clearance_mm.assign(n, kNaN);
      p.motion_mm.assign(n, kNaN);
      p.clearance_source = "not computed for " + std::to_string(n) +
                           " postures: run `fieldpath check` and give --check DIR";
      d.missing.push_back("Clearance not shown: " + p.clearance_source);
    } else {
      // As `check` computes it (cmd_check.cpp): the same mesh, tolerance and motion request.
      const pathgen::ClearanceChecker checker(
          geometry::toolMesh(scene.tool, scene.holder, pathgen::kClearanceMeshTolMm),
          scene.obstacles, pathgen::kClearanceMeshTolMm);
      const pathgen::ClearanceResult c = checker.check(postures, {}, request.progress);
      pathgen::MotionRequest motion_request;
      motion_request.required_mm = scene.clearance_mm;
      motion_request.posture_clearance_mm = c.clearance_mm;
      const pathgen::MotionResult m =
          checker.checkMotions(postures, motion_request, request.progress);
      p.clearance_mm = c.clearance_mm;
      p.motion_mm = m.clearance_mm;
      p.motion_mm.resize(n, kNaN);
      p.clearance_source =
          "computed here, as `fieldpath check` computes it (FCL, postures and motions)";
      check = CheckJson{n, c.colliding, m.colliding, p.what};
      p.clearance_known = true;
    }
    for (std::size_t i = 0; i < n; ++i) {
      p.colliding_postures += p.clearance_mm[i] <= 0.0;
      p.colliding_motions += p.motion_mm[i] <= 0.0;
      p.motions_under_required += p.motion_mm[i] < scene.clearance_mm;
    }
    for (std::size_t i : p.file.limited) p.limited_colliding += p.clearance_mm[i] <= 0.0;
    if (check && (check->colliding_postures != p.colliding_postures ||
                  check->colliding_motions != p.colliding_motions))
      d.warnings.push_back("check.json counts " + std::to_string(check->colliding_postures) +
                           " colliding postures and " + std::to_string(check->colliding_motions) +
                           " colliding motions, clearance.csv " +
                           std::to_string(p.colliding_postures) + " and " +
                           std::to_string(p.colliding_motions));
    computeAngles(scene, p);
  }

  if (!surface_dir.empty()) {
    SurfaceFigures figures;
    if (fs::exists(surface_dir / "check.json") && fs::exists(surface_dir / "deviation.npy")) {
      const json j = readJson(surface_dir / "check.json");
      const json surface = j.is_object() ? j.value("surface", json()) : json();
      auto number = [&](const char* key, double& out) {
        if (surface.is_object() && surface.value(key, json()).is_number())
          out = surface[key].get<double>();
      };
      number("gouge_tolerance_um", figures.gouge_tolerance_um);
      number("max_scallop_um", figures.max_scallop_um);
      number("max_gouge_um", figures.max_gouge_um);
    }
    d.surface = readSurface(surface_dir, scene, request.max_surface_lines, figures, d.warnings);
  }
  return d;
}

}  // namespace fieldpath::app
