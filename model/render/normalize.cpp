#include "render/normalize.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace shd {

std::vector<uint64_t> squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn,
                                            size_t count) {
  std::vector<uint64_t> f;
  if (count == 0) return f;
  f.reserve(count);
  SquaredNormRecurrence r;
  f.push_back(r.start(n0, dn));
  while (f.size() < count) f.push_back(r.next());
  return f;
}

namespace {
constexpr int kScaleRange = 256;  // |e| of the result's scale 2^(-e/2)
}  // namespace

template <int SeedBits>
const std::array<uint32_t, size_t{1} << SeedBits> RsqrtSeed<SeedBits>::table = [] {
  std::array<uint32_t, size_t{1} << SeedBits> t{};
  for (size_t i = 0; i < t.size(); ++i) {
    const double mid = 0.25 + (static_cast<double>(i) + 0.5) * (0.75 / static_cast<double>(t.size()));
    t[i] = static_cast<uint32_t>(std::lround(std::ldexp(1.0 / std::sqrt(mid), 16)));
  }
  return t;
}();
template struct RsqrtSeed<8>;
template struct RsqrtSeed<10>;

double rsqrtFixed(uint64_t v, int frac_bits) {
  if (v == 0) return 0;
  const RsqrtCore c = rsqrtCore(v);
  const int shift = c.shift;
  const int64_t r1 = c.r >> 16;  // Q16
  // value = (m / 2^62) * 2^e with e = 62 - 2 shift - frac_bits
  const int e = 62 - 2 * shift - frac_bits;
  // 2^(-e/2): a power of two, times sqrt(2) when e is odd (what pow(2, -e/2) rounds to).
  // (A table of the scales: powers of two, exact, no ldexp call per pixel.)
  static const std::array<double, 2 * kScaleRange + 1> scales = [] {
    std::array<double, 2 * kScaleRange + 1> t{};
    for (int i = 0; i < 2 * kScaleRange + 1; ++i) {
      const int ee = i - kScaleRange;
      const int h = ee >= 0 ? -((ee + 1) / 2) : (-ee) / 2;  // floor(-ee/2)
      t[static_cast<size_t>(i)] = std::ldexp((ee & 1) != 0 ? std::sqrt(2.0) : 1.0, h - 16);
    }
    return t;
  }();
  if (e < -kScaleRange || e > kScaleRange) throw std::out_of_range("rsqrtFixed: frac_bits out of range");
  return static_cast<double>(r1) * scales[static_cast<size_t>(e + kScaleRange)];
}

}  // namespace shd
