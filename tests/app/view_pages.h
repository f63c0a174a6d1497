#pragma once
/// What the `view` tests share (test_view.cpp, test_view_part.cpp): scenes and paths written for
/// them, and the page's parts read back (its JSON block, its per-posture flags).
#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "files.h"

namespace fieldpath::app::test::view {

namespace fs = std::filesystem;
using nlohmann::json;
// What the tests call from files.h, brought in with this namespace.
using fieldpath::app::test::boxStl;
using fieldpath::app::test::Outcome;
using fieldpath::app::test::runFieldpath;
using fieldpath::app::test::slurp;
using fieldpath::app::test::squareStl;
using fieldpath::app::test::TempDir;

inline const fs::path kImpellerScene =
    fs::path(FIELDPATH_SOURCE_DIR) / "examples/impeller/scene.yaml";

/// Two passes along x (y = 0 through the block, y = 8 beside it) joined by a link; one `# limit`.
inline std::string pathCl(double shift_mm = 0) {
  std::ostringstream s;
  auto line = [&](double x, double y, double z, const char* mark = "") {
    s << x + shift_mm << ' ' << y << ' ' << z << " 0 0 1" << mark << '\n';
  };
  s << "# pass 1\n";
  for (int k = 0; k < 40; ++k) line(-9.75 + 0.5 * k, 0, 0);
  s << "# link\n";
  line(9.75, 0, 15);
  line(-9.75, 8, 15);
  s << "# pass 2\n";
  for (int k = 0; k < 40; ++k) line(-9.75 + 0.5 * k, 8, 0, k == 20 ? "  # limit" : "");
  return s.str();
}

/// A scene with a block in the way of pass 1 on a floor (the part), the path as its nominal.
inline void writeBlockScene(const TempDir& dir, bool nominal = true) {
  dir.write("block.stl", boxStl(3, -3, -1, 5, 3, 4));
  dir.write("floor.stl", squareStl(20, 0));
  dir.write("path.cl", pathCl());
  dir.write("scene.yaml", std::string("obstacles:\n  - mesh: block.stl\npart: floor.stl\n"
                                      "tool: { shape: ball, radius: 1, length: 10 }\n"
                                      "clearance: 0.5\n") +
                              (nominal ? "path: { nominal: path.cl }\n" : ""));
}

inline std::string between(const std::string& text, const std::string& open,
                           const std::string& close) {
  const auto a = text.find(open);
  if (a == std::string::npos) return {};
  const auto b = text.find(close, a + open.size());
  return b == std::string::npos ? std::string() : text.substr(a + open.size(), b - a - open.size());
}

inline json pageMeta(const std::string& html) {
  return json::parse(
      between(html, "<script type=\"application/json\" id=\"fp-meta\">", "</script>"));
}

inline std::string base64Decode(const std::string& text) {
  std::string out;
  int bits = 0, buffer = 0;
  for (char c : text) {
    int v = c >= 'A' && c <= 'Z'   ? c - 'A'
            : c >= 'a' && c <= 'z' ? c - 'a' + 26
            : c >= '0' && c <= '9' ? c - '0' + 52
            : c == '+'             ? 62
            : c == '/'             ? 63
                                   : -1;
    if (v < 0) continue;
    buffer = (buffer << 6) | v;
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += char((buffer >> bits) & 0xff);
    }
  }
  return out;
}

/// An ASCII STL of the given triangles (x y z of each corner, counter-clockwise seen from above),
/// normals from their winding.
inline std::string facetsStl(const std::vector<std::array<double, 9>>& facets) {
  std::ostringstream stl;
  stl << "solid sheet\n";
  for (const auto& v : facets) {
    const double u[3] = {v[3] - v[0], v[4] - v[1], v[5] - v[2]};
    const double w[3] = {v[6] - v[0], v[7] - v[1], v[8] - v[2]};
    stl << " facet normal " << u[1] * w[2] - u[2] * w[1] << ' ' << u[2] * w[0] - u[0] * w[2] << ' '
        << u[0] * w[1] - u[1] * w[0] << "\n  outer loop\n";
    for (int k = 0; k < 9; k += 3)
      stl << "   vertex " << v[k] << ' ' << v[k + 1] << ' ' << v[k + 2] << '\n';
    stl << "  endloop\n endfacet\n";
  }
  stl << "endsolid sheet\n";
  return stl.str();
}

/// The page's array that `ref` names ({offset: bytes into the blob, count: values}).
template <class T>
std::vector<T> pageBlob(const std::string& html, const json& ref) {
  const std::string blob = base64Decode(
      between(html, "<script type=\"application/octet-stream\" id=\"fp-blob\">", "</script>"));
  const std::size_t offset = ref["offset"], count = ref["count"];
  std::vector<T> values(count);
  if (offset + count * sizeof(T) <= blob.size())
    std::memcpy(values.data(), blob.data() + offset, count * sizeof(T));
  else
    ADD_FAILURE() << "the page's array " << ref << " runs past its blob of " << blob.size()
                  << " bytes";
  return values;
}

/// The surface's values (µm from the part, or heights) and its "not cut" marker (uncut_um).
inline std::pair<std::vector<float>, double> surfaceValues(const std::string& html) {
  const json meta = pageMeta(html);
  return std::make_pair(pageBlob<float>(html, meta["surface"]["value"]),
                        meta["surface"]["uncut_um"].get<double>());
}

/// The page's path array `name` (meta.path[name]).
template <class T>
std::vector<T> pageArray(const std::string& html, const json& meta, const std::string& name) {
  return pageBlob<T>(html, meta["path"][name]);
}

/// The page's per-posture flags (1 link, 2 limit held, 4 colliding, 8 colliding motion).
inline std::vector<std::uint8_t> pageFlags(const std::string& html, const json& meta) {
  return pageArray<std::uint8_t>(html, meta, "flags");
}

inline std::size_t countBit(const std::vector<std::uint8_t>& flags, int bit) {
  return std::count_if(flags.begin(), flags.end(), [bit](std::uint8_t f) { return f & bit; });
}

inline bool oneLine(const std::string& text) {
  return !text.empty() && text.find('\n') == text.size() - 1;
}

}  // namespace fieldpath::app::test::view
