#pragma once
/// Size estimates of a scene's job, made from its keys before the heavy work allocates anything
/// (DESIGN.md: "sizes are estimated before allocation and refused with the estimate"). Each check
/// throws common::InputError "SCENE: KEY: needs about E of memory (...), limit L (--max-memory)"
/// naming the key that drives the size, against common::memoryLimitBytes().
#include <cstddef>
#include <filesystem>
#include <string>

#include "fieldpath/common/memory.h"
#include "fieldpath/geometry/cl_file.h"
#include "fieldpath/pathgen/impeller.h"
#include "scene.h"

namespace fieldpath::app {

/// Bytes a mesh triangle costs once loaded: the mesh itself (≈ 30 B) and FCL's OBBRSS hierarchy
/// over it (two nodes of ≈ 250 B per triangle), rounded up.
inline constexpr double kBytesPerMeshTriangle = 600.0;
/// Bytes an obstacle sample costs: point, normal, weight (56 B) grown by push_back (× 2) and the
/// point index, rounded up.
inline constexpr double kBytesPerSample = 128.0;
/// Bytes an output posture costs through generate: the steered posture with its angles, the path
/// and its APT / CSV text, the clearance and motion results, the cutter's stamps along the
/// motions. Measured: the mesh example's nominal path repeated 10 times (20 118 postures) peaked
/// 49.7 MB over the example's own (2 012): 2.7 KB a posture (512 was assumed: a 1 M posture path
/// ran past an accepted --max-memory by 10 times, a memory sweep's). With the repairs' memos the
/// same passes reversed (each steered again from its end) 55.2 MB over 18 090: 3.05 KB, within 1 %
/// of 3 KB; 3.5 KB leaves the estimate ~7 % over that job's peak (reliability.md 41).
inline constexpr double kBytesPerPosture = 3584.0;

/// The parametric impeller's meshes (driven by `chord_tol` and the dimensions), before they are
/// made. `where` is "SCENE:LINE: ".
void checkImpellerSize(const pathgen::Impeller& impeller, const std::string& where);

/// What loadScene can know once the meshes are loaded: the obstacle samples (`field.sample_step`
/// against the obstacles' area), `field.r0` against the obstacles' extent, and the output
/// postures (`path.step`, `path.passes` against the passes' length).
void checkSceneSize(const Scene& scene);

/// The output postures of generate (`path.step`, `path.passes` against the passes' length, or a
/// nominal path's one for one); `use`: held by generate, previewed by loadScene.
void requirePostures(const Scene& scene, common::MemoryUse use);

/// The obstacle samples at `step_mm` (the scene's `field.sample_step` or an option overriding it,
/// named by `key`); `use`: held for the run, or a study's variant's made and dropped.
void checkSampleStep(const Scene& scene, double step_mm, const std::string& key,
                     common::MemoryUse use);

/// The uniform voxel grid of `field.voxel_size` (or `--voxel`) = `voxel_mm`: the shell within r0
/// of the obstacles, at most their box padded by r0 (the field module estimates refinement).
/// `key` names where h came from.
void checkVoxelSize(const Scene& scene, double voxel_mm, const std::string& key);

/// About how many postures a path file holds, from its size: `.npy` rows of 24 bytes (float32
/// N×6; float64 counts double), text by the line length of its first 64 KiB (5-axis lines of
/// 32-bit values run ~60 bytes, 3-axis ones ~35). 0 where the file cannot be read (the reader
/// then says why). InputError for text (.cl, APT) with NUL bytes in its first 64 KiB.
double estimatePostures(const std::filesystem::path& file);

/// A path file read whole (geometry::readPathFile): ~80 bytes a posture held (a Posture, its
/// line, its block). Refused before the read above --max-memory, `what` naming where the file
/// came from, and a text file of NUL bytes at once (a helper's sparse 10 GB path.nominal was
/// mapped whole, 16 GiB reserved, 15-48 s before its first line was refused).
void checkPathFileSize(const std::filesystem::path& file, const std::string& what);

/// geometry::readPathFile after checkPathFileSize, refused when the file changed while it was
/// read (a path rewritten in place meanwhile gave a mix of both files' postures, exit 0).
geometry::PathFile readPathFileWhole(const std::filesystem::path& file, const std::string& what);

/// The obstacle samples at `step_mm`: the count sampleObstacles makes, to the sample, but for a
/// bound on the merged ones of triangles finer than the step.
double sampleCount(const Scene& scene, double step_mm);

}  // namespace fieldpath::app
