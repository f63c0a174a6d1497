#pragma once
/// What `generate` says of a finished job on stderr after its summary line (the warnings and
/// notes a user reads first: a gouge, passes far from the part, the clearance, the axis's turns,
/// the nominal's feeds and lead, rotary strays, dog-leg rapids, the repairs, the starts, corners
/// and voxels), and the note of links far outside the meshes kept in report.json too.
#include <string>

#include "fieldpath/pathgen/generate.h"
#include "fieldpath/pathgen/machine_moves.h"
#include "generate_report.h"
#include "scene.h"

namespace fieldpath::app {

/// Where a link's climb along a tilted axis to the travel plane takes the tool farthest outside
/// the scene's meshes in x-y, when by more than a quarter of their size (empty otherwise).
std::string farLinkNote(const Scene& scene, const pathgen::GenerateResult& result);

/// What the messages are of, besides the scene, the job and its result.
struct JobMessages {
  const pathgen::AxisTurn& axis_turn;
  const pathgen::RotaryStray& rotary;
  const pathgen::DogLegRapids& dog_leg;
  const JobNotes& notes;
  bool under_required = false;  ///< postures or motions under `clearance`
};

/// The warnings and notes of a finished job, on stderr, in the order a user reads them.
void printJobMessages(const Scene& scene, const pathgen::GenerateRequest& job,
                      const pathgen::GenerateResult& result, const JobMessages& said);

}  // namespace fieldpath::app
