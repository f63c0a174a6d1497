#pragma once
/// Shared test scenes for pathgen.
#include "fieldpath/pathgen/impeller.h"

namespace fieldpath::pathgen::test {

/// A straight, flat, parallel channel 72 × 20 mm with vertical 34 mm walls: closed forms apply.
inline ImpellerParams flatChannel() {
  ImpellerParams p;
  p.bend_mm = 0;
  p.hub_rise_mm = 0;
  p.hub_dish_mm = 0;
  p.width_in_mm = p.width_out_mm = 20;
  p.lean_left_deg = {0, 0};
  p.lean_right_deg = {0, 0};
  return p;
}

}  // namespace fieldpath::pathgen::test
