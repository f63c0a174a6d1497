#pragma once
/// An STL file's structure checked before assimp reads it: assimp 5.2 reads a cut ASCII STL,
/// a facet of 4 vertices or a binary STL shorter than its count without a word, and refuses
/// exporters' dialects (capital keywords, unreadable normals, text after `endsolid`) with a dump
/// of the file: what it is to read is decided here.
#include <cstdint>
#include <filesystem>
#include <string>

namespace fieldpath::geometry::detail {

/// How assimp is to read an STL: the file as it is, or a copy in memory (`length` bytes of it,
/// in lower case where `lower`).
struct StlFeed {
  bool copy = false;
  bool lower = false;
  /// A binary header starting with a UTF-8 byte-order mark's bytes: assimp skips them as text
  /// (and misreads the count, "Failed to determine STL storage"), so the copy has them blank.
  bool blank_mark = false;
  /// ASCII facets whose normal assimp cannot read (MSVC's `-nan(ind)`, `1.#QNAN`, or no
  /// `normal` word: it refused the file with a dump of its text): every facet's normal written
  /// 0 0 0 in the copy (the triangles' normals come from their winding).
  bool zero_normals = false;
  /// Bytes of white space before `solid` (a blank first line: "Failed to determine STL storage
  /// representation"), left out of the copy.
  std::uintmax_t skip = 0;
  std::uintmax_t length = 0;
  bool ascii = false;
  std::uintmax_t triangles = 0;  ///< its header's count (binary) or its facets (ASCII)
};

/// `text` (an ASCII STL) with every `facet ...` line written `facet normal 0 0 0`.
std::string zeroFacetNormals(const std::string& text);

/// How assimp is to read `file` (`size` bytes): a default feed for a file that is no STL by its
/// extension. Throws common::InputError "FILE[:LINE]: ..." for an STL assimp would misread.
StlFeed checkStl(const std::filesystem::path& file, std::uintmax_t size);

}  // namespace fieldpath::geometry::detail
