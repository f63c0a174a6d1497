#pragma once
/// Reads the PNG screenshots of headless Chromium in the view tests: 8-bit RGB or RGBA,
/// non-interlaced (what Chromium writes), through zlib. Returns an empty image for anything else.
#include <array>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include <zlib.h>

namespace fieldpath::test {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, row 0 at the top
  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = 3 * (std::size_t(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

inline Image readPng(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const auto u32 = [&](std::size_t at) {
    return (std::uint32_t(std::uint8_t(data[at])) << 24) |
           (std::uint32_t(std::uint8_t(data[at + 1])) << 16) |
           (std::uint32_t(std::uint8_t(data[at + 2])) << 8) |
           std::uint32_t(std::uint8_t(data[at + 3]));
  };
  if (data.size() < 8 || data.compare(0, 8, "\x89PNG\r\n\x1a\n") != 0) return {};
  Image image;
  int channels = 0;
  std::string idat;
  for (std::size_t at = 8; at + 12 <= data.size();) {
    const std::uint32_t length = u32(at);
    const std::string type = data.substr(at + 4, 4);
    if (at + 12 + length > data.size()) return {};
    if (type == "IHDR") {
      image.width = int(u32(at + 8));
      image.height = int(u32(at + 12));
      const int depth = std::uint8_t(data[at + 16]), colour = std::uint8_t(data[at + 17]);
      const int interlace = std::uint8_t(data[at + 20]);
      if (depth != 8 || interlace != 0 || (colour != 2 && colour != 6)) return {};
      channels = colour == 2 ? 3 : 4;
    } else if (type == "IDAT") {
      idat += data.substr(at + 8, length);
    }
    at += 12 + length;
  }
  if (channels == 0 || image.width <= 0 || image.height <= 0) return {};
  const std::size_t stride = std::size_t(image.width) * channels;
  std::vector<std::uint8_t> raw((stride + 1) * image.height);
  uLongf raw_size = raw.size();
  if (uncompress(raw.data(), &raw_size, reinterpret_cast<const Bytef*>(idat.data()), idat.size()) !=
          Z_OK ||
      raw_size != raw.size())
    return {};
  std::vector<std::uint8_t> pixels(stride * image.height), zero(stride, 0);
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t filter = raw[y * (stride + 1)];
    const std::uint8_t* src = &raw[y * (stride + 1) + 1];
    std::uint8_t* row = &pixels[y * stride];
    const std::uint8_t* up = y > 0 ? &pixels[(y - 1) * stride] : zero.data();
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= std::size_t(channels) ? row[i - channels] : 0, b = up[i],
                c = i >= std::size_t(channels) ? up[i - channels] : 0;
      int predictor = 0;
      switch (filter) {
        case 0:
          predictor = 0;
          break;
        case 1:
          predictor = a;
          break;
        case 2:
          predictor = b;
          break;
        case 3:
          predictor = (a + b) / 2;
          break;
        case 4: {
          const int p = a + b - c, pa = std::abs(p - a), pb = std::abs(p - b), pc = std::abs(p - c);
          predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
          break;
        }
        default:
          return {};
      }
      row[i] = std::uint8_t(src[i] + predictor);
    }
  }
  image.rgb.resize(3 * std::size_t(image.width) * image.height);
  for (std::size_t p = 0; p < std::size_t(image.width) * image.height; ++p)
    for (int k = 0; k < 3; ++k) image.rgb[3 * p + k] = pixels[p * channels + k];
  return image;
}

}  // namespace fieldpath::test
