// Maximum error of an approximation f(c) against cos^n = c^n over a region [c_lo, c_hi] of
// c in [0, 1]: absolute |f - c^n| and relative |f - c^n| / c^n.
//
// Two independent methods, cross-checked in test_lobe_error:
//
// maxErrorExact (for an Approx, i.e. a clamped/cut polynomial of degree <= 3):
//   The error is piecewise e = -c^n (below the cut or where p < 0), e = 1 - c^n (p > 1) and
//   e = p - c^n. The pieces are split at the cut and the roots of p and p - 1, and on a
//   p - c^n piece the extrema are the roots of e' = p' - n c^(n-1). Because the 4th derivative
//   of e', -n(n-1)(n-2)(n-3) c^(n-4), has one sign on (0, 1) for every real n, e' has at most
//   three roots and they are all found by bracketing along the derivative chain: the roots of
//   D_(k+1) split [lo, hi] into pieces on which D_k is monotone, hence has at most one root,
//   bracketed by a sign change and polished by Brent's method to ~4 ulp (rootsByDerivativeChain).
//   The relative error p c^-n - 1 has its extrema at the roots of the cubic c p' - n p.
//   Guarantee: the maximum is taken over a finite candidate set that provably contains the
//   extremum (endpoints, the cut from both sides, roots, critical points); the result is exact
//   up to double rounding of the evaluation (~1e-15 absolute) and of the critical point
//   (second-order in its ~1e-16 relative position error).
//
// maxError (for any function f):
//   Samples c on the union of (i) 1500 points uniform in y = -n ln c over [0, 60]
//   (c^n = e^-y: spacing 0.04 in y, i.e. ~0.04/n in c near the peak, which resolves the
//   1/n-wide features of c^n and of fits scaled to it), (ii) 2000 points uniform in c,
//   (iii) the endpoints, and (iv) each given breakpoint b together with its two floating-point
//   neighbours (both one-sided values at a jump or kink). Every sampled local maximum of |e|
//   whose value is at least 3/4 of the largest sample (at most 64 of them, the largest first)
//   is refined by golden-section search on its two neighbouring cells to 1e-13 in c.
//   Guarantee: the result is the true supremum to ~1e-13 * |e'| + 1e-16 provided each local
//   maximum of |e| is resolved by the grid, i.e. no other local extremum of |e| and no
//   unlisted kink lies in the two cells around it and no maximum hides entirely inside one cell.
//   This holds for c^n against smooth functions whose features are no narrower than ~0.1/n
//   (every function in this project); jumps and kinks must be passed as breakpoints. The
//   result is never more than rounding above the truth: it is a maximum over evaluated points.
//
// Relative error is only meaningful where c^n is bounded away from 0 (peak regions); points
// with c^n == 0 (c = 0, or underflow) are skipped. When want_rel is false (or the region has
// no point with c^n > 0) max_rel and worst_rel_c are NaN.
#pragma once

#include "approx/fit.h"

#include <functional>
#include <string_view>
#include <vector>

namespace shd {

struct RegionError {
  double max_abs = 0.0;          // sup |f - c^n|
  double worst_abs_c = 0.0;      // where (for a one-sided supremum at a cut: the cut)
  double signed_at_worst = 0.0;  // f - c^n there (sign shows over/undershoot)
  double max_rel = 0.0;          // sup |f - c^n| / c^n, NaN unless requested
  double worst_rel_c = 0.0;
};

RegionError maxError(const std::function<double(double)>& f, double n, double c_lo, double c_hi,
                     bool want_rel, const std::vector<double>& breakpoints = {});

RegionError maxErrorExact(const Approx& f, double n, double c_lo, double c_hi, bool want_rel);

// All candidate extrema of the signed error f(c) - c^n on [c_lo, c_hi] (see maxErrorExact),
// sorted by c; the max and min of the signed error over the region are among them.
std::vector<ErrorPoint> errorExtrema(const Approx& f, double n, double c_lo, double c_hi);

// Regions of c:
//   "lobe"        [0, 1]               the whole lobe
//   "peak50"      [0.5^(1/n), 1]       where c^n >= 0.5
//   "inflection"  [sqrt((n-1)/n), 1]   from the inflection point of cos^n(gamma) to the peak
//                                       ([0, 1] at n = 1); the paper's "up to the inflection point"
struct Region {
  const char* name;
  double lo, hi;
};
std::vector<Region> standardRegions(double n);

// Errors of one approximation at one n in each standard region (relative error for the two
// peak regions only; NaN for the lobe, where c^n -> 0).
struct RegionApproxError {
  Region region;
  RegionError error;
};
struct ApproxErrorSummary {
  double n = 0.0;
  Approx approx;
  std::vector<RegionApproxError> regions;  // in standardRegions order
  // The entry for a region name; throws std::invalid_argument for an unknown name.
  const RegionError& at(std::string_view region_name) const;
};
ApproxErrorSummary summarizeError(const Approx& f, double n);

// Numerical helpers shared with fit.cpp.

// A root of g in [lo, hi] given g(lo) = glo and g(hi) = ghi of opposite signs (infinite values
// allowed): Brent's method with bisection safeguard, to |bracket| <= 4 ulp + abs_tol.
double brentRoot(const std::function<double(double)>& g, double lo, double hi, double glo,
                 double ghi, double abs_tol = 0.0);

// All roots in [lo, hi] of D_0, where deriv(k, c) is the k-th derivative D_k(c) and D_K has no
// sign change on (lo, hi) (constant sign or identically zero). Sorted, duplicates removed.
std::vector<double> rootsByDerivativeChain(const std::function<double(int, double)>& deriv,
                                           int K, double lo, double hi);

// d^m/dc^m c^n = n (n-1) ... (n-m+1) c^(n-m) for c >= 0 (a zero coefficient gives exactly 0,
// also at c = 0 where the power may be infinite).
double powDerivative(double n, int m, double c);

}  // namespace shd
