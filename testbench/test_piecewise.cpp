// Piecewise minimax approximations of c^n (approx/piecewise.h): the Remez result equioscillates
// and its error is the true maximum (against dense sampling); segments lower the whole-lobe
// error; exact cases are exact.
#include "approx/piecewise.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace shd;

namespace {

double sampledMax(const std::function<double(double)>& f, double n, double a, double b) {
  double worst = 0;
  for (int i = 0; i <= 200000; ++i) {
    const double c = a + (b - a) * i / 200000.0;
    worst = std::max(worst, std::fabs(f(c) - std::pow(c, n)));
  }
  return worst;
}

}  // namespace

TEST(Piecewise, MinimaxSegmentEquioscillates) {
  for (double n : {2.5, 32.0, 1000.0})
    for (int d : {1, 2, 3}) {
      const double a = n > 100 ? 0.99 : 0.5;
      const SegmentFit s = minimaxSegment(n, d, a, 1.0);
      const double dense = sampledMax([&](double c) { return s.eval(c); }, n, a, 1.0);
      EXPECT_GE(s.err, dense * (1 - 1e-12)) << "n " << n << " d " << d;  // exact extrema: never below sampling
      EXPECT_LE(s.err, dense * (1 + 1e-6) + 1e-15) << "n " << n << " d " << d;
      // A higher degree never does worse.
      if (d > 1) {
        EXPECT_LT(s.err, minimaxSegment(n, d - 1, a, 1.0).err);
      }
    }
}

TEST(Piecewise, LinearMinimaxOfASquareIsKnown) {
  // c^2 on [0, 1] by a line: p = c - 1/8, error 1/8 (Chebyshev).
  const SegmentFit s = minimaxSegment(2, 1, 0, 1);
  EXPECT_NEAR(s.err, 0.125, 1e-12);
  EXPECT_NEAR(s.eval(0.5), 0.375, 1e-12);
}

TEST(Piecewise, PolynomialsReproduceThemselves) {
  const SegmentFit s = minimaxSegment(2, 2, 0.25, 1.0);
  EXPECT_LT(s.err, 1e-14);
}

TEST(Piecewise, SegmentsLowerTheWholeLobeError) {
  double last = 1;
  for (int S : {1, 2, 4}) {
    const PiecewiseFit f = fitPiecewise(100, S, 2);
    EXPECT_LT(f.err, last) << S;
    last = f.err;
    EXPECT_EQ(f.segments.size(), static_cast<size_t>(S));
    const double dense = sampledMax([&](double c) { return f.eval(c); }, 100, 0, 1);
    EXPECT_NEAR(f.err, dense, 1e-6 * f.err) << S;  // the segments and the cut meet the bound
    EXPECT_GE(f.err, dense * (1 - 1e-9)) << S;
  }
}

TEST(Piecewise, IntegerSegmentsFollowTheRealOnesToTheirRounding) {
  // With wide coefficients the integer evaluation is the real fit rounded: within half an LSB
  // of f (and a margin for the coefficients' and Horner's 2^-30 steps) at every cosine code, the
  // segment picked by comparing codes with B being the one the real fit picks.
  const int wc = 12, wf = 16;
  for (double n : {8.0, 100.0, 1000.0})
    for (int S : {1, 2, 4}) {
      const PiecewiseFit f = fitPiecewise(n, S, 2);
      const PiecewiseCodes q = quantisePiecewise(f, wc, wf, 30);
      ASSERT_EQ(q.segs.size(), static_cast<size_t>(S));
      double worst = 0;
      for (int64_t C = 0; C <= (int64_t{1} << wc); ++C) {
        const double real = std::clamp(f.eval(std::ldexp(static_cast<double>(C), -wc)), 0.0, 1.0);
        worst = std::max(worst, std::fabs(static_cast<double>(q.eval(C)) - std::ldexp(real, wf)));
      }
      EXPECT_LE(worst, 0.5 + 1e-3) << "n " << n << " S " << S;
    }
}
