#include "cutter_note.h"

#include <cmath>
#include <cstdio>

namespace fieldpath::app {
namespace {

constexpr double kCutterTolMm = 1e-3;  ///< CAM systems write 4-6 decimals; inches convert exactly

std::string mm(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%.6g", value);
  return text;
}

std::string toolWords(const geometry::ToolSpec& tool) {
  const std::string d = mm(2 * tool.radius_mm) + " mm";
  switch (tool.shape) {
    case geometry::ToolShape::Ball:
      return "a ball of radius " + mm(tool.radius_mm) + " mm (" + d + ")";
    case geometry::ToolShape::Torus:
      return "a torus " + d + " with a " + mm(tool.corner_radius_mm) + " mm corner";
    case geometry::ToolShape::Flat:
      break;
  }
  return "a flat end mill of " + d;
}

}  // namespace

std::vector<std::string> cutterNotes(const geometry::ToolSpec& tool, const geometry::PathFile& path,
                                     const std::string& tool_name, bool compare_length) {
  constexpr std::size_t kMaxLines = 3;
  const double corner_mm = geometry::cornerRadius(tool);
  std::vector<std::string> notes;
  for (const geometry::PathFile::Cutter& c : path.cutters) {
    const std::string where = path.file.string() + ":" + std::to_string(c.line) + ": ";
    if (!(c.diameter_mm > 0.0)) {  // `CUTTER/-6`: a typo or a placeholder, no tool to compare
      notes.push_back(where + c.record + " gives a diameter of " + mm(c.diameter_mm) +
                      " mm, no tool: the file does not say which cutter it was written for; " +
                      "what follows is for " + tool_name + ", " + toolWords(tool));
      continue;
    }
    const bool same_diameter = std::abs(c.diameter_mm - 2 * tool.radius_mm) <= kCutterTolMm;
    // CUTTER/d alone is, in APT, a flat end mill (corner radius 0): compared as one.
    const double file_corner_mm = c.corner_mm < 0.0 ? 0.0 : c.corner_mm;
    const bool same_corner = std::abs(file_corner_mm - corner_mm) <= kCutterTolMm;
    const bool same_length = !compare_length || c.length_mm < 0.0 ||
                             std::abs(c.length_mm - tool.length_mm) <= kCutterTolMm;
    if (same_diameter && same_corner && same_length) continue;
    if (same_diameter && same_corner) {
      // The length alone: the holder sits at it, so a shorter tool in the machine than in the
      // scene brings the holder nearer the part than the proof put it.
      const double lower_mm = tool.length_mm - c.length_mm;
      notes.push_back(
          where + c.record + " says the tool is " + mm(c.length_mm) +
          " mm long (tip to holder); the scene's tool.length_mm is " + mm(tool.length_mm) +
          (lower_mm > 0.0 ? ": with the file's tool the holder sits " + mm(lower_mm) +
                                " mm lower, nearer the part, than the scene proves it; give "
                                "tool.length_mm the length the machine runs"
                          : ": with the file's tool the holder sits " + mm(-lower_mm) +
                                " mm higher than the scene proves it (the proof is the stricter)"));
      continue;
    }
    // "an 8 mm", "an 11 mm", "an 18 mm" (as they are said), else "a"
    const std::string d = mm(c.diameter_mm);
    const bool an = d[0] == '8' || ((d.rfind("11", 0) == 0 || d.rfind("18", 0) == 0) &&
                                    (d.size() == 2 || d[2] == '.'));
    std::string file_tool = (an ? "an " : "a ") + d + " mm cutter";
    if (c.corner_mm >= 0.0)
      file_tool += " with a " + mm(c.corner_mm) + " mm corner";
    else
      file_tool += " with no corner radius given (in APT, a flat end mill)";
    if (!same_length) file_tool += ", " + mm(c.length_mm) + " mm long";
    notes.push_back(where + c.record + " says the path was written for " + file_tool + "; " +
                    tool_name + " is " + toolWords(tool) +
                    (same_length ? "" : ", " + mm(tool.length_mm) + " mm long") +
                    ": what follows is for " + tool_name + ", not the file's");
  }
  // A file that changes tools: each is proven as the scene's one (the cutters of the loads are
  // compared above where CUTTER or TLDATA records give them).
  std::vector<const geometry::PathFile::ToolLoad*> loads;
  for (const auto& load : path.tool_loads)
    if (loads.empty() || load.number != loads.back()->number) loads.push_back(&load);
  if (loads.size() > 1) {
    std::string which;
    for (std::size_t k = 0; k < loads.size() && k < 4; ++k)
      which +=
          (k ? ", " : "") + loads[k]->number + " (line " + std::to_string(loads[k]->line) + ")";
    if (loads.size() > 4) which += ", ...";
    notes.insert(notes.begin(),
                 path.file.string() + ":" + std::to_string(loads[1]->line) +
                     ": the file changes tools (" + std::to_string(loads.size()) +
                     " loads: " + which + "): " +
                     (compare_length
                          ? "every motion is proven with the scene's one tool, " + toolWords(tool) +
                                "; split the file by tool and give each its scene"
                          : "every posture is cut with " + tool_name + ", " + toolWords(tool) +
                                "; split the file by tool"));
  }
  if (notes.size() > kMaxLines) {
    const std::size_t more = notes.size() - (kMaxLines - 1);
    notes.resize(kMaxLines - 1);
    notes.push_back(path.file.string() + ": " + std::to_string(more) +
                    " more CUTTER / TLDATA records differ from the scene's tool");
  }
  return notes;
}

std::string noHolderNote(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder) {
  if (!holder.empty()) return {};
  return "no `holder` in the scene: the tool is proven clear up to its length (" +
         mm(tool.length_mm) +
         " mm from the tip), the holder and spindle above it are not (give its stations: "
         "holder: [[z, radius], ...])";
}

}  // namespace fieldpath::app
