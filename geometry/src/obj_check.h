#pragma once
/// An OBJ's faces checked for the line a bad vertex index is on. assimp 5.2 says only "OBJ:
/// Invalid face index." or, after validation, "mIndices[..] out of range", with no line (a blisk
/// helper's file: one typo in 90 000 lines). Run where assimp refused the file or a face came
/// out naming no vertex: a diagnosis, not a second reader.
#include <filesystem>
#include <string>

namespace fieldpath::geometry::detail {

/// "FILE:LINE: face index K: WHY (the file has V vertices)" for the first face (`f` line) whose
/// vertex index is not an integer, is 0, or names a vertex the file does not have (1-based; a
/// negative index counts back from the vertices read so far, as OBJ says); empty where every
/// index is good.
std::string objFaceFault(const std::filesystem::path& file);

}  // namespace fieldpath::geometry::detail
