// A tiny double-precision 3-vector for the scene stage (mesh positions, normals, camera frames).
// Only what scene/ needs; it is a plain value type, passed by value.
#pragma once

#include <cmath>

namespace shd {

constexpr double kPi = 3.14159265358979323846;

struct Vec3 {
  double x, y, z;
};

inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline Vec3& operator+=(Vec3& a, Vec3 b) { return a = a + b; }

inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(Vec3 a) { return std::sqrt(dot(a, a)); }

// a / |a|; the zero vector stays zero (callers that can meet it handle it first).
inline Vec3 normalize(Vec3 a) {
  const double len = length(a);
  if (len == 0.0) return a;
  return (1.0 / len) * a;
}

}  // namespace shd
