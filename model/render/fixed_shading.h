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
#include "render/fixed_simd.h"
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
  uint32_t device_zero = 0;  // of those, at or below the unit's zero (DeviceCoding::atZero)
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
// and a copy of the last entry (the interpolation's right neighbour at c = 1). Other formats
// (LobeFormat) for the datapath at runtime widths (render/fixed_widths.h).
// A pure function of the lobe, the shininess and the format, so the tables are built once per
// process (65,537 evaluations each at the fixed path's format) and shared; std::logic_error
// for a lobe of several cosines or a format of more than 32-bit words or 2^24 codes.
struct LobeTable {
  std::vector<uint32_t> code;  // 2^16 + 2 entries (2^cos_bits + 2)
  // The first i with code[i] or code[i + 1] nonzero: below it the lobe is 0 (for a high
  // exponent, most of the table), so a kernel may skip the reads there.
  uint32_t zero_below = 0;
};
// The tables' format: cosine codes c 2^-cos_bits, f_code = round(f 2^code_bits) in
// uQint_bits.code_bits, saturated at 2^(code_bits + int_bits) - 1 (the fixed path's:
// kFixedCosFrac, 24 and 8).
struct LobeFormat {
  int cos_bits = kFixedCosFrac;
  int code_bits = 24;
  int int_bits = 8;
};
std::shared_ptr<const LobeTable> lobeTable(Lobe lobe, double shininess, const LobeFormat& format = {});
// A lobe value f >= 0 as f_code in `format` (std::logic_error for a negative or NaN f).
uint32_t lobeCode(double f, const LobeFormat& format);

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
  // The same from `row` (row(shin, light)), evaluated and stored there on first use; evaluated
  // each time when the row is null.
  uint64_t result(uint64_t* row, uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const {
    if (row == nullptr) return evaluate(shin, cos, light);
    const uint64_t e = row[cos];
    return __builtin_expect(e == 0, 0) ? (row[cos] = evaluate(shin, cos, light)) : e;
  }
  static constexpr uint64_t kValid = uint64_t{1} << 60;
  static constexpr int kMaxCosFracBits = 20;
  const SpecUnitModel& model() const { return model_; }

 private:
  const SpecUnitModel& model_;
  std::map<std::array<uint32_t, 4>, std::vector<uint64_t>> rows_;
};

// One request of a shader to the specular unit: queued in `requests` when there is no memo (the
// batch path: the unit evaluates every request), else the memo's result (its row `row`) added to
// s.device at once, or nothing for a cosine at or below the unit's zero (its result is 0).
inline void deviceRequest(FixedShade& s, SpecResultMemo* memo, uint64_t* row, const DeviceCoding& coding, uint32_t cos,
                          const std::array<uint32_t, 3>& light, std::vector<SpecRequest>* requests) {
  ++s.device_requests;
  const bool zero = coding.atZero(cos);
  s.device_zero += zero;
  if (memo == nullptr) {
    if (requests == nullptr) throw std::logic_error("a shader's device requests need a list");
    requests->push_back(SpecRequest{coding.shin, cos, light});
  } else if (zero) {
    memo->model().checkCosine(coding.shin, cos);  // a pruned unit's limit holds for skipped requests too
  } else {
    const uint64_t r = memo->result(row, coding.shin, cos, light);
    for (size_t c = 0; c < 3; ++c) s.device[c] += static_cast<uint32_t>(r >> (20 * c)) & 0xFFFFFu;
  }
}

// The per-pixel arithmetic (inline: it runs once per fragment).
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
// rounded half up. Below zero_below (LobeTable::zero_below) both entries are 0, and so is the
// result: the table is not read there (most cosines of a high exponent, and a read of its
// 256 KB that would miss the first-level cache).
inline uint32_t lobeAt(const uint32_t* t, int64_t c32, uint32_t zero_below = 0) {
  const uint64_t c = static_cast<uint64_t>(std::clamp<int64_t>(c32, 0, int64_t{1} << 32));
  const uint64_t i = c >> (32 - kFixedCosFrac), frac = c & ((uint64_t{1} << (32 - kFixedCosFrac)) - 1);
  if (i < zero_below) return 0;
  const int64_t step = int64_t{t[i + 1]} - int64_t{t[i]};
  return static_cast<uint32_t>(t[i] + roundShift(step * static_cast<int64_t>(frac), 32 - kFixedCosFrac));
}
}  // namespace fixed_detail

// The cosine a lobe reads in phong-fixed: N.H (blinn, pow, normalized-blinn, schlick), R.V
// (phong), the three of cook-torrance, or the specular unit's (the device lobes).
enum class FixedCosine { NH, RV, CookTorrance, Device };
FixedCosine fixedCosineOf(Lobe lobe);

// A device lobe's request coding, checked for a shader named `who`: std::logic_error when there
// is none or `memo` (if any) belongs to a unit of other CosFracBits, std::invalid_argument for
// CosFracBits outside 1..30.
DeviceCoding checkedDeviceCoding(const DeviceCoding* coding, const SpecResultMemo* memo, const char* who);

// The per-light constants both phong-fixed shaders hold: each light, its factor codes (the
// material's factors of lightFactors() in the shader's format, by `code`), its specular-unit
// light codes and, for device lobes answered by `memo`, the memo's row; the ambient code. Returns
// whether a light is a point light (directions per pixel). The directions of the directional
// lights are the shader's to set.
template <class PerLight, class Code>
bool codeLights(const ShadeContext& ctx, const Material& m, Code code, SpecResultMemo* memo, uint32_t shin,
                std::array<int64_t, 3>& ambient, std::vector<PerLight>& lights) {
  const LightFactors f = lightFactors(ctx, m);
  for (size_t k = 0; k < 3; ++k) ambient[k] = code(f.ambient[k]);
  lights.resize(ctx.lights.size());
  bool point = false;
  for (size_t i = 0; i < ctx.lights.size(); ++i) {
    PerLight& pl = lights[i];
    pl.light = &ctx.lights[i];
    point = point || pl.light->point;
    for (size_t k = 0; k < 3; ++k) {
      pl.diffuse[k] = code(f.lights[i].diffuse[k]);
      pl.specular[k] = code(f.lights[i].specular[k]);
      pl.device_light[k] = f.lights[i].device[k];
    }
    if (memo != nullptr) pl.memo = memo->row(shin, pl.device_light);
  }
  return point;
}

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

  // Runs of fragments along a row, normal n0 + i dn at fragment i: the integer dot products
  // of shade() are affine in i, so they step by constant increments (exact: the same values
  // modulo 2^64, hence the same colours as shade()). For directional lights, at most
  // kMaxRunLights of them, and device lobes answered by the memo (takesRuns()).
  static constexpr size_t kMaxRunLights = 4;
  bool takesRuns() const {
    return !needs_position_ && lights_.size() <= kMaxRunLights && (cosine_ != Cosine::Device || memo_ != nullptr);
  }
  template <class F>
  void withRunKernel(F&& f);  // f(kernel), kernel a RunKernel<C, NL> for this shader (takesRuns())

 private:
  using Cosine = FixedCosine;
  // The lobe reads N.V (phong's R.V, cook-torrance).
  static constexpr bool needsNv(Cosine c) { return c == Cosine::RV || c == Cosine::CookTorrance; }
  struct PerLight {
    const CameraLight* light = nullptr;
    std::array<int32_t, 3> l{}, h{};  // Q1.30 (point lights: this pixel's)
    int64_t lv = 0;                   // L.V, Q2.32
    double vh = 0;                    // V.H (cook-torrance), double
    std::array<int64_t, 3> diffuse{}, specular{};
    std::array<uint32_t, 3> device_light{};
    uint64_t* memo = nullptr;  // the memo's row of this light's requests
  };
  // What the datapath reads: the shader's members, or a run kernel's copies of them.
  struct Consts {
    std::array<int64_t, 3> ambient;
    const uint32_t* table;  // the lobe table (lobes of one cosine)
    uint32_t zero_below;    // and its LobeTable::zero_below
    PerLight* lights;
    size_t count;
  };

 public:
  // The datapath for the fragments of one run with the lobe kind C and the light count NL
  // fixed at compile time, and the constants it reads copied into the kernel (a local object:
  // the run's loop keeps them in registers, where the shader's members would be read again
  // after every store of a pixel). start() at the run's first fragment, shade() the colour of
  // the current fragment of squared norm sqnorm, step() to the next.
  template <Cosine C, size_t NL>
  class RunKernel {
   public:
    explicit RunKernel(FixedPointShader& sh) : sh_(sh) {
      for (size_t i = 0; i < NL; ++i) lights_[i] = sh.lights_[i];
      ambient_ = sh.ambient_;
      table_ = sh.table_ ? sh.table_->code.data() : nullptr;
      zero_below_ = sh.table_ ? sh.table_->zero_below : 0;
      if constexpr (kGroups) {
        nh_ = fixed_simd::nhKernel();
        simd_params_ = {table_, zero_below_, ambient_, lights_[0].diffuse, lights_[0].specular};
      }
    }
    // The batch's case (fixed_simd.h): one light and a lobe of N.H. Its fragments are shaded
    // away from their runs, from their squared norms and raw dot products N.L and N.H (dotL,
    // dotH at the current fragment; stepL, stepH per fragment), kept in buffers:
    //   shadeBatch  up to fixed_simd::kMaxBatch of them, 8 at a time (fixed_simd::nhKernel():
    //               AVX-512, AVX2 or plain C++), declining the groups of 8 it does not take;
    //   shadeRaw    one of them in the scalar datapath.
    // Both give what shade() gives.
    static constexpr bool kGroups = C == Cosine::NH && NL == 1;
    static constexpr bool kNeedsNv = needsNv(C);
    const fixed_simd::NhParams& nhParams() const { return simd_params_; }
    const std::array<int32_t, 3>& lightL() const { return lights_[0].l; }  // the one light's (kGroups)
    const std::array<int32_t, 3>& lightH() const { return lights_[0].h; }
    uint64_t dotL() const { return l_[0]; }
    uint64_t dotH() const { return h_[0]; }
    uint64_t stepL() const { return dl_[0]; }
    uint64_t stepH() const { return dh_[0]; }
    uint64_t shadeBatch(const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n, uint32_t* rgb,
                        int64_t* const codes[3] = nullptr) const {
      static_assert(kGroups, "one light, and no N.V (a lobe of N.H)");
      return nh_(simd_params_, sq, l, h, n, rgb, codes);
    }
    FixedShade shadeRaw(uint64_t sqnorm, uint64_t l, uint64_t h) {
      static_assert(kGroups, "one light, and no N.V (a lobe of N.H)");
      return shadeAt(sqnorm, &l, &h);
    }
    void start(const int64_t* n0, const int64_t* dn) {
      using fixed_detail::dot58;
      if constexpr (kNeedsNv) v_ = static_cast<uint64_t>(dot58(n0, sh_.v_));
      for (size_t i = 0; i < NL; ++i) {
        l_[i] = static_cast<uint64_t>(dot58(n0, lights_[i].l));
        h_[i] = static_cast<uint64_t>(dot58(n0, lights_[i].h));
      }
      // The steps: the same for every row of a triangle (dn is its didx, or -didx flipped).
      if (dn[0] == dn_[0] && dn[1] == dn_[1] && dn[2] == dn_[2] && have_steps_) return;
      dn_ = {dn[0], dn[1], dn[2]};
      have_steps_ = true;
      if constexpr (kNeedsNv) dv_ = static_cast<uint64_t>(dot58(dn, sh_.v_));
      for (size_t i = 0; i < NL; ++i) {
        dl_[i] = static_cast<uint64_t>(dot58(dn, lights_[i].l));
        dh_[i] = static_cast<uint64_t>(dot58(dn, lights_[i].h));
      }
    }
    FixedShade shade(uint64_t sqnorm) { return shadeAt(sqnorm, l_.data(), h_.data()); }
    void step() {
      if constexpr (kNeedsNv) v_ += dv_;
      for (size_t i = 0; i < NL; ++i) {
        l_[i] += dl_[i];
        h_[i] += dh_[i];
      }
    }

   private:
    // The datapath from the raw dot products of the NL lights (and the current fragment's N.V).
    FixedShade shadeAt(uint64_t sqnorm, const uint64_t* l, const uint64_t* h) {
      return sh_.shadeDots<C>(
          Consts{ambient_, table_, zero_below_, lights_.data(), NL}, sqnorm, static_cast<int64_t>(v_),
          [&](size_t i, PerLight&) { return static_cast<int64_t>(l[i]); },
          [&](size_t i, const PerLight&) { return static_cast<int64_t>(h[i]); }, nullptr);
    }
    FixedPointShader& sh_;
    std::array<PerLight, NL> lights_;
    std::array<int64_t, 3> ambient_;
    const uint32_t* table_;
    uint32_t zero_below_;
    uint64_t v_ = 0, dv_ = 0;
    std::array<uint64_t, NL> l_{}, dl_{}, h_{}, dh_{};
    std::array<int64_t, 3> dn_{};  // the steps' normal increment
    bool have_steps_ = false;
    fixed_simd::NhKernel nh_ = nullptr;
    fixed_simd::NhParams simd_params_;
  };

 private:
  // The lighting from the integer dot products N.V (raw_nv), N.L (nl_of(i, light i), which may
  // first set a point light's directions) and N.H (nh_of(i, light i)), 58 fraction bits.
  template <Cosine C, class NL, class NH>
  FixedShade shadeDots(const Consts& k, uint64_t sqnorm, int64_t raw_nv, NL nl_of, NH nh_of,
                       std::vector<SpecRequest>* requests);
  template <Cosine C>
  FixedShade shadeAs(const int64_t* n28, uint64_t sqnorm, Vec3 p_cam, std::vector<SpecRequest>* requests);
  template <Cosine C, class F>
  void withLightCount(F&& f);
  // f(kernel) with a kernel built in place: passed as an lvalue, so that f taking it by
  // reference copies none of its 300-odd bytes.
  template <class Kernel, class F>
  void withKernel(F& f) {
    Kernel k(*this);
    f(k);
  }
  void setDirections(PerLight& pl, Vec3 l) const;
  uint32_t cookTorranceCode(int64_t nl, int64_t nv, int64_t nh, const PerLight& pl) const;

  const ShadeContext& ctx_;
  const Material& m_;
  Cosine cosine_;
  std::optional<DeviceCoding> coding_;
  SpecResultMemo* memo_;
  std::shared_ptr<const LobeTable> table_;  // lobes of one cosine
  bool needs_position_ = false;
  std::array<int32_t, 3> v_{};  // the view direction, Q1.30
  std::array<int64_t, 3> ambient_{};
  std::vector<PerLight> lights_;
};

// ---- the per-pixel path, inline (it runs once per fragment) ----

inline FixedShade FixedPointShader::shade(const int64_t* n28, uint64_t sqnorm, Vec3 p_cam,
                                          std::vector<SpecRequest>* requests) {
  switch (cosine_) {
    case Cosine::NH: return shadeAs<Cosine::NH>(n28, sqnorm, p_cam, requests);
    case Cosine::RV: return shadeAs<Cosine::RV>(n28, sqnorm, p_cam, requests);
    case Cosine::CookTorrance: return shadeAs<Cosine::CookTorrance>(n28, sqnorm, p_cam, requests);
    case Cosine::Device: break;
  }
  return shadeAs<Cosine::Device>(n28, sqnorm, p_cam, requests);
}

template <FixedPointShader::Cosine C>
inline FixedShade FixedPointShader::shadeAs(const int64_t* n28, uint64_t sqnorm, Vec3 p_cam,
                                            std::vector<SpecRequest>* requests) {
  using fixed_detail::dot58;
  constexpr bool needs_nv = needsNv(C);
  return shadeDots<C>(
      Consts{ambient_, table_ ? table_->code.data() : nullptr, table_ ? table_->zero_below : 0, lights_.data(),
             lights_.size()}, sqnorm,
      needs_nv ? dot58(n28, v_) : 0,
      [&](size_t, PerLight& pl) {
        if (pl.light->point) setDirections(pl, lightDirection(*pl.light, p_cam));
        return dot58(n28, pl.l);
      },
      [&](size_t, const PerLight& pl) { return dot58(n28, pl.h); }, requests);
}

template <FixedPointShader::Cosine C, class NL, class NH>
inline FixedShade FixedPointShader::shadeDots(const Consts& k, uint64_t sqnorm, int64_t raw_nv, NL nl_of, NH nh_of,
                                              std::vector<SpecRequest>* requests) {
  using namespace fixed_detail;
  FixedShade s;
  s.code = k.ambient;
  const CosineScale sc = cosineScale(sqnorm);
  constexpr bool needs_nv = needsNv(C);
  const int64_t nv = needs_nv ? scaleCosine(raw_nv, sc) : 0;
  for (size_t li = 0; li < k.count; ++li) {
    PerLight& pl = k.lights[li];
    const int64_t nl = scaleCosine(nl_of(li, pl), sc);
    if (nl <= 0) continue;  // the surface faces away from this light
    for (size_t c = 0; c < 3; ++c) s.code[c] += roundShift(pl.diffuse[c] * nl, 32);
    const int64_t nh = scaleCosine(nh_of(li, pl), sc);
    if constexpr (C == Cosine::Device) {
      const uint32_t cos = cosCode(nh, coding_->cos_frac_bits);
      deviceRequest(s, memo_, pl.memo, *coding_, cos, pl.device_light, requests);
    } else {
      uint32_t f = 0;
      if constexpr (C == Cosine::NH) {
        f = lobeAt(k.table, nh, k.zero_below);
      } else if constexpr (C == Cosine::RV) {
        // R.V = 2 (N.L)(N.V) - L.V: the product of two Q2.32 is Q4.64, 2 x it back to Q2.32
        const __int128 p = static_cast<__int128>(nl) * nv;
        const int64_t rv = static_cast<int64_t>((p + (__int128{1} << 30)) >> 31) - pl.lv;
        f = lobeAt(k.table, rv, k.zero_below);
      } else {
        f = cookTorranceCode(nl, nv, nh, pl);
      }
      for (size_t c = 0; c < 3; ++c) s.code[c] += roundShift(pl.specular[c] * f, 24);
    }
  }
  return s;
}

template <FixedPointShader::Cosine C, class F>
inline void FixedPointShader::withLightCount(F&& f) {
  static_assert(kMaxRunLights == 4, "one case per light count");
  switch (lights_.size()) {
    case 0: withKernel<RunKernel<C, 0>>(f); break;
    case 1: withKernel<RunKernel<C, 1>>(f); break;
    case 2: withKernel<RunKernel<C, 2>>(f); break;
    case 3: withKernel<RunKernel<C, 3>>(f); break;
    case 4: withKernel<RunKernel<C, 4>>(f); break;
    default: throw std::logic_error("FixedPointShader: a run with more lights than kMaxRunLights");
  }
}

template <class F>
inline void FixedPointShader::withRunKernel(F&& f) {
  if (!takesRuns()) throw std::logic_error("FixedPointShader: runs need directional lights and the memo");
  switch (cosine_) {
    case Cosine::NH: withLightCount<Cosine::NH>(f); break;
    case Cosine::RV: withLightCount<Cosine::RV>(f); break;
    case Cosine::CookTorrance: withLightCount<Cosine::CookTorrance>(f); break;
    case Cosine::Device: withLightCount<Cosine::Device>(f); break;
  }
}

}  // namespace shd
