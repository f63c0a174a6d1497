#pragma once
/// What a path file says of its cutter against the scene's tool: an APT file's `CUTTER/` records
/// name the tool its tips were computed for. `check`, `generate` and `view` prove and show the
/// scene's tool; a file written for another one is said, not refused (DESIGN.md reads CUTTER
/// past, and a machine runs the tool it is given).
#include <string>
#include <vector>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/tool.h"

namespace fieldpath::app {

/// One line per CUTTER record that differs from `tool` (diameter, corner radius where the
/// record gives one, or length where it gives one and `compare_length`, by more than 1 um),
/// "FILE:LINE: ..."; empty when they agree or there are none. At most 3 lines, the last saying
/// how many more. `tool_name` says whose tool it is ("the scene's tool", "--tool"); the length
/// is where the holder sits, which `simulate` does not model (it compares none). A record whose
/// diameter is not > 0 gives no tool: said so.
std::vector<std::string> cutterNotes(const geometry::ToolSpec& tool, const geometry::PathFile& path,
                                     const std::string& tool_name = "the scene's tool",
                                     bool compare_length = true);

/// The line said when a scene has no `holder`: what is then proven clear is the tool up to its
/// length, not what holds it (a newcomer's job read safe with no word of it). Empty with a holder.
std::string noHolderNote(const geometry::ToolSpec& tool, const geometry::HolderProfile& holder);

}  // namespace fieldpath::app
