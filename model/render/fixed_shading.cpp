#include "render/fixed_shading.h"

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <tuple>

#include <fmt/format.h>

#include "approx/brdf.h"
#include "render/normalize.h"

namespace shd {

namespace {
constexpr int64_t kFactorMax = (int64_t{1} << 30) - 1;
constexpr double kLobeScale = 1 << 24;  // f_code = round(f 2^24)

// round(lsb 2^12), saturated at kFactorMax (lsb >= 0: colours, k_d, k_s are validated >= 0)
int64_t factorCode(double lsb) {
  const double x = lsb * (1 << kFixedColourFrac);
  if (!(x >= 0)) throw std::logic_error(fmt::format("phong-fixed: a lighting factor of {} LSB", lsb));
  return x >= static_cast<double>(kFactorMax) ? kFactorMax : std::llround(x);
}

std::array<int32_t, 3> unitCodes(Vec3 v) {
  auto c = [](double x) { return static_cast<int32_t>(std::lround(std::ldexp(x, kFixedUnitFrac))); };
  return {c(v.x), c(v.y), c(v.z)};
}

// round(f 2^24), saturated at 2^32 - 1
uint32_t lobeFactorCode(double f) {
  if (!(f >= 0)) throw std::logic_error(fmt::format("phong-fixed: a lobe value of {}", f));
  const double x = f * kLobeScale;
  return x >= 4294967295.0 ? 0xFFFFFFFFu : static_cast<uint32_t>(std::llround(x));
}
}  // namespace

uint32_t lobeCode(double f, const LobeFormat& format) {
  if (!(f >= 0)) throw std::logic_error(fmt::format("phong-fixed: a lobe value of {}", f));
  const double x = f * std::ldexp(1.0, format.code_bits);
  const double max = std::ldexp(1.0, format.code_bits + format.int_bits) - 1;
  return x >= max ? static_cast<uint32_t>(max) : static_cast<uint32_t>(std::llround(x));
}

std::shared_ptr<const LobeTable> lobeTable(Lobe lobe, double shininess, const LobeFormat& format) {
  double (*f)(double, double) = nullptr;
  switch (lobe) {
    case Lobe::Phong: f = phongLobe; break;
    case Lobe::Blinn:
    case Lobe::Pow: f = blinnLobe; break;
    case Lobe::NormalizedBlinn: f = normalizedBlinn; break;
    case Lobe::Schlick: f = schlickLobe; break;
    case Lobe::CookTorrance:
    case Lobe::Quadratic:
    case Lobe::Cubic: throw std::logic_error(fmt::format("lobeTable: {} is not a lobe of one cosine", toString(lobe)));
  }
  if (format.cos_bits < 0 || format.cos_bits > 24 || format.code_bits < 0 || format.int_bits < 0 ||
      format.code_bits + format.int_bits > 32)
    throw std::logic_error("lobeTable: a format the 32-bit tables cannot hold");
  static std::mutex mutex;
  static std::map<std::tuple<double (*)(double, double), double, int, int, int>, std::shared_ptr<const LobeTable>> cache;
  static size_t cached_entries = 0;
  const std::lock_guard<std::mutex> lock(mutex);
  const auto key = std::make_tuple(f, shininess, format.cos_bits, format.code_bits, format.int_bits);
  if (const auto it = cache.find(key); it != cache.end()) return it->second;
  const size_t entries = (size_t{1} << format.cos_bits) + 2;
  // A long run over many exponents or formats: start over (tables in use live on).
  if (cache.size() >= 64 || cached_entries + entries > (size_t{1} << 24)) {
    cache.clear();
    cached_entries = 0;
  }
  auto t = std::make_shared<LobeTable>();
  std::vector<uint32_t>& code = t->code;
  code.resize(entries);
  const double codes = static_cast<double>(uint64_t{1} << format.cos_bits);
  for (size_t c = 0; c + 1 < code.size(); ++c) code[c] = lobeCode(f(static_cast<double>(c) / codes, shininess), format);
  code.back() = code[code.size() - 2];
  while (t->zero_below + 1 < code.size() && code[t->zero_below] == 0 && code[t->zero_below + 1] == 0) ++t->zero_below;
  cache.emplace(key, t);
  cached_entries += entries;
  return t;
}

uint64_t* SpecResultMemo::row(uint32_t shin, const std::array<uint32_t, 3>& light) {
  if (model_.params().CosFracBits > kMaxCosFracBits) return nullptr;
  std::vector<uint64_t>& r = rows_[{shin, light[0], light[1], light[2]}];
  if (r.empty()) r.assign(static_cast<size_t>(model_.params().cosOne()) + 1, 0);
  return r.data();
}

uint64_t SpecResultMemo::evaluate(uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const {
  model_.checkCosine(shin, cos);
  const SpecOut o = model_.evaluate(shin, cos, light);
  uint64_t e = kValid;
  for (size_t k = 0; k < 3; ++k) {
    if (o.rgb[k] > 0xFFFFFu) throw std::logic_error("SpecResultMemo: a specular unit output wider than 20 bits");
    e |= uint64_t{o.rgb[k]} << (20 * k);
  }
  return e;
}

FixedCosine fixedCosineOf(Lobe lobe) {
  switch (lobe) {
    case Lobe::Quadratic:
    case Lobe::Cubic: return FixedCosine::Device;
    case Lobe::Phong: return FixedCosine::RV;
    case Lobe::CookTorrance: return FixedCosine::CookTorrance;
    case Lobe::Blinn:
    case Lobe::Pow:
    case Lobe::NormalizedBlinn:
    case Lobe::Schlick: break;
  }
  return FixedCosine::NH;
}

DeviceCoding checkedDeviceCoding(const DeviceCoding* coding, const SpecResultMemo* memo, const char* who) {
  if (coding == nullptr) throw std::logic_error(fmt::format("{}: a device lobe needs the specular unit's coding", who));
  if (coding->cos_frac_bits < 1 || coding->cos_frac_bits > 30)
    throw std::invalid_argument(
        fmt::format("phong-fixed: the specular unit's CosFracBits {} is outside 1..30", coding->cos_frac_bits));
  if (memo != nullptr && memo->model().params().CosFracBits != coding->cos_frac_bits)
    throw std::logic_error(fmt::format("{}: the memo's unit is not the coding's", who));
  return *coding;
}

FixedPointShader::FixedPointShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding,
                                   SpecResultMemo* memo)
    : ctx_(ctx), m_(m), cosine_(fixedCosineOf(lobe)), memo_(memo) {
  if (cosine_ == Cosine::Device) coding_ = checkedDeviceCoding(coding, memo, "FixedPointShader");
  if (cosine_ == Cosine::NH || cosine_ == Cosine::RV) table_ = lobeTable(lobe, m.shininess);
  v_ = unitCodes(ctx.view);
  SpecResultMemo* rows = cosine_ == Cosine::Device ? memo_ : nullptr;
  needs_position_ = codeLights(ctx, m, factorCode, rows, rows ? coding_->shin : 0, ambient_, lights_);
  for (PerLight& pl : lights_)
    if (!pl.light->point) setDirections(pl, pl.light->dir);
}

void FixedPointShader::setDirections(PerLight& pl, Vec3 l) const {
  const Vec3 h = normalize(l + ctx_.view);
  pl.l = unitCodes(l);
  pl.h = unitCodes(h);
  const int64_t lv = int64_t{pl.l[0]} * v_[0] + int64_t{pl.l[1]} * v_[1] + int64_t{pl.l[2]} * v_[2];  // Q2.60
  pl.lv = fixed_detail::roundShift(lv, 28);
  pl.vh = dot(ctx_.view, h);
}

uint32_t FixedPointShader::cookTorranceCode(int64_t nl, int64_t nv, int64_t nh, const PerLight& pl) const {
  constexpr double kQ32 = 1.0 / 4294967296.0;
  return lobeFactorCode(cookTorrance(static_cast<double>(nl) * kQ32, static_cast<double>(nv) * kQ32,
                                     static_cast<double>(nh) * kQ32, pl.vh, CookTorranceParams{m_.roughness, m_.f0}));
}

}  // namespace shd
