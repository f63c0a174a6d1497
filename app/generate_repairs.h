#pragma once
/// What `generate` changed from DESIGN's plain recipe where that collided or came under the
/// clearance (passes written with their nominal axes, link ends taken off the pass's axis): their
/// report.json entries and the lines said of them.
#include <nlohmann/json.hpp>

#include "fieldpath/pathgen/generate.h"

namespace fieldpath::app {

/// report.json `kept_nominal`: one entry a pass written with its nominal axes.
nlohmann::json keptNominalJson(const pathgen::GenerateResult& r);

/// report.json `links.routed_off_axis`: one entry a link end taken off its pass's axis.
nlohmann::json routedLinkEndsJson(const pathgen::GenerateResult& r);

/// The warnings and notes of both, on stderr.
void printRepairs(const pathgen::GenerateResult& result, double links_retract_mm);

}  // namespace fieldpath::app
