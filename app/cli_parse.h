#pragma once
/// The small option languages of the command line (DESIGN.md command line): the Z-buffer's tool,
/// `--grid NXxNY`, comma-separated number lists (`--region`). Each refuses bad text with one
/// common::InputError naming the option; kept apart from the commands so that they can be fuzzed.
#include <string>
#include <utility>
#include <vector>

#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

/// TOOL: ball:R[:L] | torus:R:r[:L] | flat:R[:L] (mm), or a mesh file (tool frame).
zbuffer::Tool parseTool(const std::string& text);
/// "NXxNY" → (nx, ny); refuses zero and counts beyond int.
std::pair<int, int> parseGrid(const std::string& text);
/// Exactly `count` finite numbers separated by commas; the message names `option`.
std::vector<double> parseNumbers(const std::string& text, const char* option, std::size_t count);

}  // namespace fieldpath::app
