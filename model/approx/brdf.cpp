#include "approx/brdf.h"

#include <algorithm>
#include <cmath>

namespace shd {

double phongLobe(double r_dot_v, double n) {
  if (!(r_dot_v > 0.0)) return 0.0;
  return std::pow(std::min(r_dot_v, 1.0), n);
}

double blinnLobe(double n_dot_h, double n) {
  if (!(n_dot_h > 0.0)) return 0.0;
  return std::pow(std::min(n_dot_h, 1.0), n);
}

double normalizedBlinn(double n_dot_h, double n) {
  return (n + 2.0) / (2.0 * kPi) * blinnLobe(n_dot_h, n);
}

double schlickLobe(double c, double n) {
  if (!(c > 0.0)) return 0.0;
  c = std::min(c, 1.0);
  // n - n c + c = n (1 - c) + c > 0 for c in (0, 1], n >= 0: the division is safe.
  return c / (n * (1.0 - c) + c);
}

double beckmannD(double n_dot_h, double m) {
  if (!(n_dot_h > 0.0)) return 0.0;
  const double c2 = std::min(n_dot_h * n_dot_h, 1.0);
  const double tan2 = (1.0 - c2) / c2;
  const double m2 = m * m;
  return std::exp(-tan2 / m2) / (kPi * m2 * c2 * c2);
}

double cookTorrance(double n_dot_l, double n_dot_v, double n_dot_h, double v_dot_h,
                    CookTorranceParams p) {
  // Degenerate geometry: nothing is reflected; early return avoids dividing by zero below.
  if (!(n_dot_l > 0.0) || !(n_dot_v > 0.0) || !(n_dot_h > 0.0) || !(v_dot_h > 0.0)) return 0.0;
  const double d_1982 = kPi * beckmannD(n_dot_h, p.roughness_m);
  const double one_minus = 1.0 - std::min(v_dot_h, 1.0);
  const double om2 = one_minus * one_minus;
  const double fresnel = p.f0 + (1.0 - p.f0) * om2 * om2 * one_minus;
  const double g = std::min({1.0, 2.0 * n_dot_h * n_dot_v / v_dot_h,
                             2.0 * n_dot_h * n_dot_l / v_dot_h});
  return fresnel * d_1982 * g / (kPi * n_dot_l * n_dot_v);
}

double beckmannRoughnessForBlinn(double n) { return std::sqrt(2.0 / (n + 2.0)); }

}  // namespace shd
