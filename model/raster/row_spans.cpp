#include "raster/row_spans.h"

#include <algorithm>
#include <cmath>

#include "raster/exact_int.h"
#include "raster/span_walk.h"
#include "render/x86_targets.h"

namespace shd {

using namespace exact;

RowSpansConfig::RowSpansConfig(const RasterConfig& cfg) {
  const SpanParams& p = cfg.unit;
  S = cfg.subpixel_bits;
  W = cfg.width;
  H = cfg.height;
  k_lim = int64_t{1} << (p.CoordBits - 1);
  guard = static_cast<double>(int64_t{1} << (p.CoordBits - 3));
  // setup's bound (snapVertices): every covered value then fits AttrBits
  const int64_t err_bound = (1 + int64_t{W} + H) / 2 + 2;
  lim = static_cast<double>((int64_t{1} << (p.AttrBits - 1)) - 1 - err_bound);
  // A vertex within the guard band has |U| <= 2^(CoordBits - 2 + S) in u units: with
  // CoordBits + S <= 31 that is 2^29, so an edge's A and B stay below 2^40, its C below 2^61,
  // det below 2^61, and a row's N = -(B y + C) within int64_t.
  applies = p.NumTri == 1 && p.NumAttr == 4 && p.AttrBits == 32 && p.CoordBits + S <= 31 && W <= 32767;
  while ((1 << lane_shift) < p.LanesPerTri) ++lane_shift;  // a power of two (SpanParams::validate)
  align_lanes = p.AlignLanes != 0;
  if (!applies) return;
  for (size_t k = 0; k < 4; ++k) {
    frac[k] = cfg.attrFracBits(static_cast<int>(k));
    scale[k] = static_cast<double>(int64_t{1} << frac[k]);
  }
}

namespace {

// An edge's bound in the row loop: x >= q (left) or x <= -q (right), q = ceil(N / D), stepped
// by the DDA of raster/span_unit.h (N grows by -B = k D + m per row; r = q D - N in [0, D)).
struct RowEdge {
  int64_t q, r, D, k, m;
  bool right;
};

// The plane at (x, y) (screen pixels), exactly; false where it leaves int64_t.
bool planeAt(int64_t iref, int64_t didx, int64_t didy, int64_t dx, int64_t dy, int64_t& v) {
  int64_t px = 0, py = 0, s = 0;
  return !__builtin_mul_overflow(didx, dx, &px) && !__builtin_mul_overflow(didy, dy, &py) &&
         !__builtin_add_overflow(iref, px, &s) && !__builtin_add_overflow(s, py, &v);
}

bool fits32(int64_t v) { return v >= INT32_MIN && v <= INT32_MAX; }

// A triangle's attribute codes, vertex i's code of attribute k at [i][k]: as integers (the scalar
// plane) or as doubles (the AVX2 one; exact, the codes being below 2^31).
using Codes = std::array<std::array<int64_t, 4>, 3>;
using CodesF = std::array<std::array<double, 4>, 3>;

// What the plane needs of a triangle set up to its rows: the vertices' differences (subpixels),
// the reference pixel's centre from vertex 0 (u units), the determinant, and the pixels'
// bounding box: its corner from the reference pixel, its sides, the first pixel from its left.
struct PlaneGeom {
  int64_t dx1, dy1, dx2, dy2, dcx, dcy;
  int S;
  int64_t det, bx, by, across, down, dx0;
};

// The plane (setup's setPlane, its 64-bit path), and its values at the corners of the pixels'
// bounding box within int32_t (then at every pixel: the plane is affine), into o's a0, didx
// and didy; false where it does not fit.
bool planeScalar(const Codes& a, const PlaneGeom& g, RowSpans& o) {
  for (size_t k = 0; k < 4; ++k) {
    int64_t sx = 0, sy = 0, num = 0;
    const std::array<int64_t, 3> ak = {a[0][k], a[1][k], a[2][k]};
    if (!planeNumerators64(ak, g.dx1, g.dy1, g.dx2, g.dy2, g.dcx, g.dcy, g.S, sx, sy, num)) return false;
    // A constant attribute (flat's colour) has the numerators 0: no division (what it would give).
    const bool constant = ak[0] == ak[1] && ak[0] == ak[2];
    const int64_t didx = constant ? 0 : roundDivPlus(0, sx, g.det), didy = constant ? 0 : roundDivPlus(0, sy, g.det);
    const int64_t iref = constant ? ak[0] : roundDivPlus(ak[0], num, 2 * g.det);
    int64_t corner = 0;
    if (!fits32(didx) || !fits32(didy) || !planeAt(iref, didx, didy, g.bx, g.by, corner)) return false;
    // |didx|, |didy| < 2^31 and the box's sides below 2^15: exact in int64_t from its corner.
    const int64_t across = didx * g.across, down = didy * g.down;
    if (!fits32(corner) || !fits32(corner + across) || !fits32(corner + down) || !fits32(corner + across + down))
      return false;
    o.a0[k] = corner + didx * g.dx0;
    o.didx[k] = didx;
    o.didy[k] = didy;
  }
  return true;
}

#ifdef SHD_X86_KERNELS
namespace planeavx2 {

// round-half-even(base + n / d) per lane, d > 0, from doubles that hold integers exactly: |n|
// and d at most 2^51, |base| below 2^51. The correctly rounded quotient's floor is the exact
// quotient's, m: it lies in [m, m + 1] (rounding is monotone and m, m + 1 are doubles), and it
// reaches m + 1 only if m + 1 - n / d >= 1 / d is below half a unit in the last place of m + 1,
// which needs (|m| + 1) d > 2^53, where here (|m| + 1) d <= |n| + d <= 2^52. So the remainder
// n - m d is exact (|m d| <= 2^52) and in [0, d). Then roundHalfEvenFrom's rule: up when it is
// above half of d, or half with the floor (base + m) odd.
SHD_AVX2 inline __m256d roundDivPlus(__m256d base, __m256d n, __m256d d) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
  const __m256d m = _mm256_floor_pd(_mm256_div_pd(n, d));
  const __m256d r = _mm256_sub_pd(n, _mm256_mul_pd(m, d));
  const __m256d q = _mm256_add_pd(m, base);
  const __m256d rest = _mm256_sub_pd(d, r);
  const __m256d h = _mm256_floor_pd(_mm256_mul_pd(q, half));
  const __m256d odd = _mm256_cmp_pd(_mm256_sub_pd(q, _mm256_add_pd(h, h)), zero, _CMP_NEQ_OQ);
  const __m256d up = _mm256_or_pd(_mm256_cmp_pd(r, rest, _CMP_GT_OQ),
                                  _mm256_and_pd(_mm256_cmp_pd(r, rest, _CMP_EQ_OQ), odd));
  return _mm256_add_pd(q, _mm256_and_pd(up, one));
}

// The vertices' attribute codes as snapSmall snaps them, a vertex's four in the lanes, into f;
// false when one is beyond setup's bound |a 2^frac| <= lim (or NaN), as the scalar check.
SHD_AVX2 bool snapCodes(const std::array<RowSpans::Vertex, 3>& v, const RowSpansConfig& c, CodesF& f) {
  const __m256d scale = _mm256_loadu_pd(c.scale.data()), lim = _mm256_set1_pd(c.lim);
  const __m256d magic = _mm256_set1_pd(6755399441055744.0), sign = _mm256_set1_pd(-0.0);  // 1.5 2^52
  __m256d ok = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  for (size_t j = 0; j < 3; ++j) {
    const __m256d x = _mm256_mul_pd(_mm256_loadu_pd(v[j].attr.data()), scale);
    ok = _mm256_and_pd(ok, _mm256_cmp_pd(_mm256_andnot_pd(sign, x), lim, _CMP_LE_OQ));
    _mm256_storeu_pd(f[j].data(), _mm256_sub_pd(_mm256_add_pd(x, magic), magic));
  }
  return _mm256_movemask_pd(ok) == 0xF;
}

SHD_AVX2 inline __m256d cv(int64_t v) { return _mm256_set1_pd(static_cast<double>(v)); }

// All four lanes within [lo, hi].
SHD_AVX2 inline bool within(__m256d v, __m256d lo, __m256d hi) {
  const __m256d in = _mm256_and_pd(_mm256_cmp_pd(v, lo, _CMP_GE_OQ), _mm256_cmp_pd(v, hi, _CMP_LE_OQ));
  return _mm256_movemask_pd(in) == 0xF;
}

// planeScalar for the 4 attributes at once, one per lane of doubles; false (o untouched) unless
// every quantity stays where doubles hold it exactly and the plane fits, planeScalar then
// deciding. Where it returns true, o's a0, didx and didy are planeScalar's: the same integers.
//   - The codes |a| < 2^31 (RowSpansConfig::lim), so |a1 - a0| < 2^32; the coordinate
//     differences are checked below 2^20, so the four products are below 2^52 and nx, ny exact.
//   - sx = nx 2^S and sy (exact: a power of two), each product of num checked below 2^50 (fl of
//     a product below 2^50 means the product is, and then fl is exact), and det below 2^50:
//     the divisions' operands at most 2^51 (roundDivPlus above).
//   - didx, didy checked within int32_t, as the scalar code does; then the corner values
//     (|iref| <= 2^50 + 2^31, the box's sides below 2^15) are below 2^51, exact, and checked
//     within int32_t, and so is a0, a value at a covered pixel.
SHD_AVX2 bool plane(const CodesF& a, const PlaneGeom& g, RowSpans& o) {
  constexpr int64_t kCoord = int64_t{1} << 20;
  if (std::max({std::abs(g.dx1), std::abs(g.dy1), std::abs(g.dx2), std::abs(g.dy2)}) >= kCoord) return false;
  constexpr double k50 = 1125899906842624.0;  // 2^50
  if (static_cast<double>(g.det) >= k50) return false;
  const __m256d a0 = _mm256_loadu_pd(a[0].data());
  const __m256d da1 = _mm256_sub_pd(_mm256_loadu_pd(a[1].data()), a0), da2 = _mm256_sub_pd(_mm256_loadu_pd(a[2].data()), a0);
  const __m256d nx = _mm256_sub_pd(_mm256_mul_pd(da1, cv(g.dy2)), _mm256_mul_pd(da2, cv(g.dy1)));
  const __m256d ny = _mm256_sub_pd(_mm256_mul_pd(cv(g.dx1), da2), _mm256_mul_pd(cv(g.dx2), da1));
  const __m256d sign = _mm256_set1_pd(-0.0);
  const __m256d bound = _mm256_set1_pd(k50);
  const __m256d px = _mm256_mul_pd(_mm256_andnot_pd(sign, nx), cv(std::abs(g.dcx)));
  const __m256d py = _mm256_mul_pd(_mm256_andnot_pd(sign, ny), cv(std::abs(g.dcy)));
  const __m256d scale = cv(int64_t{1} << g.S);
  const __m256d sx = _mm256_mul_pd(nx, scale), sy = _mm256_mul_pd(ny, scale);
  const __m256d neg = _mm256_sub_pd(_mm256_setzero_pd(), bound);
  if (!within(px, neg, bound) || !within(py, neg, bound) || !within(sx, neg, bound) || !within(sy, neg, bound))
    return false;
  const __m256d num = _mm256_add_pd(_mm256_mul_pd(nx, cv(g.dcx)), _mm256_mul_pd(ny, cv(g.dcy)));
  const __m256d zero = _mm256_setzero_pd(), d = cv(g.det);
  const __m256d didx = roundDivPlus(zero, sx, d), didy = roundDivPlus(zero, sy, d);
  const __m256d iref = roundDivPlus(a0, num, _mm256_add_pd(d, d));
  const __m256d lo32 = _mm256_set1_pd(-2147483648.0), hi32 = _mm256_set1_pd(2147483647.0);
  if (!within(didx, lo32, hi32) || !within(didy, lo32, hi32)) return false;
  const __m256d corner = _mm256_add_pd(_mm256_add_pd(iref, _mm256_mul_pd(didx, cv(g.bx))), _mm256_mul_pd(didy, cv(g.by)));
  const __m256d right = _mm256_add_pd(corner, _mm256_mul_pd(didx, cv(g.across)));
  const __m256d below = _mm256_mul_pd(didy, cv(g.down));
  if (!within(corner, lo32, hi32) || !within(right, lo32, hi32) || !within(_mm256_add_pd(corner, below), lo32, hi32) ||
      !within(_mm256_add_pd(right, below), lo32, hi32))
    return false;
  const __m256d first = _mm256_add_pd(corner, _mm256_mul_pd(didx, cv(g.dx0)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(o.a0.data()), _mm256_cvtepi32_epi64(_mm256_cvtpd_epi32(first)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(o.didx.data()), _mm256_cvtepi32_epi64(_mm256_cvtpd_epi32(didx)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(o.didy.data()), _mm256_cvtepi32_epi64(_mm256_cvtpd_epi32(didy)));
  return true;
}

}  // namespace planeavx2
#endif

}  // namespace

RowSpansSetup setupRowSpans(const std::array<RowSpans::Vertex, 3>& v, const RowSpansConfig& c, RowSpans& o) {
  const int S = c.S;
  // Snapped as setup snaps them (snapVertices); what it refuses, setupTriangle refuses, naming it.
  // Within these bounds |x 2^S| < 2^29 and |a 2^frac| < 2^31: snapSmall's range. The checks
  // are summed into one test, the rare refusal being the one branch.
  std::array<int64_t, 3> X, Y;
  Codes a;   // the attribute codes: of the scalar plane
  CodesF af;  // of the AVX2 plane (vector)
#ifdef SHD_X86_KERNELS
  const bool vector = c.vector;
#else
  const bool vector = false;
#endif
  bool ok = true;
  const double pixel_scale = static_cast<double>(int64_t{1} << S);
  for (size_t i = 0; i < 3; ++i) {
    ok &= std::fabs(v[i].x) <= c.guard;
    ok &= std::fabs(v[i].y) <= c.guard;
  }
#ifdef SHD_X86_KERNELS
  if (vector) ok &= planeavx2::snapCodes(v, c, af);
#endif
  if (!vector)
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 4; ++k) ok &= std::fabs(v[i].attr[k] * c.scale[k]) <= c.lim;
  if (!ok) return RowSpansSetup::General;
  for (size_t i = 0; i < 3; ++i) {
    X[i] = snapSmall(v[i].x * pixel_scale);
    Y[i] = snapSmall(v[i].y * pixel_scale);
    if (!vector)
      for (size_t k = 0; k < 4; ++k) a[i][k] = snapSmall(v[i].attr[k] * c.scale[k]);
  }
  int64_t det = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  if (det == 0) return RowSpansSetup::Dropped;  // zero area
  if (det < 0) {
    std::swap(X[1], X[2]);
    std::swap(Y[1], Y[2]);
    if (vector) std::swap(af[1], af[2]);
    else std::swap(a[1], a[2]);
    det = -det;
  }
  // The edge functions (setup's screenGeom), u = 2^-(S+1) px.
  const std::array<int64_t, 3> xu = {2 * X[0], 2 * X[1], 2 * X[2]}, yu = {2 * Y[0], 2 * Y[1], 2 * Y[2]};
  const int64_t half = int64_t{1} << S, step = int64_t{1} << (S + 1);
  std::array<int64_t, 3> A, B, C;
  for (size_t s = 0; s < 3; ++s) {
    const size_t q = (s + 1) % 3;
    const int64_t dx = xu[q] - xu[s], dy = yu[q] - yu[s];
    A[s] = -dy * step;
    B[s] = dx * step;
    C[s] = dx * (half - yu[s]) - dy * (half - xu[s]);
    if (!(A[s] > 0 || (A[s] == 0 && B[s] > 0))) C[s] -= 1;  // not top-left: the bias
  }
  // Rows with a centre in the vertical extent, below a horizontal top edge and above a
  // horizontal bottom one, in the viewport (setup's buildLaneTri).
  auto [r0, r1] = centreRows(std::min({yu[0], yu[1], yu[2]}), std::max({yu[0], yu[1], yu[2]}), S);
  for (size_t s = 0; s < 3; ++s) {
    if (A[s] != 0) continue;
    if (B[s] > 0) r0 = std::max(r0, ceilDiv(-static_cast<i128>(C[s]), B[s]));
    else r1 = std::min(r1, floorDiv(C[s], -B[s]));
  }
  r0 = std::max<int64_t>(r0, 0);
  r1 = std::min<int64_t>(r1, c.H - 1);
  const auto [c0, c1] = centreRows(std::min({xu[0], xu[1], xu[2]}), std::max({xu[0], xu[1], xu[2]}), S);
  if (r0 > r1 || c1 < 0 || c0 > c.W - 1) return RowSpansSetup::Dropped;  // no centre of its box in the viewport
  if (r1 - r0 >= RowSpans::kMaxRows) return RowSpansSetup::General;
  // Each edge's DDA from row r0; a horizontal edge bounds nothing in these rows (a left bound
  // far to the left, never stepped).
  std::array<RowEdge, 3> e;
  for (size_t s = 0; s < 3; ++s) {
    if (A[s] == 0) {
      e[s] = {-(int64_t{1} << 40), 0, 1, 0, 0, false};
      continue;
    }
    const int64_t D = A[s] < 0 ? -A[s] : A[s];
    const int64_t N = -(B[s] * r0 + C[s]);
    const int64_t q = ceilDiv64(N, D);
    const int64_t k = static_cast<int64_t>(floorDiv(-B[s], D));
    // Setup checks this register bound on the edges the unit steps (a subset of these): beyond
    // it setupTriangle decides.
    if (k >= c.k_lim || k < -c.k_lim) return RowSpansSetup::General;
    e[s] = {q, q * D - N, D, k, -B[s] - k * D, A[s] < 0};
  }
  // The rows' spans, with what the unit's cycles and the plane's check below need: the pixels'
  // bounding columns, the fragments and the lane groups (span_detail::firstGroup: a multiple of
  // LanesPerTri, a power of two, below a span's first column, which is >= 0 here).
  int64_t first = -1, last = -1, xmin = c.W, xmax = -1, fragments = 0, groups = 0;
  const int64_t align = c.align_lanes ? ~((int64_t{1} << c.lane_shift) - 1) : -1;
  for (int64_t i = 0; i <= r1 - r0; ++i) {
    int64_t lo = 0, hi = c.W - 1;
    for (RowEdge& g : e) {
      lo = g.right ? lo : std::max(lo, g.q);
      hi = g.right ? std::min(hi, -g.q) : hi;
      const int64_t r = g.r - g.m;
      const int64_t borrow = r < 0 ? 1 : 0;  // without a branch, as the walker's stepEdge
      g.r = r + (g.D & -borrow);
      g.q += g.k + borrow;
    }
    const bool any = lo <= hi;
    o.span[static_cast<size_t>(i)] = {static_cast<int16_t>(any ? lo : 1), static_cast<int16_t>(any ? hi : 0)};
    if (any) {
      first = first < 0 ? i : first;
      last = i;
      xmin = std::min(xmin, lo);
      xmax = std::max(xmax, hi);
      fragments += hi - lo + 1;
      groups += ((hi - (lo & align)) >> c.lane_shift) + 1;
    }
  }
  if (first < 0) return RowSpansSetup::Dropped;  // no pixel centre inside it in the viewport
  if (first > 0) std::copy(o.span.begin() + first, o.span.begin() + last + 1, o.span.begin());
  o.y0 = static_cast<int32_t>(r0 + first);
  o.rows = static_cast<int32_t>(last - first + 1);
  o.x0 = o.span[0][0];
  o.fragments = static_cast<uint32_t>(fragments);
  o.groups = static_cast<uint32_t>(groups);
  // The plane, from the reference pixel (setup's setPlane).
  const int64_t xref = std::clamp<int64_t>(std::min({X[0], X[1], X[2]}) >> S, 0, c.W - 1);
  const int64_t yref = std::clamp<int64_t>(std::min({Y[0], Y[1], Y[2]}) >> S, 0, c.H - 1);
  const PlaneGeom g{X[1] - X[0], Y[1] - Y[0], X[2] - X[0], Y[2] - Y[0], ((2 * xref + 1) << S) - xu[0],
                    ((2 * yref + 1) << S) - yu[0], S, det, xmin - xref, o.y0 - yref, xmax - xmin, o.rows - 1,
                    o.x0 - xmin};
#ifdef SHD_X86_KERNELS
  if (vector) {
    if (planeavx2::plane(af, g, o)) return RowSpansSetup::Drawn;
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 4; ++k) a[i][k] = static_cast<int64_t>(af[i][k]);  // exact: below 2^31
  }
#endif
  if (!planeScalar(a, g, o)) return RowSpansSetup::General;
  return RowSpansSetup::Drawn;
}

SpanWalk countRowSpans(const SpanParams& p, const RowSpans& s, SpanStream* stream) {
  SpanWalk w;
  w.fragments = s.fragments;
  w.span_cycles = s.groups;
  w.row_cycles = static_cast<uint64_t>(s.rows);
  // The paper's unit: the IDLE cycle accepting the descriptor, its ROW and SPAN cycles.
  if (!p.RowAhead) {
    w.cycles = 1 + w.row_cycles + w.span_cycles;
    return w;
  }
  // The full-rate unit: the stream fed row by row.
  SpanStream alone;
  SpanStream& timing = stream != nullptr ? *stream : alone;
  const uint64_t end0 = timing.end();
  const int64_t L = p.LanesPerTri;
  for (int32_t i = 0; i < s.rows; ++i) {
    const int64_t lo = s.span[static_cast<size_t>(i)][0], hi = s.span[static_cast<size_t>(i)][1];
    timing.row(lo <= hi ? static_cast<uint64_t>((hi - span_detail::firstGroup(p, lo)) / L + 1) : 0);
  }
  w.cycles = timing.end() - end0;
  return w;
}

}  // namespace shd
