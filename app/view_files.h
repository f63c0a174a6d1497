#pragma once
/// Internal to `fieldpath view` (view_data.cpp): the files of a `check` or `simulate` folder read
/// and checked (check.json, the surface's .npy and its grid .json); view_files.cpp. Every reader
/// throws common::InputError naming the file (and the line or key).
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "scene.h"
#include "surface_check.h"
#include "view_data.h"

#include "fieldpath/pathgen/link_check.h"

namespace fieldpath::app::view_files {

/// A JSON file, parsed.
nlohmann::json readJson(const std::filesystem::path& file);

/// The counts of check.json (the page must agree with them) and the path it checked.
struct CheckJson {
  std::size_t postures = 0, colliding_postures = 0, colliding_motions = 0;
  /// check.json `clearance.min_posture`: the closest posture as check named it from its exact
  /// distances (clearance.csv's rounded ones tie; npos: not given).
  std::size_t min_posture = static_cast<std::size_t>(-1);
  std::string path;
  std::string path_digest;  ///< common::fileDigest of the path checked (empty in older check.json)
  std::string scene;        ///< the scene file checked against, as `check` was given it
  std::string scene_digest;  ///< sceneDigest of it and its meshes (empty in older check.json)
  /// check.json `link_part` and `holder_part`: the part's contacts (the page's colours are the
  /// obstacles'), where check found them.
  std::optional<pathgen::LinkPartResult> link_part, holder_part;
  /// check.json `cutter_part`: the counts, the first gouging posture and motion, the depth.
  std::optional<pathgen::CutterPartResult> cutter_part;
};
/// check.json of a `check --out` folder (`--check DIR`).
CheckJson readCheckJson(const std::filesystem::path& dir);

/// What check.json says of the surface (the colour scale agrees with it), where it is known.
struct SurfaceFigures {
  double gouge_tolerance_um = kGougeToleranceUm;
  double max_scallop_um = NAN, max_gouge_um = NAN;
  bool from_check = false;  ///< read from check.json: a null scallop there is "none measured"
};
/// The surface of a `check` (deviation.npy) or `simulate` (heights.npy) folder with its grid,
/// decimated to at most `max_lines` lines; warnings for the page.
ViewSurface readSurface(const std::filesystem::path& dir, const Scene& scene, std::size_t max_lines,
                        const SurfaceFigures& figures, std::vector<std::string>& warnings);

}  // namespace fieldpath::app::view_files
