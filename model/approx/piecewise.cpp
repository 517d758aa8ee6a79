#include "approx/piecewise.h"

#include <algorithm>
#include <cmath>
#include <limits>
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

// A search on a non-decreasing h(v) over [lo, hi] that ends on the feasible side (h <= 0) next to
// the root: at a v with h(v) in [-win, 0] (accepted), at a feasible v within minWidth of an
// infeasible one, or at a bound. Each step aims at h = -win/2, the middle of the accepted window,
// so a good one ends the search: Newton's from the latest point, along the slope (the caller's
// h' there, else the latest secant's, at first a given one), at most maxStep; once bracketed,
// when that leaves the bracket, regula falsi with the Illinois modification (an end kept twice
// has its value halved), or bisection where an end's value is not finite. The caller evaluates
// h at next() (or at a guess of its own first) and reports it by add(); as the feasible end only
// moves up, the caller's latest feasible evaluation is the one the search ends on.
struct FeasibleRoot {
  double lo, hi, win, minWidth, slope, maxStep;
  bool hasF = false, hasI = false, accepted = false;
  double vF = 0, gF = 0, vI = 0, gI = 0;  // the ends, g = h + win/2 (Illinois-scaled)
  double vLast = 0, hLast = NAN;
  int side = 0;  // +1: the latest evaluation was feasible, -1: it was not

  bool done() const {
    return accepted || (hasF && hasI && vI - vF <= minWidth) || (hasF && !hasI && vF >= hi) ||
           (hasI && !hasF && vI <= lo);
  }
  double next() const {
    double step = -(hLast + 0.5 * win) / slope;
    if (!std::isfinite(step)) step = hLast < 0 ? maxStep : -maxStep;
    const double v = std::clamp(vLast + std::clamp(step, -maxStep, maxStep), lo, hi);
    if (!(hasF && hasI) || (v > vF && v < vI)) return v;
    if (std::isfinite(gF) && std::isfinite(gI)) {
      const double rf = vF + (vI - vF) * (-gF / (gI - gF));
      if (rf > vF && rf < vI) return rf;
    }
    return 0.5 * (vF + vI);
  }
  void add(double v, double h, double dh = NAN) {
    if (std::isfinite(dh) && dh > 0) {
      slope = dh;
    } else if (std::isfinite(h) && std::isfinite(hLast) && v != vLast) {
      const double s = (h - hLast) / (v - vLast);
      if (s > 0 && std::isfinite(s)) slope = s;
    }
    vLast = v, hLast = h;
    const double g = h + 0.5 * win;
    if (h <= 0) {
      accepted = h >= -win;
      if (side == 1 && hasI) gI *= 0.5;
      hasF = true, vF = v, gF = g, side = 1;
    } else {
      if (side == -1 && hasF) gF *= 0.5;
      hasI = true, vI = v, gI = g, side = -1;
    }
  }
};

// Rounding in a segment's error, relative to the largest c^n on it, with a margin (the Remez
// exchange stops below 1e-15): the searches' windows are kept wider than it.
constexpr double kNoise = 1e-13;

// A segment [a, top] in scale-free terms: the error of c^n on [k a, k top] is k^n times that on
// [a, top], so err = top^n eps(a / top), and the segment meeting E solves ln eps = T = ln E -
// n ln top. v = ln((top - a) / top); slope = d ln err / d v (0: nothing known yet).
struct SegmentStart {
  double v = 0, T = 0, slope = 0;
};

// The longest [a, top] with error at most E: its error within a relative 1e-7 below E (or its
// relative length within 1e-12 of the shortest that exceeds E), a = 0 if [0, top] meets E. The
// search is on v, where ln err is close to linear (err ~ length^(d+1) for short segments; the
// error only grows with the length), from start (updated) moved to the new T along its slope.
// false when even a segment of length top 2^-44 exceeds E.
bool longestSegment(double n, int degree, double top, double E, SegmentStart& start, SegmentFit& out) {
  const double lnE = std::log(E), T = lnE - n * std::log(top);
  const double win = std::max(1e-7, kNoise * std::pow(top, n) / E);
  FeasibleRoot root{-44 * std::log(2.0), 0, win, 1e-12, start.slope, 3.0};
  double v = std::clamp(start.v + (T - start.T) / start.slope, root.lo, root.hi);
  bool found = false;
  for (int it = 0; it < 200 && !root.done(); ++it, v = root.next()) {
    const double a = v >= 0 ? 0.0 : -top * std::expm1(v);
    SegmentFit f = minimaxSegment(n, degree, a, top);
    const double h = std::log(f.err) - lnE;  // -inf for an exact fit
    if (h <= 0) out = std::move(f), found = true;
    root.add(v, h);
  }
  if (found) start = {std::log1p(-out.a / top), T, root.slope};
  return found;
}

struct Mismatch {
  double h, dh;  // h = cut E^(-1/n) - 1 and its derivative in -ln E
};

// The segments for a target error E, each the longest that meets it, from c = 1 down; cut = where
// they end. h <= 0 when the cut meets E too (cut^n <= E): -inf when the segments reach c = 0, +inf
// when one cannot meet E. dh from the segments' slopes: with r = a / top, ln eps(r) = T moves
// with ln E and with the top, which moves with the segments above (D = d ln top / d ln E).
// starts[s] carries segment s's search from one E to the next.
Mismatch layFor(double n, int count, int degree, double E, std::vector<SegmentStart>& starts, PiecewiseFit& out) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  out.segments.clear();
  double top = 1, D = 0;
  for (int s = 0; s < count && top > 0; ++s) {
    if (starts[s].slope <= 0)  // first: from the whole [0, 1], or the one above (the same eps)
      starts[s] = s == 0 ? SegmentStart{0.0, std::log(E), degree + 1.0} : starts[s - 1];
    SegmentFit seg;
    if (!longestSegment(n, degree, top, E, starts[s], seg)) return {inf, NAN};
    if (seg.a > 0) {  // d ln eps / d ln r = slope dv / d ln r = -slope r / (1 - r)
      const double r = seg.a / top;
      D += (1 - n * D) / (-starts[s].slope * r / (1 - r));
    }
    top = seg.a;
    out.segments.push_back(std::move(seg));
  }
  out.cut = top;
  if (top <= 0) return {-inf, NAN};
  const double h = top * std::pow(E, -1.0 / n) - 1;
  return {h, (1 + h) * (1 / n - D)};
}

}  // namespace

PiecewiseFit fitPiecewise(double n, int segments, int degree) {
  if (segments < 1 || segments > 64)
    throw std::invalid_argument(fmt::format("fitPiecewise: {} segments (1..64)", segments));
  PiecewiseFit best;
  best.n = n;
  best.degree = degree;
  best.segments = {minimaxSegment(n, degree, 0, 1)};  // validates n and degree; feasible at its error
  best.cut = 0;
  const double e0 = best.segments[0].err, floorE = std::ldexp(1.0, -36);
  if (e0 > floorE) {
    // On t = -E^(1/(d+1)), where the layout's mismatch rises as E falls, close to linearly (the
    // segments' lengths go as E^(1/(d+1))). Accepted when the cut's error is within a relative
    // 1e-5 of E (more where the segments' rounding shows): the least feasible E lies between the
    // two. The first E: an empirical fit to (E / e0)^(1/(d+1)) S, which is 0.43..0.96 for
    // S = 1..8, d = 1..3, n = 2..1000.
    const double k = degree + 1.0, rho = std::pow(segments, 0.1) * (0.45 + 0.35 * k / (n + degree));
    const double lo = -std::pow(e0, 1 / k), hi = -std::pow(floorE, 1 / k);
    const double t0 = std::min(lo * std::min(0.9, rho / segments), hi);
    const double b0 = std::pow(-t0, k / n);  // the cut at t0's fixed point, for a first slope
    FeasibleRoot root{lo, hi, 0 /* set per E */, -1e-7 * t0, ((1 - b0) / (b0 * k) + 1 / n) * k / -t0, -0.5 * t0};
    std::vector<SegmentStart> starts(static_cast<size_t>(segments));
    PiecewiseFit trial = best;
    double t = t0;
    for (int it = 0; it < 200 && !root.done(); ++it, t = root.next()) {
      const double E = std::pow(-t, k);
      const Mismatch m = layFor(n, segments, degree, E, starts, trial);
      if (m.h <= 0) best = trial;
      root.win = std::max(1e-5, 100 * kNoise / E) / n;  // wider where the segments' rounding shows
      root.add(t, m.h, m.dh * k / -t);  // dh/dt = dh/d(-ln E) (d+1) / -t
    }
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
