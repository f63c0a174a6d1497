#pragma once
/// An OBJ's vertex and face lines checked for the line a fault is on. assimp 5.2 says only "OBJ:
/// Invalid face index.", "vertex index out of range" or, after validation, "mIndices[..] out of
/// range", with no line (a blisk helper's file: one typo in 90 000 lines), and numbers vertices
/// as it expands them (a NaN on line 4 read "vertex 6"). Run where assimp refused the file or a
/// vertex or face came out wrong: a diagnosis, not a second reader.
#include <filesystem>
#include <string>

namespace fieldpath::geometry::detail {

/// "FILE:LINE: ..." for the first statement (lines joined where one ends in `\`, as OBJ
/// continues them; keys after leading blanks) that is a vertex (`v`) without three finite
/// coordinates, or a face (`f`) whose vertex index is not an integer, is 0, or names a vertex the
/// file does not have (1-based; a negative index counts back from the vertices read so far, as
/// OBJ says); ": no vertex ..." for a file of none (comments only, or another format saved as
/// .obj); empty where none of these is.
std::string objFault(const std::filesystem::path& file);

/// "FILE:LINE: ..." for the first statement whose key is no OBJ polygon statement: free-form
/// geometry (`cstype`, `curv`, `surf`, ...: a part given so would lose those surfaces; assimp
/// then dropped the faces after them, "Mesh contains no faces"), `call` (another file's
/// statements), or a key OBJ does not have (`foo 1 2 3` was read by assimp as a face, its first
/// letter's: a triangle more, without a word, an adversary's). Empty where every key is one.
/// Run before assimp reads the file.
std::string objStatementFault(const std::filesystem::path& file);

}  // namespace fieldpath::geometry::detail
