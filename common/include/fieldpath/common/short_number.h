#pragma once
/// Numbers in messages as a user wrote them: `5`, `0.25`, `1e+06` (printf's %g), not
/// std::to_string's `5.000000`.
#include <cstdio>
#include <string>

namespace fieldpath::common {

inline std::string shortNumber(double value) {
  char text[32];
  std::snprintf(text, sizeof text, "%g", value);
  return text;
}

}  // namespace fieldpath::common
