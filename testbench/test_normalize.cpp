// The normalisation hardware of phong-incremental: the squared-norm recurrence of errata 4.1
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
