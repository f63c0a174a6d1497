#pragma once
/// What `check` says of the machined surface: why it was not measured (surface_skipped), its
/// figures in check.json, its line on stdout, and the finish `--max-scallop` holds it to.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "surface_check.h"

namespace fieldpath::app {

/// What `check` learned of the surface and the part, for surfaceSkipped.
struct SurfaceFacts {
  bool part = false;          ///< the scene has a part
  bool surface = false;       ///< a surface was measured
  bool never_cut = false;     ///< the Z-buffer lowered no line over the part
  bool touches_part = false;  ///< the cutter enters the part (cutter_part)
  bool reaches_part = false;  ///< the ball comes within kReachesPartMm of it
};

/// Why the surface was not checked (nullptr: it was), as check.json's surface_skipped says it.
const char* surfaceSkipped(const SurfaceFacts& f);

/// check.json's `surface`.
nlohmann::json surfaceJson(const SurfaceResult& s);

/// stdout's `surface:` line (the lines in the band, the gouge, the scallop and its bound).
std::string surfaceLine(const SurfaceResult& s);

/// Why the path does not hold the finish `max_scallop_um` (empty: it does, or none was asked):
/// a measured scallop over it, one the cusps between the lines may take over it (the lines
/// sample the surface: a cusp may stand up to scallop_grid_error_um higher; a measured 457 um
/// with 24 um between the lines read ok under 460), an unbounded one, lines between passes no
/// pass cut (2 mm of stock read as a finished part, a helper's), or no scallop measured at all
/// (`surface` null or no band: `skipped` says why; one pass read ok under --max-scallop 10).
std::vector<std::string> finishReasons(const SurfaceResult* surface,
                                       const std::optional<double>& max_scallop_um,
                                       const char* skipped);

}  // namespace fieldpath::app
