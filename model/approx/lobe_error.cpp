#include "approx/lobe_error.h"

#include <fmt/format.h>

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

namespace shd {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// Sign-preserving replacement of +-inf by +-DBL_MAX so that Brent's interpolation stays finite
// where possible (where it does not, NaN comparisons fail and it bisects).
double finiteOrMax(double x) {
  if (std::isinf(x)) return x > 0 ? DBL_MAX : -DBL_MAX;
  return x;
}

bool oppositeSigns(double x, double y) { return (x < 0 && y > 0) || (x > 0 && y < 0); }

std::vector<double> rootsChainRec(const std::function<double(int, double)>& deriv, int k, int K,
                                  double lo, double hi) {
  if (k >= K) return {};
  std::vector<double> pts{lo};
  for (double r : rootsChainRec(deriv, k + 1, K, lo, hi))
    if (r > lo && r < hi) pts.push_back(r);
  pts.push_back(hi);
  // D_k is monotone between consecutive points: at most one root on each piece.
  std::vector<double> roots;
  std::vector<double> vals(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) vals[i] = deriv(k, pts[i]);
  const std::function<double(double)> g = [&](double c) { return deriv(k, c); };
  for (size_t i = 0; i + 1 < pts.size(); ++i) {
    if (vals[i] == 0.0) {
      roots.push_back(pts[i]);
    } else if (oppositeSigns(vals[i], vals[i + 1])) {
      roots.push_back(brentRoot(g, pts[i], pts[i + 1], vals[i], vals[i + 1]));
    }
  }
  if (vals.back() == 0.0) roots.push_back(pts.back());
  std::sort(roots.begin(), roots.end());
  roots.erase(std::unique(roots.begin(), roots.end()), roots.end());
  return roots;
}

// Monomial coefficients of p(c) = P1 c + P2 c^2 + P3 c^3 (from the v = a1 + b1 form).
struct Monomials {
  double P1, P2, P3;
  explicit Monomials(const Approx& f) {
    const double u = f.a1;
    const double v = f.a1 + f.b1;
    P1 = 1.0 - v;
    P2 = v - u;
    P3 = u;
  }
  // k-th derivative of p; k = 0 uses Approx::poly for accuracy near c = 1.
  double deriv(const Approx& f, int k, double c) const {
    switch (k) {
      case 0: return f.poly(c);
      case 1: return P1 + c * (2.0 * P2 + 3.0 * P3 * c);
      case 2: return 2.0 * P2 + 6.0 * P3 * c;
      case 3: return 6.0 * P3;
      default: return 0.0;
    }
  }
};

void consider(RegionError& r, double c, double err) {
  if (std::fabs(err) > r.max_abs) {
    r.max_abs = std::fabs(err);
    r.worst_abs_c = c;
    r.signed_at_worst = err;
  }
}

void considerRel(RegionError& r, double c, double fc, double cn) {
  if (!(cn > 0.0)) return;
  const double rel = std::fabs(fc - cn) / cn;
  if (std::isnan(r.max_rel) || rel > r.max_rel) {
    r.max_rel = rel;
    r.worst_rel_c = c;
  }
}

RegionError emptyResult(double lo) {
  RegionError r;
  r.worst_abs_c = lo;
  r.max_rel = kNaN;
  r.worst_rel_c = kNaN;
  return r;
}

void checkRegion(double n, double lo, double hi) {
  if (!(n > 0.0) || !std::isfinite(n))
    throw std::invalid_argument(fmt::format("maxError: n = {} must be positive and finite", n));
  if (!(lo >= 0.0 && lo <= hi && hi <= 1.0))
    throw std::invalid_argument(
        fmt::format("maxError: region [{}, {}] must satisfy 0 <= lo <= hi <= 1", lo, hi));
}

// Golden-section search for the maximum of h on [a, b], to |b - a| <= tol. Returns (c, h(c))
// of the best point evaluated.
std::pair<double, double> goldenMax(const std::function<double(double)>& h, double a, double b,
                                    double tol) {
  const double invphi = 0.6180339887498949;
  double x1 = b - invphi * (b - a), x2 = a + invphi * (b - a);
  double h1 = h(x1), h2 = h(x2);
  std::pair<double, double> best = h1 >= h2 ? std::pair{x1, h1} : std::pair{x2, h2};
  for (int it = 0; it < 200 && (b - a) > tol; ++it) {
    if (h1 >= h2) {
      b = x2;
      x2 = x1;
      h2 = h1;
      x1 = b - invphi * (b - a);
      h1 = h(x1);
      if (h1 > best.second) best = {x1, h1};
    } else {
      a = x1;
      x1 = x2;
      h1 = h2;
      x2 = a + invphi * (b - a);
      h2 = h(x2);
      if (h2 > best.second) best = {x2, h2};
    }
  }
  return best;
}

}  // namespace

double powDerivative(double n, int m, double c) {
  double coef = 1.0;
  for (int i = 0; i < m; ++i) coef *= (n - i);
  if (coef == 0.0) return 0.0;
  return coef * std::pow(c, n - m);
}

double brentRoot(const std::function<double(double)>& g, double a, double b, double fa, double fb,
                 double abs_tol) {
  // Brent's zeroin [Brent 1973, ch. 4]: inverse quadratic interpolation / secant with a
  // bisection fallback; b is always the best estimate, [b, c] always brackets the root.
  if (fa == 0.0) return a;
  if (fb == 0.0) return b;
  fa = finiteOrMax(fa);
  fb = finiteOrMax(fb);
  double c = a, fc = fa;
  double d = b - a, e = d;
  for (int it = 0; it < 400; ++it) {
    if ((fb > 0) == (fc > 0)) {
      c = a;
      fc = fa;
      d = e = b - a;
    }
    if (std::fabs(fc) < std::fabs(fb)) {
      a = b;
      b = c;
      c = a;
      fa = fb;
      fb = fc;
      fc = fa;
    }
    const double tol = 2.0 * DBL_EPSILON * std::fabs(b) + 0.5 * abs_tol + 1e-300;
    const double m = 0.5 * (c - b);
    if (std::fabs(m) <= tol || fb == 0.0) return b;
    if (std::fabs(e) < tol || std::fabs(fa) <= std::fabs(fb)) {
      d = e = m;
    } else {
      double p, q;
      const double s = fb / fa;
      if (a == c) {
        p = 2.0 * m * s;
        q = 1.0 - s;
      } else {
        const double qq = fa / fc, r = fb / fc;
        p = s * (2.0 * m * qq * (qq - r) - (b - a) * (r - 1.0));
        q = (qq - 1.0) * (r - 1.0) * (s - 1.0);
      }
      if (p > 0)
        q = -q;
      else
        p = -p;
      if (2.0 * p < 3.0 * m * q - std::fabs(tol * q) && p < std::fabs(0.5 * e * q)) {
        e = d;
        d = p / q;
      } else {
        d = e = m;
      }
    }
    a = b;
    fa = fb;
    b += std::fabs(d) > tol ? d : (m > 0 ? tol : -tol);
    fb = finiteOrMax(g(b));
  }
  return b;
}

std::vector<double> rootsByDerivativeChain(const std::function<double(int, double)>& deriv,
                                           int K, double lo, double hi) {
  if (!(lo <= hi)) return {};
  return rootsChainRec(deriv, 0, K, lo, hi);
}

std::vector<ErrorPoint> errorExtrema(const Approx& f, double n, double lo, double hi) {
  checkRegion(n, lo, hi);
  std::vector<ErrorPoint> pts;
  auto add = [&](double c) { pts.push_back({c, f.eval(c) - std::pow(c, n), false}); };
  add(lo);
  add(hi);
  double A = lo;
  if (f.cut > lo) {
    // Below the cut f = 0 and e = -c^n is monotone: its supremum over [lo, min(cut, hi)) is
    // approached at the right end, from the left.
    if (f.cut > hi) return pts;  // the whole region is cut: lo and hi are the extrema
    pts.push_back({f.cut, -std::pow(f.cut, n), true});
    A = f.cut;
    add(A);  // and the value from the right, f(cut) = clamped p(cut): f may jump at the cut
  }
  const Monomials m(f);
  // Roots of p and p - 1 split [A, hi] into pieces where the clamp is inactive or constant.
  for (double level : {0.0, 1.0}) {
    const auto roots = rootsByDerivativeChain(
        [&](int k, double c) { return m.deriv(f, k, c) - (k == 0 ? level : 0.0); }, 3, A, hi);
    for (double r : roots) add(r);
  }
  // Critical points of p - c^n: roots of e' whose 3rd derivative, p'''' - (c^n)'''', has one sign.
  const auto crit = rootsByDerivativeChain(
      [&](int k, double c) { return m.deriv(f, k + 1, c) - powDerivative(n, k + 1, c); }, 3, A,
      hi);
  for (double r : crit) add(r);
  std::sort(pts.begin(), pts.end(),
            [](const ErrorPoint& x, const ErrorPoint& y) { return x.c < y.c; });
  return pts;
}

RegionError maxErrorExact(const Approx& f, double n, double lo, double hi, bool want_rel) {
  RegionError r = emptyResult(lo);
  const auto pts = errorExtrema(f, n, lo, hi);
  for (const auto& p : pts) consider(r, p.c, p.err);
  if (!want_rel) return r;
  // Relative error r = F c^-n - 1. Where F = 0 it is -1 (|r| = 1); where F = 1 it is
  // c^-n - 1, decreasing; on p pieces its extrema are the roots of c p' - n p (a cubic).
  for (const auto& p : pts) {
    const double cn = std::pow(p.c, n);
    considerRel(r, p.c, p.left_limit ? 0.0 : f.eval(p.c), cn);
  }
  const double A = std::max(lo, f.cut);
  if (A <= hi) {
    const Monomials m(f);
    const double Q1 = (1.0 - n) * m.P1, Q2 = (2.0 - n) * m.P2, Q3 = (3.0 - n) * m.P3;
    const auto roots = rootsByDerivativeChain(
        [&](int k, double c) {
          switch (k) {
            case 0: return c * (Q1 + c * (Q2 + c * Q3));
            case 1: return Q1 + c * (2.0 * Q2 + 3.0 * Q3 * c);
            case 2: return 2.0 * Q2 + 6.0 * Q3 * c;
            default: return 6.0 * Q3;
          }
        },
        3, A, hi);
    for (double c : roots) considerRel(r, c, f.eval(c), std::pow(c, n));
  }
  return r;
}

RegionError maxError(const std::function<double(double)>& f, double n, double lo, double hi,
                     bool want_rel, const std::vector<double>& breakpoints) {
  checkRegion(n, lo, hi);
  // The grid (see the header): uniform in y = -n ln c, uniform in c, endpoints, breakpoints.
  constexpr int kYPoints = 1500;
  constexpr double kYMax = 60.0;
  constexpr int kCPoints = 2000;
  std::vector<double> cs;
  cs.reserve(kYPoints + kCPoints + 3 * breakpoints.size() + 2);
  cs.push_back(lo);
  cs.push_back(hi);
  for (int i = 0; i <= kYPoints; ++i) {
    const double c = std::exp(-kYMax * i / kYPoints / n);
    if (c >= lo && c <= hi) cs.push_back(c);
  }
  for (int i = 1; i < kCPoints; ++i) cs.push_back(lo + (hi - lo) * i / kCPoints);
  for (double b : breakpoints) {
    for (double c : {std::nextafter(b, -1.0), b, std::nextafter(b, 2.0)})
      if (c >= lo && c <= hi) cs.push_back(c);
  }
  std::sort(cs.begin(), cs.end());
  cs.erase(std::unique(cs.begin(), cs.end()), cs.end());

  const size_t N = cs.size();
  std::vector<double> fv(N), cn(N), ea(N), er(N);
  for (size_t i = 0; i < N; ++i) {
    fv[i] = f(cs[i]);
    cn[i] = std::pow(cs[i], n);
    ea[i] = std::fabs(fv[i] - cn[i]);
    er[i] = cn[i] > 0.0 ? ea[i] / cn[i] : -1.0;  // -1: not a relative-error point
  }

  RegionError r = emptyResult(lo);
  for (size_t i = 0; i < N; ++i) consider(r, cs[i], fv[i] - cn[i]);
  if (want_rel)
    for (size_t i = 0; i < N; ++i)
      if (er[i] >= 0.0) considerRel(r, cs[i], fv[i], cn[i]);

  // Refine sampled local maxima of a sequence vals (>= both neighbours, > at least one).
  auto refine = [&](const std::vector<double>& vals, const std::function<double(double)>& h,
                    double best, auto&& accept) {
    std::vector<size_t> peaks;
    for (size_t i = 0; i < N; ++i) {
      const double l = i > 0 ? vals[i - 1] : -1.0;
      const double rr = i + 1 < N ? vals[i + 1] : -1.0;
      if (vals[i] >= l && vals[i] >= rr && (vals[i] > l || vals[i] > rr) &&
          vals[i] >= 0.75 * best && vals[i] >= 0.0)
        peaks.push_back(i);
    }
    std::sort(peaks.begin(), peaks.end(), [&](size_t x, size_t y) { return vals[x] > vals[y]; });
    if (peaks.size() > 64) peaks.resize(64);
    for (size_t i : peaks) {
      const double a = cs[i > 0 ? i - 1 : 0], b = cs[i + 1 < N ? i + 1 : N - 1];
      if (!(b > a)) continue;
      accept(goldenMax(h, a, b, 1e-13).first);
    }
  };
  refine(
      ea, [&](double c) { return std::fabs(f(c) - std::pow(c, n)); }, r.max_abs,
      [&](double c) { consider(r, c, f(c) - std::pow(c, n)); });
  if (want_rel && !std::isnan(r.max_rel)) {
    refine(
        er,
        [&](double c) {
          const double p = std::pow(c, n);
          return p > 0.0 ? std::fabs(f(c) - p) / p : -1.0;
        },
        r.max_rel, [&](double c) { considerRel(r, c, f(c), std::pow(c, n)); });
  }
  return r;
}

std::vector<Region> standardRegions(double n) {
  return {{"lobe", 0.0, 1.0},
          {"peak50", levelCos(n, 0.5), 1.0},
          {"inflection", inflectionCos(n), 1.0}};
}

const RegionError& ApproxErrorSummary::at(std::string_view region_name) const {
  for (const auto& r : regions)
    if (region_name == r.region.name) return r.error;
  throw std::invalid_argument(fmt::format("unknown region '{}' (expected lobe, peak50 or inflection)",
                                          region_name));
}

ApproxErrorSummary summarizeError(const Approx& f, double n) {
  ApproxErrorSummary s;
  s.n = n;
  s.approx = f;
  for (const Region& reg : standardRegions(n)) {
    const bool rel = std::string_view(reg.name) != "lobe";
    // The exact method covers the polynomial; the table's steps, Schlick's rational and the
    // power itself are sampled with their kinks as breakpoints (maxError, whose guarantee holds
    // for each).
    const RegionError e = f.form == Approx::Form::Poly
                              ? maxErrorExact(f, n, reg.lo, reg.hi, rel)
                              : maxError([&](double c) { return f.eval(c); }, n, reg.lo, reg.hi, rel, f.kinks());
    s.regions.push_back({reg, e});
  }
  return s;
}

}  // namespace shd
