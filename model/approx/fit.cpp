#include "approx/fit.h"

#include "approx/lobe_error.h"
#include "approx/piecewise.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <string>

namespace shd {

const char* toString(FitKind k) {
  switch (k) {
    case FitKind::Inflection: return "inflection";
    case FitKind::Level: return "level";
    case FitKind::Shortcut: return "shortcut";
    case FitKind::Minimax: return "minimax";
    case FitKind::Exact: return "exact";
  }
  return "?";
}

FitKind parseFitKind(std::string_view s) {
  for (FitKind k : {FitKind::Inflection, FitKind::Level, FitKind::Shortcut, FitKind::Minimax, FitKind::Exact})
    if (s == toString(k)) return k;
  throw std::invalid_argument(
      fmt::format("unknown fit '{}' (expected inflection, level, shortcut, minimax or exact)", s));
}

// ---------------------------------------------------------------------------------------------
// Approx

namespace {

// The local minimum of p(c) = u c^3 + (v - u) c^2 + (1 - v) c inside (0, 1), or 0.
// p'(c) = 3u c^2 - 2(u - v) c + (1 - v); a local minimum is a root with p'' = 6uc - 2(u - v) > 0.
double localMinInUnit(double u, double v) {
  const double A = 3.0 * u, B = -2.0 * (u - v), C = 1.0 - v;
  double r;
  if (A == 0.0) {
    if (!(B > 0.0)) return 0.0;  // p'' = B: a minimum only for B > 0 (and B = 0: no extremum)
    r = -C / B;
  } else {
    const double disc = B * B - 4.0 * A * C;
    if (!(disc > 0.0)) return 0.0;  // p' does not change sign: no local minimum
    const double sq = std::sqrt(disc);
    // Stable roots: q = -(B + sign(B) sq)/2, roots q/A and C/q. At a root p'' = 2Ar + B = +-sq;
    // the minimum is the root with 2Ar + B = +sq, i.e. r = (-B + sq)/(2A).
    const double q = -0.5 * (B + std::copysign(sq, B));
    const double r1 = q / A, r2 = (q != 0.0) ? C / q : r1;
    r = (2.0 * A * r1 + B > 0.0) ? r1 : r2;
  }
  return (r > 0.0 && r < 1.0) ? r : 0.0;
}

double clamp01(double x) { return std::min(1.0, std::max(0.0, x)); }

}  // namespace

double Approx::poly(double c) const {
  if (degree == 2) return c - a * c * (1.0 - c);
  return c - c * (1.0 - c) * (a1 * c + (a1 + b1));
}

double Approx::eval(double c) const {
  c = clamp01(c);
  if (form == Form::Schlick) return c / (n - n * c + c);
  if (form == Form::Power) return std::pow(c, n);
  if (form == Form::Piecewise) return clamp01(pieces->eval(c));
  if (form == Form::Table) {
    const double scaled = std::floor(std::ldexp(c, tableBits()));
    return table[static_cast<size_t>(std::min(scaled, static_cast<double>(table.size() - 1)))];
  }
  if (degree == 3 && c < cut) return 0.0;
  return clamp01(poly(c));
}

std::vector<double> Approx::kinks() const {
  std::vector<double> k;
  if (form == Form::Schlick || form == Form::Power) return k;
  if (form == Form::Piecewise) {
    if (pieces->cut > 0) k.push_back(pieces->cut);
    for (const SegmentFit& s : pieces->segments)
      if (s.a > 0) k.push_back(s.a);
    std::sort(k.begin(), k.end());
    k.erase(std::unique(k.begin(), k.end()), k.end());
    return k;
  }
  if (form == Form::Table) {
    for (size_t i = 1; i < table.size(); ++i) k.push_back(std::ldexp(static_cast<double>(i), -tableBits()));
    return k;
  }
  const double lo = degree == 3 ? cut : 0.0;
  if (degree == 3 && cut > 0.0) k.push_back(cut);
  const double u = degree == 3 ? a1 : 0.0;
  const double v = degree == 3 ? a1 + b1 : a;
  const double P1 = 1.0 - v, P2 = v - u, P3 = u;
  for (double level : {0.0, 1.0}) {
    const auto roots = rootsByDerivativeChain(
        [&](int d, double c) {
          switch (d) {
            case 0: return poly(c) - level;
            case 1: return P1 + c * (2.0 * P2 + 3.0 * P3 * c);
            case 2: return 2.0 * P2 + 6.0 * P3 * c;
            default: return 6.0 * P3;
          }
        },
        3, lo, 1.0);
    for (double r : roots)
      if (r > 0.0 && r < 1.0) k.push_back(r);
  }
  std::sort(k.begin(), k.end());
  k.erase(std::unique(k.begin(), k.end()), k.end());
  return k;
}

Approx Approx::quadratic(double a) {
  Approx f;
  f.degree = 2;
  f.a = a;
  f.a1 = 0.0;
  f.b1 = a;
  f.c1 = 1.0 - a;
  f.cut = 0.0;
  return f;
}

Approx Approx::cubic(double a1, double b1) {
  Approx f;
  f.degree = 3;
  f.a = 0.0;
  f.a1 = a1;
  f.b1 = b1;
  f.c1 = 1.0 - a1 - b1;
  f.cut = localMinInUnit(a1, a1 + b1);
  return f;
}

Approx Approx::schlick(double n) {
  Approx f;
  f.form = Form::Schlick;
  f.n = n;
  return f;
}

Approx Approx::power(double n) {
  Approx f;
  f.form = Form::Power;
  f.n = n;
  return f;
}

Approx Approx::piecewise(PiecewiseFit fit) {
  Approx f;
  f.form = Form::Piecewise;
  f.degree = fit.degree;
  f.n = fit.n;
  f.pieces = std::make_shared<const PiecewiseFit>(std::move(fit));
  return f;
}

Approx Approx::stepTable(std::vector<double> values) {
  if (values.empty() || (values.size() & (values.size() - 1)) != 0)
    throw std::invalid_argument(fmt::format("a step table needs a power-of-two size, got {}", values.size()));
  Approx f;
  f.form = Form::Table;
  f.table = std::move(values);
  return f;
}

int Approx::tableBits() const {
  int t = 0;
  while ((size_t{1} << t) < table.size()) ++t;
  return t;
}

// ---------------------------------------------------------------------------------------------
// Closed-form fits

namespace {

void checkN(double n) {
  if (!(n >= kMinShininess && n <= kMaxShininess))
    throw std::invalid_argument(
        fmt::format("shininess n = {} out of range (expected a real number in [{}, {}])", n,
                    kMinShininess, kMaxShininess));
}

void checkQ(double q) {
  if (!(q > 0.0 && q < 1.0))
    throw std::invalid_argument(fmt::format("level_q = {} out of range (expected 0 < q < 1)", q));
}

// ln t for the inflection point t = sqrt((n-1)/n) = sqrt(1 - 1/n), n > 1.
double logInflectionCos(double n) { return 0.5 * std::log1p(-1.0 / n); }

}  // namespace

double inflectionCos(double n) {
  if (n <= 1.0) return 0.0;
  return std::sqrt((n - 1.0) / n);
}

double levelCos(double n, double q) { return std::pow(q, 1.0 / n); }

double quadraticA(FitKind kind, double n, double level_q) {
  checkN(n);
  checkQ(level_q);
  switch (kind) {
    case FitKind::Inflection: {
      // a = (t^(n-1) - 1)/(t - 1) = (1 - t^(n-1)) / (1 - t). Both differences cancel for large
      // n (t -> 1): 1 - t^(n-1) = -expm1((n-1) ln t) and 1 - t = (1 - t^2)/(1 + t) = (1/n)/(1+t).
      // n = 1: t = 0 and t^0 = 1, so a = 0 (p = c, exact); the formula would form 0 * -inf.
      // n = 2: a = 1 (p = c^2, exact); returned exactly rather than to within an ulp.
      if (n == 1.0) return 0.0;
      if (n == 2.0) return 1.0;
      const double t = inflectionCos(n);
      const double one_minus_t = (1.0 / n) / (1.0 + t);
      return -std::expm1((n - 1.0) * logInflectionCos(n)) / one_minus_t;
    }
    case FitKind::Level: {
      // a = (q^((n-1)/n) - 1)/(q^(1/n) - 1) = expm1((n-1) L) / expm1(L), L = ln(q)/n.
      // n = 1 gives expm1(0) = 0 exactly.
      const double L = std::log(level_q) / n;
      return std::expm1((n - 1.0) * L) / std::expm1(L);
    }
    case FitKind::Shortcut: return 0.786 * n;
    case FitKind::Minimax: return minimaxQuadratic(n).a;
    case FitKind::Exact: break;
  }
  throw std::invalid_argument("fit 'exact' has no polynomial: it is the fit of the table, schlick and explog kinds");
}

Approx cubicMatchedAt(double n, double log_s) {
  // n = 1, 2, 3: c^n is itself in the family, and the matched cubic is unique, so return it
  // exactly (u, v) = (0, 0), (0, 1), (1, 1).
  if (n == 1.0) return Approx::cubic(0.0, 0.0);
  if (n == 2.0) return Approx::cubic(0.0, 1.0);
  if (n == 3.0) return Approx::cubic(1.0, 0.0);
  if (!(log_s < 0.0) || !std::isfinite(log_s))
    throw std::invalid_argument(fmt::format("cubicMatchedAt: log_s = {} must be < 0", log_s));
  // p(c) = c - c(1 - c) g(c), g(c) = u c + v. With eps = 1 - s and P = s^(n-1) = c^n(s)/s:
  //   value  p(s) = s^n        <=>  g(s) = w = (1 - P) / eps
  //   slope  p'(s) = n s^(n-1) <=>  s eps u = 1 - (1 - 2s) w - n P
  //                                        = (1 - P) s / eps - (n - 1) P
  // (substitute 1 - 2s = 2 eps - 1 and collect). eps, 1 - P come from expm1, so the only
  // cancellation left is the mild one in the last difference (~10x at n = 1000), against the
  // ~1e6x loss of the printed closed forms in s - 1 and their monomial sums.
  const double s = std::exp(log_s);
  const double eps = -std::expm1(log_s);
  const double P = std::exp((n - 1.0) * log_s);
  const double one_minus_P = -std::expm1((n - 1.0) * log_s);
  const double w = one_minus_P / eps;
  const double u = (one_minus_P * s / eps - (n - 1.0) * P) / (s * eps);
  const double v = w - u * s;
  return Approx::cubic(u, v - u);
}

Approx fitApprox(FitKind kind, int degree, double n, double level_q) {
  checkN(n);
  checkQ(level_q);
  if (degree == 2) return Approx::quadratic(quadraticA(kind, n, level_q));
  if (degree != 3)
    throw std::invalid_argument(fmt::format("degree {} not supported (expected 2 or 3)", degree));
  switch (kind) {
    case FitKind::Inflection:
      // n = 1: t = 0 is degenerate (0/0); the limit and the exact answer is p = c.
      if (n == 1.0) return Approx::cubic(0.0, 0.0);
      return cubicMatchedAt(n, logInflectionCos(n));
    case FitKind::Level: return cubicMatchedAt(n, std::log(level_q) / n);
    case FitKind::Shortcut:
      throw std::invalid_argument("fit 'shortcut' exists only for degree 2");
    case FitKind::Minimax: return minimaxCubic(n).approx;
    case FitKind::Exact: break;
  }
  throw std::invalid_argument("fitApprox: bad fit kind");
}

// ---------------------------------------------------------------------------------------------
// Minimax quadratic

namespace {

struct SignedMax {
  double e_plus = 0.0, c_plus = 0.0, e_minus = 0.0, c_minus = 0.0;
};

SignedMax signedMax(const Approx& f, double n) {
  SignedMax m;
  for (const ErrorPoint& p : errorExtrema(f, n, 0.0, 1.0)) {
    if (p.err > m.e_plus) {
      m.e_plus = p.err;
      m.c_plus = p.c;
    }
    if (-p.err > m.e_minus) {
      m.e_minus = -p.err;
      m.c_minus = p.c;
    }
  }
  return m;
}

}  // namespace

QuadMinimax minimaxQuadratic(double n) {
  checkN(n);
  QuadMinimax r;
  auto fill = [&](double a) {
    const SignedMax m = signedMax(Approx::quadratic(a), n);
    r.a = a;
    r.e_plus = m.e_plus;
    r.c_plus = m.c_plus;
    r.e_minus = m.e_minus;
    r.c_minus = m.c_minus;
    r.err = std::max(m.e_plus, m.e_minus);
  };
  // n = 1 and n = 2: c^n is a member of the family (a = 0, a = 1): zero error.
  if (n == 1.0 || n == 2.0) {
    fill(n - 1.0);
    return r;
  }
  auto D = [&](double a) {
    ++r.evaluations;
    const SignedMax m = signedMax(Approx::quadratic(a), n);
    return m.e_plus - m.e_minus;
  };
  // D(a) = e+(a) - e-(a) is non-increasing. D(0) = max(c - c^n) > 0 for n > 1.
  double lo = 0.0, hi = std::max(1.0, n);
  double dlo = D(lo), dhi = D(hi);
  while (dhi > 0.0) {
    lo = hi;
    dlo = dhi;
    hi *= 2.0;
    dhi = D(hi);
  }
  fill(brentRoot(D, lo, hi, dlo, dhi));
  return r;
}

// ---------------------------------------------------------------------------------------------
// Minimax cubic

namespace {

// 2-parameter Nelder-Mead (reflection 1, expansion 2, contraction 1/2, shrink 1/2).
struct Point2 {
  std::array<double, 2> x;
  double f;
};

template <class F>
Point2 nelderMead(F&& obj, std::array<double, 2> x0, std::array<double, 2> step, int max_evals) {
  std::array<Point2, 3> s;
  s[0] = {x0, obj(x0)};
  s[1] = {{x0[0] + step[0], x0[1]}, 0.0};
  s[1].f = obj(s[1].x);
  s[2] = {{x0[0], x0[1] + step[1]}, 0.0};
  s[2].f = obj(s[2].x);
  auto comb = [](const std::array<double, 2>& a, const std::array<double, 2>& b, double t) {
    return std::array<double, 2>{a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])};
  };
  for (int used = 3; used < max_evals;) {
    std::sort(s.begin(), s.end(), [](const Point2& p, const Point2& q) { return p.f < q.f; });
    // Converged when the simplex has collapsed to rounding level.
    double size = 0.0, scale = 0.0;
    for (int i = 1; i < 3; ++i)
      for (int k = 0; k < 2; ++k) {
        size = std::max(size, std::fabs(s[i].x[k] - s[0].x[k]));
        scale = std::max(scale, std::fabs(s[0].x[k]));
      }
    if (size <= 1e-15 * std::max(scale, 1.0) || s[2].f - s[0].f <= 1e-17 * s[0].f) break;
    const std::array<double, 2> cen{0.5 * (s[0].x[0] + s[1].x[0]), 0.5 * (s[0].x[1] + s[1].x[1])};
    const auto xr = comb(cen, s[2].x, -1.0);
    const double fr = obj(xr);
    ++used;
    if (fr < s[0].f) {
      const auto xe = comb(cen, s[2].x, -2.0);
      const double fe = obj(xe);
      ++used;
      s[2] = fe < fr ? Point2{xe, fe} : Point2{xr, fr};
    } else if (fr < s[1].f) {
      s[2] = {xr, fr};
    } else {
      const bool outside = fr < s[2].f;
      const auto xc = outside ? comb(cen, xr, 0.5) : comb(cen, s[2].x, 0.5);
      const double fc = obj(xc);
      ++used;
      if (fc < std::min(fr, s[2].f)) {
        s[2] = {xc, fc};
      } else {
        for (int i = 1; i < 3; ++i) {
          s[i].x = comb(s[0].x, s[i].x, 0.5);
          s[i].f = obj(s[i].x);
          ++used;
        }
      }
    }
  }
  std::sort(s.begin(), s.end(), [](const Point2& p, const Point2& q) { return p.f < q.f; });
  return s[0];
}

// Remez exchange for min over (u, v) of max over [0, 1] of |c - c^n - c(1-c)(u c + v)| (no
// clamp, no cut). Returns (u, v).
std::array<double, 2> remezLinear(double n) {
  // Reference: three points spread over the 1/n-wide peak in y = -n ln c.
  std::array<double, 3> x{std::exp(-3.0 / n), std::exp(-1.2 / n), std::exp(-0.3 / n)};
  double u = 0.0, v = 0.0;
  for (int it = 0; it < 40; ++it) {
    // Solve c_i(1-c_i)(u c_i + v) + (-1)^i E = c_i - c_i^n, i = 0..2 (Cramer, 3x3).
    double M[3][4];
    for (int i = 0; i < 3; ++i) {
      const double c = x[i], w = c * (1.0 - c);
      M[i][0] = w * c;
      M[i][1] = w;
      M[i][2] = (i % 2 == 0) ? 1.0 : -1.0;
      M[i][3] = c - std::pow(c, n);
    }
    auto det3 = [](double a[3][3]) {
      return a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) -
             a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
             a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
    };
    double A[3][3], Au[3][3], Av[3][3];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) A[i][j] = Au[i][j] = Av[i][j] = M[i][j];
    for (int i = 0; i < 3; ++i) {
      Au[i][0] = M[i][3];
      Av[i][1] = M[i][3];
    }
    const double d = det3(A);
    if (!(std::fabs(d) > 0.0)) break;
    u = det3(Au) / d;
    v = det3(Av) / d;
    // Extrema of the unclamped error e = p - c^n on (0, 1).
    const Approx p = Approx::cubic(u, v - u);
    const double P1 = 1.0 - v, P2 = v - u, P3 = u;
    auto err = [&](double c) { return p.poly(c) - std::pow(c, n); };
    auto crit = rootsByDerivativeChain(
        [&](int k, double c) {
          double pk = 0.0;
          switch (k + 1) {
            case 1: pk = P1 + c * (2.0 * P2 + 3.0 * P3 * c); break;
            case 2: pk = 2.0 * P2 + 6.0 * P3 * c; break;
            case 3: pk = 6.0 * P3; break;
            default: pk = 0.0;
          }
          return pk - powDerivative(n, k + 1, c);
        },
        3, 0.0, 1.0);
    crit.erase(std::remove_if(crit.begin(), crit.end(),
                              [](double c) { return !(c > 0.0 && c < 1.0); }),
               crit.end());
    if (crit.size() != 3) break;  // no full alternation set: keep the last solution
    const double e0 = err(crit[0]), e1 = err(crit[1]), e2 = err(crit[2]);
    if (!(e0 * e1 < 0 && e1 * e2 < 0)) break;
    const double emax = std::max({std::fabs(e0), std::fabs(e1), std::fabs(e2)});
    const double emin = std::min({std::fabs(e0), std::fabs(e1), std::fabs(e2)});
    x = {crit[0], crit[1], crit[2]};
    if (emax - emin <= 1e-14 * emax) break;
  }
  return {u, v};
}

}  // namespace

CubicMinimax minimaxCubic(double n) {
  checkN(n);
  CubicMinimax r;
  auto finish = [&](const Approx& f) {
    r.approx = f;
    r.alternation.clear();
    const auto pts = errorExtrema(f, n, 0.0, 1.0);
    r.err = 0.0;
    for (const auto& p : pts) r.err = std::max(r.err, std::fabs(p.err));
    for (const auto& p : pts)
      if (std::fabs(p.err) >= r.err * (1.0 - 1e-6) && r.err > 0.0) r.alternation.push_back(p);
  };
  if (n == 1.0 || n == 2.0 || n == 3.0) {
    finish(cubicMatchedAt(n, -1.0));
    return r;
  }
  // Parameters x = (g(s), g(1)) of g(c) = u c + v, s = 0.5^(1/n): both O(n) and far less
  // correlated than (u, v) themselves (u ~ -v ~ 3e5 at n = 1000).
  const double log_s = std::log(0.5) / n;
  const double s = std::exp(log_s), one_minus_s = -std::expm1(log_s);
  auto toApprox = [&](const std::array<double, 2>& x) {
    const double u = (x[1] - x[0]) / one_minus_s;
    const double v = x[1] - u;
    return Approx::cubic(u, v - u);
  };
  auto toX = [&](const Approx& f) {
    const double u = f.a1, v = f.a1 + f.b1;
    return std::array<double, 2>{u * s + v, u + v};
  };
  auto obj = [&](const std::array<double, 2>& x) {
    ++r.evaluations;
    return maxErrorExact(toApprox(x), n, 0.0, 1.0, false).max_abs;
  };
  std::vector<Point2> starts;
  {
    const auto uv = remezLinear(n);
    const Approx rem = Approx::cubic(uv[0], uv[1] - uv[0]);
    r.remez_err = maxErrorExact(rem, n, 0.0, 1.0, false).max_abs;
    starts.push_back({toX(rem), r.remez_err});
  }
  for (double q : {0.1, 0.25, 0.5, 0.75, 0.9}) {
    const Approx f = cubicMatchedAt(n, std::log(q) / n);
    starts.push_back({toX(f), obj(toX(f))});
  }
  {
    const Approx f = fitApprox(FitKind::Inflection, 3, n);
    starts.push_back({toX(f), obj(toX(f))});
  }
  std::sort(starts.begin(), starts.end(),
            [](const Point2& p, const Point2& q) { return p.f < q.f; });
  Point2 best = starts[0];
  // Nelder-Mead from the two best starts, then restarts with fresh simplices of decreasing
  // size around the best point until a full round gains nothing.
  for (size_t i = 0; i < std::min<size_t>(2, starts.size()); ++i) {
    const auto& x = starts[i].x;
    const Point2 p = nelderMead(obj, x, {0.05 * std::fabs(x[0]) + 1e-3, 0.05 * std::fabs(x[1]) + 1e-3},
                                600);
    if (p.f < best.f) best = p;
  }
  for (int round = 0; round < 6; ++round) {
    const double before = best.f;
    for (double rel : {1e-2, 1e-4, 1e-6}) {
      const auto& x = best.x;
      const Point2 p = nelderMead(obj, x, {rel * std::fabs(x[0]) + 1e-9, rel * std::fabs(x[1]) + 1e-9},
                                  400);
      if (p.f < best.f) best = p;
    }
    if (!(best.f < before * (1.0 - 1e-12))) break;
  }
  finish(toApprox(best.x));
  return r;
}

}  // namespace shd
