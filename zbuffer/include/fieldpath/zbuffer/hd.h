#pragma once
/// Host/device math shared by the CPU (reference) and CUDA backends, written once.
/// Every function here is plain IEEE float arithmetic (no FMA contraction: the build passes
/// -ffp-contract=off to the host compiler and -fmad=false to nvcc) so that both backends compute
/// the same bits for the same (line, posture) pair; the minimum over postures is order independent,
/// hence the two height maps are bit-identical.
#include <cmath>
#include <cstdint>

#if defined(__CUDACC__)
#define FIELDPATH_HD __host__ __device__ inline
#else
#define FIELDPATH_HD inline
#endif

namespace fieldpath::zbuffer {

struct Vec3f {
  float x = 0.f, y = 0.f, z = 0.f;
};

FIELDPATH_HD Vec3f operator+(Vec3f a, Vec3f b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
FIELDPATH_HD Vec3f operator-(Vec3f a, Vec3f b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
FIELDPATH_HD Vec3f operator*(float s, Vec3f a) { return {s * a.x, s * a.y, s * a.z}; }
FIELDPATH_HD float dot(Vec3f a, Vec3f b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
FIELDPATH_HD float comp(Vec3f a, int k) { return k == 0 ? a.x : (k == 1 ? a.y : a.z); }
FIELDPATH_HD float minf(float a, float b) { return a < b ? a : b; }
FIELDPATH_HD float maxf(float a, float b) { return a > b ? a : b; }
FIELDPATH_HD float absf(float a) { return a < 0.f ? -a : a; }

/// Tool posture (DESIGN.md): tip p (mm, world) and unit axis a from the tip towards the spindle.
/// The spindle angle φ (the optional 7th column) as cos φ, sin φ: the tool turned by φ about its
/// own axis first, for a mesh tool with cutting edges (the seed's worn-edge "Cutting" case); a
/// revolved tool reads the same at any angle. Rounded from doubles on the host where the posture
/// is made, so that the CPU and CUDA backends turn it by the same floats.
struct Posture {
  Vec3f tip_mm;
  Vec3f axis{0.f, 0.f, 1.f};
  float spindle_cos = 1.f, spindle_sin = 0.f;
};

/// Row-major 3×3 rotation, tool frame → world frame.
struct Mat3f {
  float m[3][3];
};

/// Minimal rotation about e_z × a mapping e_z onto `axis` (normalised here), the float twin of
/// geometry::rotationFromZ: f = 1/(1+k) for k >= 0 and (1-k)/(i²+j²) for k < 0 (no cancellation
/// near either pole); a = -e_z exactly gives diag(1,-1,-1).
FIELDPATH_HD Mat3f rotationFromZ(Vec3f axis) {
  const float n = sqrtf(dot(axis, axis));
  const float i = axis.x / n, j = axis.y / n, k = axis.z / n;
  const float s = i * i + j * j;
  Mat3f r;
  if (k < 0.f && s == 0.f) {
    r.m[0][0] = 1.f;
    r.m[0][1] = 0.f;
    r.m[0][2] = 0.f;
    r.m[1][0] = 0.f;
    r.m[1][1] = -1.f;
    r.m[1][2] = 0.f;
    r.m[2][0] = 0.f;
    r.m[2][1] = 0.f;
    r.m[2][2] = -1.f;
    return r;
  }
  const float f = k >= 0.f ? 1.f / (1.f + k) : (1.f - k) / s;
  r.m[0][0] = 1.f - f * i * i;
  r.m[0][1] = -f * i * j;
  r.m[0][2] = i;
  r.m[1][0] = -f * i * j;
  r.m[1][1] = 1.f - f * j * j;
  r.m[1][2] = j;
  r.m[2][0] = -i;
  r.m[2][1] = -j;
  r.m[2][2] = k;
  return r;
}

FIELDPATH_HD Vec3f mul(const Mat3f& r, Vec3f v) {
  return {r.m[0][0] * v.x + r.m[0][1] * v.y + r.m[0][2] * v.z,
          r.m[1][0] * v.x + r.m[1][1] * v.y + r.m[1][2] * v.z,
          r.m[2][0] * v.x + r.m[2][1] * v.y + r.m[2][2] * v.z};
}
/// Tool frame → world frame of a posture: the turn by the spindle angle about the tool's +z, then
/// the minimal rotation onto the axis (DESIGN.md). At angle 0 exactly rotationFromZ, bit for bit.
FIELDPATH_HD Mat3f postureRotation(const Posture& pose) {
  Mat3f r = rotationFromZ(pose.axis);
  if (pose.spindle_sin == 0.f && pose.spindle_cos == 1.f) return r;
  const float c = pose.spindle_cos, s = pose.spindle_sin;
  for (int row = 0; row < 3; ++row) {  // r · Rz: columns x, y turned; z (the axis) kept
    const float x = r.m[row][0], y = r.m[row][1];
    r.m[row][0] = c * x + s * y;
    r.m[row][1] = -s * x + c * y;
  }
  return r;
}

FIELDPATH_HD Vec3f mulTransposed(const Mat3f& r, Vec3f v) {
  return {r.m[0][0] * v.x + r.m[1][0] * v.y + r.m[2][0] * v.z,
          r.m[0][1] * v.x + r.m[1][1] * v.y + r.m[2][1] * v.z,
          r.m[0][2] * v.x + r.m[1][2] * v.y + r.m[2][2] * v.z};
}

/// Monotone, self-inverse map of a float's bit pattern to an int32 (a < b ⇔ key(a) < key(b) for
/// non-NaN floats), so that a height minimum is one integer atomicMin on the device.
FIELDPATH_HD std::int32_t orderedBits(std::int32_t bits) {
  return bits >= 0 ? bits : bits ^ 0x7fffffff;
}

}  // namespace fieldpath::zbuffer
