/// The files of a `check` or `simulate` folder that `fieldpath view` reads (view_files.h).
#include "view_files.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "errors.h"
#include "fieldpath/common/file_digest.h"
#include "fieldpath/common/limits.h"
#include "scene.h"
#include "surface_check.h"
#include "to_zbuffer.h"

namespace fieldpath::app {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// A sidecar JSON of check or simulate is a few kB: past this it is no such file (a helper's
/// check.json padded to 10 GB was read whole, 96 s, and parsed up to its first NUL).
constexpr std::uintmax_t kMaxJsonBytes = std::uintmax_t{64} << 20;

std::string readBytes(const fs::path& file) {
  std::error_code size_ec;
  const std::uintmax_t bytes = fs::file_size(file, size_ec);
  if (!size_ec && bytes > kMaxJsonBytes)
    throw InputError(file.string() + ": " + common::formatBytes(double(bytes)) +
                     ": not one of check's or simulate's JSON files (a few kB; at most 64 MiB)");
  std::ifstream in(file, std::ios::binary);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t count(const json& node, const fs::path& file, const char* key) {
  if (!node.is_number_unsigned())
    throw InputError(file.string() + ": " + key + ": missing or not a count (not check.json?)");
  return node.get<std::size_t>();
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

zbuffer::Grid readGridJson(const fs::path& file) {
  const json j = view_files::readJson(file);
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

}  // namespace

// ------------------------------------------------------------------------------ check folder

namespace view_files {

json readJson(const fs::path& file) {
  try {
    return json::parse(readBytes(file));
  } catch (const json::exception& e) {
    throw InputError(file.string() + ": not valid JSON (" + e.what() + ")");
  }
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
  if (clearance.value("min_posture", json()).is_number_unsigned())
    c.min_posture = clearance["min_posture"].get<std::size_t>();
  if (j.contains("path") && j["path"].is_string()) c.path = j["path"].get<std::string>();
  if (j.contains("path_digest") && j["path_digest"].is_string())
    c.path_digest = j["path_digest"].get<std::string>();
  if (j.contains("scene") && j["scene"].is_string()) c.scene = j["scene"].get<std::string>();
  if (j.contains("scene_digest") && j["scene_digest"].is_string())
    c.scene_digest = j["scene_digest"].get<std::string>();
  // The part's contacts: counts and first indices (null: none) of `link_part` / `holder_part`.
  const auto contacts = [&](const char* key) -> std::optional<pathgen::LinkPartResult> {
    const json block = j.value(key, json());
    if (!block.is_object()) return std::nullopt;
    const std::string name = key;
    pathgen::LinkPartResult r;
    r.colliding_postures = count(block.value("colliding_postures", json()), file,
                                 (name + ".colliding_postures").c_str());
    r.colliding_motions = count(block.value("colliding_motions", json()), file,
                                (name + ".colliding_motions").c_str());
    if (block.value("first_colliding_posture", json()).is_number_unsigned())
      r.first_colliding_posture = block["first_colliding_posture"].get<std::size_t>();
    if (block.value("first_colliding_motion", json()).is_number_unsigned())
      r.first_colliding_motion = block["first_colliding_motion"].get<std::size_t>();
    return r;
  };
  c.link_part = contacts("link_part");
  c.holder_part = contacts("holder_part");
  if (const json cut = j.value("cutter_part", json()); cut.is_object()) {
    pathgen::CutterPartResult& r = c.cutter_part.emplace();
    r.gouging_postures =
        count(cut.value("gouging_postures", json()), file, "cutter_part.gouging_postures");
    r.gouging_motions =
        count(cut.value("gouging_motions", json()), file, "cutter_part.gouging_motions");
    if (cut.value("first_gouging_posture", json()).is_number_unsigned())
      r.first_gouging_posture = cut["first_gouging_posture"].get<std::size_t>();
    if (cut.value("first_gouging_motion", json()).is_number_unsigned())
      r.first_gouging_motion = cut["first_gouging_motion"].get<std::size_t>();
    if (cut.value("max_depth_um", json()).is_number())
      r.max_depth_mm = 1e-3 * cut["max_depth_um"].get<double>();
    // The tolerance the gouges were counted against (the page's banner said "0 um": a helper).
    if (cut.value("tolerance_um", json()).is_number())
      r.tolerance_mm = 1e-3 * cut["tolerance_um"].get<double>();
  }
  return c;
}

// ------------------------------------------------------------------------------ surface

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
  // The part's top and facet normal under each source line, once: a check's uncut lines and
  // simulate's per-line deviation both read them; the blocks' top places a check's surface.
  std::vector<float> top, source_top, source_nz;
  if (scene.part) {
    const zbuffer::ToolMesh part = toZbuffer(*scene.part);
    if (deviation) top = zbuffer::partTop(s.grid, part.vertices, part.triangles);
    source_top = zbuffer::partTop(source, part.vertices, part.triangles, &source_nz);
  }
  // Lines no pass cut keep simulate's stock: its plane (simulate.json `stock.plane_mm`, stored
  // as the heights are, in float: a line at it was never lowered), or the part's top (`--part`
  // of the scene's part, by its digest: another mesh's top is not known here, and a cast stock
  // 1 mm over the part read every cut line as uncut, a reviewer's finding). Without
  // simulate.json (older folders, --outputs without json), lines at the highest height: wrong
  // where every line was cut (the highest cusps then read as uncut), so simulate.json's
  // `lines_lowered` equal to the line count overrides it.
  float stock = -INFINITY;
  bool part_stock = false, all_cut = false;
  if (!deviation) {
    for (float v : values)
      if (std::isfinite(v)) stock = std::max(stock, v);
    if (fs::exists(dir / "simulate.json")) {
      const json j = view_files::readJson(dir / "simulate.json");
      all_cut = j.value("lines_lowered", std::size_t{0}) == source.lineCount();
      if (j.contains("stock") && j["stock"].is_object()) {
        const json& st = j["stock"];
        if (st.contains("plane_mm") && st["plane_mm"].is_number())
          stock = static_cast<float>(st["plane_mm"].get<double>());
        if (st.contains("part")) {
          const std::string digest = st.value("part_digest", std::string());
          part_stock =
              scene.part_file && !digest.empty() && digest == common::fileDigest(*scene.part_file);
          if (!part_stock && !all_cut) {
            all_cut = true;  // nothing greyed: every line shown as it stands
            warnings.push_back(where + ": simulate started from " + st["part"].get<std::string>() +
                               ", not this scene's part (or a folder written before simulate "
                               "said which): the lines no pass cut are not told apart");
          }
        }
      }
    }
  }
  // A line's deviation from the part along its facet's normal, um, as a check's (simulate's
  // heights: a block's lowest line less the part at the block's centre read the downhill line
  // of every block on a slope as a gouge, a helper's finding; the vertical gap read 1/n_z too
  // much on a steep one, a reviewer's); NaN off the part. Without a part: the height.
  const bool measured = deviation || scene.part.has_value();
  auto lineValue = [&](std::size_t i) -> float {
    if (deviation || !measured) return values[i];
    if (!std::isfinite(source_top[i])) return NAN;
    return (values[i] - source_top[i]) * 1e3f * source_nz[i];
  };
  // Whether no pass cut line i. A check's line keeps the stock allowance, told along its facet's
  // normal (2000 cos(slope) um: on a 45° slope 1414, which the page showed as stock beside the
  // band), to 0.5 % (a cut line under an overhang, measured against the part beneath, may stand
  // above it: a reviewer's 990-3999 um lines under a 60° cap).
  auto lineUncut = [&](std::size_t i) -> bool {
    if (deviation) {
      const float stock_um = kStockAllowanceMm * 1e3f * source_nz[i];
      return std::isfinite(source_top[i]) &&
             std::abs(values[i] - stock_um) <= 0.005f * stock_um + 0.5f;
    }
    if (all_cut) return false;
    return part_stock ? values[i] >= source_top[i] - 1e-4f : values[i] >= stock - 1e-4f;
  };
  constexpr float kUncut = 1e30f;  // value of a block never cut (grey on the page)
  // Block representative: a deviation's deepest gouge if it has one, else its largest scallop (a
  // gouge is never averaged away); a height (no part): the lowest (deepest cut). Only the cut
  // lines of a block that has some.
  for (int by = 0; by < s.grid.ny; ++by)
    for (int bx = 0; bx < s.grid.nx; ++bx) {
      float lo = INFINITY, hi = -INFINITY;
      float lowest = INFINITY;  // the block's lowest height (simulate's)
      bool cut = false;
      for (int iy = by * k; iy < std::min(source.ny, (by + 1) * k); ++iy)
        for (int ix = bx * k; ix < std::min(source.nx, (bx + 1) * k); ++ix) {
          const std::size_t i = std::size_t(iy) * source.nx + ix;
          if (std::isnan(values[i])) continue;
          lowest = std::min(lowest, values[i]);
          const float v = lineValue(i);
          if (std::isnan(v)) continue;  // a line off the part
          const bool uncut_line = lineUncut(i);
          if (cut && uncut_line) continue;
          if (!cut && !uncut_line) lo = INFINITY, hi = -INFINITY;
          cut = cut || !uncut_line;
          lo = std::min(lo, v);
          hi = std::max(hi, v);
        }
      const std::size_t b = std::size_t(by) * s.grid.nx + bx;
      if (!deviation && std::isfinite(lowest)) s.height_mm[b] = lowest;
      if (lo > hi) continue;  // every line of the block off the part
      const float dev = !measured ? lo : lo < -gouge_tolerance_um ? lo : hi;
      if (deviation)
        s.height_mm[b] = top[b] + dev * 1e-3f;  // NaN where the block centre misses the part
      s.value[b] = cut ? dev : kUncut;
    }
  s.deviation = deviation || scene.part.has_value();
  s.uncut_um = kUncut;
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
    else if (figures.from_check)  // no scallop over the band: what stands higher is stock left
      s.range[1] = 10;            // beside it (a single pass's 1861 um topped the scale: a helper)
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

}  // namespace view_files

// ------------------------------------------------------------------------------ readers

void readClearanceCsv(const fs::path& file, std::size_t postures, std::vector<double>& clearance_mm,
                      std::vector<double>& motion_mm, std::vector<std::uint8_t>& part_contact,
                      std::vector<std::uint8_t>& part_contact_to_next) {
  if (!fs::exists(file))
    throw InputError(file.string() + ": missing (the check folder has check.json without it)");
  // A row is ~60 bytes: far past that, no check's file of this path (a helper's padded to 10 GB
  // was read for 50 s).
  std::error_code size_ec;
  const std::uintmax_t bytes = fs::file_size(file, size_ec);
  if (!size_ec && double(bytes) > 512.0 * double(postures) + 65536.0)
    throw InputError(file.string() + ": " + common::formatBytes(double(bytes)) + " for a path of " +
                     std::to_string(postures) + " postures: not the clearance.csv of its check");
  std::ifstream in(file);
  if (!in) throw InputError(file.string() + ": cannot be read");
  std::string line;
  // The part's columns came later: a check folder written before them has 6 cells a row.
  const std::string header = "posture,block,pass,clearance_mm,motion_to_next_mm,limited";
  const std::string part_columns = ",part_contact,part_contact_to_next";
  // (a file saved again with CR LF line ends: the CR is not part of the last cell)
  auto withoutCr = [](std::string& text) {
    if (!text.empty() && text.back() == '\r') text.pop_back();
  };
  if (std::getline(in, line)) withoutCr(line);
  if (!in || (line != header && line != header + part_columns))
    throw InputError(file.string() + ":1: expected the header '" + header + part_columns + "'");
  const std::size_t cell_count = line == header ? 6 : 8;
  clearance_mm.assign(postures, kNaN);
  motion_mm.assign(postures, kNaN);
  part_contact.assign(postures, 0);
  part_contact_to_next.assign(postures, 0);
  // A part-contact cell: 0 or 1 in every row, or empty in every row (the scene had no part); a
  // file with both was edited (one blank cell would hide every contact).
  std::size_t empty_line = 0, filled_line = 0;
  auto flag = [&](std::string_view cell, std::size_t number, std::uint8_t& out) {
    if (!cell.empty() && cell != "0" && cell != "1")
      throw InputError(file.string() + ":" + std::to_string(number) + ": a part contact of '" +
                       std::string(cell) + "' (0 or 1)");
    std::size_t& first = cell.empty() ? empty_line : filled_line;
    if (first == 0) first = number;
    if (empty_line && filled_line)
      throw InputError(file.string() + ":" + std::to_string(std::max(empty_line, filled_line)) +
                       ": part contact cells empty in some rows and not in others (0 or 1 in "
                       "every row, or empty in all)");
    if (!cell.empty()) out = cell == "1";
  };
  std::size_t row = 0, number = 1;
  while (std::getline(in, line)) {
    ++number;
    withoutCr(line);
    if (line.empty()) continue;
    std::vector<std::string_view> cells;
    std::string_view rest = line;
    for (std::size_t comma; (comma = rest.find(',')) != std::string_view::npos;) {
      cells.push_back(rest.substr(0, comma));
      rest.remove_prefix(comma + 1);
    }
    cells.push_back(rest);
    if (cells.size() != cell_count)
      throw InputError(file.string() + ":" + std::to_string(number) + ": expected " +
                       std::to_string(cell_count) + " cells");
    if (row >= postures)
      throw InputError(file.string() + ":" + std::to_string(number) + ": more rows than the " +
                       std::to_string(postures) + " postures of the path");
    if (parseCell(cells[0], file, number, false) != double(row))
      throw InputError(file.string() + ":" + std::to_string(number) + ": posture " +
                       std::string(cells[0]) + " where " + std::to_string(row) + " was expected");
    clearance_mm[row] = parseCell(cells[3], file, number, false);
    motion_mm[row] = parseCell(cells[4], file, number, true);
    if (cell_count == 8) {
      flag(cells[6], number, part_contact[row]);
      if (row + 1 < postures) flag(cells[7], number, part_contact_to_next[row]);
    }
    ++row;
  }
  if (cell_count == 6 || filled_line == 0) {
    part_contact.clear();
    part_contact_to_next.clear();
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

}  // namespace fieldpath::app
