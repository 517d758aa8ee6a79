// The paper's polynomial approximations of cos^n (section 4.3, with the corrections of docs/paper-corrections.md) and
// the fits of their coefficients. c = cos(gamma) = N.H in [0, 1], n = shininess in [1, 1000].
//
// Degree 2 (the device of Fig. 11):  p(c) = a c^2 + (1 - a) c = c - a c (1 - c)
//   f(c) = max(0, p(c)). p(0) = 0, p(1) = 1; for a > 1 p is negative on (0, 1 - 1/a), so the
//   clamp is mandatory (the paper omits it). For a >= 0 (every fit below) p <= c <= 1, so f <= 1 as well.
//
// Degree 3:  p(c) = a1 c^3 + b1 c^2 + c1 c,  c1 = 1 - a1 - b1  (p(0) = 0, p(1) = 1)
//   Written as p(c) = c - c (1 - c) (a1 c + v), v = a1 + b1, which is how it is evaluated: the
//   coefficients reach |a1| ~ 3e5 at n = 1000 and the monomial sum would lose ~1e-10 near c = 1,
//   while this form keeps p(0) = 0 and p(1) = 1 exact and loses < 1e-13 near the peak.
//   Cut-off rule (the paper gives none): for n >= 3 the fitted cubics have no root in
//   (0, 1) and rise to a large local maximum away from the peak, so clamping at 0 does nothing.
//     cut = the local minimum of p inside (0, 1), if p has one (a cubic has at most one local
//           minimum; p'(cut) = 0, p''(cut) > 0); cut = 0 otherwise.
//     f(c) = 0                      for c <  cut
//     f(c) = min(1, max(0, p(c)))   for c >= cut.
//   Why the local minimum: left of it p climbs back towards its spurious maximum, so it is the
//   last point where p can be trusted, and p - c^n there is whatever the fit made it. If
//   p(cut) < 0 the rule is continuous (p is clamped to 0 up to its root above cut); if
//   p(cut) > 0, f jumps from 0 to p(cut) at cut and the error has a one-sided supremum cut^n
//   there (lobe_error.h accounts for it). The device compares c with a per-n cut word.
//   The upper clamp: the hardware saturates its output to [0, 1] (unorm), so the ideal device
//   does too; a fitted cubic may overshoot 1 slightly just below c = 1.
// Both degrees: c outside [0, 1] is first clamped to [0, 1] (the device's uQ1.f input), and
// both degrees apply the same [0, 1] output clamp (for a degree-2 a >= 0 the upper one never acts).
//
// Fits (FitKind):
//   Inflection  match cos^n at the inflection point of cos^n(gamma): c = t = sqrt((n-1)/n).
//               Degree 2: a = (t^(n-1) - 1)/(t - 1) (corrected), a = 0 at n = 1 (p = c) and a = 1
//               at n = 2 (p = c^2), both exact. Degree 3: value and slope matched at t (the
//               Level rule with Q = t^n); n = 1, 2, 3 give c, c^2, c^3 exactly; for real n in
//               (1, 3) the matched cubic is well defined since t is in (0, 1).
//   Level       match at the level q: c_q = q^(1/n), so cos^n(c_q) = q. Degree 2:
//               a = (q^((n-1)/n) - 1)/(q^(1/n) - 1) (the printed form is garbled). Degree 3: value Q = q and slope
//               n Q / c_Q at c_Q (the printed general closed forms for a1, b1, evaluated here in
//               a cancellation-free form; exact c^n at n = 1, 2, 3).
//   Shortcut    degree 2 only: a = 0.786 n, the paper's cheap formula; offered as a labelled
//               option only, its error claims do not hold (test_fit).
//   Exact       no polynomial: the table kind stores c^n itself, the schlick and explog kinds use
//               n itself (the Approx forms Table, Schlick and Power below); fitApprox refuses it.
//   Minimax     the coefficients minimising the whole-lobe (c in [0, 1]) maximum absolute error
//               of the CLAMPED (and, degree 3, cut) approximation. See minimaxQuadratic and
//               minimaxCubic.
#pragma once

#include <memory>
#include <string_view>
#include <vector>

namespace shd {

enum class FitKind { Inflection, Level, Shortcut, Minimax, Exact };

const char* toString(FitKind k);  // "inflection", "level", "shortcut", "minimax", "exact"
// Throws std::invalid_argument("unknown fit 'x' (expected inflection, level, shortcut, minimax or exact)").
FitKind parseFitKind(std::string_view s);

constexpr double kMinShininess = 1.0;
constexpr double kMaxShininess = 1000.0;

// The ideal device in double precision. Form Poly: the polynomial with its clamp and cut (the
// header comment). Form Table (the table kind): f(c) = table[min(floor(c 2^T), 2^T - 1)], a step
// function of c. Form Schlick: f(c) = c / (n - n c + c). Form Power (the explog kind): f(c) = c^n.
// Form Piecewise (the piecewise kind): the segments' polynomials, 0 below the cut (piecewise.h).
struct PiecewiseFit;
struct Approx {
  enum class Form { Poly, Table, Schlick, Power, Piecewise };
  Form form = Form::Poly;
  int degree = 2;
  double a = 0.0;                      // degree 2 coefficient
  double a1 = 0.0, b1 = 0.0, c1 = 0.0;  // monomial coefficients of p (degree 2: 0, a, 1 - a)
  double cut = 0.0;                    // degree 3 cut-off (0: none); always 0 for degree 2
  double n = 0.0;                      // Schlick, Power: the shininess
  std::vector<double> table;           // Table: 2^T values in [0, 1], bucket k = [k, k+1) / 2^T
  std::shared_ptr<const PiecewiseFit> pieces;  // Piecewise

  // The ideal device: the rule of the header comment, exactly.
  double eval(double c) const;
  // The unclamped, uncut polynomial p(c) = c - c (1 - c) (a1 c + a1 + b1).
  double poly(double c) const;
  // Points in [0, 1] where f is not smooth: the cut, the roots of p and of p - 1 above it; the
  // table's bucket edges; the segments' ends.
  std::vector<double> kinks() const;

  static Approx quadratic(double a);
  // c1 = 1 - a1 - b1; the cut is derived from (a1, b1) by the rule above.
  static Approx cubic(double a1, double b1);
  static Approx schlick(double n);
  static Approx power(double n);
  static Approx piecewise(PiecewiseFit fit);
  static Approx stepTable(std::vector<double> values);  // size a power of two
  int tableBits() const;  // T: log2 of the table's size
};

// Cosine of the inflection point of cos^n(gamma), tan^2 = 1/(n-1): sqrt((n-1)/n); 0 at n = 1.
double inflectionCos(double n);
// c_q with c_q^n = q: q^(1/n).
double levelCos(double n, double q);

// Throws std::invalid_argument unless 1 <= n <= 1000 (n is real), 0 < level_q < 1,
// degree is 2 or 3, and the kind exists for the degree (shortcut: degree 2 only).
// level_q is used by FitKind::Level only but is validated always.
Approx fitApprox(FitKind kind, int degree, double n, double level_q = 0.5);

// The degree-2 coefficient of the closed-form fits (Inflection, Level, Shortcut). Same checks.
double quadraticA(FitKind kind, double n, double level_q = 0.5);

// Degree-3 cubic whose value equals c^n and whose slope equals n c^(n-1) at c = s = exp(log_s),
// s in (0, 1). Solved in the basis p = c - c (1 - c)(u c + v) with 1 - s from expm1 so that
// nothing cancels catastrophically for large n (see fit.cpp). Exact c^n for n = 1, 2, 3.
Approx cubicMatchedAt(double n, double log_s);

// Minimax quadratic with the clamp, whole lobe. f_a is pointwise non-increasing in a
// (dp/da = c^2 - c <= 0 and max(0, .) is monotone), so the largest positive error
// e+(a) = max(f_a - c^n) is non-increasing and the largest negative error
// e-(a) = max(c^n - f_a) non-decreasing; max(e+, e-) is minimal where they cross. The
// crossing is found by Brent's method on e+ - e-, each evaluated exactly (lobe_error.h
// errorExtrema). Certificate of optimality (equioscillation): c_plus and c_minus are points
// where the error is +err and -err; any other a raises one of them.
struct QuadMinimax {
  double a = 0.0;
  double err = 0.0;                  // max(e_plus, e_minus) at a
  double e_plus = 0.0, c_plus = 0.0;   // largest f - c^n and where
  double e_minus = 0.0, c_minus = 0.0; // largest c^n - f and where (c_minus may be a cut/root)
  int evaluations = 0;               // error evaluations spent
};
QuadMinimax minimaxQuadratic(double n);

// A local extremum of the signed error f(c) - c^n (left_limit: the one-sided value just below
// a cut, a supremum that is approached but not attained).
struct ErrorPoint {
  double c = 0.0;
  double err = 0.0;
  bool left_limit = false;
};

// Minimax cubic with cut and clamp, whole lobe, over the two free parameters (a1, b1).
// Method (our own code, no library):
//   1. Remez exchange on the linear family p = c - c (1 - c)(u c + v) over [0, 1] ignoring cut
//      and clamp (3-point alternation, exact extrema) -> one starting point;
//   2. further starts: the Level cubics for several Q and the Inflection cubic;
//   3. Nelder-Mead on the true (cut, clamped) whole-lobe maximum error, evaluated exactly
//      (lobe_error.h maxErrorExact), in the well-scaled parameters (g(s), g(1)) with
//      g(c) = u c + v, s = 0.5^(1/n); restarted with a fresh simplex until a restart gains
//      nothing.
// The problem is not convex (the cut moves with the coefficients), so this is the best minimum
// found, not a proven global one; `alternation` lists the error extrema within 1e-6 relative of
// err (signed) as evidence of (near) equioscillation, and test_fit checks local optimality.
struct CubicMinimax {
  Approx approx;
  double err = 0.0;
  std::vector<ErrorPoint> alternation;
  double remez_err = 0.0;   // whole-lobe error of the unclamped Remez start (with the cut rule)
  int evaluations = 0;
};
CubicMinimax minimaxCubic(double n);

}  // namespace shd
