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
#include <cmath>
#include <array>
#include <cstdint>
#include <optional>
#include <stdexcept>
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

// A device request's light code of one channel: k_s times the light colour as unorm8.
inline uint32_t deviceLightCode(double ks_light) {
  return static_cast<uint32_t>(std::lround(255.0 * std::clamp(ks_light, 0.0, 1.0)));
}

// A material's colour factors under a scene's lights, in output LSBs (0..255 scale), which each
// shader codes in its own format: the ambient term 255 ambient base, and per light the diffuse
// factor 255 k_d base light and the specular factor 255 k_s light per channel, the specular
// unit's light codes, and whether the light is a point light.
struct LightFactors {
  struct Light {
    std::array<double, 3> diffuse{}, specular{};
    std::array<uint32_t, 3> device{};
    bool point = false;
  };
  std::array<double, 3> ambient{};
  std::vector<Light> lights;  // ShadeContext::lights' order
};
LightFactors lightFactors(const ShadeContext& ctx, const Material& m);

// How a material's device-lobe requests are coded for the specular unit.
struct DeviceCoding {
  int cos_frac_bits = 15;
  uint32_t shin = 0;  // the PROM address of the material's shininess
  int64_t zero = -1;  // SpecEngine::zeroCode(shin): a request's cos code at or below it gives 0
  bool atZero(uint32_t cos) const { return static_cast<int64_t>(cos) <= zero; }
};
struct Shade {
  std::array<double, 3> lsb{};  // ambient + diffuse + analytic specular, 0..255 scale
};
// The lighting of the points of one material and lobe. The per-material factors (ambient, k_d
// and k_s times base and light colours, a device request's light codes) are computed once.
// ctx and m must outlive it.
class PointShader {
 public:
  // coding and device may be null unless the lobe is a device lobe (std::logic_error then).
  PointShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding);
  // Colour of a point in output LSBs (0..255 scale, unclamped, double): ambient + diffuse + the
  // analytic specular lobes. Device lobes add nothing here; for them one request per lit light
  // (N.H, shininess code, light colour) is appended to *device, to be added by combine().
  Shade shade(Vec3 n_unit, Vec3 p_cam, std::vector<SpecRequest>* device) const;
  // Whether shade() reads p_cam: only point lights depend on the position (the viewer is at
  // infinity), so with directional lights alone a caller may pass any point.
  bool needsPosition() const { return needs_position_; }

 private:
  struct PerLight {
    std::array<double, 3> diffuse{};   // 255 k_d base light, per channel
    std::array<double, 3> specular{};  // 255 k_s light, per channel
    std::array<uint32_t, 3> device_light{};  // a device request's light*k_s codes
  };
  const ShadeContext& ctx_;
  const Material& m_;
  Lobe lobe_;
  bool device_lobe_;
  std::optional<DeviceCoding> coding_;
  bool needs_position_ = false;
  std::array<double, 3> ambient_{};  // 255 ambient base
  std::vector<PerLight> lights_;
};

// Final unorm8: round(lsb) plus the device outputs, clamped to 0..255.
// device_rgb points at `count` specular-unit results (may be null when count is 0).
// Inline: it runs once per pixel.
inline std::array<uint8_t, 3> combine(const std::array<double, 3>& lsb, const std::array<uint32_t, 3>* device_rgb,
                                      size_t count) {
  std::array<uint8_t, 3> out{};
  for (size_t k = 0; k < 3; ++k) {
    // round(clamp(lsb, 0, 255)), half away from zero, without a libm call: the fraction of a
    // value in [0, 255] is exact in double. min/max rather than clamp: no branch on the value.
    if (std::isnan(lsb[k])) throw std::logic_error("combine: a NaN colour (a shading bug)");
    const double c = std::min(std::max(lsb[k], 0.0), 255.0);
    uint32_t v = static_cast<uint32_t>(c);
    if (c - v >= 0.5) ++v;
    for (size_t i = 0; i < count; ++i) v += device_rgb[i][k];
    out[k] = static_cast<uint8_t>(std::min<uint32_t>(255, v));
  }
  return out;
}

// combine() of one channel without device outputs, from a fixed-point code with `frac` fraction
// bits: round(clamp(code 2^-frac, 0, 255)) in integers (round half up = half away from zero
// for the non-negative values left after the clamp).
inline uint8_t unorm8FromCode(int64_t code, int frac) {
  const int64_t c = std::clamp<int64_t>(code, 0, int64_t{255} << frac);
  return static_cast<uint8_t>((c + (int64_t{1} << (frac - 1))) >> frac);
}

}  // namespace shd
