#pragma once
/// A PLY file's structure checked before assimp reads it: assimp 5.2 trusts what a PLY says
/// (loops forever on some malformed headers, sizes its allocations from element counts, reads a
/// binary body past the file's end), so whatever it would take for PLY is read here first.
#include <cstdint>
#include <filesystem>

namespace fieldpath::geometry::detail {

/// Nothing for a file assimp would not take for PLY (neither `ply` at its start nor a .ply
/// extension). Else throws common::InputError "FILE:LINE: PLY header: ..." for a header outside
/// the standard's grammar, and "FILE: ... PLY: ..." for a body that does not hold what the header
/// declares (an ASCII body's lines, a binary body's bytes walked element by element). Returns
/// the bytes of a header assimp must read with CRLF line ends (a binary body whose first byte is
/// 0x0A after `end_header\n`: assimp 5.2 takes that byte for the line end's and misreads the
/// body), else 0.
std::uintmax_t checkPly(const std::filesystem::path& file, std::uintmax_t size);

}  // namespace fieldpath::geometry::detail
