/// The Z-buffer's output files against their formats: heights.npy (header, shape, C order),
/// heights.json, surface.stl (triangles between line centres; on big grids every k-th line, each
/// the lowest of its block, the last kept), heights.png (and with zlib, its chunks' CRCs and
/// scanlines inflated independently).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#ifdef FIELDPATH_TEST_ZLIB
#include <zlib.h>
#endif

#include "fieldpath/zbuffer/outputs.h"
#include "fieldpath/zbuffer/simulator.h"

namespace fieldpath::zbuffer {
namespace {

TEST(Outputs, NpyJsonStlPngAreWellFormed) {
  const auto dir = std::filesystem::temp_directory_path() / "fieldpath_zbuffer_outputs";
  std::filesystem::create_directories(dir);
  const Grid g = Grid::fromRegion(0, 0, 3, 2, 3, 2);
  const std::vector<float> h = {1, 2, 3, 4, 5, 6};
  writeHeightsNpy(dir / "h.npy", g, h);
  std::ifstream in(dir / "h.npy", std::ios::binary);
  std::string data((std::istreambuf_iterator<char>(in)), {});
  ASSERT_EQ(data.substr(0, 6), "\x93NUMPY");
  const std::size_t header = std::uint8_t(data[8]) | (std::uint8_t(data[9]) << 8);
  EXPECT_EQ((10 + header) % 64, 0u);
  EXPECT_NE(data.find("'shape': (2, 3)"), std::string::npos);
  ASSERT_EQ(data.size(), 10 + header + 6 * 4);
  float last;
  std::memcpy(&last, data.data() + data.size() - 4, 4);
  EXPECT_EQ(last, 6.f);
  EXPECT_EQ(writeSurfaceStl(dir / "s.stl", g, h), 4u);
  {
    std::ifstream stl(dir / "s.stl", std::ios::binary);
    const std::string s((std::istreambuf_iterator<char>(stl)), {});
    ASSERT_EQ(s.size(), 84u + 4 * 50);
    // first triangle: lines (0,0), (1,0), (1,1) at (0.5,0.5,1), (1.5,0.5,2), (1.5,1.5,5)
    float f[12];
    std::memcpy(f, s.data() + 84, sizeof f);
    const float want[9] = {0.5f, 0.5f, 1, 1.5f, 0.5f, 2, 1.5f, 1.5f, 5};
    for (int k = 0; k < 9; ++k) EXPECT_EQ(f[3 + k], want[k]) << k;
    // unit normal of the plane z = 1 + (x - 0.5) + 3 (y - 0.5): (-1, -3, 1) / sqrt(11), facing up
    const float n[3] = {-1.f, -3.f, 1.f};
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(f[k], n[k] / std::sqrt(11.f), 1e-6f) << k;
  }
  {
    // Every 3rd line of an 11 x 11 grid at most 4 a side: lines 0 3 6 9 and 10 (the last, the
    // region's edge, was dropped); a cut two lines wide between kept lines stays as the lowest
    // of the lines a kept one stands for (it vanished: a helper's finding).
    const Grid big = Grid::fromRegion(0, 0, 11, 11, 11, 11);
    std::vector<float> flat(121, 1.f);
    flat[4 * 11 + 4] = flat[4 * 11 + 5] = -0.5f;  // lines (4, 4) and (5, 4)
    EXPECT_EQ(writeSurfaceStl(dir / "big.stl", big, flat, 4), 2u * 4u * 4u);
    std::ifstream stl(dir / "big.stl", std::ios::binary);
    const std::string s((std::istreambuf_iterator<char>(stl)), {});
    ASSERT_EQ(s.size(), 84u + 32 * 50);
    float lowest = 1.f, x_max = 0.f;
    for (std::size_t t = 0; t < 32; ++t)
      for (int v = 0; v < 3; ++v) {
        float p3[3];
        std::memcpy(p3, s.data() + 84 + t * 50 + 12 + v * 12, sizeof p3);
        lowest = std::min(lowest, p3[2]);
        x_max = std::max(x_max, p3[0]);
      }
    EXPECT_EQ(lowest, -0.5f);
    EXPECT_EQ(x_max, 10.5f);  // the last line's centre
  }
  writeReliefPng(dir / "r.png", g, h);
  std::ifstream png(dir / "r.png", std::ios::binary);
  std::string p((std::istreambuf_iterator<char>(png)), {});
  EXPECT_EQ(p.substr(1, 3), "PNG");
  EXPECT_EQ(p.substr(p.size() - 8, 4), "IEND");
  writeHeightsJson(dir / "h.json", g);
  std::ifstream js(dir / "h.json");
  std::string j((std::istreambuf_iterator<char>(js)), {});
  EXPECT_NE(j.find("\"shape\":[2,3]"), std::string::npos);
  std::filesystem::remove_all(dir);
}

#ifdef FIELDPATH_TEST_ZLIB
/// Reads a big-endian u32 at `at`.
std::uint32_t be32(const std::string& s, std::size_t at) {
  std::uint32_t v = 0;
  for (int k = 0; k < 4; ++k) v = (v << 8) | static_cast<std::uint8_t>(s[at + k]);
  return v;
}

TEST(Outputs, PngDecodesToTheSamePixels) {
  // Independent check with zlib: every chunk's CRC, and the inflated scanlines equal the input.
  const int w = 37, h = 11;
  std::vector<std::uint8_t> rgb(3 * w * h);
  std::mt19937 rng(7);
  for (std::size_t i = 0; i < rgb.size(); ++i) rgb[i] = (i % 5 == 0) ? rng() & 0xff : i & 0xff;
  const std::string png = encodePng(w, h, rgb);
  ASSERT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
  std::string idat;
  for (std::size_t at = 8; at < png.size();) {
    const std::uint32_t len = be32(png, at);
    const std::string type = png.substr(at + 4, 4);
    const uLong crc = crc32(0L, reinterpret_cast<const Bytef*>(png.data() + at + 4), len + 4);
    EXPECT_EQ(be32(png, at + 8 + len), crc) << type;
    if (type == "IHDR") {
      EXPECT_EQ(be32(png, at + 8), std::uint32_t(w));
      EXPECT_EQ(be32(png, at + 12), std::uint32_t(h));
    }
    if (type == "IDAT") idat += png.substr(at + 8, len);
    at += 12 + len;
  }
  std::string raw(h * (3 * w + 1), '\xff');
  uLongf size = raw.size();
  ASSERT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &size,
                       reinterpret_cast<const Bytef*>(idat.data()), idat.size()),
            Z_OK);
  ASSERT_EQ(size, raw.size());
  for (int y = 0; y < h; ++y) {
    EXPECT_EQ(raw[y * (3 * w + 1)], 0) << "filter byte of row " << y;
    EXPECT_EQ(0, std::memcmp(raw.data() + y * (3 * w + 1) + 1, rgb.data() + 3 * w * y, 3 * w))
        << "row " << y;
  }
}

/// The RGB pixels of a PNG the encoder wrote (one IDAT stream, filter 0 rows), read with zlib.
std::vector<std::uint8_t> decodeRgb(const std::string& png, int& w, int& h) {
  std::string idat;
  for (std::size_t at = 8; at < png.size();) {
    const std::uint32_t len = be32(png, at);
    const std::string type = png.substr(at + 4, 4);
    if (type == "IHDR") w = int(be32(png, at + 8)), h = int(be32(png, at + 12));
    if (type == "IDAT") idat += png.substr(at + 8, len);
    at += 12 + len;
  }
  std::string raw(std::size_t(h) * (3 * w + 1), '\0');
  uLongf size = raw.size();
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(raw.data()), &size,
                       reinterpret_cast<const Bytef*>(idat.data()), idat.size()),
            Z_OK);
  std::vector<std::uint8_t> rgb;
  for (int y = 0; y < h; ++y)
    rgb.insert(rgb.end(), raw.begin() + y * (3 * w + 1) + 1, raw.begin() + (y + 1) * (3 * w + 1));
  return rgb;
}

// heights.png: a pixel of k × k lines shows their lowest (a pit one line wide stays in the
// picture), tinted blue where low and red where high, and row 0 is the largest y (README). A flat
// 8 × 8 grid at 5 mm with one line at 0 (x 3, y 6), drawn 4 × 4: the pit is the pixel of column 1,
// top row; the bottom row is flat. (Only the PNG's wellformedness was read: a pixel taking its
// last line, or the image upside down, passed.)
TEST(Outputs, ReliefShowsEachPixelsLowestLineWithYUp) {
  const auto dir = std::filesystem::temp_directory_path() / "fieldpath_zbuffer_relief";
  std::filesystem::create_directories(dir);
  const Grid g = Grid::fromRegion(0, 0, 8, 8, 8, 8);
  std::vector<float> heights(64, 5.0f);
  heights[6 * 8 + 3] = 0.0f;
  writeReliefPng(dir / "r.png", g, heights, 4);
  std::ifstream in(dir / "r.png", std::ios::binary);
  const std::string png((std::istreambuf_iterator<char>(in)), {});
  int w = 0, h = 0;
  const std::vector<std::uint8_t> rgb = decodeRgb(png, w, h);
  ASSERT_EQ(w, 4);
  ASSERT_EQ(h, 4);
  const auto px = [&](int x, int y) { return &rgb[(std::size_t(y) * w + x) * 3]; };
  EXPECT_GT(px(1, 0)[2], px(1, 0)[0]);  // the pit: low, blue over red
  for (int x = 0; x < 4; ++x) EXPECT_GT(px(x, 3)[0], px(x, 3)[2]) << x;  // flat and high
  std::filesystem::remove_all(dir);
}
#endif

}  // namespace
}  // namespace fieldpath::zbuffer
