// Piecewise polynomial approximations of cos^n = c^n: the cosine range split into S segments per
// n, each with its own polynomial of degree d, and f = 0 below the lowest segment (the cut-off).
// The study behind a segmented specular unit: how far S segments bring the whole-lobe error
// down, against the PROM bits and multipliers they cost (docs/specular-unit.md).
//
// minimaxSegment: the minimax polynomial of degree d for c^n on [a, b], by the Remez exchange
//   with exact extrema: the error e = p - c^n has e^(d+2) = -n (n-1) ... c^(n-d-2), of one sign on
//   (0, 1) for every real n not an integer in 1..d+1, so rootsByDerivativeChain finds every root
//   of e' (lobe_error.h) and the extrema of e are those roots and the two ends. The polynomial is
//   kept in the local variable t = (c - a) / (b - a) for conditioning.
// fitPiecewise: the least whole-lobe maximum error reachable with S segments. For a target E
//   the segments are laid greedily from c = 1 down, each as long as its minimax error stays
//   within E (the error of a segment grows with its length); E is feasible when the S segments
//   reach down to a cut b_0 with b_0^n <= E (the error of f = 0 below it). The least feasible E
//   is found by Newton's method on E^(1/(d+1)) (the cut moves close to linearly in it; the
//   derivative from the segments' slopes) to a relative 1e-5 (more below E ~ 1e-6, where
//   rounding shows in the segments' errors), each segment's start by the secant method on
//   ln(length) to an error within a relative 1e-7 below E. Both keep a bracket and fall back to
//   regula falsi (Illinois) or bisection. A segment's search starts where the last E's ended,
//   moved along its slope: the error of c^n on [k a, k b] is k^n times that on [a, b], so every
//   segment follows one curve, err / top^n against a / top. Every segment's error is then at
//   most E, and the result says which is largest.
#pragma once

#include <cstdint>
#include <vector>

namespace shd {

struct SegmentFit {
  double a = 0, b = 1;              // the segment [a, b]
  std::vector<double> q;            // p = sum q_i t^i, t = (c - a) / (b - a), i = 0..d
  double err = 0;                   // max over [a, b] of |p - c^n|, exact up to rounding
  int iterations = 0;               // Remez exchanges
  double eval(double c) const;
};

// std::invalid_argument unless 0 <= a < b <= 1, 0 <= degree <= 3 and n >= 1.
SegmentFit minimaxSegment(double n, int degree, double a, double b);

struct PiecewiseFit {
  double n = 0;
  int degree = 2;
  std::vector<SegmentFit> segments;  // from the top (ending at c = 1) down
  double cut = 0;                    // b_0: f = 0 below it
  double err = 0;                    // whole-lobe max |f - c^n| over [0, 1]
  double eval(double c) const;
};

// std::invalid_argument unless 1 <= segments <= 64 and the arguments of minimaxSegment hold.
PiecewiseFit fitPiecewise(double n, int segments, int degree);

// A piecewise fit in the integers a segmented unit would hold: cosine codes C (uQ1.Wc); per
// segment its first code B = ceil(a 2^Wc) (so a code belongs to the segment the real fit puts it
// in), a scale e (the largest, at most Wc, with u = (C - B) 2^(e-Wc) < 1 over the segment's codes)
// and the coefficients K_j of p in u, rounded half-even to Kf fraction bits. f = K_d u^d + ...
// by Horner's scheme, each product truncated (floor) back to Kf fraction bits, rounded half up to
// Wf bits and clamped to [0, 1]; 0 below the lowest segment's B (the cut).
struct PiecewiseCodes {
  struct Seg {
    int64_t B = 0;
    int e = 0;
    std::vector<int64_t> K;  // K_0 .. K_d
  };
  int wc = 15, wf = 16, kf = 16;
  std::vector<Seg> segs;  // ascending B: segs[0].B is the cut
  int64_t eval(int64_t C) const;  // the f code, 0..2^Wf
  int coefIntBits() const;        // integer bits (with the sign) that every K_j needs
};

// std::invalid_argument unless 2 <= Wc <= 24, 1 <= Wf <= Kf <= 40.
PiecewiseCodes quantisePiecewise(const PiecewiseFit& f, int wc, int wf, int kf);

}  // namespace shd
