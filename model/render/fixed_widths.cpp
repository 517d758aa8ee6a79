#include "render/fixed_widths.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "approx/brdf.h"

namespace shd {

namespace {

using i128 = __int128;
using u128 = unsigned __int128;

// round(x 2^-s), half up; x itself for s = 0.
inline i128 roundShift(i128 x, int s) { return s == 0 ? x : (x + (i128{1} << (s - 1))) >> s; }

// x 2^(to - from), rounded half up when it narrows.
inline i128 rescale(i128 x, int from, int to) {
  return to >= from ? x * (i128{1} << (to - from)) : roundShift(x, from - to);
}

// N (NormalFracBits) . u (UnitFracBits): exact, NormalFracBits + UnitFracBits fraction bits.
inline i128 dot(const int64_t* n, const std::array<int64_t, 3>& u) {
  return i128{n[0]} * u[0] + i128{n[1]} * u[1] + i128{n[2]} * u[2];
}

}  // namespace

std::shared_ptr<const std::vector<uint32_t>> rsqrtSeedTable(int seed_bits, int frac_bits) {
  static std::mutex mutex;
  static std::map<std::pair<int, int>, std::shared_ptr<const std::vector<uint32_t>>> cache;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_pair(seed_bits, frac_bits);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  if (cache.size() >= 32) cache.clear();  // tables in use live on
  auto t = std::make_shared<std::vector<uint32_t>>(size_t{1} << seed_bits);
  for (size_t i = 0; i < t->size(); ++i) {  // RsqrtSeed's expression, at these widths
    const double mid = 0.25 + (static_cast<double>(i) + 0.5) * (0.75 / static_cast<double>(t->size()));
    (*t)[i] = static_cast<uint32_t>(std::lround(std::ldexp(1.0 / std::sqrt(mid), frac_bits)));
  }
  cache.emplace(key, t);
  return t;
}

WidthsRsqrt widthsRsqrt(uint64_t v, const PhongWidths& w, const uint32_t* seeds) {
  // m = v 4^shift in [2^60, 2^62) (v >= 2^62: down by 4), as rsqrtCore.
  const int bits = 64 - __builtin_clzll(v);
  const int shift = bits <= 62 ? (62 - bits) / 2 : -1;
  const uint64_t m = shift >= 0 ? v << (2 * shift) : v >> 2;
  // The seed's interval: floor((m 2^-62 - 1/4) 2^RsqrtSeedBits / (3/4)), exact.
  const size_t idx = static_cast<size_t>((u128{m - (uint64_t{1} << 60)} << w.RsqrtSeedBits) / (u128{3} << 60));
  const u128 r0 = seeds[idx];  // uQ2.RsqrtSeedFracBits
  const int rf = w.NewtonFracBits, sf = w.RsqrtSeedFracBits;
  if (w.NewtonSteps == 0) return {static_cast<uint64_t>(rf >= sf ? r0 << (rf - sf) : r0 >> (sf - rf)), shift};
  const u128 mq = m >> (62 - rf);  // m 2^-62, truncated to uQ0.NewtonFracBits
  u128 r = r0;
  int frac = sf;  // r's fraction bits
  for (int k = 0; k < w.NewtonSteps; ++k) {
    const u128 mr = (mq * r * r) >> (2 * frac);                // m r^2, truncated to NewtonFracBits
    r = (r * ((u128{3} << rf) - mr)) >> (frac + 1);            // r (3 - m r^2) / 2, truncated likewise
    frac = rf;
  }
  return {static_cast<uint64_t>(r), shift};
}

FixedWidthsShader::FixedWidthsShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding,
                                     SpecResultMemo* memo, const PhongWidths& w)
    : ctx_(ctx), m_(m), w_(w), memo_(memo), lobe_format_{w.LobeCosBits, w.LobeCodeBits, w.LobeIntBits} {
  w_.validate();
  cosine_ = fixedCosineOf(lobe);
  if (cosine_ == Cosine::Device) coding_ = checkedDeviceCoding(coding, memo, "FixedWidthsShader");
  if (cosine_ == Cosine::NH || cosine_ == Cosine::RV) table_ = lobeTable(lobe, m.shininess, lobe_format_);
  seeds_ = rsqrtSeedTable(w_.RsqrtSeedBits, w_.RsqrtSeedFracBits);
  v_ = {unitCode(ctx.view.x), unitCode(ctx.view.y), unitCode(ctx.view.z)};
  // The factor codes: round(lsb 2^ColourFracBits), saturated at 2^(FactorIntBits + ColourFracBits) - 1.
  const double scale = std::ldexp(1.0, w_.ColourFracBits);
  const double factor_max = std::ldexp(1.0, w_.FactorIntBits + w_.ColourFracBits) - 1;
  auto factor = [&](double lsb) -> int64_t {
    const double x = lsb * scale;
    if (!(x >= 0)) throw std::logic_error(fmt::format("phong-fixed: a lighting factor of {} LSB", lsb));
    return x >= factor_max ? static_cast<int64_t>(factor_max) : std::llround(x);
  };
  SpecResultMemo* rows = cosine_ == Cosine::Device ? memo_ : nullptr;
  needs_position_ = codeLights(ctx, m, factor, rows, rows ? coding_->shin : 0, ambient_, lights_);
  for (PerLight& pl : lights_)
    if (!pl.light->point) setDirections(pl, pl.light->dir);
}

int64_t FixedWidthsShader::unitCode(double x) const { return std::llround(std::ldexp(x, w_.UnitFracBits)); }

void FixedWidthsShader::setDirections(PerLight& pl, Vec3 l) const {
  const Vec3 h = normalize(l + ctx_.view);
  pl.l = {unitCode(l.x), unitCode(l.y), unitCode(l.z)};
  pl.h = {unitCode(h.x), unitCode(h.y), unitCode(h.z)};
  const i128 lv = i128{pl.l[0]} * v_[0] + i128{pl.l[1]} * v_[1] + i128{pl.l[2]} * v_[2];  // 2 UnitFracBits
  pl.lv = static_cast<int64_t>(rescale(lv, 2 * w_.UnitFracBits, w_.CosFracBits));
  pl.vh = dot(ctx_.view, h);
}

FixedWidthsShader::Scale FixedWidthsShader::scaleOf(uint64_t sqnorm) const {
  if (sqnorm == 0) return {0, 1};  // a zero normal: every cosine 0
  const WidthsRsqrt q = widthsRsqrt(sqnorm, w_, seeds_->data());
  // N.u / |N| = N.u r 2^(shift - 31 - UnitFracBits - NewtonFracBits) (NormalFracBits cancels:
  // |N|^2 has twice its fraction bits), in sQ2.CosFracBits.
  return {q.r, 31 + w_.UnitFracBits + w_.NewtonFracBits - w_.CosFracBits - q.shift};
}

int64_t FixedWidthsShader::cosine(i128 d, Scale sc) const {
  return static_cast<int64_t>((d * static_cast<i128>(sc.r) + (i128{1} << (sc.s - 1))) >> sc.s);
}

uint32_t FixedWidthsShader::lobeAt(int64_t c) const {
  // The cosine clamped to [0, 1]: the entry at its top LobeCosBits bits and the linear step to
  // the next with its other CosFracBits - LobeCosBits bits, rounded half up.
  const uint32_t* t = table_->code.data();
  const int fb = w_.CosFracBits - w_.LobeCosBits;
  const uint64_t cc = static_cast<uint64_t>(std::clamp<int64_t>(c, 0, int64_t{1} << w_.CosFracBits));
  const uint64_t i = cc >> fb, frac = cc & ((uint64_t{1} << fb) - 1);
  const int64_t step = int64_t{t[i + 1]} - int64_t{t[i]};
  return static_cast<uint32_t>(t[i] + static_cast<int64_t>(roundShift(i128{step} * static_cast<i128>(frac), fb)));
}

FixedShade FixedWidthsShader::shade(const int64_t* n, uint64_t sqnorm, Vec3 p_cam, std::vector<SpecRequest>* requests) {
  FixedShade s;
  s.code = ambient_;
  const Scale sc = scaleOf(sqnorm);
  const bool needs_nv = cosine_ == Cosine::RV || cosine_ == Cosine::CookTorrance;
  const int64_t nv = needs_nv ? cosine(dot(n, v_), sc) : 0;
  for (PerLight& pl : lights_) {
    if (pl.light->point) setDirections(pl, lightDirection(*pl.light, p_cam));
    const int64_t nl = cosine(dot(n, pl.l), sc);
    if (nl <= 0) continue;  // the surface faces away from this light
    for (size_t c = 0; c < 3; ++c)
      s.code[c] += static_cast<int64_t>(roundShift(i128{pl.diffuse[c]} * nl, w_.CosFracBits));
    addSpecular(s, pl, nl, nv, cosine(dot(n, pl.h), sc), requests);
  }
  return s;
}

void FixedWidthsShader::addSpecular(FixedShade& s, PerLight& pl, int64_t nl, int64_t nv, int64_t nh,
                                    std::vector<SpecRequest>* requests) const {
  if (cosine_ == Cosine::Device) {
    // N.H at the unit's CosFracBits, rounded half up, clamped to [0, 1].
    const int cf = coding_->cos_frac_bits;
    const uint32_t cos = static_cast<uint32_t>(
        std::clamp<i128>(rescale(nh, w_.CosFracBits, cf), 0, i128{1} << cf));
    deviceRequest(s, memo_, pl.memo, *coding_, cos, pl.device_light, requests);
    return;
  }
  uint32_t f = 0;
  if (cosine_ == Cosine::NH) {
    f = lobeAt(nh);
  } else if (cosine_ == Cosine::RV) {
    // R.V = 2 (N.L)(N.V) - L.V: the product of two sQ2.CosFracBits, twice it back to CosFracBits
    const i128 p = i128{nl} * nv;
    f = lobeAt(static_cast<int64_t>((p + (i128{1} << (w_.CosFracBits - 2))) >> (w_.CosFracBits - 1)) - pl.lv);
  } else {
    const double q = std::ldexp(1.0, -w_.CosFracBits);
    f = lobeCode(cookTorrance(static_cast<double>(nl) * q, static_cast<double>(nv) * q, static_cast<double>(nh) * q,
                              pl.vh, CookTorranceParams{m_.roughness, m_.f0}),
                 lobe_format_);
  }
  for (size_t c = 0; c < 3; ++c)
    s.code[c] += static_cast<int64_t>(roundShift(i128{pl.specular[c]} * f, w_.LobeCodeBits));
}

std::array<uint8_t, 3> FixedWidthsShader::colour(const FixedShade& s) const {
  std::array<uint8_t, 3> out{};
  for (size_t k = 0; k < 3; ++k)
    out[k] = static_cast<uint8_t>(std::min<uint32_t>(255, unorm8FromCode(s.code[k], w_.ColourFracBits) + s.device[k]));
  return out;
}

double FixedWidthsShader::lsb(int64_t code) const { return std::ldexp(static_cast<double>(code), -w_.ColourFracBits); }

}  // namespace shd
