// phong-fixed at runtime widths (RenderOptions::phong_widths, render/phong_widths.h): the
// datapath of render/fixed_shading.h with each of its widths a parameter, one fragment at a
// time (no run kernels, no vector kernel: the fixed path keeps those, untouched). The formats
// are phong_widths.h's; with PhongWidths{} every value equals FixedPointShader's, so the images
// are bit-identical (test PhongWidths.DefaultsAreBitIdenticalOnEveryScene). Narrower widths
// round or truncate at each stated format, as the hardware would, not only at the end.
//
// The model's containers: codes in int64_t, every product in 128 bits (PhongWidths::validate
// bounds each product and shift, so none wraps).
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "render/fixed_shading.h"
#include "render/phong_widths.h"
#include "render/shading.h"

namespace shd {

// The 1/sqrt seeds of seed_bits index bits and frac_bits fraction bits: entry i =
// round(2^frac_bits / sqrt(mid_i)), mid_i = 1/4 + (i + 1/2) 3/4 2^-seed_bits, in uQ2.frac_bits
// (below 2); RsqrtSeed<10>'s entries at (10, 16). Built once per process and shared.
std::shared_ptr<const std::vector<uint32_t>> rsqrtSeedTable(int seed_bits, int frac_bits);

// The reciprocal square root of the widths for v > 0: v = m 4^-shift with m in [2^60, 2^62) (as
// rsqrtCore), r ~ 2^NewtonFracBits / sqrt(m 2^-62) in uQ2.NewtonFracBits: the seed of `seeds`
// at m's interval, then NewtonSteps steps r' = r (3 - m r^2) / 2, m truncated to
// NewtonFracBits fraction bits, m r^2 and r' truncated to NewtonFracBits (truncation, as
// rsqrtCore's shifts). With no step: the seed shifted to NewtonFracBits (truncated if it is
// wider). Equals rsqrtCore<10> at the defaults.
struct WidthsRsqrt {
  uint64_t r = 0;
  int shift = 0;
};
WidthsRsqrt widthsRsqrt(uint64_t v, const PhongWidths& w, const uint32_t* seeds);

class FixedWidthsShader {
 public:
  // As FixedPointShader's constructor; w must be valid (PhongWidths::validate).
  FixedWidthsShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding,
                    SpecResultMemo* memo, const PhongWidths& w);

  // The colour at a point with interpolated normal n (NormalFracBits fraction bits per
  // component) of squared norm sqnorm (2 NormalFracBits fraction bits): codes with
  // ColourFracBits fraction bits. p_cam is read only when needsPosition(). Device requests go
  // to *requests when there is no memo (one per lit light).
  FixedShade shade(const int64_t* n, uint64_t sqnorm, Vec3 p_cam, std::vector<SpecRequest>* requests);
  bool needsPosition() const { return needs_position_; }
  // The output pixel of a shade (fixedColour at ColourFracBits), and a code in LSBs.
  std::array<uint8_t, 3> colour(const FixedShade& s) const;
  double lsb(int64_t code) const;
  const PhongWidths& widths() const { return w_; }

 private:
  using Cosine = FixedCosine;
  struct PerLight {
    const CameraLight* light = nullptr;
    std::array<int64_t, 3> l{}, h{};  // sQ1.UnitFracBits (point lights: this pixel's)
    int64_t lv = 0;                   // L.V, sQ2.CosFracBits
    double vh = 0;                    // V.H (cook-torrance), double
    std::array<int64_t, 3> diffuse{}, specular{};  // uQFactorIntBits.ColourFracBits
    std::array<uint32_t, 3> device_light{};
    uint64_t* memo = nullptr;  // the memo's row of this light's requests
  };
  // 1/|N| as a rounding shift: cosine = round(N.u r 2^-s).
  struct Scale {
    uint64_t r = 0;
    int s = 1;
  };
  Scale scaleOf(uint64_t sqnorm) const;
  int64_t cosine(__int128 dot, Scale sc) const;
  uint32_t lobeAt(int64_t c) const;  // the lobe table at a cosine (sQ2.CosFracBits)
  int64_t unitCode(double x) const;
  void setDirections(PerLight& pl, Vec3 l) const;
  void addSpecular(FixedShade& s, PerLight& pl, int64_t nl, int64_t nv, int64_t nh,
                   std::vector<SpecRequest>* requests) const;

  const ShadeContext& ctx_;
  const Material& m_;
  PhongWidths w_;
  Cosine cosine_;
  std::optional<DeviceCoding> coding_;
  SpecResultMemo* memo_;
  LobeFormat lobe_format_;
  std::shared_ptr<const LobeTable> table_;  // lobes of one cosine
  std::shared_ptr<const std::vector<uint32_t>> seeds_;
  bool needs_position_ = false;
  std::array<int64_t, 3> v_{};  // the view direction, sQ1.UnitFracBits
  std::array<int64_t, 3> ambient_{};
  std::vector<PerLight> lights_;
};

}  // namespace shd
