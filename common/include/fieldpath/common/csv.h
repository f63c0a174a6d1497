#pragma once
/// CSV cells for numbers: CSV readers (spreadsheets, numpy, pandas) disagree on `inf` / `nan`, so
/// a non-finite value (no obstacle within reach, no motion after the last posture) is an empty
/// cell, never text that one reader takes and another chokes on.
#include <cmath>
#include <ostream>

namespace fieldpath::common {

struct CsvNumber {
  double value;
};

/// `csv << csvNumber(x)`: x, or nothing when x is inf or nan.
inline CsvNumber csvNumber(double value) { return {value}; }

inline std::ostream& operator<<(std::ostream& os, CsvNumber n) {
  if (std::isfinite(n.value)) os << n.value;
  return os;
}

}  // namespace fieldpath::common
