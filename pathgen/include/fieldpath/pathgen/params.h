#pragma once
/// Settings of the pass generation (scene `path:` block). Defaults documented here, once.

namespace fieldpath::pathgen {

struct PathParams {
  int passes = 7;
  double step_mm = 0.5;  ///< between output postures
  double lead_deg = 0.0; ///< nominal lead angle
};

}  // namespace fieldpath::pathgen
