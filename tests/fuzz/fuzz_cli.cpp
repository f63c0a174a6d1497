/// libFuzzer target: the small option languages of the command line: `--grid NXxNY`,
/// `--region x0,y0,x1,y1` (number lists), the Z-buffer's analytic `--tool`, `--max-memory`, and
/// the grid they make together (Grid::fromRegion, checkGridFits): lines "GRID\nREGION\nTOOL\nMEM".
#include <cmath>
#include <cstdlib>

#include "cli_parse.h"
#include "fieldpath/common/errors.h"
#include "fieldpath/common/limits.h"
#include "fieldpath/zbuffer/simulator.h"
#include "fuzz_support.h"

namespace {
std::string line(std::string_view& rest) {
  const auto cut = rest.find('\n');
  const std::string out(rest.substr(0, cut));
  rest = cut == std::string_view::npos ? std::string_view{} : rest.substr(cut + 1);
  return out;
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fieldpath::common::releaseHeldMemory();  // each input a run of its own (--max-memory)
  using namespace fieldpath;
  std::string_view rest = fuzz::view(data, size);
  const std::string grid = line(rest), region = line(rest), tool = line(rest), memory = line(rest);
  fuzz::scratchDir();  // sets the memory limit
  std::pair<int, int> lines{0, 0};
  try {
    lines = app::parseGrid(grid);
  } catch (const common::InputError&) {
  }
  try {
    const std::vector<double> r = app::parseNumbers(region, "--region", 4);
    if (r.size() != 4) std::abort();
    for (double v : r)
      if (!std::isfinite(v)) std::abort();
    if (lines.first > 0) {
      const zbuffer::Grid g =
          zbuffer::Grid::fromRegion(r[0], r[1], r[2], r[3], lines.first, lines.second);
      if (!(g.dx_mm > 0) || !(g.dy_mm > 0) || !std::isfinite(g.dx_mm) || !std::isfinite(g.dy_mm))
        std::abort();  // a degenerate grid got through
      zbuffer::checkGridFits(g);
    }
  } catch (const common::InputError&) {
  }
  try {
    // Only the analytic forms: any other text names a mesh file to load (fuzz_mesh covers it).
    if (tool.rfind("ball:", 0) == 0 || tool.rfind("torus:", 0) == 0 || tool.rfind("flat:", 0) == 0)
      (void)app::parseTool(tool);
  } catch (const common::InputError&) {
  }
  try {
    const std::size_t bytes = common::parseMemorySize(memory, "--max-memory");
    if (bytes < (std::size_t{1} << 20)) std::abort();
  } catch (const common::InputError&) {
  }
  return 0;
}
