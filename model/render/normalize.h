// Normalising interpolated normals in hardware terms (phong-incremental, phong-fixed).
//
// Squared norm along a span (paper 4.1, as corrected in docs/paper-corrections.md): with N_i = N_0 + i dN,
//   F_i = |N_i|^2 = A + 2 i B + i^2 C,  A = |N_0|^2, B = N_0 . dN, C = |dN|^2,
// and by finite differences F_{i+1} = F_i + 2B + C_{i+1}, C_{i+1} = C_i + 2C, with F_0 = A and
// C_1 = C (the paper's seed "C_0 = 1" is wrong). After the three products of A, B and C once per
// span, each pixel costs two additions. On integer attribute codes the recurrence is exact;
// it runs in uint64_t, i.e. modulo 2^64, so large increments (slivers) wrap in the partial sums
// but every F_i, which fits, comes out exact.
//
// Reciprocal square root in fixed point: a 256-entry table of 1/sqrt(m) (uQ2.16) for the
// mantissa m in [1/4, 1) and one Newton step, all in integers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace shd {

// The recurrence along one span: start() at its first pixel returns F_0 = A, each next() the
// following pixel's F_i (two additions).
class SquaredNormRecurrence {
 public:
  // The closed form's terms, mod 2^64: F_i = a + i two_b + i^2 c.
  struct Terms {
    uint64_t a, two_b, c;
  };
  static Terms terms(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn) {
    uint64_t A = 0, B = 0, C = 0;
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t a = static_cast<uint64_t>(n0[k]), d = static_cast<uint64_t>(dn[k]);
      A += a * a;
      B += a * d;
      C += d * d;
    }
    return {A, 2 * B, C};
  }
  uint64_t start(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn) {
    const Terms t = terms(n0, dn);
    F_ = t.a;
    two_b_ = t.two_b;
    two_c_ = 2 * t.c;
    ci_ = t.c;  // C_1 = C
    return F_;
  }
  uint64_t next() {
    F_ += two_b_ + ci_;  // F_i = F_{i-1} + 2B + C_i
    ci_ += two_c_;       // C_{i+1} = C_i + 2C
    return F_;
  }

 private:
  uint64_t F_ = 0, two_b_ = 0, two_c_ = 0, ci_ = 0;
};

std::vector<uint64_t> squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn,
                                            size_t count);

// The integer core of the reciprocal square root: for v > 0, v = m 4^-shift with m in
// [2^60, 2^62), and r ~ 1/sqrt(m 2^-62) in uQ2.32 (< 2^33.1): the seed of a table of 2^SeedBits
// values of 1/sqrt at the interval midpoints of m 2^-62 in [1/4, 1), then one Newton step
// r1 = r0 (3 - m r0^2) / 2 in integers. So 1/sqrt(v 2^-f) = r 2^-32 2^((f - 62) / 2 + shift).
// Relative error (test RsqrtCore.*): below 1.3e-5 (2^-16.2) with the 8-bit seed of
// phong-incremental, below 1e-6 with phong-fixed's 10-bit seed (the Newton step squares the
// seed's error: 4 times the entries, 1/16 of the error).
struct RsqrtCore {
  int64_t r = 0;
  int shift = 0;
};
template <int SeedBits>
struct RsqrtSeed {  // round(2^16 / sqrt(1/4 + (i + 1/2) 3/4 2^-SeedBits))
  static const std::array<uint32_t, size_t{1} << SeedBits> table;
};
extern template struct RsqrtSeed<8>;
extern template struct RsqrtSeed<10>;
template <int SeedBits = 8>
inline RsqrtCore rsqrtCore(uint64_t v) {
  // The shift that brings the bit length of m to 61 or 62 (v < 2^60 up, v >= 2^62 down by 4).
  const int bits = 64 - __builtin_clzll(v);
  const int shift = bits <= 62 ? (62 - bits) / 2 : -1;
  const uint64_t m = shift >= 0 ? v << (2 * shift) : v >> 2;
  const uint64_t mq = m >> 30;  // m 2^-62 in Q32, in [2^30, 2^32)
  const size_t idx = static_cast<size_t>(((mq - (uint64_t{1} << 30)) << SeedBits) / (3 * (uint64_t{1} << 30)));
  const uint64_t r0 = RsqrtSeed<SeedBits>::table[idx];  // Q16, < 2^17
  const uint64_t mr = static_cast<uint64_t>((static_cast<unsigned __int128>(mq) * (r0 * r0)) >> 32);  // m r0^2, Q32
  return {static_cast<int64_t>(r0) * ((int64_t{3} << 32) - static_cast<int64_t>(mr)) >> 17, shift};  // Q32
}

// 1/sqrt(v * 2^-frac_bits) for v > 0 (0 for v == 0), rsqrtCore's r truncated to 16 fraction
// bits (phong-incremental).
double rsqrtFixed(uint64_t v, int frac_bits);

// phong-fixed's cosines: the dot product d of an interpolated normal (28 fraction bits per
// component) with a Q1.30 unit vector (58 fraction bits), divided by |N|: with sqnorm = |N|^2
// (56 fraction bits, exact from the recurrence) and (r, shift) = rsqrtCore<10>(sqnorm), d / |N|
// in Q2.32 is d r 2^(shift - 61), rounded half up, in 128 bits. shift <= 30 for sqnorm >= 1,
// so the shift right is 61 - shift in [31, 62].
// Evaluation (the same values): for s >= 35, r 2^(64 - s) < 2^63 (r < 2^33.1), and
// (d r + 2^(s-1)) >> s = (d r 2^(64-s) + 2^63) >> 64, the high word of one product and a
// carry, with no shift by a variable amount; smaller s (sqnorm below 2^8, |N| < 2^-24) in
// full.
struct CosineScale {
  int64_t r = 0;
  int s = 1;  // shift right, 1..62
  int64_t r64 = 0;  // r 2^(64 - s) for s >= 35, else 0
};
constexpr int kFixedSeedBits = 10;
inline CosineScale cosineScale(uint64_t sqnorm) {
  if (sqnorm == 0) return {0, 1, 0};  // a zero normal: every cosine 0
  const RsqrtCore c = rsqrtCore<kFixedSeedBits>(sqnorm);
  const int s = 61 - c.shift;
  return {c.r, s, s >= 35 ? c.r << (64 - s) : 0};
}
inline int64_t scaleCosine(int64_t d, CosineScale c) {
  if (__builtin_expect(c.r64 != 0, 1))
    return static_cast<int64_t>((static_cast<__int128>(d) * c.r64 + (__int128{1} << 63)) >> 64);
  return static_cast<int64_t>((static_cast<__int128>(d) * c.r + (__int128{1} << (c.s - 1))) >> c.s);
}
}  // namespace shd
