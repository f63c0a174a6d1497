#include "view_page.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <numeric>
#include <sstream>
#include <type_traits>

#include <nlohmann/json.hpp>

#include "errors.h"
#include "view_assets.h"

#ifndef FIELDPATH_THREE_DIR
#define FIELDPATH_THREE_DIR "/usr/share/javascript/three"
#endif

namespace fieldpath::app {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// Bits of the page's per-posture flags (view.js, panel.js and state.js read the same).
constexpr std::uint8_t kLink = 1, kLimited = 2, kColliding = 4, kMotionColliding = 8,
                       kBlockStart = 16, kPartContact = 32, kMotionPartContact = 64;

/// The page's binary data: typed arrays, each 4-byte aligned, referenced from the JSON block as
/// {type, offset, count}.
class Blob {
 public:
  template <class T>
  json add(const std::vector<T>& values) {
    while (bytes_.size() % 4) bytes_.push_back('\0');
    const std::size_t offset = bytes_.size();
    bytes_.append(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(T));
    return {{"type", typeName<T>()}, {"offset", offset}, {"count", values.size()}};
  }
  const std::string& bytes() const { return bytes_; }

 private:
  template <class T>
  static const char* typeName() {
    if constexpr (std::is_same_v<T, float>) return "f32";
    if constexpr (std::is_same_v<T, std::uint32_t>) return "u32";
    if constexpr (std::is_same_v<T, std::uint16_t>) return "u16";
    if constexpr (std::is_same_v<T, std::uint8_t>) return "u8";
  }
  std::string bytes_;
};

std::string base64(const std::string& bytes) {
  static const char* const kAlphabet =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint8_t(bytes[i]) << 16) | (std::uint8_t(bytes[i + 1]) << 8) |
                            std::uint8_t(bytes[i + 2]);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (i < bytes.size()) {
    const bool two = i + 1 < bytes.size();
    const std::uint32_t v =
        (std::uint8_t(bytes[i]) << 16) | (two ? std::uint8_t(bytes[i + 1]) << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += two ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string htmlEscape(const std::string& text) {
  std::string out;
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

/// JSON that can stand inside a <script> element: no '<' at all ("</script>", "<!--").
std::string scriptJson(const json& j) {
  const std::string text = j.dump(-1, ' ', false, json::error_handler_t::replace);  // any file name
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<')
      out += "\\u003c";
    else
      out += c;
  }
  return out;
}

std::string readText(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

json vec(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

/// A scene mesh, decimated to `max_triangles`: positions quantized to 16 bits over its box.
json meshJson(const ViewMesh& m, std::size_t max_triangles, Blob& blob, std::size_t* shown) {
  const geometry::TriangleMesh mesh = decimateMesh(m.mesh, max_triangles);
  Eigen::AlignedBox3d box;
  for (const auto& v : mesh.vertices) box.extend(v);
  const Eigen::Vector3d step = (box.diagonal() / 65535.0).cwiseMax(1e-12);
  std::vector<std::uint16_t> q;
  q.reserve(3 * mesh.vertices.size());
  for (const auto& v : mesh.vertices)
    for (int k = 0; k < 3; ++k)
      q.push_back(static_cast<std::uint16_t>(
          std::clamp(std::lround((v[k] - box.min()[k]) / step[k]), 0L, 65535L)));
  json j = {{"name", m.name},
            {"role", m.role == ViewMesh::Role::Part ? "part" : "obstacle"},
            {"triangles", mesh.triangles.size()},
            {"source_triangles", m.mesh.triangles.size()},
            {"origin", vec(box.min())},
            {"step", vec(step)},
            {"positions", blob.add(q)}};
  if (mesh.vertices.size() <= 65536) {
    std::vector<std::uint16_t> index;
    for (const auto& t : mesh.triangles)
      for (int c = 0; c < 3; ++c) index.push_back(static_cast<std::uint16_t>(t[c]));
    j["indices"] = blob.add(index);
  } else {
    std::vector<std::uint32_t> index;
    for (const auto& t : mesh.triangles)
      for (int c = 0; c < 3; ++c) index.push_back(static_cast<std::uint32_t>(t[c]));
    j["indices"] = blob.add(index);
  }
  *shown = mesh.triangles.size();
  return j;
}

json toolJson(const ViewData& d, Blob& blob) {
  std::vector<float> p;
  for (const auto& v : d.tool.vertices)
    for (int k = 0; k < 3; ++k) p.push_back(static_cast<float>(v[k]));
  std::vector<std::uint32_t> index;
  for (const auto& t : d.tool.triangles)
    for (int c = 0; c < 3; ++c) index.push_back(static_cast<std::uint32_t>(t[c]));
  const char* shape = d.tool_spec.shape == geometry::ToolShape::Ball    ? "ball"
                      : d.tool_spec.shape == geometry::ToolShape::Torus ? "torus"
                                                                        : "flat";
  return {{"shape", shape},
          {"radius_mm", d.tool_spec.radius_mm},
          {"length_mm", d.tool_spec.length_mm},
          {"triangles", d.tool.triangles.size()},
          {"positions", blob.add(p)},
          {"indices", blob.add(index)}};
}

json pathJson(const ViewData& d, std::size_t max_postures, Blob& blob, std::size_t* shown_count) {
  const ViewPath& p = *d.path;
  const auto& postures = p.file.postures;
  const std::size_t n = postures.size();
  std::vector<std::uint8_t> flags(n, 0);
  for (const geometry::PathBlock& b : p.file.blocks) {
    for (std::size_t i = b.begin; i < b.end; ++i)
      if (b.kind == geometry::PathBlock::Kind::Link) flags[i] |= kLink;
    if (b.begin < n) flags[b.begin] |= kBlockStart;
  }
  for (std::size_t i : p.file.limited)
    if (i < n) flags[i] |= kLimited;
  for (std::size_t i = 0; i < n; ++i) {
    if (p.clearance_mm[i] <= 0.0) flags[i] |= kColliding;
    if (p.motion_mm[i] <= 0.0) flags[i] |= kMotionColliding;
    if (i < p.part_contact.size() && p.part_contact[i]) flags[i] |= kPartContact;
    if (i < p.part_contact_to_next.size() && p.part_contact_to_next[i])
      flags[i] |= kMotionPartContact;
  }
  std::size_t part_postures = 0, part_motions = 0;
  for (std::uint8_t f : flags) {
    part_postures += (f & kPartContact) != 0;
    part_motions += (f & kMotionPartContact) != 0;
  }
  // The slider's postures: every k-th, and always the flagged ones, both ends of a colliding
  // motion and the first and last of each block.
  const std::size_t stride =
      std::max<std::size_t>(1, (n + max_postures - 1) / std::max<std::size_t>(1, max_postures));
  std::vector<std::size_t> shown;
  for (std::size_t i = 0; i < n; ++i) {
    const bool keep = i % stride == 0 || i + 1 == n || (flags[i] & ~kLink) ||
                      (i > 0 && (flags[i - 1] & (kMotionColliding | kMotionPartContact))) ||
                      (i + 1 < n && (flags[i + 1] & kBlockStart));
    if (keep) shown.push_back(i);
  }
  std::vector<float> tip, axis, s, tilt, lead, clearance, motion;
  std::vector<std::uint32_t> index, line;
  std::vector<std::uint16_t> pass;
  std::vector<std::uint8_t> shown_flags;
  for (std::size_t i : shown) {
    for (int k = 0; k < 3; ++k) {
      tip.push_back(static_cast<float>(postures[i].tip_mm[k]));
      axis.push_back(static_cast<float>(postures[i].axis[k]));
    }
    index.push_back(static_cast<std::uint32_t>(i));
    line.push_back(static_cast<std::uint32_t>(i < p.file.lines.size() ? p.file.lines[i] : 0));
    pass.push_back(static_cast<std::uint16_t>(std::clamp(p.pass[i], 0, 65535)));
    s.push_back(static_cast<float>(p.s_mm[i]));
    tilt.push_back(static_cast<float>(p.tilt_deg[i]));
    lead.push_back(static_cast<float>(p.lead_deg[i]));
    clearance.push_back(static_cast<float>(p.clearance_mm[i]));
    motion.push_back(static_cast<float>(p.motion_mm[i]));
    shown_flags.push_back(flags[i]);
  }
  *shown_count = shown.size();
  return {
      {"file", p.what},
      {"rows", p.file.rows},
      {"shown", shown.size()},
      {"stride", stride},
      {"offset_mm", geometry::cornerRadius(d.tool_spec)},
      {"required_mm", d.required_mm},
      {"clearance_source", p.clearance_source},
      {"angles_source", p.angles_source},
      {"counts",
       {{"postures", n},
        {"passes", p.file.count(geometry::PathBlock::Kind::Pass)},
        {"links", p.file.count(geometry::PathBlock::Kind::Link)},
        {"colliding_postures", p.colliding_postures},
        {"colliding_motions", p.colliding_motions},
        {"motions_under_required", p.motions_under_required},
        {"postures_under_required", p.postures_under_required},
        {"part_contact_holder", p.holder_part_contacts},
        {"part_contact_cutter", p.cutter_part_contacts},
        {"limited", p.file.limited.size()},
        {"limited_colliding", p.limited_colliding},
        // null: not known (no part, or a check folder written before clearance.csv had them)
        {"part_contact_postures", p.part_contact.empty() ? json() : json(part_postures)},
        {"part_contact_motions", p.part_contact.empty() ? json() : json(part_motions)},
        {"outside", p.outside}}},
      {"tip", blob.add(tip)},
      {"axis", blob.add(axis)},
      {"index", blob.add(index)},
      {"line", blob.add(line)},
      {"flags", blob.add(shown_flags)},
      {"pass", blob.add(pass)},
      {"s_mm", blob.add(s)},
      {"tilt_deg", blob.add(tilt)},
      {"lead_deg", blob.add(lead)},
      {"clearance_mm", blob.add(clearance)},
      {"motion_mm", blob.add(motion)},
  };
}

json surfaceJson(const ViewSurface& s, Blob& blob) {
  return {{"kind", s.deviation ? "deviation" : "height"},
          {"nx", s.grid.nx},
          {"ny", s.grid.ny},
          {"x0", s.grid.x0_mm},
          {"y0", s.grid.y0_mm},
          {"dx", s.grid.dx_mm},
          {"dy", s.grid.dy_mm},
          {"stride", s.stride},
          {"source_lines", s.source_lines},
          {"uncut_um", s.uncut_um},
          {"range", {s.range[0], s.range[1]}},
          {"source", s.source},
          {"height", blob.add(s.height_mm)},
          {"value", blob.add(s.value)}};
}

/// Replaces each @@FP_NAME@@ of the template once, in order; inserted text is not scanned.
std::string fill(std::string_view page,
                 const std::vector<std::pair<std::string, const std::string*>>& values) {
  std::string out;
  std::size_t at = 0;
  while (true) {
    const std::size_t open = page.find("@@FP_", at);
    if (open == std::string_view::npos) break;
    const std::size_t close = page.find("@@", open + 5);
    if (close == std::string_view::npos) break;
    const std::string_view name = page.substr(open + 5, close - open - 5);
    const auto it =
        std::find_if(values.begin(), values.end(), [&](const auto& v) { return v.first == name; });
    out.append(page.substr(at, open - at));
    if (it != values.end())
      out += *it->second;
    else
      out.append(page.substr(open, close + 2 - open));  // not ours (e.g. the comment)
    at = close + 2;
  }
  out.append(page.substr(at));
  return out;
}

}  // namespace

fs::path threeJsDir() {
  if (const char* dir = std::getenv("FIELDPATH_THREE_DIR"); dir && *dir) return dir;
  return FIELDPATH_THREE_DIR;
}

ThreeJs loadThreeJs(const fs::path& dir) {
  ThreeJs t;
  const fs::path three = dir / "three.min.js";
  const fs::path orbit = dir / "examples/js/controls/OrbitControls.js";
  for (const fs::path& file : {three, orbit})
    if (!fs::is_regular_file(file))
      throw InputError(file.string() +
                       ": missing; the page inlines three.js from Debian's libjs-three "
                       "(scripts/setup.sh installs it; or set FIELDPATH_THREE_DIR)");
  t.three = readText(three);
  t.orbit_controls = readText(orbit);
  if (t.three.empty() || t.three.find("</script") != std::string::npos ||
      t.orbit_controls.find("</script") != std::string::npos)
    throw InputError(three.string() + ": cannot be inlined (empty, or it holds '</script')");
  return t;
}

std::string viewPage(const ViewData& d, const ThreeJs& three, const PageBudget& budget,
                     const std::string& generator, PageStats* stats) {
  PageStats st;
  Blob blob;
  json meshes = json::array();
  for (const ViewMesh& m : d.meshes) st.source_triangles += m.mesh.triangles.size();
  // The budget shared out from the smallest mesh up: each takes its own triangles or an equal
  // share of what is left, so a small mesh stays whole, the large ones share alike, and the page
  // holds max_triangles at most (a floor of 2000 a mesh showed 3444 for --max-triangles 1000).
  std::vector<std::size_t> order(d.meshes.size()), allowed(d.meshes.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return d.meshes[a].mesh.triangles.size() < d.meshes[b].mesh.triangles.size();
  });
  std::size_t left = budget.max_triangles;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const std::size_t i = order[k];
    allowed[i] = std::max<std::size_t>(
        1, std::min(d.meshes[i].mesh.triangles.size(), left / (order.size() - k)));
    left -= std::min(left, allowed[i]);
  }
  for (std::size_t i = 0; i < d.meshes.size(); ++i) {
    std::size_t shown = 0;
    meshes.push_back(meshJson(d.meshes[i], allowed[i], blob, &shown));
    st.triangles += shown;
  }
  json meta = {
      {"generator", generator},
      {"scene", d.scene_file.string()},
      {"box", {{"min", vec(d.box.min())}, {"max", vec(d.box.max())}}},
      {"meshes", meshes},
      {"tool", toolJson(d, blob)},
      {"path", nullptr},
      {"surface", nullptr},
      {"missing", d.missing},
      {"warnings", d.warnings},
      {"notes", d.notes},
  };
  if (d.path) meta["path"] = pathJson(d, budget.max_postures, blob, &st.shown_postures);
  if (d.surface) meta["surface"] = surfaceJson(*d.surface, blob);

  std::string title = "fieldpath view: " + d.scene_file.filename().string();
  if (d.path) title += ", " + d.path->file.file.filename().string();
  const std::string meta_text = scriptJson(meta), blob_text = base64(blob.bytes());
  const std::string title_text = htmlEscape(title), generator_text = htmlEscape(generator);
  const std::string css = view_assets::kViewCss, colours = view_assets::kColoursJs,
                    geometry = view_assets::kGeometryJs, js = view_assets::kViewJs,
                    panel = view_assets::kPanelJs, page_state = view_assets::kStateJs;
  const std::string page = fill(view_assets::kPageHtml, {{"GENERATOR", &generator_text},
                                                         {"TITLE", &title_text},
                                                         {"CSS", &css},
                                                         {"META", &meta_text},
                                                         {"BLOB", &blob_text},
                                                         {"THREE", &three.three},
                                                         {"ORBIT", &three.orbit_controls},
                                                         {"COLOURSJS", &colours},
                                                         {"GEOMETRYJS", &geometry},
                                                         {"VIEWJS", &js},
                                                         {"PANELJS", &panel},
                                                         {"STATEJS", &page_state}});
  st.bytes = page.size();
  if (stats) *stats = st;
  return page;
}

}  // namespace fieldpath::app
