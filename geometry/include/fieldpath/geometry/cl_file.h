#pragma once
/// Path files (DESIGN.md "Conventions of data"): `.cl` (x y z i j k [spindle_rad] per line, `#`
/// comments) and APT CLDATA.
#include <filesystem>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fieldpath/geometry/posture.h"
#include "fieldpath/geometry/tool.h"

namespace fieldpath::geometry {

/// Reads a `.cl` file. Axes off unit length by < 1e-3 are normalised. Throws common::InputError
/// "FILE:LINE: reason" for non-finite numbers, short/long lines, zero or non-unit axes, garbage,
/// and "FILE: reason" for a missing file or one without postures.
std::vector<Posture> readClFile(const std::filesystem::path& file);

/// Writes a `.cl` file atomically, numbers in shortest round-trip form (reading it back gives the
/// same doubles). The spindle column is written for postures with has_spindle. `comment` lines are
/// prefixed with "# ".
void writeClFile(const std::filesystem::path& file, std::span<const Posture> postures,
                 std::string_view comment = {});

struct AptHeader {
  std::string part_name = "FIELDPATH";
  ToolSpec tool;
  double feed_mm_per_min = 1000;
};

/// Writes APT CLDATA atomically: PARTNO, UNITS/MM, MULTAX/ON, CUTTER/d,r,e,f,a,b,h, FEDRAT/, one
/// GOTO/x,y,z,i,j,k per posture, FINI.
void writeAptFile(const std::filesystem::path& file, std::span<const Posture> postures,
                  const AptHeader& header);

/// Reads the GOTO records of an APT file back (for round-trip tests). Throws common::InputError
/// "FILE:LINE: reason".
std::vector<Posture> readAptFile(const std::filesystem::path& file);

}  // namespace fieldpath::geometry
