#include "render/normalize.h"

#include <algorithm>
#include <cmath>

namespace shd {

std::vector<uint64_t> squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn,
                                            size_t count) {
  std::vector<uint64_t> f;
  if (count == 0) return f;
  f.reserve(count);
  uint64_t A = 0, B = 0, C = 0;
  for (size_t k = 0; k < 3; ++k) {
    const uint64_t a = static_cast<uint64_t>(n0[k]), d = static_cast<uint64_t>(dn[k]);
    A += a * a;
    B += a * d;
    C += d * d;
  }
  uint64_t F = A, Ci = C;  // F_0 = A, C_1 = C
  f.push_back(F);
  for (size_t i = 1; i < count; ++i) {
    F += 2 * B + Ci;  // F_i = F_{i-1} + 2B + C_i
    Ci += 2 * C;      // C_{i+1} = C_i + 2C
    f.push_back(F);
  }
  return f;
}

double rsqrtFixed(uint64_t v, int frac_bits) {
  if (v == 0) return 0;
  // v = m * 4^-shift with m in [2^60, 2^62): m / 2^62 in [1/4, 1).
  int shift = 0;
  uint64_t m = v;
  while (m < (uint64_t{1} << 60)) {
    m <<= 2;
    ++shift;
  }
  while (m >= (uint64_t{1} << 62)) {
    m >>= 2;
    --shift;
  }
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double mid = 0.25 + (i + 0.5) * (0.75 / 256);
      t[static_cast<size_t>(i)] = static_cast<uint32_t>(std::lround(std::ldexp(1.0 / std::sqrt(mid), 16)));
    }
    return t;
  }();
  const uint64_t mq = m >> 30;  // m / 2^62 in Q32, in [2^30, 2^32)
  const size_t idx = std::min<size_t>(255, static_cast<size_t>(((mq - (uint64_t{1} << 30)) * 256) / (3 * (uint64_t{1} << 30))));
  const uint64_t r0 = table[idx];                                                             // Q16, < 2^17
  const uint64_t mr = static_cast<uint64_t>((static_cast<unsigned __int128>(mq) * (r0 * r0)) >> 32);  // m r0^2, Q32
  const int64_t r1 = static_cast<int64_t>(r0) * ((int64_t{3} << 32) - static_cast<int64_t>(mr)) >> 33;  // Q16
  // value = (m / 2^62) * 2^e with e = 62 - 2 shift - frac_bits
  const int e = 62 - 2 * shift - frac_bits;
  return std::ldexp(static_cast<double>(r1), -16) * std::pow(2.0, -0.5 * e);
}

}  // namespace shd
