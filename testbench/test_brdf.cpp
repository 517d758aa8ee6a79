// Reference lobes: limits, normalisation, monotonicity, reciprocity.
#include "approx/brdf.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "scene/vec.h"

using namespace shd;

namespace {

// Composite Simpson over theta in [0, pi/2] of 2 pi * g(cos theta) * sin theta: the integral of
// g(N.H) over the hemisphere (the phi integral of an isotropic lobe is 2 pi).
template <class G>
double hemisphereIntegral(G&& g, int intervals) {
  const double h = (kPi / 2) / intervals;
  double sum = 0.0;
  for (int i = 0; i <= intervals; ++i) {
    const double th = i * h;
    const double w = (i == 0 || i == intervals) ? 1.0 : (i % 2 ? 4.0 : 2.0);
    sum += w * g(std::cos(th)) * std::sin(th);
  }
  return 2.0 * kPi * sum * h / 3.0;
}

const double kShininess[] = {0.0, 1.0, 2.0, 3.5, 8.0, 32.0, 100.0, 256.0, 1000.0};

}  // namespace

TEST(BrdfLobes, ZeroWhenBackFacingOneAtPeak) {
  for (double n : kShininess) {
    for (double c : {-1.0, -0.5, -1e-12, 0.0}) {
      EXPECT_EQ(phongLobe(c, n), 0.0) << "n=" << n << " c=" << c;
      EXPECT_EQ(blinnLobe(c, n), 0.0) << "n=" << n << " c=" << c;
      EXPECT_EQ(normalizedBlinn(c, n), 0.0) << "n=" << n << " c=" << c;
      EXPECT_EQ(schlickLobe(c, n), 0.0) << "n=" << n << " c=" << c;
    }
    EXPECT_EQ(phongLobe(1.0, n), 1.0);
    EXPECT_EQ(blinnLobe(1.0, n), 1.0);
    EXPECT_DOUBLE_EQ(normalizedBlinn(1.0, n), (n + 2) / (2 * kPi));
  }
}

TEST(BrdfLobes, BlinnIsCosPowerAndLinearAtNOne) {
  for (int i = 1; i <= 1000; ++i) {
    const double c = i / 1000.0;
    EXPECT_EQ(blinnLobe(c, 1.0), c);  // exact: pow(c, 1) = c
    EXPECT_EQ(phongLobe(c, 1.0), c);
    EXPECT_NEAR(blinnLobe(c, 7.0), c * c * c * c * c * c * c, 1e-15);
  }
}

TEST(BrdfSchlick, OneAtPeakMonotoneAndMatchesSlopeOfCosPower) {
  for (double n : kShininess) {
    EXPECT_EQ(schlickLobe(1.0, n), 1.0) << "n=" << n;
    double prev = 0.0;
    for (int i = 1; i <= 10000; ++i) {
      const double v = schlickLobe(i / 10000.0, n);
      ASSERT_GE(v, prev) << "not monotone at c=" << i / 10000.0 << " n=" << n;
      ASSERT_LE(v, 1.0);
      prev = v;
    }
    // Schlick's construction: value 1 and slope n at c = 1, like c^n. One-sided difference
    // with h = 1e-7: truncation ~ n^2 h, rounding ~ 1e-16/h; tolerance 1e-4 * max(1, n).
    if (n > 0) {
      const double h = 1e-7;
      const double slope = (schlickLobe(1.0, n) - schlickLobe(1.0 - h, n)) / h;
      EXPECT_NEAR(slope, n, 1e-4 * std::max(1.0, n) + n * n * h) << "n=" << n;
    }
  }
  for (int i = 1; i <= 100; ++i) EXPECT_DOUBLE_EQ(schlickLobe(i / 100.0, 1.0), i / 100.0);
}

TEST(BrdfNormalizedBlinn, ProjectedAreaIntegratesToOne) {
  // (n + 2)/(2 pi) makes the integral of D(h) (N.H) dw over the hemisphere exactly 1;
  // Simpson with 20000 intervals resolves the 1/sqrt(n)-wide lobe at n = 1000 (tolerance 1e-4).
  for (double n : kShininess) {
    const double integral =
        hemisphereIntegral([&](double c) { return normalizedBlinn(c, n) * c; }, 20000);
    EXPECT_NEAR(integral, 1.0, 1e-4) << "n=" << n;
  }
}

TEST(BrdfBeckmann, ProjectedAreaIntegratesToOneAndMatchesBlinnPeak) {
  for (double n : {1.0, 8.0, 32.0, 200.0, 1000.0}) {
    const double m = beckmannRoughnessForBlinn(n);
    EXPECT_NEAR(m * m * (n + 2.0), 2.0, 1e-14);
    const double integral = hemisphereIntegral([&](double c) { return beckmannD(c, m) * c; }, 20000);
    EXPECT_NEAR(integral, 1.0, 1e-4) << "n=" << n;
    // The correspondence equates the peak heights 1/(pi m^2) = (n+2)/(2 pi) exactly.
    EXPECT_NEAR(beckmannD(1.0, m), normalizedBlinn(1.0, n), 1e-12 * normalizedBlinn(1.0, n));
    // And the lobes agree near the peak for large n: at half maximum of cos^n within 2 %.
    if (n >= 200) {
      const double c = std::pow(0.5, 1.0 / n);
      EXPECT_NEAR(beckmannD(c, m) / normalizedBlinn(c, n), 1.0, 0.02) << "n=" << n;
    }
  }
}

TEST(BrdfCookTorrance, ZeroBelowHorizonPositiveAboveAndReciprocal) {
  std::mt19937_64 rng(20230417);
  std::printf("seed 20230417\n");
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  const Vec3 N{0.0, 0.0, 1.0};
  for (const CookTorranceParams p : {CookTorranceParams{0.1, 0.04}, CookTorranceParams{0.3, 0.9},
                                     CookTorranceParams{0.8, 0.5}}) {
    for (int k = 0; k < 20000; ++k) {
      Vec3 L = normalize({U(rng), U(rng), U(rng)});
      Vec3 V = normalize({U(rng), U(rng), U(rng)});
      const Vec3 H = normalize(L + V);
      const double nl = dot(N, L), nv = dot(N, V), nh = dot(N, H), vh = dot(V, H), lh = dot(L, H);
      const double f = cookTorrance(nl, nv, nh, vh, p);
      ASSERT_TRUE(std::isfinite(f));
      if (nl <= 0.0 || nv <= 0.0) {
        ASSERT_EQ(f, 0.0) << "back-facing nl=" << nl << " nv=" << nv;
        continue;
      }
      // Positive, except where exp(-tan^2/m^2) underflows (e.g. m = 0.1 far from the peak).
      if (beckmannD(nh, p.roughness_m) > 0.0)
        ASSERT_GT(f, 0.0) << "nl=" << nl << " nv=" << nv << " nh=" << nh << " vh=" << vh;
      else
        ASSERT_EQ(f, 0.0);
      // Reciprocity: swapping L and V leaves H, hence N.H, unchanged and V.H becomes L.H.
      const double g = cookTorrance(nv, nl, nh, lh, p);
      ASSERT_NEAR(f, g, 1e-12 * f) << "nl=" << nl << " nv=" << nv;
    }
  }
  EXPECT_EQ(cookTorrance(0.0, 0.5, 0.9, 0.9, {}), 0.0);
  EXPECT_EQ(cookTorrance(0.5, -0.1, 0.9, 0.9, {}), 0.0);
}

TEST(BrdfCookTorrance, MirrorConfigurationMatchesHandComputation) {
  // L = V = N: D_1982 = 1/m^2, F = f0, G = 1, f = f0 / (pi m^2).
  const CookTorranceParams p{0.25, 0.04};
  EXPECT_NEAR(cookTorrance(1.0, 1.0, 1.0, 1.0, p), 0.04 / (kPi * 0.0625), 1e-14);
}
