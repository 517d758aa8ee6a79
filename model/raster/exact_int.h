// Exact integer rounding and division, shared by triangle setup (raster/setup.cpp) and the row
// spans of small triangles (raster/row_spans.cpp), which must give the same codes bit for bit:
// the snapping of vertices and attributes, floor, ceiling and round-half-even divisions in 64
// bits where the operands fit (else 128), and the pixel-centre rows of a vertical extent.
#pragma once

#include <array>
#include <climits>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <utility>

namespace shd::exact {

using i128 = __int128;


// round-half-even(x) for |x| < 2^51 (the caller bounds it): x + 1.5 2^52 lies in
// [2^52, 2^53), where the doubles are the integers, so the sum is x rounded half to even (in
// IEEE double's default rounding mode, as nearbyint uses; 1.5 2^52 is even), and its bits less
// the constant's are that integer: no libm call and no conversion instruction.
inline int64_t snapSmall(double x) {
  constexpr double kMagic = 6755399441055744.0;  // 1.5 * 2^52
  const double y = x + kMagic;
  int64_t yb = 0, mb = 0;
  std::memcpy(&yb, &y, sizeof y);
  std::memcpy(&mb, &kMagic, sizeof kMagic);
  return yb - mb;
}

// round-half-even(v 2^frac): Fixed::fromDouble's RoundHalfEven, without its format checks: the
// callers have bounded |v 2^frac| well below 2^62 (the guard band, the attribute range). 2^frac
// as a double multiplier is exact, like ldexp. Below 2^51 snapSmall, larger values nearbyint.
inline int64_t snapHalfEven(double v, int frac) {
  const double x = v * static_cast<double>(int64_t{1} << frac);
  if (std::fabs(x) < 2251799813685248.0) return snapSmall(x);  // 2^51
  return static_cast<int64_t>(std::nearbyint(x));
}

inline bool fitsI64(i128 v) { return v >= INT64_MIN && v <= INT64_MAX; }

[[gnu::noinline]] inline int64_t floorDivWide(i128 a, i128 b) {
  i128 q = a / b;
  if ((a % b) != 0 && a < 0) --q;
  return static_cast<int64_t>(q);
}
// b > 0. Inlined: the common case is one 64-bit division, the 128-bit one out of line.
[[gnu::always_inline]] inline int64_t floorDiv(i128 a, i128 b) {
  if (!fitsI64(a) || !fitsI64(b)) return floorDivWide(a, b);
  const int64_t a64 = static_cast<int64_t>(a), b64 = static_cast<int64_t>(b);
  const int64_t q = a64 / b64;
  return q - static_cast<int64_t>(((a64 % b64) != 0) & (a64 < 0));  // without a branch, as roundHalfEvenFrom
}
[[gnu::always_inline]] inline int64_t ceilDiv(i128 a, i128 b) { return -floorDiv(-a, b); }  // b > 0
// ceil(a / b) for b > 0 in 64 bits: one division.
[[gnu::always_inline]] inline int64_t ceilDiv64(int64_t a, int64_t b) {
  const int64_t q = a / b;
  return q + static_cast<int64_t>(((a % b) != 0) & (a > 0));
}
// ceil((x y - c) / b) for b > 0: in 64 bits where x y - c fits, else in 128.
[[gnu::always_inline]] inline int64_t ceilDivOfProduct(int64_t x, int64_t y, int64_t c, int64_t b) {
  int64_t xy = 0, n = 0;
  if (!__builtin_mul_overflow(x, y, &xy) && !__builtin_sub_overflow(xy, c, &n)) return ceilDiv64(n, b);
  return ceilDiv(static_cast<i128>(x) * y - c, b);
}

// round-half-even(num / den) from the truncated quotient q and remainder r of num / den
// (|r| < den, den > 0): floor first, then up when the remainder is above half, or exactly half
// with q odd (r vs den - r: no overflow of 2r).
// Without branches: the remainder's sign and the rounding are data, not a pattern (setup
// runs a dozen of these per triangle; mispredicted branches cost more than the arithmetic).
template <class T>
inline T roundHalfEvenFrom(T q, T r, T den) {
  const T neg = r < 0 ? 1 : 0;
  q -= neg;
  r += den * neg;
  const T rest = den - r;
  return q + static_cast<T>((r > rest) | ((r == rest) & ((q & 1) != 0)));
}

// round-half-even(num / den), den > 0: in 64 bits with one division when both fit (the
// common case, inlined), else in 128 bits.
[[gnu::noinline]] inline i128 roundDivWide(i128 num, i128 den) { return roundHalfEvenFrom(num / den, num % den, den); }
inline i128 roundDiv(i128 num, i128 den) {
  if (!fitsI64(num) || !fitsI64(den)) return roundDivWide(num, den);
  const int64_t n = static_cast<int64_t>(num), d = static_cast<int64_t>(den);
  return roundHalfEvenFrom(n / d, n % d, d);
}

// round-half-even(base + num / den), den > 0, in 64 bits: one division, then
// roundHalfEvenFrom(base + q, r, den), whose floor and parity are those of base + num / den.
// No overflow: |q| <= |num| / den, and base is an attribute code (|base| < 2^61) with
// den = 2 det >= 2, or 0. (On a 2-core AMD EPYC VM, interleaved runs: a quotient estimated from
// one reciprocal of den and corrected in integers took 2-4 % longer a Gouraud frame than the
// division; one division of doubles per quotient, its truncation corrected by the remainder's
// sign, 8.7 % longer with SHD_SCALAR and 2.0 % with AVX-512, though 12 independent ones alone
// ran 1.8 times as fast: setup's quotients are short, which the integer divider finishes early.)
inline int64_t roundDivPlus(int64_t base, int64_t num, int64_t den) {
  return roundHalfEvenFrom(base + num / den, num % den, den);
}

// Rows whose pixel centre (2w+1)*2^S lies in [lo, hi] (u units): floor and ceiling divisions
// by step = 2^(S+1) as arithmetic shifts (floor for any sign; |lo|, |hi| are far below 2^62).
inline std::pair<int64_t, int64_t> centreRows(int64_t lo, int64_t hi, int S) {
  const int64_t half = int64_t{1} << S;
  return {-((half - lo) >> (S + 1)), (hi - half) >> (S + 1)};
}

// One attribute plane's numerators (raster/setup.h) in 64 bits: the gradients per pixel are
// sx / det and sy / det, sx = nx 2^S and sy = ny 2^S, and the exact plane at the reference
// pixel's centre, at (dcx, dcy) from vertex 0 (u units), a0 + num / (2 det), num = nx dcx +
// ny dcy, each to be rounded half to even, with nx = (a1 - a0) dy2 - (a2 - a0) dy1 and
// ny = dx1 (a2 - a0) - dx2 (a1 - a0) (subpixel vertex differences, |a| < 2^61). False, the
// outputs unspecified, where a product or sum does not fit int64_t (checked): the caller
// computes them in 128 bits instead.
inline bool planeNumerators64(const std::array<int64_t, 3>& a, int64_t dx1, int64_t dy1, int64_t dx2, int64_t dy2,
                              int64_t dcx, int64_t dcy, int S, int64_t& sx, int64_t& sy, int64_t& num) {
  const int64_t da1 = a[1] - a[0], da2 = a[2] - a[0];  // |a| < 2^61: no overflow
  int64_t p1, p2, p3, p4, nx, ny, rx, ry;
  return !__builtin_mul_overflow(da1, dy2, &p1) && !__builtin_mul_overflow(da2, dy1, &p2) &&
         !__builtin_sub_overflow(p1, p2, &nx) && !__builtin_mul_overflow(dx1, da2, &p3) &&
         !__builtin_mul_overflow(dx2, da1, &p4) && !__builtin_sub_overflow(p3, p4, &ny) &&
         !__builtin_mul_overflow(nx, int64_t{1} << S, &sx) && !__builtin_mul_overflow(ny, int64_t{1} << S, &sy) &&
         !__builtin_mul_overflow(nx, dcx, &rx) && !__builtin_mul_overflow(ny, dcy, &ry) &&
         !__builtin_add_overflow(rx, ry, &num);
}

}  // namespace shd::exact
