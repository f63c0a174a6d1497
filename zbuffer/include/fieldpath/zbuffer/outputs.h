#pragma once
/// Height-map outputs (DESIGN.md "Height map"), each written atomically (temporary, then rename).
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {

/// heights.npy: NumPy v1.0, '<f4', shape (ny, nx), C order (row = iy).
void writeHeightsNpy(const std::filesystem::path& file, const Grid& grid,
                     std::span<const float> heights_mm);
/// heights.json: {"origin":[x0,y0],"spacing":[dx,dy],"shape":[ny,nx]}.
void writeHeightsJson(const std::filesystem::path& file, const Grid& grid);
/// Binary STL of the simulated surface: two triangles per cell between line centres, facing up.
/// Grids above max_side lines per side keep every k-th line (k = ceil(side / max_side)) and the
/// last, each at the lowest height of the lines nearest to it (a gouge narrower than k lines
/// stays). Returns the triangle count.
std::size_t writeSurfaceStl(const std::filesystem::path& file, const Grid& grid,
                            std::span<const float> heights_mm, int max_side = 2048);
/// Shaded relief (8-bit RGB PNG, light from the north-west, tinted by height), at most max_side
/// pixels per side; row 0 of the image is the largest y.
void writeReliefPng(const std::filesystem::path& file, const Grid& grid,
                    std::span<const float> heights_mm, int max_side = 4096);

/// Minimal PNG encoder: 8-bit RGB, row-major, top row first. Compressed with zlib where it is
/// installed, stored (uncompressed) deflate blocks otherwise.
std::string encodePng(int width, int height, std::span<const std::uint8_t> rgb);

}  // namespace fieldpath::zbuffer
