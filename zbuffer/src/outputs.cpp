#include "fieldpath/zbuffer/outputs.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <sstream>
#include <stdexcept>

#include "fieldpath/common/atomic_file.h"

#ifdef FIELDPATH_HAVE_ZLIB
#include <zlib.h>
#endif

namespace fieldpath::zbuffer {
namespace {

void putU32be(std::string& s, std::uint32_t v) {
  for (int k = 3; k >= 0; --k) s.push_back(static_cast<char>((v >> (8 * k)) & 0xff));
}

#ifdef FIELDPATH_HAVE_ZLIB
std::uint32_t pngCrc(const std::string& typed) {
  return static_cast<std::uint32_t>(
      ::crc32(0L, reinterpret_cast<const Bytef*>(typed.data()), static_cast<uInt>(typed.size())));
}

/// zlib stream of the filtered scanlines, compressed (heights.png is mostly smooth shading).
std::string zlibStream(const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string z(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(z.data()), &size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                6) != Z_OK)
    throw std::runtime_error("PNG: zlib compression failed");
  z.resize(size);
  return z;
}
#else
// Without zlib (the GPU machine builds the Z-buffer alone): CRC-32 and stored (uncompressed)
// deflate blocks, which every PNG reader accepts.
std::uint32_t pngCrc(const std::string& typed) {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xedb88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  std::uint32_t crc = ~0u;
  for (unsigned char c : typed) crc = table[(crc ^ c) & 0xff] ^ (crc >> 8);
  return ~crc;
}

std::string zlibStream(const std::string& raw) {
  std::string z = {'\x78', '\x01'};
  std::uint32_t a = 1, b = 0;
  for (unsigned char c : raw) {
    a = (a + c) % 65521;
    b = (b + a) % 65521;
  }
  for (std::size_t pos = 0; pos < raw.size() || pos == 0; pos += 65535) {
    const std::size_t n = std::min<std::size_t>(65535, raw.size() - pos);
    const bool last = pos + n >= raw.size();
    z.push_back(last ? '\x01' : '\x00');
    z.push_back(static_cast<char>(n & 0xff));
    z.push_back(static_cast<char>(n >> 8));
    z.push_back(static_cast<char>(~n & 0xff));
    z.push_back(static_cast<char>((~n >> 8) & 0xff));
    z.append(raw, pos, n);
    if (last) break;
  }
  putU32be(z, (b << 16) | a);
  return z;
}
#endif

void chunk(std::string& png, const char* type, const std::string& body) {
  putU32be(png, static_cast<std::uint32_t>(body.size()));
  std::string typed = std::string(type, 4) + body;
  png += typed;
  putU32be(png, pngCrc(typed));
}

/// Sampling stride so that a side of n lines gives at most max_side samples.
int strideFor(int n, int max_side) { return std::max(1, (n + max_side - 1) / max_side); }

}  // namespace

std::string encodePng(int width, int height, std::span<const std::uint8_t> rgb) {
  // Filtered scanlines (filter 0: none) in one zlib stream.
  std::string raw;
  raw.reserve(std::size_t(height) * (3 * std::size_t(width) + 1));
  for (int y = 0; y < height; ++y) {
    raw.push_back('\0');
    raw.append(reinterpret_cast<const char*>(rgb.data()) + std::size_t(y) * 3 * width,
               3 * std::size_t(width));
  }
  const std::string z = zlibStream(raw);

  std::string png = "\x89PNG\r\n\x1a\n";
  std::string ihdr;
  putU32be(ihdr, static_cast<std::uint32_t>(width));
  putU32be(ihdr, static_cast<std::uint32_t>(height));
  ihdr += std::string("\x08\x02\x00\x00\x00", 5);  // 8-bit, RGB, deflate, filter 0, no interlace
  chunk(png, "IHDR", ihdr);
  chunk(png, "IDAT", z);
  chunk(png, "IEND", "");
  return png;
}

void writeHeightsNpy(const std::filesystem::path& file, const Grid& grid,
                     std::span<const float> heights_mm) {
  std::ostringstream dict;
  dict << "{'descr': '<f4', 'fortran_order': False, 'shape': (" << grid.ny << ", " << grid.nx
       << "), }";
  std::string header = dict.str();
  const std::size_t total = 10 + header.size() + 1;
  header.append((64 - total % 64) % 64, ' ');
  header.push_back('\n');
  common::writeFileAtomically(
      file,
      [&](std::ostream& out) {
        out.write("\x93NUMPY\x01\x00", 8);
        const std::uint16_t len = static_cast<std::uint16_t>(header.size());
        const char le[2] = {static_cast<char>(len & 0xff), static_cast<char>(len >> 8)};
        out.write(le, 2);
        out << header;
        out.write(reinterpret_cast<const char*>(heights_mm.data()),
                  std::streamsize(heights_mm.size() * sizeof(float)));
      },
      std::ios::out | std::ios::binary);
}

void writeHeightsJson(const std::filesystem::path& file, const Grid& grid) {
  std::ostringstream os;
  os.precision(17);
  // JSON has no inf / nan: such a number is written as null (Grid::fromRegion refuses them, so
  // this is a guard, not a format).
  const auto number = [&os](double v) -> std::ostream& {
    return std::isfinite(v) ? os << v : os << "null";
  };
  os << "{\"origin\":[";
  number(grid.x0_mm) << ",";
  number(grid.y0_mm) << "],\"spacing\":[";
  number(grid.dx_mm) << ",";
  number(grid.dy_mm) << "],\"shape\":[" << grid.ny << "," << grid.nx << "]}\n";
  common::writeTextAtomically(file, os.str());
}

/// The lines a side keeps at stride k: every k-th from the first, and the last (the region's
/// edge: it was dropped), each standing for the lines nearer to it than to its neighbours.
std::vector<int> keptLines(int n, int k) {
  std::vector<int> kept;
  for (int i = 0; i < n; i += k) kept.push_back(i);
  if (kept.back() != n - 1) kept.push_back(n - 1);
  return kept;
}

std::size_t writeSurfaceStl(const std::filesystem::path& file, const Grid& grid,
                            std::span<const float> heights_mm, int max_side) {
  const int sx = strideFor(grid.nx, max_side), sy = strideFor(grid.ny, max_side);
  const std::vector<int> xs = keptLines(grid.nx, sx), ys = keptLines(grid.ny, sy);
  const int mx = static_cast<int>(xs.size()), my = static_cast<int>(ys.size());
  const std::size_t count = mx > 1 && my > 1 ? 2 * std::size_t(mx - 1) * std::size_t(my - 1) : 0;
  // Each kept line at the lowest height of the lines it stands for: a cut narrower than the
  // stride (a gouge) stays in the surface (a 0.5 mm cut two lines wide vanished at 6000 lines).
  const auto span = [](const std::vector<int>& kept, int i, int n) {
    const int lo = i == 0 ? 0 : (kept[i - 1] + kept[i]) / 2 + 1;
    const int hi = i + 1 == int(kept.size()) ? n - 1 : (kept[i] + kept[i + 1]) / 2;
    return std::pair<int, int>(lo, hi);
  };
  std::vector<float> lowest(std::size_t(mx) * my);
  for (int j = 0; j < my; ++j)
    for (int i = 0; i < mx; ++i) {
      const auto [x0, x1] = span(xs, i, grid.nx);
      const auto [y0, y1] = span(ys, j, grid.ny);
      float z = heights_mm[std::size_t(ys[j]) * grid.nx + xs[i]];
      for (int y = y0; y <= y1; ++y)
        for (int x = x0; x <= x1; ++x) z = std::min(z, heights_mm[std::size_t(y) * grid.nx + x]);
      lowest[std::size_t(j) * mx + i] = z;
    }
  const auto point = [&](int i, int j) {
    return Vec3f{static_cast<float>(grid.x0_mm + (xs[i] + 0.5) * grid.dx_mm),
                 static_cast<float>(grid.y0_mm + (ys[j] + 0.5) * grid.dy_mm),
                 lowest[std::size_t(j) * mx + i]};
  };
  common::writeFileAtomically(
      file,
      [&](std::ostream& out) {
        char header[80] = "fieldpath simulate: machined surface (Z-buffer)";
        out.write(header, 80);
        const std::uint32_t n = static_cast<std::uint32_t>(count);
        out.write(reinterpret_cast<const char*>(&n), 4);
        std::vector<char> row;
        const auto tri = [&](Vec3f a, Vec3f b, Vec3f c) {
          const Vec3f u = b - a, v = c - a;
          Vec3f nrm{u.y * v.z - u.z * v.y, u.z * v.x - u.x * v.z, u.x * v.y - u.y * v.x};
          const float len = std::sqrt(dot(nrm, nrm));
          if (len > 0) nrm = (1.f / len) * nrm;
          float f[12] = {nrm.x, nrm.y, nrm.z, a.x, a.y, a.z, b.x, b.y, b.z, c.x, c.y, c.z};
          const std::size_t at = row.size();
          row.resize(at + 50, 0);
          std::memcpy(row.data() + at, f, 48);
        };
        for (int j = 0; j + 1 < my; ++j) {
          row.clear();
          for (int i = 0; i + 1 < mx; ++i) {
            tri(point(i, j), point(i + 1, j), point(i + 1, j + 1));
            tri(point(i, j), point(i + 1, j + 1), point(i, j + 1));
          }
          out.write(row.data(), std::streamsize(row.size()));
        }
      },
      std::ios::out | std::ios::binary);
  return count;
}

void writeReliefPng(const std::filesystem::path& file, const Grid& grid,
                    std::span<const float> heights_mm, int max_side) {
  const int s = std::max(strideFor(grid.nx, max_side), strideFor(grid.ny, max_side));
  const int w = (grid.nx - 1) / s + 1, h = (grid.ny - 1) / s + 1;
  // A pixel of s × s lines shows their lowest (a cut narrower than a pixel stays in the picture).
  std::vector<float> lowest(std::size_t(w) * h, FLT_MAX);
  for (int y = 0; y < grid.ny; ++y)
    for (int x = 0; x < grid.nx; ++x) {
      float& z = lowest[std::size_t(std::min(y / s, h - 1)) * w + std::min(x / s, w - 1)];
      z = std::min(z, heights_mm[std::size_t(y) * grid.nx + x]);
    }
  const auto at = [&](int i, int j) {
    i = std::clamp(i, 0, w - 1);
    j = std::clamp(j, 0, h - 1);
    return lowest[std::size_t(j) * w + i];
  };
  float lo = FLT_MAX, hi = -FLT_MAX;
  for (float z : heights_mm) {
    lo = std::min(lo, z);
    hi = std::max(hi, z);
  }
  const float range = hi > lo ? hi - lo : 1.f;
  const double px = grid.dx_mm * s, py = grid.dy_mm * s;
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  const double lx = -0.5, ly = 0.5, lz = 0.7071;  // from the north-west, 45° up
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const double gx = (at(i + 1, j) - at(i - 1, j)) / (2 * px),
                   gy = (at(i, j + 1) - at(i, j - 1)) / (2 * py);
      const double nz = 1.0 / std::sqrt(1 + gx * gx + gy * gy);
      const double shade = std::clamp((-gx * lx - gy * ly + lz) * nz, 0.0, 1.0);
      const double t = (at(i, j) - lo) / range;
      const double base = 0.35 + 0.65 * shade;
      const std::size_t o = (std::size_t(h - 1 - j) * w + i) * 3;
      rgb[o] = static_cast<std::uint8_t>(std::clamp(255.0 * base * (0.75 + 0.25 * t), 0.0, 255.0));
      rgb[o + 1] = static_cast<std::uint8_t>(std::clamp(255.0 * base * 0.85, 0.0, 255.0));
      rgb[o + 2] =
          static_cast<std::uint8_t>(std::clamp(255.0 * base * (1.0 - 0.25 * t), 0.0, 255.0));
    }
  common::writeTextAtomically(file, encodePng(w, h, rgb));
}

}  // namespace fieldpath::zbuffer
