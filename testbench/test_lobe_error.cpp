// Maximum-error measurement: the rigorous sampled method and the exact method against brute
// force, against each other, on regions, kinks and jumps.
#include "approx/lobe_error.h"

#include "approx/brdf.h"
#include "approx/fit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

using namespace shd;

namespace {

// Brute force: 10^7 uniform samples of [lo, hi] plus 10^6 samples geometric in 1 - c from
// 1e-13 to 1 (near the peak, where c^n has its 1/n-wide features).
double bruteForceAbs(const std::function<double(double)>& f, double n, double lo, double hi) {
  double best = 0.0;
  auto at = [&](double c) {
    if (c < lo || c > hi) return;
    best = std::max(best, std::fabs(f(c) - std::pow(c, n)));
  };
  const long N = 10000000;
  for (long i = 0; i <= N; ++i) at(lo + (hi - lo) * (double(i) / N));
  for (int i = 0; i <= 1000000; ++i) at(1.0 - std::pow(10.0, -13.0 + 13.0 * i / 1000000.0));
  return best;
}

struct Case {
  std::string name;
  double n;
  std::function<double(double)> f;
  std::vector<double> kinks;
  const Approx* approx;  // non-null: the exact method applies too
};

}  // namespace

TEST(LobeError, RigorousAtLeastBruteForceAndNotAboveIt) {
  const Approx quad_infl = fitApprox(FitKind::Inflection, 2, 1000.0);
  const Approx quad_mm = fitApprox(FitKind::Minimax, 2, 50.0);
  const Approx cub_level = fitApprox(FitKind::Level, 3, 200.0);  // jumps at its cut
  const Approx cub_small = fitApprox(FitKind::Inflection, 3, 4.0);
  std::vector<Case> cases = {
      {"quad inflection n=1000", 1000.0, [&](double c) { return quad_infl.eval(c); },
       quad_infl.kinks(), &quad_infl},
      {"quad minimax n=50", 50.0, [&](double c) { return quad_mm.eval(c); }, quad_mm.kinks(),
       &quad_mm},
      {"cubic level n=200", 200.0, [&](double c) { return cub_level.eval(c); },
       cub_level.kinks(), &cub_level},
      {"cubic inflection n=4", 4.0, [&](double c) { return cub_small.eval(c); },
       cub_small.kinks(), &cub_small},
      {"schlick n=100", 100.0, [](double c) { return schlickLobe(c, 100.0); }, {}, nullptr},
  };
  for (const Case& k : cases) {
    const double brute = bruteForceAbs(k.f, k.n, 0.0, 1.0);
    const RegionError r = maxError(k.f, k.n, 0.0, 1.0, false, k.kinks);
    // Never below brute force, and above it only by what brute force's 1e-7 grid can miss at
    // a jump or kink: the slope of the error (<= ~n here) times the spacing.
    EXPECT_GE(r.max_abs, brute - 1e-12) << k.name;
    EXPECT_LE(r.max_abs, brute + k.n * 1e-7) << k.name;
    // The reported point carries the reported error (a one-sided supremum at a cut, from the
    // left where f = 0, is reported at the cut itself).
    const double c = r.worst_abs_c;
    double at_c = std::fabs(k.f(c) - std::pow(c, k.n));
    if (k.approx && c == k.approx->cut) at_c = std::max(at_c, std::pow(c, k.n));
    EXPECT_NEAR(at_c, r.max_abs, 1e-15) << k.name;
    if (k.approx) {
      const RegionError e = maxErrorExact(*k.approx, k.n, 0.0, 1.0, false);
      EXPECT_GE(e.max_abs, brute - 1e-12) << k.name;
      EXPECT_NEAR(e.max_abs, r.max_abs, 1e-12) << k.name;
    }
  }
}

TEST(LobeError, ExactAndSampledMethodsAgreeOnAllFitsAndRegions) {
  // Two independent algorithms (derivative-chain candidates vs dense grid + golden section):
  // agreement to 1e-12 absolute and 1e-10 relative.
  for (double n : {1.0, 1.5, 2.0, 2.5, 3.0, 4.0, 7.0, 16.0, 50.0, 128.0, 333.3, 1000.0}) {
    std::vector<Approx> fits;
    for (FitKind k : {FitKind::Inflection, FitKind::Level, FitKind::Shortcut, FitKind::Minimax})
      fits.push_back(fitApprox(k, 2, n));
    for (FitKind k : {FitKind::Inflection, FitKind::Level}) fits.push_back(fitApprox(k, 3, n));
    fits.push_back(fitApprox(FitKind::Level, 3, n, 0.1));
    for (const Approx& f : fits) {
      for (const Region& reg : standardRegions(n)) {
        const bool rel = reg.lo > 0.0;
        const RegionError e = maxErrorExact(f, n, reg.lo, reg.hi, rel);
        const RegionError s =
            maxError([&](double c) { return f.eval(c); }, n, reg.lo, reg.hi, rel, f.kinks());
        EXPECT_NEAR(e.max_abs, s.max_abs, 1e-12)
            << "n=" << n << " deg=" << f.degree << " a=" << f.a << " a1=" << f.a1 << " " << reg.name;
        if (rel) {
          EXPECT_NEAR(e.max_rel, s.max_rel, 1e-10 * std::max(1.0, e.max_rel))
              << "n=" << n << " deg=" << f.degree << " " << reg.name;
        } else {
          EXPECT_TRUE(std::isnan(e.max_rel));
          EXPECT_TRUE(std::isnan(s.max_rel));
        }
      }
    }
  }
}

TEST(LobeError, StandardRegionBounds) {
  for (double n : {1.0, 1.5, 2.0, 10.0, 100.0, 1000.0}) {
    const auto regs = standardRegions(n);
    ASSERT_EQ(regs.size(), 3u);
    EXPECT_STREQ(regs[0].name, "lobe");
    EXPECT_EQ(regs[0].lo, 0.0);
    EXPECT_EQ(regs[0].hi, 1.0);
    EXPECT_STREQ(regs[1].name, "peak50");
    EXPECT_NEAR(std::pow(regs[1].lo, n), 0.5, 1e-14);
    EXPECT_EQ(regs[1].hi, 1.0);
    EXPECT_STREQ(regs[2].name, "inflection");
    EXPECT_EQ(regs[2].lo, std::sqrt((n - 1.0) / n));
    EXPECT_EQ(regs[2].hi, 1.0);
    // tan^2 = 1/(n-1) at the inflection point of cos^n(gamma): cos^2 = (n-1)/n.
    if (n > 1) {
      const double g = std::atan(1.0 / std::sqrt(n - 1.0));
      EXPECT_NEAR(std::cos(g), regs[2].lo, 1e-15);
      // t^n = (1 - 1/n)^(n/2) increases with n from 1/2 at n = 2 towards e^-1/2: for n > 2 the
      // inflection region lies inside peak50, for n < 2 it is the larger one.
      if (n > 2) {
        EXPECT_GT(regs[2].lo, regs[1].lo) << n;
      } else if (n < 2) {
        EXPECT_LT(regs[2].lo, regs[1].lo) << n;
      } else {
        EXPECT_NEAR(regs[2].lo, regs[1].lo, 1e-15);
      }
    }
  }
}

TEST(LobeError, OnlyTheRegionCounts) {
  const double n = 10.0;
  auto f = [&](double c) { return c < 0.5 ? 1.0 : std::pow(c, n); };  // wrong only below 0.5
  EXPECT_EQ(maxError(f, n, 0.5, 1.0, true).max_abs, 0.0);
  EXPECT_EQ(maxError(f, n, 0.5, 1.0, true).max_rel, 0.0);
  const RegionError r = maxError(f, n, 0.4, 1.0, false, {0.5});
  // sup over [0.4, 0.5) of 1 - c^n is approached at c = 0.4: 1 - 0.4^10.
  EXPECT_NEAR(r.max_abs, 1.0 - std::pow(0.4, n), 1e-15);
  EXPECT_EQ(r.worst_abs_c, 0.4);
  EXPECT_THROW(maxError(f, n, 0.6, 0.5, false), std::invalid_argument);
  EXPECT_THROW(maxError(f, n, -0.1, 0.5, false), std::invalid_argument);
  EXPECT_THROW(maxError(f, n, 0.1, 1.5, false), std::invalid_argument);
  EXPECT_THROW(maxError(f, -1.0, 0.1, 0.5, false), std::invalid_argument);
}

TEST(LobeError, NarrowKinksAndJumpsAtBreakpointsAreFound) {
  const double n = 64.0;
  // A tent of height 0.2 and half-width 1e-6 at b: far narrower than the grid; the breakpoint
  // puts a sample on its apex.
  const double b = 0.7316;
  auto tent = [&](double c) {
    return std::pow(c, n) + 0.2 * std::max(0.0, 1.0 - std::fabs(c - b) / 1e-6);
  };
  const RegionError r = maxError(tent, n, 0.0, 1.0, false, {b});
  EXPECT_NEAR(r.max_abs, 0.2, 1e-12);
  EXPECT_NEAR(r.worst_abs_c, b, 1e-15);
  EXPECT_GT(r.signed_at_worst, 0.0);
  // A 1e-9-wide plateau of error -0.5 between two breakpoints.
  const double b0 = 0.98765, b1 = b0 + 1e-9;
  auto dip = [&](double c) { return c >= b0 && c <= b1 ? std::pow(c, n) - 0.5 : std::pow(c, n); };
  const RegionError d = maxError(dip, n, 0.0, 1.0, false, {b0, b1});
  EXPECT_NEAR(d.max_abs, 0.5, 1e-15);
  EXPECT_LT(d.signed_at_worst, 0.0);
  // A kink of the error inside the peak (|c - k| shaped), resolved by golden section alone.
  const double k = std::pow(0.7, 1.0 / n);
  auto vee = [&](double c) { return std::pow(c, n) + 0.01 - std::fabs(c - k); };
  // On [k - 0.005, 1] the error 0.01 - |c - k| peaks at the kink (0.01), ends are lower.
  const RegionError v = maxError(vee, n, k - 0.005, 1.0, false);
  EXPECT_NEAR(v.max_abs, 0.01, 1e-12);
  EXPECT_NEAR(v.worst_abs_c, k, 1e-12);
}

TEST(LobeError, JumpAtCubicCutCountsBothSides) {
  // The level cubic at n = 32 has p(cut) > 0: f jumps from 0 to p(cut); the error has the
  // one-sided supremum cut^n (from the left) and p(cut) - cut^n (from the right).
  const double n = 32.0;
  const Approx f = fitApprox(FitKind::Level, 3, n);
  ASSERT_GT(f.cut, 0.0);
  ASSERT_GT(f.poly(f.cut), 0.0);
  const auto pts = errorExtrema(f, n, 0.0, 1.0);
  bool left = false, right = false;
  for (const ErrorPoint& p : pts) {
    if (p.c == f.cut && p.left_limit) {
      left = true;
      EXPECT_NEAR(p.err, -std::pow(f.cut, n), 1e-15);
    }
    if (p.c == f.cut && !p.left_limit) {
      right = true;
      EXPECT_NEAR(p.err, std::min(1.0, f.poly(f.cut)) - std::pow(f.cut, n), 1e-15);
    }
  }
  EXPECT_TRUE(left);
  EXPECT_TRUE(right);
  const RegionError e = maxErrorExact(f, n, 0.0, 1.0, false);
  EXPECT_GE(e.max_abs, f.poly(f.cut) - std::pow(f.cut, n) - 1e-15);
  // errorExtrema is sorted by c.
  for (size_t i = 1; i < pts.size(); ++i) EXPECT_LE(pts[i - 1].c, pts[i].c);
}

TEST(LobeError, RelativeError) {
  const double n = 20.0;
  auto f = [&](double c) { return 1.02 * std::pow(c, n); };
  const RegionError r = maxError(f, n, 0.0, 1.0, true);
  EXPECT_NEAR(r.max_rel, 0.02, 1e-14);
  EXPECT_NEAR(r.max_abs, 0.02, 1e-14);
  EXPECT_EQ(r.worst_abs_c, 1.0);
  const RegionError no = maxError(f, n, 0.0, 1.0, false);
  EXPECT_TRUE(std::isnan(no.max_rel));
  EXPECT_TRUE(std::isnan(no.worst_rel_c));
}

TEST(LobeError, SummaryHasEveryStandardRegion) {
  const double n = 32.0;
  const Approx f = fitApprox(FitKind::Inflection, 2, n);
  const ApproxErrorSummary s = summarizeError(f, n);
  EXPECT_EQ(s.n, n);
  ASSERT_EQ(s.regions.size(), 3u);
  EXPECT_TRUE(std::isnan(s.at("lobe").max_rel));
  EXPECT_FALSE(std::isnan(s.at("peak50").max_rel));
  // Nested regions: inflection within peak50 within lobe.
  EXPECT_LE(s.at("inflection").max_abs, s.at("peak50").max_abs);
  EXPECT_LE(s.at("peak50").max_abs, s.at("lobe").max_abs);
  EXPECT_THROW(s.at("epicentre"), std::invalid_argument);
}

TEST(LobeErrorRoots, DerivativeChainFindsEveryRootOfACubic) {
  // (c - 0.1)(c - 0.5)(c - 0.9): three roots; derivatives by hand; D_3 = 6 has one sign.
  auto d = [](int k, double c) {
    switch (k) {
      case 0: return (c - 0.1) * (c - 0.5) * (c - 0.9);
      case 1: return 3 * c * c - 3.0 * c + 0.59;
      case 2: return 6 * c - 3.0;
      default: return 6.0;
    }
  };
  const auto r = rootsByDerivativeChain(d, 3, 0.0, 1.0);
  ASSERT_EQ(r.size(), 3u);
  EXPECT_NEAR(r[0], 0.1, 1e-15);
  EXPECT_NEAR(r[1], 0.5, 1e-15);
  EXPECT_NEAR(r[2], 0.9, 1e-15);
  EXPECT_TRUE(rootsByDerivativeChain(d, 3, 0.2, 0.4).empty());
  EXPECT_EQ(powDerivative(2.0, 3, 0.0), 0.0);  // zero coefficient wins over 0^-1
  EXPECT_EQ(powDerivative(3.0, 3, 0.0), 6.0);
  EXPECT_NEAR(powDerivative(5.5, 2, 0.5), 5.5 * 4.5 * std::pow(0.5, 3.5), 1e-15);
}
