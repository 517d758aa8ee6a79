// Lighting of a surface point, shared by every shading method and by the RTL-in-the-loop path.
//
// Model (the idx3d/paper setting): directional and point lights, diffuse k_d * base * max(0, N.L),
// a specular lobe f(N, L, V) chosen per material (its "brdf"), and an infinite viewer: V is the
// camera's backward axis, (0, 0, -1) in camera space, so H = normalize(L + V) is constant per
// directional light (the listings' h = light + lookat). Colours are linear, 0..1 per channel.
//
// The device lobes (quadratic, cubic) are not evaluated here: the specular unit (its bit-exact
// model or its verilated RTL) gives them as unorm8 per channel, SpecRequest describes one
// evaluation, and combine() adds them to the rest of the colour in the output's LSBs.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/scene.h"

namespace shd {

struct CameraLight {
  bool point = false;
  Vec3 dir{0, 0, -1};  // directional: toward the light, camera space, unit
  Vec3 half{0, 0, 1};  // directional: normalize(dir + view), the same at every point
  Vec3 pos{0, 0, 0};   // point: camera space
  Vec3 colour{1, 1, 1};
};

struct ShadeContext {
  Vec3 ambient{0, 0, 0};
  std::vector<CameraLight> lights;
  Vec3 view{0, 0, -1};  // toward the viewer, camera space
};
ShadeContext makeShadeContext(const Scene& s);

enum class Lobe { Phong, Blinn, NormalizedBlinn, Schlick, Quadratic, Cubic, CookTorrance, Pow };
Lobe parseLobe(const std::string& s);  // the material's brdf names; std::invalid_argument otherwise
const char* toString(Lobe l);
bool isDeviceLobe(Lobe l);  // quadratic, cubic: evaluated by the specular unit

// The light direction at a camera-space point (unit, toward the light).
Vec3 lightDirection(const CameraLight& l, Vec3 p_cam);

// The specular factor f of an analytic lobe (not the device ones): phong (R.V)^n, blinn and pow
// (N.H)^n, normalized blinn (n+2)/(2 pi) (N.H)^n, schlick, Cook-Torrance with Beckmann
// roughness from the material.
double lobeValue(Lobe lobe, const Material& m, Vec3 n, Vec3 l, Vec3 v);
// The same with the half vector h = normalize(l + v) given (constant for a directional light).
double lobeValue(Lobe lobe, const Material& m, Vec3 n, Vec3 l, Vec3 v, Vec3 h);

// One specular-unit evaluation: shininess code, N.H as a uQ1.Wc code, light*k_s as unorm8.
struct SpecRequest {
  uint32_t shin = 0, cos = 0;
  std::array<uint32_t, 3> light{};
};

// Colour of a point in output LSBs (0..255 scale, unclamped, double): ambient + diffuse + the
// analytic specular lobes. Device lobes add nothing here; for them one request per lit light
// (N.H, shininess code, light colour) is appended to *device, to be added by combine().
struct DeviceCoding {
  int cos_frac_bits = 15;
  uint32_t shin = 0;  // the PROM address of the material's shininess
};
struct Shade {
  std::array<double, 3> lsb{};  // ambient + diffuse + analytic specular, 0..255 scale
};
// coding and device may be null unless the lobe is a device lobe (std::logic_error then).
Shade shadePoint(const ShadeContext& ctx, const Material& m, Lobe lobe, Vec3 n_unit, Vec3 p_cam,
                 const DeviceCoding* coding, std::vector<SpecRequest>* device);

// Final unorm8: round(lsb) plus the device outputs, clamped to 0..255.
// device_rgb points at `count` specular-unit results (may be null when count is 0).
std::array<uint8_t, 3> combine(const std::array<double, 3>& lsb, const std::array<uint32_t, 3>* device_rgb, size_t count);

// combine() of one channel without device outputs, from a fixed-point code with `frac` fraction
// bits: round(clamp(code 2^-frac, 0, 255)) in integers (round half up = half away from zero
// for the non-negative values left after the clamp).
inline uint8_t unorm8FromCode(int64_t code, int frac) {
  const int64_t c = std::clamp<int64_t>(code, 0, int64_t{255} << frac);
  return static_cast<uint8_t>((c + (int64_t{1} << (frac - 1))) >> frac);
}

}  // namespace shd
