// phong-fixed: the per-pixel lighting of Phong shading as a fixed-point datapath, the way the
// paper's hardware would compute it: no floating point and no pow per pixel (with directional
// lights), every step an integer operation with a stated format.
//
//   L, H, V      Q1.30, rounded once per object for directional lights (per pixel for point
//                lights, from the double direction at the pixel's camera-space point)
//   cosines      N.L, N.H, N.V of the interpolated normal N (28 fraction bits): integer dot
//                products, then times 1/|N| from the squared-norm recurrence and the table +
//                Newton 1/sqrt (cosineScale, normalize.h), Q2.32. (Dot first, scale after: two
//                or three scalings per pixel instead of normalising three components.)
//   diffuse      D_k (N.L) 2^-32 rounded half up to 12 fraction bits, D_k = round(255 k_d base_k
//                light_k 2^12) (the output LSB scale)
//   specular     lobes of one cosine look the lobe up in a table over that cosine at 16 fraction
//                bits, the exact lobe at each code (f_code = round(f 2^24), lobeTable), and
//                interpolate linearly with the cosine's next 16 bits: N.H for blinn, pow,
//                normalized-blinn and schlick; R.V = 2 (N.L)(N.V) - L.V for phong. The term is
//                S_k f_code 2^-24 rounded half up to 12 fraction bits, S_k = round(255 k_s
//                light_k 2^12). cook-torrance (three cosines) is evaluated in double from the
//                fixed-point cosines and then coded the same way.
//                Device lobes: one request per lit light to the specular unit, N.H rounded to
//                its cos_frac_bits; on the unit's bit-exact model the results come from a memo
//                filled from the model (SpecResultMemo: exact, the unit being a function of
//                shininess, cos and light).
//   colour       the ambient code round(255 ambient_k base_k 2^12) plus the terms, then
//                round(clamp(code 2^-12, 0, 255)) plus the device outputs, clamped to 255
//                (combine()).
// Saturation (what fixed-width factors do with absurd inputs): the factor codes D_k, S_k and the
// ambient code saturate at 2^30 - 1 (about 1000x full scale, a light colour above ~1000), and
// f_code at 2^32 - 1 (f < 256: only cook-torrance near grazing angles exceeds it, where the
// term saturates the output unless k_s light < 1/255).
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <vector>

#include "device/spec_unit.h"
#include "render/normalize.h"
#include "render/shading.h"

namespace shd {

constexpr int kFixedColourFrac = 12;  // colour codes: output LSBs with 12 fraction bits
constexpr int kFixedCosFrac = 16;     // the lobe tables' cosine codes
constexpr int kFixedUnitFrac = 30;    // L, H, V: Q1.30

// The colour of one point: 12-fraction-bit codes and, on the specular unit's model, the sum of
// its results (the unit's outputs, added after rounding, as combine() does) and how many
// requests the unit answered (the hardware evaluates each one; the model's memo only saves
// the model's time).
struct FixedShade {
  std::array<int64_t, 3> code{};
  std::array<uint32_t, 3> device{};
  uint32_t device_requests = 0;
};

// The output pixel: round(clamp(code 2^-12, 0, 255)) plus the device results, clamped to 255
// (what combine() gives for the value code 2^-12).
inline std::array<uint8_t, 3> fixedColour(const FixedShade& s) {
  std::array<uint8_t, 3> out{};
  for (size_t k = 0; k < 3; ++k)
    out[k] = static_cast<uint8_t>(std::min<uint32_t>(255, unorm8FromCode(s.code[k], kFixedColourFrac) + s.device[k]));
  return out;
}

// A lobe of one cosine (phong over R.V; blinn, pow, normalized-blinn, schlick over N.H) at every
// cosine code c / 2^16, c = 0..2^16: f_code = round(f 2^24), saturated at 2^32 - 1 (f < 256),
// and a copy of the last entry (the interpolation's right neighbour at c = 1).
// A pure function of the lobe and the shininess, so the tables are built once per process
// (65,537 evaluations each) and shared; std::logic_error for a lobe of several cosines.
std::shared_ptr<const std::vector<uint32_t>> lobeTable(Lobe lobe, double shininess);

// The specular unit's results by cos code for each (shininess code, light codes) it is asked
// about, filled on first use from the unit's bit-exact model: exact, because the unit is a
// function of those inputs. ModelSpecEngine owns one, so it lasts from frame to frame.
class SpecResultMemo {
 public:
  explicit SpecResultMemo(const SpecUnitModel& model) : model_(model) {}
  // The row of (shin, light): 2^CosFracBits + 1 entries, 0 where not yet evaluated, else
  // evaluate()'s word. The row stays valid as long as the memo. Null for a unit with more than
  // kMaxCosFracBits (a row would take 8 MB and more): evaluate() directly then.
  uint64_t* row(uint32_t shin, const std::array<uint32_t, 3>& light);
  // The unit's result as one word: kValid | r | g << 20 | b << 40.
  uint64_t evaluate(uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const;
  uint64_t fill(uint64_t* row, uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const {
    return row[cos] = evaluate(shin, cos, light);
  }
  static constexpr uint64_t kValid = uint64_t{1} << 60;
  static constexpr int kMaxCosFracBits = 20;
  const SpecUnitModel& model() const { return model_; }

 private:
  const SpecUnitModel& model_;
  std::map<std::array<uint32_t, 4>, std::vector<uint64_t>> rows_;
};

class FixedPointShader {
 public:
  // coding: the specular unit's request coding (device lobes; std::logic_error if null then).
  // memo: the unit's results from its model, or null when requests go to `requests` of
  // shade() (the RTL in the loop). ctx, m and memo must outlive the shader.
  FixedPointShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding,
                   SpecResultMemo* memo);

  // The colour at a point with interpolated normal n28 (28 fraction bits per component) of
  // squared norm sqnorm (56 fraction bits). p_cam is read only when needsPosition(). Device
  // requests go to *requests when there is no memo (one per lit light).
  FixedShade shade(const int64_t* n28, uint64_t sqnorm, Vec3 p_cam, std::vector<SpecRequest>* requests);
  bool needsPosition() const { return needs_position_; }

 private:
  enum class Cosine { NH, RV, CookTorrance, Device };
  struct PerLight {
    const CameraLight* light = nullptr;
    std::array<int32_t, 3> l{}, h{};  // Q1.30 (point lights: this pixel's)
    int64_t lv = 0;                   // L.V, Q2.32
    double vh = 0;                    // V.H (cook-torrance), double
    std::array<int64_t, 3> diffuse{}, specular{};
    std::array<uint32_t, 3> device_light{};
    uint64_t* memo = nullptr;  // the memo's row of this light's requests
  };

  void setDirections(PerLight& pl, Vec3 l) const;
  uint32_t cookTorranceCode(int64_t nl, int64_t nv, int64_t nh, const PerLight& pl) const;
  uint64_t deviceResult(const PerLight& pl, uint32_t cos) const;  // the memo entry, evaluated on first use

  const ShadeContext& ctx_;
  const Material& m_;
  Cosine cosine_;
  std::optional<DeviceCoding> coding_;
  SpecResultMemo* memo_;
  std::shared_ptr<const std::vector<uint32_t>> table_;  // lobes of one cosine
  bool needs_position_ = false;
  std::array<int32_t, 3> v_{};  // the view direction, Q1.30
  std::array<int64_t, 3> ambient_{};
  std::vector<PerLight> lights_;
};

// ---- the per-pixel path, inline (it runs once per fragment) ----

namespace fixed_detail {
// N (28 fraction bits) . u (Q1.30): 58 fraction bits, in 64-bit modular arithmetic (the
// partial sums may wrap; the result, |N.u| <= |N| 2^58, fits)
inline int64_t dot58(const int64_t* n28, const std::array<int32_t, 3>& u) {
  uint64_t d = 0;
  for (size_t k = 0; k < 3; ++k) d += static_cast<uint64_t>(n28[k]) * static_cast<uint64_t>(int64_t{u[k]});
  return static_cast<int64_t>(d);
}
// round(x 2^-s), half up
inline int64_t roundShift(int64_t x, int s) { return (x + (int64_t{1} << (s - 1))) >> s; }
// A Q2.32 cosine as a code with `frac` fraction bits, rounded half up, clamped to [0, 1].
inline uint32_t cosCode(int64_t c32, int frac) {
  return static_cast<uint32_t>(std::clamp<int64_t>(roundShift(c32, 32 - frac), 0, int64_t{1} << frac));
}
// A lobe table (kFixedCosFrac-bit entries and the copy of the last) at a Q2.32 cosine clamped
// to [0, 1]: the entry below and the linear step to the next with the cosine's next 16 bits,
// rounded half up.
inline uint32_t lobeAt(const uint32_t* t, int64_t c32) {
  const uint64_t c = static_cast<uint64_t>(std::clamp<int64_t>(c32, 0, int64_t{1} << 32));
  const uint64_t i = c >> (32 - kFixedCosFrac), frac = c & ((uint64_t{1} << (32 - kFixedCosFrac)) - 1);
  const int64_t step = int64_t{t[i + 1]} - int64_t{t[i]};
  return static_cast<uint32_t>(t[i] + roundShift(step * static_cast<int64_t>(frac), 32 - kFixedCosFrac));
}
}  // namespace fixed_detail

inline FixedShade FixedPointShader::shade(const int64_t* n28, uint64_t sqnorm, Vec3 p_cam,
                                          std::vector<SpecRequest>* requests) {
  using namespace fixed_detail;
  FixedShade s;
  s.code = ambient_;
  const CosineScale sc = cosineScale(sqnorm);
  const bool needs_nv = cosine_ == Cosine::RV || cosine_ == Cosine::CookTorrance;
  const int64_t nv = needs_nv ? scaleCosine(dot58(n28, v_), sc) : 0;
  for (PerLight& pl : lights_) {
    if (pl.light->point) setDirections(pl, lightDirection(*pl.light, p_cam));
    const int64_t nl = scaleCosine(dot58(n28, pl.l), sc);
    if (nl <= 0) continue;  // the surface faces away from this light
    for (size_t k = 0; k < 3; ++k) s.code[k] += roundShift(pl.diffuse[k] * nl, 32);
    const int64_t nh = scaleCosine(dot58(n28, pl.h), sc);
    uint32_t f = 0;
    switch (cosine_) {
      case Cosine::Device: {
        const uint32_t cos = cosCode(nh, coding_->cos_frac_bits);
        if (memo_ == nullptr) {
          if (requests == nullptr) throw std::logic_error("FixedPointShader: device requests need a list");
          requests->push_back(SpecRequest{coding_->shin, cos, pl.device_light});
        } else {
          const uint64_t r = deviceResult(pl, cos);
          for (size_t k = 0; k < 3; ++k) s.device[k] += static_cast<uint32_t>(r >> (20 * k)) & 0xFFFFFu;
        }
        ++s.device_requests;
        continue;
      }
      case Cosine::NH: f = lobeAt(table_->data(), nh); break;
      case Cosine::RV: {
        // R.V = 2 (N.L)(N.V) - L.V: the product of two Q2.32 is Q4.64, 2 x it back to Q2.32
        const __int128 p = static_cast<__int128>(nl) * nv;
        const int64_t rv = static_cast<int64_t>((p + (__int128{1} << 30)) >> 31) - pl.lv;
        f = lobeAt(table_->data(), rv);
        break;
      }
      case Cosine::CookTorrance: f = cookTorranceCode(nl, nv, nh, pl); break;
    }
    for (size_t k = 0; k < 3; ++k) s.code[k] += roundShift(pl.specular[k] * f, 24);
  }
  return s;
}

inline uint64_t FixedPointShader::deviceResult(const PerLight& pl, uint32_t cos) const {
  if (pl.memo == nullptr) return memo_->evaluate(coding_->shin, cos, pl.device_light);
  const uint64_t e = pl.memo[cos];
  return __builtin_expect(e == 0, 0) ? memo_->fill(pl.memo, coding_->shin, cos, pl.device_light) : e;
}

}  // namespace shd
