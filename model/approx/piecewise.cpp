#include "approx/piecewise.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "approx/lobe_error.h"

namespace shd {

namespace {

// p^(m)(c) for p = sum q_i t^i, t = (c - a) / h.
double polyDerivative(const std::vector<double>& q, int m, double a, double h, double c) {
  const double t = (c - a) / h;
  double s = 0;
  for (size_t i = q.size(); i-- > static_cast<size_t>(m);) {
    double falling = 1;
    for (int k = 0; k < m; ++k) falling *= static_cast<double>(i - static_cast<size_t>(k));
    s = s * t + q[i] * falling;
  }
  return s / std::pow(h, m);
}

// Solves A x = y in place (Gaussian elimination with partial pivoting); A is k x k, row-major.
std::vector<double> solve(std::vector<double> A, std::vector<double> y) {
  const size_t k = y.size();
  for (size_t col = 0; col < k; ++col) {
    size_t piv = col;
    for (size_t r = col + 1; r < k; ++r)
      if (std::fabs(A[r * k + col]) > std::fabs(A[piv * k + col])) piv = r;
    for (size_t c = 0; c < k; ++c) std::swap(A[col * k + c], A[piv * k + c]);
    std::swap(y[col], y[piv]);
    for (size_t r = col + 1; r < k; ++r) {
      const double f = A[r * k + col] / A[col * k + col];
      for (size_t c = col; c < k; ++c) A[r * k + c] -= f * A[col * k + c];
      y[r] -= f * y[col];
    }
  }
  std::vector<double> x(k);
  for (size_t r = k; r-- > 0;) {
    double s = y[r];
    for (size_t c = r + 1; c < k; ++c) s -= A[r * k + c] * x[c];
    x[r] = s / A[r * k + r];
  }
  return x;
}

struct Extremum {
  double c, e;
};

// The extrema of e = p - c^n on [a, b]: the ends and the roots of e', with their errors.
std::vector<Extremum> extrema(const SegmentFit& s, double n) {
  const int d = static_cast<int>(s.q.size()) - 1;
  const double h = s.b - s.a;
  // D_k = e^(k+1); D_(d+1) = -n (n-1) ... c^(n-d-2): one sign on (0, 1) (or identically 0).
  auto deriv = [&](int k, double c) { return polyDerivative(s.q, k + 1, s.a, h, c) - powDerivative(n, k + 1, c); };
  std::vector<double> cs = rootsByDerivativeChain(deriv, d + 1, s.a, s.b);
  cs.push_back(s.a);
  cs.push_back(s.b);
  std::sort(cs.begin(), cs.end());
  cs.erase(std::unique(cs.begin(), cs.end()), cs.end());
  std::vector<Extremum> out;
  for (double c : cs) out.push_back({c, s.eval(c) - std::pow(c, n)});
  return out;
}

// The next reference of the exchange: the candidates merged into runs of one sign (each run's
// largest), then d + 2 consecutive ones that keep the largest error.
std::vector<double> exchange(const std::vector<Extremum>& cand, size_t want) {
  std::vector<Extremum> alt;
  for (const Extremum& x : cand) {
    if (!alt.empty() && (alt.back().e >= 0) == (x.e >= 0)) {
      if (std::fabs(x.e) > std::fabs(alt.back().e)) alt.back() = x;
    } else {
      alt.push_back(x);
    }
  }
  size_t lo = 0, hi = alt.size();
  while (hi - lo > want) {
    if (std::fabs(alt[lo].e) < std::fabs(alt[hi - 1].e)) ++lo;
    else --hi;
  }
  std::vector<double> ref;
  for (size_t i = lo; i < hi; ++i) ref.push_back(alt[i].c);
  return ref;
}

}  // namespace

double SegmentFit::eval(double c) const {
  const double t = (c - a) / (b - a);
  double s = 0;
  for (size_t i = q.size(); i-- > 0;) s = s * t + q[i];
  return s;
}

SegmentFit minimaxSegment(double n, int degree, double a, double b) {
  if (!(a >= 0 && a < b && b <= 1) || degree < 0 || degree > 3 || !(n >= 1))
    throw std::invalid_argument(fmt::format("minimaxSegment: n {} degree {} on [{}, {}]", n, degree, a, b));
  SegmentFit s;
  s.a = a;
  s.b = b;
  const size_t k = static_cast<size_t>(degree) + 2;  // unknowns: d + 1 coefficients and E
  std::vector<double> ref(k);
  for (size_t j = 0; j < k; ++j)  // Chebyshev extrema on [a, b]
    ref[j] = a + (b - a) * 0.5 * (1 - std::cos(std::acos(-1.0) * static_cast<double>(j) / static_cast<double>(k - 1)));
  for (s.iterations = 1; s.iterations <= 40; ++s.iterations) {
    std::vector<double> A(k * k), y(k);
    for (size_t j = 0; j < k; ++j) {
      const double t = (ref[j] - a) / (b - a);
      double tp = 1;
      for (size_t i = 0; i + 1 < k; ++i, tp *= t) A[j * k + i] = tp;
      A[j * k + k - 1] = (j % 2 == 0) ? -1.0 : 1.0;  // p(x_j) - x_j^n = (-1)^j E
      y[j] = std::pow(ref[j], n);
    }
    const std::vector<double> x = solve(A, y);
    s.q.assign(x.begin(), x.end() - 1);
    const double level = std::fabs(x.back());
    const std::vector<Extremum> cand = extrema(s, n);
    s.err = 0;
    for (const Extremum& e : cand) s.err = std::max(s.err, std::fabs(e.e));
    // Converged when the reference's level is the true maximum (de la Vallee Poussin: the
    // minimax error lies between them), or when the error is at rounding level.
    if (s.err - level <= 1e-9 * s.err || s.err < 1e-15) break;
    std::vector<double> next = exchange(cand, k);
    if (next.size() < k) break;  // fewer alternations than the degree needs: p interpolates c^n
    ref = next;
  }
  return s;
}

double PiecewiseFit::eval(double c) const {
  if (c < cut) return 0;
  for (const SegmentFit& s : segments)
    if (c >= s.a) return s.eval(c);
  return 0;
}

namespace {

// The segments for a target error E from c = 1 down; cut = where they end.
bool layFor(double n, int count, int degree, double E, PiecewiseFit& out) {
  out.segments.clear();
  double top = 1;
  for (int s = 0; s < count && top > 0; ++s) {
    SegmentFit whole = minimaxSegment(n, degree, 0, top);
    if (whole.err <= E) {
      out.segments.push_back(whole);
      top = 0;
      break;
    }
    double lo = 0, hi = top;  // err(lo) > E; the shortest segments' error tends to 0
    SegmentFit best;
    bool found = false;
    for (int it = 0; it < 44; ++it) {
      const double mid = 0.5 * (lo + hi);
      if (mid >= top) break;
      const SegmentFit f = minimaxSegment(n, degree, mid, top);
      if (f.err <= E) hi = mid, best = f, found = true;
      else lo = mid;
    }
    if (!found) return false;
    out.segments.push_back(best);
    top = best.a;
  }
  out.cut = top;
  return std::pow(top, n) <= E;
}

}  // namespace

PiecewiseFit fitPiecewise(double n, int segments, int degree) {
  if (segments < 1 || segments > 64)
    throw std::invalid_argument(fmt::format("fitPiecewise: {} segments (1..64)", segments));
  minimaxSegment(n, degree, 0, 1);  // validates n and degree
  PiecewiseFit best;
  best.n = n;
  best.degree = degree;
  double lo = 0, hi = 1;
  if (!layFor(n, segments, degree, hi, best)) throw std::logic_error("fitPiecewise: E = 1 must be reachable");
  PiecewiseFit trial = best;
  for (int it = 0; it < 36; ++it) {
    const double mid = 0.5 * (lo + hi);
    if (layFor(n, segments, degree, mid, trial)) hi = mid, best = trial;
    else lo = mid;
  }
  best.err = std::pow(best.cut, n);
  for (const SegmentFit& s : best.segments) best.err = std::max(best.err, s.err);
  return best;
}

PiecewiseCodes quantisePiecewise(const PiecewiseFit& f, int wc, int wf, int kf) {
  if (wc < 2 || wc > 24 || wf < 1 || kf < wf || kf > 40)
    throw std::invalid_argument(fmt::format("quantisePiecewise: Wc {} Wf {} Kf {}", wc, wf, kf));
  PiecewiseCodes q;
  q.wc = wc;
  q.wf = wf;
  q.kf = kf;
  const double one = std::ldexp(1.0, wc);
  int64_t top = (int64_t{1} << wc) + 1;  // one past the segment's last code
  for (const SegmentFit& s : f.segments) {  // from the top down
    PiecewiseCodes::Seg g;
    g.B = static_cast<int64_t>(std::ceil(s.a * one));
    const int64_t last = std::max<int64_t>(top - 1 - g.B, 0);  // C - B of the segment's last code
    g.e = 0;
    while (g.e < wc && (last << (g.e + 1)) < (int64_t{1} << wc)) ++g.e;
    // t = (c - a) / (b - a) = alpha + beta u with c = B 2^-Wc + u 2^-e.
    const double alpha = (g.B / one - s.a) / (s.b - s.a), beta = std::ldexp(1.0, -g.e) / (s.b - s.a);
    const size_t d = s.q.size() - 1;
    std::vector<double> K(d + 1, 0.0);
    for (size_t i = 0; i <= d; ++i) {
      double binom = 1;  // C(i, j)
      for (size_t j = 0; j <= i; ++j) {
        K[j] += s.q[i] * binom * std::pow(alpha, static_cast<double>(i - j)) * std::pow(beta, static_cast<double>(j));
        binom = binom * static_cast<double>(i - j) / static_cast<double>(j + 1);
      }
    }
    for (double k : K) g.K.push_back(static_cast<int64_t>(std::nearbyint(std::ldexp(k, kf))));
    q.segs.insert(q.segs.begin(), g);
    top = g.B;
  }
  return q;
}

int64_t PiecewiseCodes::eval(int64_t C) const {
  const Seg* s = nullptr;
  for (const Seg& g : segs)
    if (C >= g.B) s = &g;
  if (s == nullptr) return 0;  // below the cut
  const int64_t x = C - s->B;  // u = x 2^(e - Wc)
  const int ush = wc - s->e;
  int64_t acc = s->K.back();
  for (size_t j = s->K.size() - 1; j-- > 0;) {
    const __int128 p = static_cast<__int128>(acc) * x;
    acc = static_cast<int64_t>(p >> ush) + s->K[j];  // arithmetic shift: floor
  }
  const int sh = kf - wf;
  const int64_t f = sh == 0 ? acc : (acc + (int64_t{1} << (sh - 1))) >> sh;
  return std::clamp<int64_t>(f, 0, int64_t{1} << wf);
}

int PiecewiseCodes::coefIntBits() const {
  int bits = 1;
  for (const Seg& g : segs)
    for (int64_t k : g.K)
      while ((k >> kf) >= (int64_t{1} << (bits - 1)) || (k >> kf) < -(int64_t{1} << (bits - 1))) ++bits;
  return bits;
}

}  // namespace shd
