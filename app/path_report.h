#pragma once
/// The JSON blocks and the messages about a checked path that `generate` and `check` both write
/// (report.json, check.json, their warnings and notes), defined in path_report.cpp.
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/pathgen/clearance.h"
#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/link_check.h"
#include "fieldpath/pathgen/machine_moves.h"
#include "scene.h"

namespace fieldpath::app {
/// JSON null for a missing index (npos), else the index.
nlohmann::json jsonIndex(std::size_t i);

/// A finite number, or null (JSON has no inf / nan).
nlohmann::json jsonNumber(double value);

/// The `clearance` block of report.json and check.json (posture and obstacle indices 0- and
/// 1-based as printed; null when there is none); `min_obstacle_name` names the nearest obstacle
/// as the scene gives it (app/scene.h obstacleName; empty: null).
nlohmann::json clearanceJson(const pathgen::ClearanceResult& c, double required_mm,
                             double chord_tol_mm, const std::string& min_obstacle_name);

/// The `motions` block of report.json and check.json (motion i: posture i → i + 1).
nlohmann::json motionsJson(const pathgen::MotionResult& m, double required_mm,
                           double resolution_mm);

/// A block of the part's contacts (LinkPartResult) as report.json and check.json write it, its
/// counts named `postures_key` / `motions_key` and its `method` said.
nlohmann::json partContactsJson(const pathgen::LinkPartResult& r, const char* postures_key,
                                const char* motions_key, const char* method);

/// The `link_part` block of report.json and check.json: the links against the part (null with the
/// reason when the job has no part or no links).
nlohmann::json linkPartJson(const std::optional<pathgen::LinkPartResult>& l);

/// The `holder_part` block of report.json and check.json: the holder against the part at every
/// posture and motion (null with the reason when the job has no part or no holder).
nlohmann::json holderPartJson(const std::optional<pathgen::LinkPartResult>& h);

/// The `cutter_part` block of report.json and check.json: the cutter against the part, exactly
/// (null with the reason when the job has no part or a flat end).
nlohmann::json cutterPartJson(const std::optional<pathgen::CutterPartResult>& c);

/// The digest of what a check reads of its scene: the scene file and every mesh it loads (the
/// part and the obstacles, in order), joined; `view --check` refuses a check whose scene or
/// meshes have changed since (a part added after the check left its contacts unshown).
std::string sceneDigest(const Scene& scene);

/// The path's largest axis turn between two postures of a pass (pathgen::largestAxisTurn), for
/// report.json and check.json: deg, the first posture (null: no pass of two), ball-centre step.
nlohmann::json axisTurnJson(const pathgen::AxisTurn& t);

/// The warning for a turn over kNoteAxisTurnDeg (empty otherwise), postures numbered from 0 with
/// the file's line where it has one.
std::string axisTurnWarning(const geometry::PathFile& path, const pathgen::AxisTurn& t);

/// The block posture i lies in, as a user reads it: "pass K" (numbered from 1, as `# pass K`),
/// "the link into pass K", "the link after the last pass" ("a link" in a path of links only);
/// empty past the blocks.
std::string blockOf(const geometry::PathFile& path, std::size_t i);

/// "posture i (BLOCK, FILE:LINE)": the posture a reason names, with the block `block_of` lies in
/// (i's own, or for a motion the end that makes it a link's) and i's file line where the path was
/// read from a file (a reviewer: "posture 5123" alone sent users counting through a 40 000-line
/// file, and did not say the fault was a link's).
std::string postureWhere(const geometry::PathFile& path, std::size_t i, std::size_t block_of);
std::string postureWhere(const geometry::PathFile& path, std::size_t i);

/// Whether posture i lies in a link block.
bool inLink(const geometry::PathFile& path, std::size_t i);

/// inLink for every posture at once (one pass over the blocks, where inLink scans them per call).
std::vector<bool> linkMask(const geometry::PathFile& path);

/// "posture i to the next (BLOCK, FILE:LINE)": motion i, from posture i to i + 1, in the block of
/// the end that makes it a link's (the retract and the plunge are), else i's own: a move from one
/// pass straight into the next is named with the pass it leaves, at the line it leaves from (a
/// helper read "pass 5" beside the last line of pass 4).
std::string motionWhere(const geometry::PathFile& path, std::size_t i);

/// " in passes 1, 2 and 28" (up to 8 named, then "and N more"; links as "links"): the blocks of
/// the postures whose clearance reads 0 (`posture_mm`: ClearanceResult::clearance_mm, empty where
/// it was not kept); empty when none. A summary named the first colliding posture only, and which
/// passes collide was in report.json only (a CAM engineer's mould: 19 passes).
std::string collidingPasses(const geometry::PathFile& path, const std::vector<double>& posture_mm);

/// Why a path is not safe to run as it stands (empty: it is): postures or motions that touch an
/// obstacle, links that touch the part, the holder touching the part. Postures numbered from 0,
/// as in the JSON and clearance.csv, with their block and line (postureWhere); motion i from
/// posture i to i + 1, a link's when either end is (the retract and the plunge are). A reason
/// whose first posture or motion is a link's ends with `link_hint` where one is given (`generate`
/// made the links: it says which keys move them; `check` reads the user's).
std::vector<std::string> unsafeReasons(const geometry::PathFile& path,
                                       const pathgen::ClearanceResult& c,
                                       const pathgen::MotionResult& m,
                                       const std::optional<pathgen::LinkPartResult>& l,
                                       const std::optional<pathgen::LinkPartResult>& h,
                                       const std::string& link_hint = {});

/// What the cutter does to the part, beyond the gouge tolerance (empty: nothing): not a crash and
/// not in `unsafe` (a part meshed with a 20 um chordal error reads a path on its true surface as
/// entering it by up to that, where it is concave: a reviewer's case), but `check`'s not-ok and
/// `generate`'s warning. Postures numbered from 0, with their block and line (postureWhere);
/// motion i from posture i to i + 1.
std::string cutterGougeReason(const geometry::PathFile& path,
                              const std::optional<pathgen::CutterPartResult>& cut);

/// What a post-processor writing rotary angles would do to the path's motions
/// (pathgen::rotaryStray), for report.json and check.json.
nlohmann::json rotaryJson(const pathgen::RotaryStray& s, double reach_mm);

/// The warning where interpolated rotary angles stray past a motion's clearance (empty
/// otherwise): not part of `unsafe` (the checked motion is the tool vector's), said so that
/// whoever posts the path knows which output the proof holds for.
std::string rotaryWarning(const geometry::PathFile& path, const pathgen::RotaryStray& s,
                          const pathgen::MotionResult& m);

/// The rapids a controller running them axis by axis is proven to run clear
/// (pathgen::dogLegRapids), for report.json and check.json.
nlohmann::json dogLegJson(const pathgen::DogLegRapids& d);

/// The warning where some passes, not all, keep the ball farther than `far_mm` from the part at
/// every posture (empty otherwise; all of them is the path's own warning): they cut nothing, most
/// often passes beside a part turned or offset, or a path in other units (a units adversary's:
/// a part turned 90 deg under a raster left 22 of 31 passes beside it, unsaid). Postures alone
/// are counted, not warned: a raster's run-off past the part's edge keeps a third of them far.
std::string farPassesWarning(const geometry::PathFile& path, const pathgen::FarFromPart& c,
                             double far_mm);

/// The note where some rapids are proven clear of the obstacles only as straight moves, or where
/// the scene has a part, which the bound leaves out (empty otherwise): a controller whose rapids
/// are not linear may leave them (a machine-side helper's dog-leg of the impeller's retract came
/// 0.245 mm from a blade, under the 0.5 required; a verifier's X-first retract out of a pass on a
/// sloped plate cut 1.17 mm into the part).
std::string dogLegNote(const geometry::PathFile& path, const pathgen::DogLegRapids& d,
                       const pathgen::MotionResult& m, bool has_part);

/// The note where colliding postures of a steered path have an angle held at its limit (empty
/// otherwise): how many, which angle at which limit (`max_lead_deg`, `max_tilt_deg` of
/// dynamics), the first. The UNSAFE line named only the collisions, and the summary's count of
/// limited postures did not say they were the same ones (an oracle found that at the corpus's
/// UNSAFE corners the limits, not the steering, leave the holder in the wall; in three of seven
/// the lead's).
std::string limitsAtCollisionsNote(const pathgen::GenerateResult& r, double max_lead_deg,
                                   double max_tilt_deg);

}  // namespace fieldpath::app
