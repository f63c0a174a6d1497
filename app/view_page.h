#pragma once
/// The page of `fieldpath view`: one HTML file that opens from the disk in any current browser,
/// with no server and no network. The template, its style and script (app/view/) are compiled
/// into the program; three.js and its OrbitControls come from Debian's libjs-three at run time
/// and are inlined; the geometry travels as base64 typed arrays described by a JSON block,
/// decimated to the budgets below.
#include <cstddef>
#include <filesystem>
#include <string>

#include "view_data.h"

namespace fieldpath::app {

/// Where three.js is looked for: $FIELDPATH_THREE_DIR, else Debian's libjs-three folder.
std::filesystem::path threeJsDir();

/// three.min.js and examples/js/controls/OrbitControls.js of `dir`. Throws common::InputError
/// naming the missing file and the package that has it.
struct ThreeJs {
  std::string three, orbit_controls;
};
ThreeJs loadThreeJs(const std::filesystem::path& dir);

struct PageBudget {
  std::size_t max_triangles = 200'000;  ///< scene meshes together (the tool is extra, small)
  std::size_t max_postures = 50'000;    ///< postures of the slider; flagged ones always kept
};

struct PageStats {
  std::size_t bytes = 0;
  std::size_t triangles = 0, source_triangles = 0;
  std::size_t shown_postures = 0;
};

/// The page. `generator` (the command line) goes into a meta tag.
std::string viewPage(const ViewData& data, const ThreeJs& three, const PageBudget& budget,
                     const std::string& generator, PageStats* stats = nullptr);

}  // namespace fieldpath::app
