#pragma once
/// What `fieldpath view` shows, gathered with the program's own readers and checks: the scene's
/// meshes and tool, a path with per-posture clearance (from a `check` folder, or computed as
/// `check` computes it), tilt and lead (in the frames of the scene's passes), and a simulated
/// surface (a `check` or `simulate` folder). view_page.h turns this into the page.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "fieldpath/common/progress.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/geometry/mesh.h"
#include "fieldpath/geometry/tool.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::app {

struct ViewMesh {
  enum class Role { Obstacle, Part };
  std::string name;  ///< for the page's toggles: the file name, or "impeller blade 1", ...
  Role role = Role::Obstacle;
  geometry::TriangleMesh mesh;  ///< world frame, mm
};

/// The path shown, posture by posture (all vectors have one entry per posture; NaN: unknown).
struct ViewPath {
  static constexpr std::size_t npos = std::numeric_limits<std::size_t>::max();
  geometry::PathFile file;
  std::string what;  ///< where it came from, for the page ("path.cl", "the scene's path.nominal")
  std::vector<double> clearance_mm;  ///< tool + holder ↔ obstacles, as `check` (0: colliding)
  std::vector<double> motion_mm;     ///< lower bound along the motion to the next posture
  /// 1 where the links, the holder or the cutter (beyond the gouge tolerance) touch the part
  /// (check's link_part, holder_part, cutter_part) at the
  /// posture / on the motion to the next; empty when not known (no part, an older check folder).
  std::vector<std::uint8_t> part_contact, part_contact_to_next;
  std::vector<double> s_mm;          ///< ball-centre arc length from the start of its pass block
  std::vector<double> tilt_deg, lead_deg;  ///< in the frame of the nearest pass station
  std::vector<int> pass;                   ///< 1-based pass block, 0 for link postures
  std::string clearance_source, angles_source;
  bool clearance_known = false;        ///< from a check folder or computed here
  std::size_t colliding_postures = 0;  ///< clearance_mm <= 0
  std::size_t colliding_motions = 0;   ///< motion_mm <= 0
  std::size_t motions_under_required = 0;
  std::size_t postures_under_required = 0;  ///< clearance_mm under the scene's `clearance`
  /// The part's contacts by whose they are (postures + motions): the holder's, the cutter's
  /// beyond the gouge tolerance (a pass posture's mark is either; a link's is the link's).
  std::size_t holder_part_contacts = 0, cutter_part_contacts = 0;
  std::size_t limited_colliding = 0;
  /// Postures whose tip lies far outside the scene's meshes (see gatherView).
  std::size_t outside = 0, first_outside = npos;
};

/// A simulated surface, decimated: one value per block of `stride`² lines of the source grid.
struct ViewSurface {
  zbuffer::Grid grid;            ///< of the decimated arrays (line centres = block centres)
  std::vector<float> height_mm;  ///< machined height; NaN off the part
  /// deviation: machined − part height, µm (gouge < 0 < scallop), the block's deepest gouge
  /// where it has one, else its largest scallop; otherwise the height, mm.
  std::vector<float> value;
  bool deviation = false;
  double uncut_um = 0.0;     ///< deviation at and above which a line was never cut (0: unknown)
  double range[2] = {0, 1};  ///< colour scale (µm or mm)
  std::string source;        ///< for the page
  int stride = 1;
  std::size_t source_lines = 0;
};

struct ViewData {
  std::filesystem::path scene_file;
  std::vector<ViewMesh> meshes;  ///< obstacles in scene order, then the part
  geometry::ToolSpec tool_spec;
  geometry::TriangleMesh tool;  ///< tool + holder in the tool frame (tip at origin, axis +z)
  double required_mm = 0.0;     ///< the scene's `clearance`
  Eigen::AlignedBox3d box;      ///< of the scene's meshes, mm
  std::optional<ViewPath> path;
  std::optional<ViewSurface> surface;
  /// Lines for the page: what is missing (shown in its banner), warnings (also in the banner),
  /// notes (in the side panel).
  std::vector<std::string> missing, warnings, notes;
};

struct ViewRequest {
  std::filesystem::path scene;
  std::filesystem::path path;         ///< empty: the scene's path.nominal, if it names one
  std::filesystem::path check_dir;    ///< empty: clearance computed here (as `check` does)
  std::filesystem::path surface_dir;  ///< empty: the check folder's deviation, if it has one
  /// Lines of the surface at most (decimated in square blocks beyond).
  std::size_t max_surface_lines = 160'000;
  /// Beyond this many postures the clearance is not computed here (use --check).
  std::size_t max_clearance_postures = 20'000;  ///< about 20 s on 2 cores (1 ms a posture)
  common::Progress progress;
};

/// Loads and checks everything. Throws common::InputError (exit 1, one line) for a bad scene or
/// path file, a check folder without check.json / clearance.csv or of another path, a missing
/// or unreadable surface folder, and a path most of whose postures lie far outside the scene's
/// meshes (a path for another scene); a few such postures are a warning on the page.
ViewData gatherView(const ViewRequest& request);

/// `check`'s clearance.csv of `postures` postures: clearance_mm and motion_to_next_mm per
/// posture (NaN for the last motion), and where its last two columns are filled (a scene with a
/// part; older files have neither column) the part contacts (ViewPath::part_contact, left empty
/// otherwise). Throws common::InputError naming the file and line.
void readClearanceCsv(const std::filesystem::path& file, std::size_t postures,
                      std::vector<double>& clearance_mm, std::vector<double>& motion_mm,
                      std::vector<std::uint8_t>& part_contact,
                      std::vector<std::uint8_t>& part_contact_to_next);

/// A NumPy file of float32 ('<f4'), C order, shape (ny, nx) as `check` and `simulate` write
/// heights and deviations. The size is checked against the file before anything is allocated.
/// Throws common::InputError naming the file.
std::vector<float> readGridNpy(const std::filesystem::path& file, int ny, int nx);

/// The vertex-clustering decimation of `mesh` to at most `max_triangles` triangles (cells grown
/// until it fits; degenerate and repeated triangles dropped). The mesh itself when it fits.
geometry::TriangleMesh decimateMesh(const geometry::TriangleMesh& mesh, std::size_t max_triangles);

}  // namespace fieldpath::app
