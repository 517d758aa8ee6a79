// The normalisation hardware of phong-incremental: the corrected squared-norm recurrence of paper 4.1 (docs/paper-corrections.md)
// against direct evaluation, and the fixed-point reciprocal square root's error.
#include "render/normalize.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace shd;

TEST(SquaredNormRecurrence, EqualsDirectEvaluationExactly) {
  std::mt19937_64 rng(3);
  for (int t = 0; t < 20000; ++t) {
    std::array<int64_t, 3> n0{}, dn{};
    for (size_t k = 0; k < 3; ++k) {
      n0[k] = static_cast<int64_t>(rng() % (1u << 29)) - (1 << 28);                 // |N| <= 1 at 28 bits
      dn[k] = static_cast<int64_t>(rng() % (uint64_t{1} << 34)) - (int64_t{1} << 33);  // up to sliver gradients
    }
    const size_t count = 1 + rng() % 40;
    const auto f = squaredNormsAlongSpan(n0, dn, count);
    ASSERT_EQ(f.size(), count);
    for (size_t i = 0; i < count; ++i) {
      uint64_t direct = 0;  // modulo 2^64, like the recurrence
      for (size_t k = 0; k < 3; ++k) {
        const uint64_t v = static_cast<uint64_t>(n0[k]) + static_cast<uint64_t>(i) * static_cast<uint64_t>(dn[k]);
        direct += v * v;
      }
      ASSERT_EQ(f[i], direct) << "pixel " << i;
    }
  }
}

TEST(SquaredNormRecurrence, PrintedSeedWouldBeWrong) {
  // The paper seeds the second difference with "C_0 = 1"; starting the recurrence there
  // (F_1 = F_0 + 2B + C_0 with C_0 = 1) is wrong whenever C != 1.
  const std::array<int64_t, 3> n0{100, 0, 0}, dn{3, 0, 0};  // A = 10000, B = 300, C = 9
  const auto f = squaredNormsAlongSpan(n0, dn, 3);
  EXPECT_EQ(f[1], 103u * 103u);
  EXPECT_NE(10000u + 2 * 300u + 1u, 103u * 103u);
  EXPECT_EQ(f[2], 106u * 106u);
}

TEST(RsqrtFixed, RelativeErrorBelowTwoToMinus14) {
  std::mt19937_64 rng(4);
  double worst = 0;
  for (int t = 0; t < 200000; ++t) {
    const int frac = 56;
    // |N|^2 between 1/16 and 4 (normals of length 1/4..2 after interpolation)
    const double v = std::ldexp(1.0, -4) + (4 - std::ldexp(1.0, -4)) * std::ldexp(static_cast<double>(rng() >> 11), -53);
    const uint64_t code = static_cast<uint64_t>(std::ldexp(v, frac));
    const double exact = 1 / std::sqrt(std::ldexp(static_cast<double>(code), -frac));
    const double rel = std::fabs(rsqrtFixed(code, frac) / exact - 1);
    worst = std::max(worst, rel);
  }
  EXPECT_LT(worst, std::ldexp(1.0, -14)) << worst;
  RecordProperty("worst_relative_error", std::to_string(worst));
  EXPECT_EQ(rsqrtFixed(0, 56), 0.0);
}

// rsqrtCore's normalisation (by the bit length, no loop) against the definition: m = v 4^shift
// in [2^60, 2^62); and its relative error against 1/sqrt of the Q32 mantissa it reads.
template <int SeedBits>
double rsqrtCoreWorst() {
  std::mt19937_64 rng(5);
  double worst = 0;
  for (int bits = 1; bits <= 64; ++bits)
    for (int t = 0; t < 5000; ++t) {
      const uint64_t v = (rng() >> (64 - bits)) | (uint64_t{1} << (bits - 1));
      const RsqrtCore c = rsqrtCore<SeedBits>(v);
      const long double m = std::ldexp(static_cast<long double>(v), 2 * c.shift);
      EXPECT_GE(m, std::ldexp(1.0L, 60)) << v;
      EXPECT_LT(m, std::ldexp(1.0L, 62)) << v;
      // the first version's loops: up by 4 while v < 2^60, down by 4 while v >= 2^62
      EXPECT_EQ(c.shift, bits >= 63 ? -1 : (62 - bits) / 2) << v;
      const long double exact = 1 / std::sqrt(std::ldexp(std::floor(m / std::ldexp(1.0L, 30)), -32));
      worst = std::max(worst, static_cast<double>(std::fabs(std::ldexp(static_cast<long double>(c.r), -32) / exact - 1)));
    }
  return worst;
}

TEST(RsqrtCore, NormalisesByTheBitLengthWithinItsSeedsError) {
  const double w8 = rsqrtCoreWorst<8>(), w10 = rsqrtCoreWorst<10>();
  // One Newton step squares the seed's relative error e0 (1.5 e0^2): e0 <= 2^-8.4 with 256
  // entries over [1/4, 1), a quarter of it with 1024.
  EXPECT_LT(w8, 1.3e-5) << w8;
  EXPECT_LT(w10, 1e-6) << w10;
  RecordProperty("worst_relative_error_seed8", std::to_string(w8));
  RecordProperty("worst_relative_error_seed10", std::to_string(w10));
}

// rsqrtCore's Newton step r0 (3 2^32 - m r0^2) >> 17 is not negative with either seed table:
// m r0^2 (mr, Q32) stays below 3 2^32 at the top of every entry's interval of m (mr grows with
// m), so 3 2^32 - mr > 0. The vector kernels (shadeNh, shadeNhAvx2) shift the product right
// logically.
template <int SeedBits>
void checkSeedProducts() {
  const auto& table = RsqrtSeed<SeedBits>::table;
  for (size_t i = 0; i < table.size(); ++i) {
    // The largest Q32 mantissa mq whose index ((mq - 2^30) << SeedBits) / (3 2^30) is i.
    const uint64_t top = (uint64_t{1} << 30) + (i + 1) * (uint64_t{3} << (30 - SeedBits)) - 1;
    const uint64_t r0 = table[i];
    const uint64_t mr = static_cast<uint64_t>((static_cast<unsigned __int128>(top) * (r0 * r0)) >> 32);
    EXPECT_LT(mr, uint64_t{3} << 32) << "seed bits " << SeedBits << " entry " << i;
    EXPECT_GT(rsqrtCore<SeedBits>(top << 30).r, 0) << "seed bits " << SeedBits << " entry " << i;
  }
}
TEST(RsqrtCore, SeedProductsStayBelowThree) {
  checkSeedProducts<8>();
  checkSeedProducts<10>();
}

// phong-fixed's cosines: (N.u) / |N| from the integer dot product, the exact squared norm and
// the 10-bit-seed rsqrtCore, against the exact value of the same codes, for normals of length
// 1/16 to 1.2 (interpolation shortens them).
TEST(CosineScale, WithinTheRsqrtErrorOfTheExactCosineOfTheCodes) {
  std::mt19937_64 rng(6);
  std::normal_distribution<double> g;
  double worst = 0;
  for (int t = 0; t < 200000; ++t) {
    const double len = 0.0625 + 1.1375 * std::ldexp(static_cast<double>(rng() >> 11), -53);
    std::array<double, 3> n{g(rng), g(rng), g(rng)}, u{g(rng), g(rng), g(rng)};
    const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    const double un = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    int64_t d = 0;
    uint64_t sq = 0;
    long double dl = 0, sql = 0;
    for (size_t k = 0; k < 3; ++k) {
      const int64_t n28 = std::llround(std::ldexp(n[k] / nn * len, 28));
      const int64_t u30 = std::llround(std::ldexp(u[k] / un, 30));
      d += n28 * u30;
      sq += static_cast<uint64_t>(n28 * n28);
      dl += static_cast<long double>(n28) * u30;
      sql += static_cast<long double>(n28) * n28;
    }
    const long double exact = dl / std::sqrt(sql) * 4;  // d 2^-58 / (|N| 2^-28), in Q2.32
    const int64_t got = scaleCosine(d, cosineScale(sq));
    worst = std::max(worst, static_cast<double>(std::fabs(got - exact) / std::ldexp(1.0L, 32)));
  }
  EXPECT_LT(worst, 1e-6) << worst;
  RecordProperty("worst_abs_error", std::to_string(worst));
  EXPECT_EQ(scaleCosine(int64_t{1} << 58, cosineScale(0)), 0);  // a zero normal: cosine 0
}

// scaleCosine evaluates (d r + 2^(s-1)) >> s for s >= 35 as the high word of d r 2^(64-s) plus
// 2^63: the same value as the 128-bit definition, for every squared norm's bit length (every s
// from 31 to 62) and dot products of either sign up to the largest a normal of AttrBits 32
// codes gives, and the definition's own path below s = 35.
TEST(CosineScale, HighWordEvaluationEqualsTheDefinition) {
  std::mt19937_64 rng(7);
  uint64_t fast = 0, full = 0;
  for (int bits = 1; bits <= 64; ++bits) {
    for (int t = 0; t < 20000; ++t) {
      const uint64_t top = uint64_t{1} << (bits - 1);
      const uint64_t sq = top | (bits > 1 ? rng() & (top - 1) : 0);
      const CosineScale c = cosineScale(sq);
      // |d| <= |N| |u| with |u| <= 2^30 (Q1.30) and |N| = sqrt(sq): up to 2^(bits/2 + 30)
      const int shift = std::min(62, bits / 2 + 31);
      const int64_t d = static_cast<int64_t>(rng() >> (64 - shift)) * ((rng() & 1) != 0 ? 1 : -1);
      const int64_t want =
          static_cast<int64_t>((static_cast<__int128>(d) * c.r + (static_cast<__int128>(1) << (c.s - 1))) >> c.s);
      ASSERT_EQ(scaleCosine(d, c), want) << "sqnorm " << sq << " d " << d;
      ++(c.r64 != 0 ? fast : full);
    }
  }
  EXPECT_GT(fast, 0u);
  EXPECT_GT(full, 0u);
}
