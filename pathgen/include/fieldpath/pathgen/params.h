#pragma once
/// Settings of the pass generation (scene `path:` and `links:` blocks). Defaults documented here,
/// once.
#include <optional>

namespace fieldpath::pathgen {

/// The finest `path.step`, mm: a machine's resolution. A finer step only multiplies the postures
/// (1e-5 mm on 80 mm of passes: 8 M of them, minutes of work for one path).
inline constexpr double kMinPathStepMm = 1e-3;

struct PathParams {
  int passes = 7;  ///< `passes`: isoparametric passes of the parametric impeller (≥ 1)
  bool passes_given = false;  ///< the scene names `path.passes` (a nominal path refuses it)
  /// `step`: largest distance between output postures along a pass (ball-centre arc, mm). The
  /// impeller's passes are always stepped so; a nominal path only when `step_given`.
  double step_mm = 0.5;
  bool step_given = false;  ///< the scene names `path.step`: a nominal path is resampled
  double lead_deg = 0.0;    ///< `lead_deg`: nominal lead angle (axis turned about b towards f)
  /// `pass_gap`: consecutive tips of a nominal path farther apart than this start a new pass;
  /// 0: 4 × the median step of the block.
  double pass_gap_mm = 0.0;
};

/// `links:`: how passes are joined (DESIGN.md "Links and motion").
struct LinkParams {
  double retract_mm = 10.0;         ///< `retract`: along the tool axis at each pass end and start
  std::optional<double> safe_z_mm;  ///< `safe_z`: the travel plane; absent (`auto`): computed
};

}  // namespace fieldpath::pathgen
