#pragma once
/// Settings of the pass generation (scene `path:` block). Defaults documented here, once.

namespace fieldpath::pathgen {

struct PathParams {
  int passes = 7;         ///< `passes`: number of isoparametric passes (≥ 1)
  double step_mm = 0.5;   ///< `step`: largest distance between output postures along a pass
  double lead_deg = 0.0;  ///< `lead_deg`: nominal lead angle (axis turned about b towards f)
};

}  // namespace fieldpath::pathgen
