#pragma once
/// The text of a JSON output file (report.json, check.json, simulate.json).
#include <string>

#include <nlohmann/json.hpp>

namespace fieldpath::app {

/// Indented, with a final newline. Bytes that are not UTF-8 (a file name given in another
/// encoding) are written as U+FFFD: the file stays valid JSON and the run does not fail.
inline std::string jsonText(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace fieldpath::app
