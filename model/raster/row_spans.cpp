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

// What the row loop gathers besides the spans: the first and the last row with a pixel, the
// pixels' bounding columns, the fragments and the lane groups (span_detail::firstGroup: a
// multiple of LanesPerTri, a power of two, below a span's first column, which is >= 0 here).
struct RowTally {
  RowSpans* o;
  int64_t align;
  int lane_shift;
  int64_t first = -1, last = -1, xmin, xmax = -1, fragments = 0, groups = 0;
  RowTally(const RowSpansConfig& c, RowSpans& out)
      : o(&out), align(c.align_lanes ? ~((int64_t{1} << c.lane_shift) - 1) : -1), lane_shift(c.lane_shift), xmin(c.W) {}
  // Row i's pixels [lo, hi] (none where lo > hi), lo >= 0 and hi below the viewport's width.
  [[gnu::always_inline]] void add(int64_t i, int64_t lo, int64_t hi) {
    const bool any = lo <= hi;
    o->span[static_cast<size_t>(i)] = {static_cast<int16_t>(any ? lo : 1), static_cast<int16_t>(any ? hi : 0)};
    if (any) {
      first = first < 0 ? i : first;
      last = i;
      xmin = std::min(xmin, lo);
      xmax = std::max(xmax, hi);
      fragments += hi - lo + 1;
      groups += ((hi - (lo & align)) >> lane_shift) + 1;
    }
  }
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
    const std::array<int64_t, 3> ak = {a[0][k], a[1][k], a[2][k]};
    // A constant attribute (flat's colour): its numerators are 0, and so are its gradients; the
    // plane is its code everywhere (what the steps below give).
    if (ak[0] == ak[1] && ak[0] == ak[2]) {
      if (!fits32(ak[0])) return false;
      o.a0[k] = ak[0];
      o.didx[k] = o.didy[k] = 0;
      continue;
    }
    int64_t sx = 0, sy = 0, num = 0;
    if (!planeNumerators64(ak, g.dx1, g.dy1, g.dx2, g.dy2, g.dcx, g.dcy, g.S, sx, sy, num)) return false;
    const int64_t didx = roundDivPlus(0, sx, g.det), didy = roundDivPlus(0, sy, g.det);
    const int64_t iref = roundDivPlus(ak[0], num, 2 * g.det);
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
// and d at most 2^51, |base| below 2^51; inv = 1 / d, correctly rounded (or a power of two
// times it: 1 / (2 d) = inv / 2 exactly). No division: t = n inv, two roundings, lies within
// |n / d| 2^-52 (1 + 2^-52) < 1 / d of n / d (|n| < 2^52). A quotient that is not an integer
// lies at least 1 / d from the integers, so m = floor(t) is its floor and the remainder
// n - m d is in (0, d); an integer quotient j gives m = j (remainder 0) or m = j - 1
// (remainder d). The remainder is exact (|m d| <= |n| + d <= 2^52). Then roundHalfEvenFrom's
// rule: up when the remainder is above half of d (j - 1 with remainder d: up to j), or half
// with the floor (base + m) odd.
SHD_AVX2 inline __m256d roundDivPlus(__m256d base, __m256d n, __m256d d, __m256d inv) {
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0), half = _mm256_set1_pd(0.5);
  const __m256d m = _mm256_floor_pd(_mm256_mul_pd(n, inv));
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
//     a product below 2^50 means the product is, and then fl is exact), and det = dx1 dy2 -
//     dx2 dy1 below 2^41 by the coordinates' bound: the divisions' operands at most 2^51
//     (roundDivPlus above).
//   - didx, didy checked within int32_t, as the scalar code does; then the corner values
//     (|iref| <= 2^50 + 2^31, the box's sides below 2^15) are below 2^51, exact, and checked
//     within int32_t, and so is a0, a value at a covered pixel.
SHD_AVX2 bool plane(const CodesF& a, const PlaneGeom& g, RowSpans& o) {
  constexpr int64_t kCoord = int64_t{1} << 20;
  if (std::max({std::abs(g.dx1), std::abs(g.dy1), std::abs(g.dx2), std::abs(g.dy2)}) >= kCoord) return false;
  constexpr double k50 = 1125899906842624.0;  // 2^50
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
  const __m256d inv = _mm256_set1_pd(1.0 / static_cast<double>(g.det));
  const __m256d didx = roundDivPlus(zero, sx, d, inv), didy = roundDivPlus(zero, sy, d, inv);
  const __m256d iref = roundDivPlus(a0, num, _mm256_add_pd(d, d), _mm256_mul_pd(inv, _mm256_set1_pd(0.5)));
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

namespace rowsx86 {

// The sum, the least and the greatest of 8 32-bit lanes.
SHD_AVX2 inline __m256i swapHalves(__m256i v) { return _mm256_permute2x128_si256(v, v, 1); }
SHD_AVX2 inline int64_t lane0(__m256i v) { return _mm_cvtsi128_si32(_mm256_castsi256_si128(v)); }
SHD_AVX2 inline int64_t sum8(__m256i v) {
  v = _mm256_add_epi32(v, swapHalves(v));
  v = _mm256_add_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  return lane0(_mm256_add_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1))));
}
SHD_AVX2 inline int64_t min8(__m256i v) {
  v = _mm256_min_epi32(v, swapHalves(v));
  v = _mm256_min_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  return lane0(_mm256_min_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1))));
}
SHD_AVX2 inline int64_t max8(__m256i v) {
  v = _mm256_max_epi32(v, swapHalves(v));
  v = _mm256_max_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(1, 0, 3, 2)));
  return lane0(_mm256_max_epi32(v, _mm256_shuffle_epi32(v, _MM_SHUFFLE(2, 3, 0, 1))));
}

// Pass 2 of the row loops below: RowTally::add of 8 rows at a time, in 32-bit lanes, from the
// rows' [lo, hi] (clamped as walk's pass 1 clamps them).
struct Tally8 {
  RowTally& t;
  __m256i w, none, one, align, rows8, fragments, groups, xmin, xmax;
  __m128i shift;
  int64_t first = -1, last = -1;
  SHD_AVX2 Tally8(int64_t W, RowTally& tally)
      : t(tally),
        w(_mm256_set1_epi32(static_cast<int32_t>(W))),
        none(_mm256_set1_epi32(-1)),
        one(_mm256_set1_epi32(1)),
        align(_mm256_set1_epi32(static_cast<int32_t>(tally.align))),
        rows8(_mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)),
        fragments(_mm256_setzero_si256()),
        groups(_mm256_setzero_si256()),
        xmin(w),
        xmax(none),
        shift(_mm_cvtsi32_si128(tally.lane_shift)) {}
  // Rows g .. g + 7 (those below n).
  SHD_AVX2 inline void add(int64_t g, int64_t n, __m256i lo, __m256i hi) {
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int32_t>(n - g)), rows8);
    const __m256i any = _mm256_andnot_si256(_mm256_cmpgt_epi32(lo, hi), valid);
    fragments = _mm256_add_epi32(fragments, _mm256_and_si256(any, _mm256_add_epi32(_mm256_sub_epi32(hi, lo), one)));
    const __m256i span_groups =
        _mm256_add_epi32(_mm256_sra_epi32(_mm256_sub_epi32(hi, _mm256_and_si256(lo, align)), shift), one);
    groups = _mm256_add_epi32(groups, _mm256_and_si256(any, span_groups));
    xmin = _mm256_min_epi32(xmin, _mm256_blendv_epi8(w, lo, any));
    xmax = _mm256_max_epi32(xmax, _mm256_blendv_epi8(none, hi, any));
    // span: (lo, hi) as int16_t, or (1, 0) without a pixel.
    const __m256i span = _mm256_or_si256(_mm256_and_si256(lo, _mm256_set1_epi32(0xFFFF)), _mm256_slli_epi32(hi, 16));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(t.o->span.data() + g), _mm256_blendv_epi8(one, span, any));
    const unsigned mask = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(any)));
    if (mask != 0) {
      first = first < 0 ? g + __builtin_ctz(mask) : first;
      last = g + 31 - __builtin_clz(mask);
    }
  }
  SHD_AVX2 void finish() {
    t.first = first;
    t.last = last;
    t.fragments = sum8(fragments);
    t.groups = sum8(groups);
    t.xmin = min8(xmin);
    t.xmax = max8(xmax);
  }
};

// The scalar row loop in AVX2 lanes, in two passes.
//   1. The edges: the left ones (x >= q) in lanes 0 and 1, the right ones (x <= -q) in lanes 2
//      and 3, a side's single edge in both of its lanes (the same values, so the same bound).
//      Each row the lanes' bounds pair up into max(q0, q1) and max(q2, q3), and every lane
//      steps by the scalar DDA's integer operations. A triangle has an edge of each side: its
//      edges' dy sum to 0 and at most one is 0 (a horizontal edge is a left bound out of
//      reach), so the non-horizontal ones include a downward and an upward one; false (nothing
//      done) otherwise, the scalar loop then deciding. A row's [lo, hi] is clamped to [0, W]
//      and [-1, W - 1] (the scalar loop's [0, ...] and [..., W - 1] and, beyond them, a row as
//      empty: lo > W - 1 >= hi or hi < 0 <= lo), so it fits 32 bits: stored as (lo, -hi).
//   2. RowTally::add of 8 rows at a time, in 32-bit lanes.
SHD_AVX2 bool walk(const std::array<RowEdge, 3>& e, int64_t n, int64_t W, RowTally& t) {
  static_assert(RowSpans::kMaxRows % 8 == 0, "pass 2 writes the spans of whole groups of 8 rows");
  // The edges of lanes 0 .. 3 by the triangle's right edges (bit s: edge s is one).
  static constexpr std::array<std::array<uint8_t, 4>, 8> kLanes = {
      {{0, 0, 0, 0}, {1, 2, 0, 0}, {0, 2, 1, 1}, {2, 2, 0, 1}, {0, 1, 2, 2}, {1, 1, 0, 2}, {0, 0, 1, 2}, {0, 0, 0, 0}}};
  const unsigned sides = (e[0].right ? 1u : 0u) | (e[1].right ? 2u : 0u) | (e[2].right ? 4u : 0u);
  if (sides == 0 || sides == 7) return false;
  const std::array<uint8_t, 4>& lane = kLanes[sides];
  const RowEdge &l0 = e[lane[0]], &l1 = e[lane[1]], &r0 = e[lane[2]], &r1 = e[lane[3]];
  __m256i q = _mm256_set_epi64x(r1.q, r0.q, l1.q, l0.q), r = _mm256_set_epi64x(r1.r, r0.r, l1.r, l0.r);
  const __m256i D = _mm256_set_epi64x(r1.D, r0.D, l1.D, l0.D), k = _mm256_set_epi64x(r1.k, r0.k, l1.k, l0.k);
  const __m256i m = _mm256_set_epi64x(r1.m, r0.m, l1.m, l0.m);
  const __m256i zero = _mm256_setzero_si256();
  // lo within [0, W]; -hi within [1 - W, 1].
  const __m256i low = _mm256_set_epi64x(1 - W, 1 - W, 0, 0), high = _mm256_set_epi64x(1, 1, W, W);
  const __m256i pick = _mm256_setr_epi32(0, 4, 0, 4, 0, 4, 0, 4);  // lanes 0 and 2's low halves
  alignas(32) std::array<int32_t, 2 * RowSpans::kMaxRows + 16> bound;  // (lo, -hi) of row i at 2 i
  for (int64_t i = 0; i < n; ++i) {
    const __m256i swapped = _mm256_shuffle_epi32(q, _MM_SHUFFLE(1, 0, 3, 2));  // q1 q0 q3 q2
    __m256i most = _mm256_blendv_epi8(q, swapped, _mm256_cmpgt_epi64(swapped, q));
    most = _mm256_blendv_epi8(most, low, _mm256_cmpgt_epi64(low, most));
    most = _mm256_blendv_epi8(most, high, _mm256_cmpgt_epi64(most, high));
    _mm_storel_epi64(reinterpret_cast<__m128i*>(bound.data() + 2 * i),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(most, pick)));
    r = _mm256_sub_epi64(r, m);
    const __m256i borrow = _mm256_cmpgt_epi64(zero, r);  // -1 where r < 0
    r = _mm256_add_epi64(r, _mm256_and_si256(D, borrow));
    q = _mm256_sub_epi64(_mm256_add_epi64(q, k), borrow);
  }
  // The rows after the last of its group of 8: defined, and not rows (the valid lanes below).
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(bound.data() + 2 * n), zero);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(bound.data() + 2 * n + 8), zero);

  Tally8 tally(W, t);
  for (int64_t g = 0; g < n; g += 8) {
    const __m256 a = _mm256_load_ps(reinterpret_cast<const float*>(bound.data() + 2 * g));     // rows g .. g + 3
    const __m256 b = _mm256_load_ps(reinterpret_cast<const float*>(bound.data() + 2 * g + 8));  // g + 4 .. g + 7
    // Rows 0 1 4 5 | 2 3 6 7 of the group, then in order.
    const __m256i lo = _mm256_permute4x64_epi64(_mm256_castps_si256(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(2, 0, 2, 0))),
                                                _MM_SHUFFLE(3, 1, 2, 0));
    const __m256i hi = _mm256_sub_epi32(
        zero, _mm256_permute4x64_epi64(_mm256_castps_si256(_mm256_shuffle_ps(a, b, _MM_SHUFFLE(3, 1, 3, 1))),
                                       _MM_SHUFFLE(3, 1, 2, 0)));
    tally.add(g, n, lo, hi);
  }
  tally.finish();
  return true;
}

// GCC 12's AVX-512 headers pass an undefined vector as the unused merge source of unmasked
// intrinsics, which -Wmaybe-uninitialized reports (GCC bug 105593, as in render/fixed_simd.cpp).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#ifndef __clang__
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC's own: clang has no such group
#endif
// walk in AVX-512 (RowSpansConfig::avx512), its pass 1 in closed form, 8 rows at once in 64-bit
// lanes and an edge a vector: the DDA's bound after i steps is q0 + i k + ceil((i m - r0) / D)
// (q_i = ceil(N_i / D) with N_i = q0 D - r0 + i (k D + m)). Its quotient in doubles, without a
// division per group: x = i m - r0 and D are integers below 2^47 (i < 64, 0 <= m, r0 < D, and
// D = |A| < 2^40 by RowSpansConfig::applies), exact, and |x / D| < 64. The product t = x (1 / D),
// two roundings, lies within 2^-46 of x / D, so c = ceil(t) is the exact ceiling, or one above
// it where x / D is an integer j and t rounded above j. (It is never below: a quotient that is
// not an integer lies at least 1 / D > 2^-40 from the integers, farther than t moves.) Then
// e = c D - x is exact (integers below 2^53), and e >= D where c is one too many. i k is one signed
// 32 x 32 product (|k| < 2^30: CoordBits <= 31). Each side's bound is the greatest of its
// edges' (a side without an edge: none, as the scalar loop's), clamped as walk's. Takes every
// triangle.
SHD_AVX512 void walk512(const std::array<RowEdge, 3>& e, int64_t n, int64_t W, RowTally& t) {
  const __m512i iota = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  const __m512d iota_d = _mm512_cvtepi64_pd(iota);
  __m512i base[3], step[3];    // q0 + i k for the group's rows, and 8 k
  __m512d num[3], num_step[3];  // i m - r0, and 8 m
  __m512d den[3], rcp[3];       // D and 1 / D
  for (size_t s = 0; s < 3; ++s) {
    const RowEdge& g = e[s];
    base[s] = _mm512_add_epi64(_mm512_set1_epi64(g.q), _mm512_mul_epi32(iota, _mm512_set1_epi64(g.k)));
    step[s] = _mm512_set1_epi64(8 * g.k);
    const __m512d m = _mm512_set1_pd(static_cast<double>(g.m));
    num[s] = _mm512_fmsub_pd(iota_d, m, _mm512_set1_pd(static_cast<double>(g.r)));
    num_step[s] = _mm512_mul_pd(m, _mm512_set1_pd(8.0));
    den[s] = _mm512_set1_pd(static_cast<double>(g.D));
    rcp[s] = _mm512_set1_pd(1.0 / static_cast<double>(g.D));
  }
  const __m512d one_d = _mm512_set1_pd(1.0);
  const __m512i none = _mm512_set1_epi64(INT64_MIN);
  const __m512i lo_min = _mm512_setzero_si512(), lo_max = _mm512_set1_epi64(W);
  const __m512i nhi_min = _mm512_set1_epi64(1 - W), nhi_max = _mm512_set1_epi64(1);
  Tally8 tally(W, t);
  for (int64_t g = 0; g < n; g += 8) {
    __m512i lo = none, nhi = none;  // the greatest bound of each side: x >= lo, x <= -nhi
    for (size_t s = 0; s < 3; ++s) {
      __m512d c = _mm512_roundscale_pd(_mm512_mul_pd(num[s], rcp[s]), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
      const __m512d err = _mm512_fmsub_pd(c, den[s], num[s]);  // c D - x, exact
      c = _mm512_mask_sub_pd(c, _mm512_cmp_pd_mask(err, den[s], _CMP_GE_OQ), c, one_d);
      const __m512i q = _mm512_add_epi64(base[s], _mm512_cvtpd_epi64(c));
      if (e[s].right) nhi = _mm512_max_epi64(nhi, q);
      else lo = _mm512_max_epi64(lo, q);
      base[s] = _mm512_add_epi64(base[s], step[s]);
      num[s] = _mm512_add_pd(num[s], num_step[s]);
    }
    lo = _mm512_min_epi64(_mm512_max_epi64(lo, lo_min), lo_max);
    nhi = _mm512_min_epi64(_mm512_max_epi64(nhi, nhi_min), nhi_max);
    tally.add(g, n, _mm512_cvtepi64_epi32(lo), _mm256_sub_epi32(_mm256_setzero_si256(), _mm512_cvtepi64_epi32(nhi)));
  }
  tally.finish();
}
#pragma GCC diagnostic pop

}  // namespace rowsx86
#endif

// setupRowSpans from its edges on: its vertices snapped and ordered counter-clockwise, and its
// edges' DDAs from row r0. Then the rows' spans (spans) and the plane (planeOf), which
// setupRowSpans and setupRowSpansBlock share.
struct Front {
  std::array<int64_t, 3> X, Y;
  int64_t det, r0, r1;
  std::array<RowEdge, 3> e;
};
// The rows' spans into o, and the plane's geometry g: Dropped (no pixel centre inside it in the
// viewport) or Drawn (the plane to follow: planeOf).
RowSpansSetup spans(const Front& f, const RowSpansConfig& c, RowSpans& o, PlaneGeom& g) {
  const std::array<int64_t, 3>& X = f.X;
  const std::array<int64_t, 3>& Y = f.Y;
  const int S = c.S;
  const int64_t r0 = f.r0, r1 = f.r1, det = f.det;
  const std::array<RowEdge, 3>& e = f.e;
#ifdef SHD_X86_KERNELS
  const bool vector = c.vector;
#else
  const bool vector = false;
#endif
  // The rows' spans, with what the unit's cycles and the plane's check below need.
  RowTally t(c, o);
  const int64_t n = r1 - r0 + 1;
#ifdef SHD_X86_KERNELS
  if (vector && c.avx512) rowsx86::walk512(e, n, c.W, t);
  else if (!vector || !rowsx86::walk(e, n, c.W, t))
#endif
  {
    std::array<RowEdge, 3> d = e;
    for (int64_t i = 0; i < n; ++i) {
      int64_t lo = 0, hi = c.W - 1;
      for (RowEdge& g : d) {
        lo = g.right ? lo : std::max(lo, g.q);
        hi = g.right ? std::min(hi, -g.q) : hi;
        const int64_t r = g.r - g.m;
        const int64_t borrow = r < 0 ? 1 : 0;  // without a branch, as the walker's stepEdge
        g.r = r + (g.D & -borrow);
        g.q += g.k + borrow;
      }
      t.add(i, lo, hi);
    }
  }
  const int64_t first = t.first, last = t.last, xmin = t.xmin, xmax = t.xmax;
  if (first < 0) return RowSpansSetup::Dropped;  // no pixel centre inside it in the viewport
  if (first > 0) std::copy(o.span.begin() + first, o.span.begin() + last + 1, o.span.begin());
  o.y0 = static_cast<int32_t>(r0 + first);
  o.rows = static_cast<int32_t>(last - first + 1);
  o.x0 = o.span[0][0];
  o.fragments = static_cast<uint32_t>(t.fragments);
  o.groups = static_cast<uint32_t>(t.groups);
  // The plane, from the reference pixel (setup's setPlane).
  const int64_t xref = std::clamp<int64_t>(std::min({X[0], X[1], X[2]}) >> S, 0, c.W - 1);
  const int64_t yref = std::clamp<int64_t>(std::min({Y[0], Y[1], Y[2]}) >> S, 0, c.H - 1);
  g = {X[1] - X[0], Y[1] - Y[0], X[2] - X[0], Y[2] - Y[0], ((2 * xref + 1) << S) - 2 * X[0],
       ((2 * yref + 1) << S) - 2 * Y[0], S, det, xmin - xref, o.y0 - yref, xmax - xmin, o.rows - 1,
       o.x0 - xmin};
  return RowSpansSetup::Drawn;
}

// The plane of g into o (Drawn), or General where it does not fit. a or af: the attribute
// codes, in the vertices' order (af where c.vector).
RowSpansSetup planeOf(const RowSpansConfig& c, Codes& a, const CodesF& af, const PlaneGeom& g, RowSpans& o) {
#ifdef SHD_X86_KERNELS
  if (c.vector) {
    if (planeavx2::plane(af, g, o)) return RowSpansSetup::Drawn;
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 4; ++k) a[i][k] = static_cast<int64_t>(af[i][k]);  // exact: below 2^31
  }
#else
  (void)af;
#endif
  if (!planeScalar(a, g, o)) return RowSpansSetup::General;
  return RowSpansSetup::Drawn;
}

}  // namespace

RowSpansSetup setupRowSpans(const std::array<RowSpans::Vertex, 3>& v, const RowSpansConfig& c, RowSpans& o) {
  const int S = c.S;
  // Snapped as setup snaps them (snapVertices); what it refuses, setupTriangle refuses, naming it.
  // Within these bounds |x 2^S| < 2^29 and |a 2^frac| < 2^31: snapSmall's range. The checks
  // are summed into one test, the rare refusal being the one branch.
  // The front part is built in place: a Front assembled from local arrays was copied with
  // 16-byte loads of what had just been stored 8 bytes at a time, which the processor cannot
  // forward (a store-forwarding stall: a tenth of this function's samples).
  Front f;
  std::array<int64_t, 3>& X = f.X;
  std::array<int64_t, 3>& Y = f.Y;
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
  std::array<RowEdge, 3>& e = f.e;
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
  f.det = det;
  f.r0 = r0;
  f.r1 = r1;
  PlaneGeom g;
  if (spans(f, c, o, g) == RowSpansSetup::Dropped) return RowSpansSetup::Dropped;
  return planeOf(c, a, af, g, o);
}


// ---- setupRowSpans of 8 triangles at once (AVX-512): each lane a triangle up to its edges ----
#ifdef SHD_X86_KERNELS
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#ifndef __clang__
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC's own: clang has no such group
#endif
namespace {
// setupRowSpans's steps before its rows, for triangle lane t of v (t < n; the lanes past n take
// triangle n - 1), in 64-bit lanes: the same integers, from the same operations. Snapping as
// snapSmall: x 2^S + 1.5 2^52 rounds x 2^S to an integer (the power of two is exact), which the
// subtraction leaves exact; within the guard band |x 2^S| < 2^29. The products of coordinates
// (below 2^31) are 64-bit lane products. The DDA's quotients q = ceil(N / D) and k = floor(-B / D)
// are those of the correctly rounded quotients of doubles: N, B and D are integers below 2^51,
// exact, and a quotient that is not an integer lies at least 1 / D from the integers, farther
// than rounding moves a double of magnitude below 2^51 / D (half a unit in its last place, at
// most |N / D| 2^-53 < 1 / D); an integer quotient is exact. Lanes that setupRowSpans would
// settle with a 128-bit division (a horizontal edge) or an N beyond 2^51 go to it whole.
struct Front8 {
  alignas(64) int64_t X[3][8], Y[3][8], det[8], r0[8], r1[8];
  alignas(64) int64_t q[3][8], r[3][8], D[3][8], k[3][8], m[3][8];
  __mmask8 general = 0, dropped = 0, whole = 0, swapped = 0, right[3] = {0, 0, 0};
};
// What a block's lanes found (a bit per lane), and setupRowSpans's order of outcomes from them
// into f's lanes `lanes`: General outside the guard band (not ok), the lane whole where its
// arithmetic would not be exact (inexact: front4's doubles), Dropped at zero area, a horizontal
// edge whole, Dropped outside the viewport, General for too many rows, an N beyond 2^51 whole,
// General for a DDA step beyond the register bound.
struct LaneFindings {
  __mmask8 ok, inexact, flat, horizontal, box_out, tall, wide, steep, swapped;
};
void setOutcomes(Front8& f, __mmask8 lanes, const LaneFindings& l) {
  __mmask8 open = l.ok & lanes;
  __mmask8 general = static_cast<__mmask8>(lanes & ~l.ok);
  __mmask8 whole = open & l.inexact;
  open &= static_cast<__mmask8>(~l.inexact);
  __mmask8 dropped = open & l.flat;
  open &= static_cast<__mmask8>(~l.flat);
  whole |= open & l.horizontal;
  open &= static_cast<__mmask8>(~l.horizontal);
  dropped |= open & l.box_out;
  open &= static_cast<__mmask8>(~l.box_out);
  general |= open & l.tall;
  open &= static_cast<__mmask8>(~l.tall);
  whole |= open & l.wide;
  open &= static_cast<__mmask8>(~l.wide);
  general |= open & l.steep;
  const auto keep = static_cast<__mmask8>(~lanes);
  f.general = static_cast<__mmask8>((f.general & keep) | general);
  f.dropped = static_cast<__mmask8>((f.dropped & keep) | dropped);
  f.whole = static_cast<__mmask8>((f.whole & keep) | whole);
  f.swapped = static_cast<__mmask8>((f.swapped & keep) | (l.swapped & lanes));
}
SHD_AVX512 void front8(const std::array<RowSpans::Vertex, 3>* v, size_t n, const RowSpansConfig& c, Front8& f) {
  static_assert(sizeof(RowSpans::Vertex) == 6 * sizeof(double), "a vertex: x, y and 4 attributes");
  const int S = c.S;
  const __m512i lane =
      _mm512_min_epi64(_mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7), _mm512_set1_epi64(static_cast<int64_t>(n) - 1));
  const __m512i base = _mm512_mul_epu32(lane, _mm512_set1_epi64(18));  // 3 vertices of 6 doubles
  const double* p = &v[0][0].x;
  const __m512d scale = _mm512_set1_pd(static_cast<double>(int64_t{1} << S)), guard = _mm512_set1_pd(c.guard);
  const __m512d magic = _mm512_set1_pd(6755399441055744.0);  // 1.5 2^52
  __m512i X[3], Y[3];
  __mmask8 ok = 0xFF;
  for (int i = 0; i < 3; ++i) {
    const __m512d x = _mm512_i64gather_pd(_mm512_add_epi64(base, _mm512_set1_epi64(6 * i)), p, 8);
    const __m512d y = _mm512_i64gather_pd(_mm512_add_epi64(base, _mm512_set1_epi64(6 * i + 1)), p, 8);
    ok &= _mm512_cmp_pd_mask(_mm512_abs_pd(x), guard, _CMP_LE_OQ) &
          _mm512_cmp_pd_mask(_mm512_abs_pd(y), guard, _CMP_LE_OQ);
    const __m512d xs = _mm512_mask_blend_pd(ok, _mm512_setzero_pd(), _mm512_mul_pd(x, scale));
    const __m512d ys = _mm512_mask_blend_pd(ok, _mm512_setzero_pd(), _mm512_mul_pd(y, scale));
    X[i] = _mm512_cvtpd_epi64(_mm512_sub_pd(_mm512_add_pd(xs, magic), magic));
    Y[i] = _mm512_cvtpd_epi64(_mm512_sub_pd(_mm512_add_pd(ys, magic), magic));
  }
  const __m512i zero = _mm512_setzero_si512();
  __m512i det = _mm512_sub_epi64(_mm512_mullo_epi64(_mm512_sub_epi64(X[1], X[0]), _mm512_sub_epi64(Y[2], Y[0])),
                                 _mm512_mullo_epi64(_mm512_sub_epi64(X[2], X[0]), _mm512_sub_epi64(Y[1], Y[0])));
  const __mmask8 flat = _mm512_cmpeq_epi64_mask(det, zero), neg = _mm512_cmplt_epi64_mask(det, zero);
  {
    const __m512i x1 = X[1], y1 = Y[1];
    X[1] = _mm512_mask_blend_epi64(neg, X[1], X[2]);
    Y[1] = _mm512_mask_blend_epi64(neg, Y[1], Y[2]);
    X[2] = _mm512_mask_blend_epi64(neg, X[2], x1);
    Y[2] = _mm512_mask_blend_epi64(neg, Y[2], y1);
  }
  det = _mm512_abs_epi64(det);
  __m512i xu[3], yu[3];
  for (int i = 0; i < 3; ++i) {
    xu[i] = _mm512_slli_epi64(X[i], 1);
    yu[i] = _mm512_slli_epi64(Y[i], 1);
  }
  const __m512i half = _mm512_set1_epi64(int64_t{1} << S);
  __m512i A[3], B[3], C[3];
  __mmask8 horizontal = 0;
  for (int s = 0; s < 3; ++s) {
    const int q = (s + 1) % 3;
    const __m512i dx = _mm512_sub_epi64(xu[q], xu[s]), dy = _mm512_sub_epi64(yu[q], yu[s]);
    A[s] = _mm512_sub_epi64(zero, _mm512_slli_epi64(dy, static_cast<unsigned>(S + 1)));
    B[s] = _mm512_slli_epi64(dx, static_cast<unsigned>(S + 1));
    C[s] = _mm512_sub_epi64(_mm512_mullo_epi64(dx, _mm512_sub_epi64(half, yu[s])),
                            _mm512_mullo_epi64(dy, _mm512_sub_epi64(half, xu[s])));
    const __mmask8 a0 = _mm512_cmpeq_epi64_mask(A[s], zero);
    const __mmask8 top_left = _mm512_cmpgt_epi64_mask(A[s], zero) | (a0 & _mm512_cmpgt_epi64_mask(B[s], zero));
    C[s] = _mm512_mask_sub_epi64(C[s], static_cast<__mmask8>(~top_left), C[s], _mm512_set1_epi64(1));
    horizontal |= a0;
  }
  // centreRows: -((half - lo) >> (S + 1)) and (hi - half) >> (S + 1), arithmetic shifts.
  auto rowsLo = [&](__m512i lo) SHD_AVX512 {
    return _mm512_sub_epi64(zero, _mm512_srai_epi64(_mm512_sub_epi64(half, lo), static_cast<unsigned>(S + 1)));
  };
  auto rowsHi = [&](__m512i hi) SHD_AVX512 {
    return _mm512_srai_epi64(_mm512_sub_epi64(hi, half), static_cast<unsigned>(S + 1));
  };
  const __m512i r0 = _mm512_max_epi64(rowsLo(_mm512_min_epi64(_mm512_min_epi64(yu[0], yu[1]), yu[2])), zero);
  const __m512i r1 =
      _mm512_min_epi64(rowsHi(_mm512_max_epi64(_mm512_max_epi64(yu[0], yu[1]), yu[2])), _mm512_set1_epi64(c.H - 1));
  const __m512i c0 = rowsLo(_mm512_min_epi64(_mm512_min_epi64(xu[0], xu[1]), xu[2]));
  const __m512i c1 = rowsHi(_mm512_max_epi64(_mm512_max_epi64(xu[0], xu[1]), xu[2]));
  const __mmask8 box_out = _mm512_cmpgt_epi64_mask(r0, r1) | _mm512_cmplt_epi64_mask(c1, zero) |
                           _mm512_cmpgt_epi64_mask(c0, _mm512_set1_epi64(c.W - 1));
  const __mmask8 tall = _mm512_cmpge_epi64_mask(_mm512_sub_epi64(r1, r0), _mm512_set1_epi64(RowSpans::kMaxRows));
  __mmask8 wide = 0, steep = 0;
  const __m512i lim = _mm512_set1_epi64(int64_t{1} << 51), k_lim = _mm512_set1_epi64(c.k_lim);
  for (int s = 0; s < 3; ++s) {
    const __m512i D = _mm512_abs_epi64(A[s]);
    const __m512i N = _mm512_sub_epi64(zero, _mm512_add_epi64(_mm512_mullo_epi64(B[s], r0), C[s]));
    wide |= _mm512_cmpge_epi64_mask(_mm512_abs_epi64(N), lim);
    const __m512d Dd = _mm512_cvtepi64_pd(D);
    const __m512i q =
        _mm512_cvt_roundpd_epi64(_mm512_div_pd(_mm512_cvtepi64_pd(N), Dd), _MM_FROUND_TO_POS_INF | _MM_FROUND_NO_EXC);
    const __m512i negB = _mm512_sub_epi64(zero, B[s]);
    const __m512d k_quotient = _mm512_div_pd(_mm512_cvtepi64_pd(negB), Dd);
    const __m512i k = _mm512_cvt_roundpd_epi64(k_quotient, _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
    steep |= _mm512_cmpge_epi64_mask(k, k_lim) | _mm512_cmplt_epi64_mask(k, _mm512_sub_epi64(zero, k_lim));
    _mm512_store_si512(f.q[s], q);
    _mm512_store_si512(f.r[s], _mm512_sub_epi64(_mm512_mullo_epi64(q, D), N));
    _mm512_store_si512(f.D[s], D);
    _mm512_store_si512(f.k[s], k);
    _mm512_store_si512(f.m[s], _mm512_sub_epi64(negB, _mm512_mullo_epi64(k, D)));
    f.right[s] = _mm512_cmplt_epi64_mask(A[s], zero);
  }
  for (int i = 0; i < 3; ++i) {
    _mm512_store_si512(f.X[i], X[i]);
    _mm512_store_si512(f.Y[i], Y[i]);
  }
  _mm512_store_si512(f.det, det);
  _mm512_store_si512(f.r0, r0);
  _mm512_store_si512(f.r1, r1);
  setOutcomes(f, 0xFF, {ok, 0, flat, horizontal, box_out, tall, wide, steep, neg});
}

// front8 in AVX2 for the block's lanes t0 .. t0 + 3 (lane t0 + j takes triangle t0 + j, those
// past n triangle n - 1), into the same Front8: setupRowSpans's steps on doubles, which hold
// every integer of them exactly where the lane's magnitudes allow; a lane where they do not goes
// to setupRowSpans whole. Snapping as front8. With the vertices' differences below 2^25
// subpixels (checked) the determinant's products lie below 2^50. In a lane whose box meets the
// viewport (the others are dropped before the DDA) the edge functions' factors dx, dy, half - yu
// and half - xu are even and below 2^28 (u units: the vertices within 2^27 of each other, one
// of them by the viewport, below 2^16 px), so their products are multiples of 4 below 2^55,
// exact; B r0 is below 2^47. Where |C| rounds (2^53 and more), |N| = |B r0 + C| lies above
// 2^51 however it rounds, and N is checked below 2^51 (as front8 checks it): then C and N are
// exact, N / D, -B / D and their correctly rounded quotients give front8's q and k (its
// argument), and q D - N, -B - k D are exact. Integers leave the doubles by the magic constant
// (1.5 2^52: for |v| < 2^51 the sum's low bits are v in two's complement).
namespace front4x {
SHD_AVX2 inline __m256d abs(__m256d x) { return _mm256_andnot_pd(_mm256_set1_pd(-0.0), x); }
SHD_AVX2 inline __m256d lt(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
SHD_AVX2 inline __m256d le(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_LE_OQ); }
SHD_AVX2 inline __m256d eq(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, _CMP_EQ_OQ); }
// Coordinate i (x, or y where y) of the four lanes' triangles.
SHD_AVX2 inline __m256d coords(const std::array<RowSpans::Vertex, 3>* v, const std::array<size_t, 4>& tri, size_t i,
                               bool y) {
  auto at = [&](size_t j) { return y ? v[tri[j]][i].y : v[tri[j]][i].x; };
  return _mm256_setr_pd(at(0), at(1), at(2), at(3));
}
// centreRows: -floor((half - lo) / step) and floor((hi - half) / step), exact (a power of two).
SHD_AVX2 inline __m256d rowsLo(__m256d lo, __m256d half, __m256d inv_step) {
  return _mm256_sub_pd(_mm256_setzero_pd(), _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(half, lo), inv_step)));
}
SHD_AVX2 inline __m256d rowsHi(__m256d hi, __m256d half, __m256d inv_step) {
  return _mm256_floor_pd(_mm256_mul_pd(_mm256_sub_pd(hi, half), inv_step));
}
}  // namespace front4x
SHD_AVX2 void front4(const std::array<RowSpans::Vertex, 3>* v, size_t n, size_t t0, const RowSpansConfig& c,
                     Front8& f) {
  using front4x::abs, front4x::lt, front4x::le, front4x::eq;
  const int S = c.S;
  std::array<size_t, 4> tri;
  for (size_t j = 0; j < 4; ++j) tri[j] = std::min(t0 + j, n - 1);
  const __m256d zero = _mm256_setzero_pd();
  const __m256d magic = _mm256_set1_pd(6755399441055744.0);  // 1.5 2^52
  auto bits = [t0](__m256d m) SHD_AVX2 { return static_cast<__mmask8>(_mm256_movemask_pd(m) << t0); };
  const auto mine = static_cast<__mmask8>(0xFu << t0);  // this call's lanes of the block
  auto store = [&](int64_t* out, __m256d x) SHD_AVX2 {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + t0),
                        _mm256_sub_epi64(_mm256_castpd_si256(_mm256_add_pd(x, magic)), _mm256_castpd_si256(magic)));
  };
  const __m256d scale = _mm256_set1_pd(static_cast<double>(int64_t{1} << S)), guard = _mm256_set1_pd(c.guard);
  __m256d X[3], Y[3];
  __m256d ok = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  for (size_t i = 0; i < 3; ++i) {
    const __m256d x = front4x::coords(v, tri, i, false), y = front4x::coords(v, tri, i, true);
    ok = _mm256_and_pd(ok, _mm256_and_pd(le(abs(x), guard), le(abs(y), guard)));
    X[i] = _mm256_sub_pd(_mm256_add_pd(_mm256_and_pd(ok, _mm256_mul_pd(x, scale)), magic), magic);
    Y[i] = _mm256_sub_pd(_mm256_add_pd(_mm256_and_pd(ok, _mm256_mul_pd(y, scale)), magic), magic);
  }
  const __m256d lim25 = _mm256_set1_pd(33554432.0), lim51 = _mm256_set1_pd(2251799813685248.0);
  const __m256d d1x = _mm256_sub_pd(X[1], X[0]), d1y = _mm256_sub_pd(Y[1], Y[0]);
  const __m256d d2x = _mm256_sub_pd(X[2], X[0]), d2y = _mm256_sub_pd(Y[2], Y[0]);
  const __m256d exact = _mm256_and_pd(_mm256_and_pd(lt(abs(d1x), lim25), lt(abs(d1y), lim25)),
                                      _mm256_and_pd(lt(abs(d2x), lim25), lt(abs(d2y), lim25)));
  __m256d det = _mm256_sub_pd(_mm256_mul_pd(d1x, d2y), _mm256_mul_pd(d2x, d1y));
  const __m256d flat = eq(det, zero), neg = lt(det, zero);
  {
    const __m256d x1 = X[1], y1 = Y[1];
    X[1] = _mm256_blendv_pd(X[1], X[2], neg);
    Y[1] = _mm256_blendv_pd(Y[1], Y[2], neg);
    X[2] = _mm256_blendv_pd(X[2], x1, neg);
    Y[2] = _mm256_blendv_pd(Y[2], y1, neg);
  }
  det = abs(det);
  __m256d xu[3], yu[3];
  for (size_t i = 0; i < 3; ++i) {
    xu[i] = _mm256_add_pd(X[i], X[i]);
    yu[i] = _mm256_add_pd(Y[i], Y[i]);
  }
  const __m256d half = _mm256_set1_pd(static_cast<double>(int64_t{1} << S));
  const __m256d step = _mm256_set1_pd(static_cast<double>(int64_t{1} << (S + 1)));
  const __m256d inv_step = _mm256_set1_pd(1.0 / static_cast<double>(int64_t{1} << (S + 1)));
  __m256d A[3], B[3], C[3];
  __m256d horizontal = zero;
  for (size_t s = 0; s < 3; ++s) {
    const size_t q = (s + 1) % 3;
    const __m256d dx = _mm256_sub_pd(xu[q], xu[s]), dy = _mm256_sub_pd(yu[q], yu[s]);
    A[s] = _mm256_sub_pd(zero, _mm256_mul_pd(dy, step));
    B[s] = _mm256_mul_pd(dx, step);
    const __m256d p1 = _mm256_mul_pd(dx, _mm256_sub_pd(half, yu[s]));
    const __m256d p2 = _mm256_mul_pd(dy, _mm256_sub_pd(half, xu[s]));
    const __m256d a0 = eq(A[s], zero);
    const __m256d top_left = _mm256_or_pd(lt(zero, A[s]), _mm256_and_pd(a0, lt(zero, B[s])));
    C[s] = _mm256_sub_pd(_mm256_sub_pd(p1, p2), _mm256_andnot_pd(top_left, _mm256_set1_pd(1.0)));
    horizontal = _mm256_or_pd(horizontal, a0);
  }
  const __m256d ylo = _mm256_min_pd(_mm256_min_pd(yu[0], yu[1]), yu[2]);
  const __m256d yhi = _mm256_max_pd(_mm256_max_pd(yu[0], yu[1]), yu[2]);
  const __m256d r0 = _mm256_max_pd(front4x::rowsLo(ylo, half, inv_step), zero);
  const __m256d r1 = _mm256_min_pd(front4x::rowsHi(yhi, half, inv_step),
                                   _mm256_set1_pd(static_cast<double>(c.H - 1)));
  const __m256d c0 = front4x::rowsLo(_mm256_min_pd(_mm256_min_pd(xu[0], xu[1]), xu[2]), half, inv_step);
  const __m256d c1 = front4x::rowsHi(_mm256_max_pd(_mm256_max_pd(xu[0], xu[1]), xu[2]), half, inv_step);
  const __m256d box_out = _mm256_or_pd(_mm256_or_pd(lt(r1, r0), lt(c1, zero)),
                                       lt(_mm256_set1_pd(static_cast<double>(c.W - 1)), c0));
  const __m256d tall = le(_mm256_set1_pd(RowSpans::kMaxRows), _mm256_sub_pd(r1, r0));
  const __m256d k_lim = _mm256_set1_pd(static_cast<double>(c.k_lim));
  __m256d steep = zero, narrow = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));  // every N below 2^51
  for (size_t s = 0; s < 3; ++s) {
    const __m256d D = abs(A[s]);
    const __m256d Br0 = _mm256_mul_pd(B[s], r0);
    const __m256d N = _mm256_sub_pd(zero, _mm256_add_pd(Br0, C[s]));
    narrow = _mm256_and_pd(narrow, lt(abs(N), lim51));
    const __m256d negB = _mm256_sub_pd(zero, B[s]);
    const __m256d q = _mm256_ceil_pd(_mm256_div_pd(N, D));
    const __m256d k = _mm256_floor_pd(_mm256_div_pd(negB, D));
    steep = _mm256_or_pd(steep, _mm256_or_pd(le(k_lim, k), lt(k, _mm256_sub_pd(zero, k_lim))));
    store(f.q[s], q);
    store(f.r[s], _mm256_sub_pd(_mm256_mul_pd(q, D), N));
    store(f.D[s], D);
    store(f.k[s], k);
    store(f.m[s], _mm256_sub_pd(negB, _mm256_mul_pd(k, D)));
    f.right[s] = static_cast<__mmask8>((f.right[s] & ~mine) | bits(lt(A[s], zero)));
  }
  for (size_t i = 0; i < 3; ++i) {
    store(f.X[i], X[i]);
    store(f.Y[i], Y[i]);
  }
  store(f.det, det);
  store(f.r0, r0);
  store(f.r1, r1);
  setOutcomes(f, mine, {bits(ok), static_cast<__mmask8>(~bits(exact)), bits(flat), bits(horizontal), bits(box_out),
                       bits(tall), static_cast<__mmask8>(~bits(narrow)), bits(steep), bits(neg)});
}

// planeavx2::plane of 8 triangles at once, a triangle per lane and an attribute at a time: the
// same operations on the same doubles, so a lane that passes every check of plane gets plane's
// (and planeScalar's) integers. The lanes of `lanes` whose triangles have their codes in a and
// their geometry in the other arrays; returns those done (o's a0, didx and didy written), the
// others for planeOf. The other lanes are not read (zero: their results are not stored).
struct Plane8 {
  alignas(64) double a[3][4][8];  // vertex, attribute, lane
  alignas(64) int64_t dx1[8], dy1[8], dx2[8], dy2[8], dcx[8], dcy[8], det[8], bx[8], by[8], across[8], down[8],
      dx0[8];
  // Lane t: triangle t's codes af and geometry g.
  void set(size_t t, const CodesF& af, const PlaneGeom& g) {
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 4; ++k) a[i][k][t] = af[i][k];
    dx1[t] = g.dx1, dy1[t] = g.dy1, dx2[t] = g.dx2, dy2[t] = g.dy2, dcx[t] = g.dcx, dcy[t] = g.dcy, det[t] = g.det;
    bx[t] = g.bx, by[t] = g.by, across[t] = g.across, down[t] = g.down, dx0[t] = g.dx0;
  }
  // Lane t's codes and geometry back, for planeOf where the lane does not fit (S: the config's).
  CodesF codes(size_t t) const {
    CodesF af;
    for (size_t i = 0; i < 3; ++i)
      for (size_t k = 0; k < 4; ++k) af[i][k] = a[i][k][t];
    return af;
  }
  PlaneGeom geom(size_t t, int S) const {
    return {dx1[t], dy1[t], dx2[t], dy2[t], dcx[t], dcy[t], S, det[t], bx[t], by[t], across[t], down[t], dx0[t]};
  }
};
// roundDivPlus of planeavx2 in 8 lanes.
SHD_AVX512 inline __m512d roundDivPlus8(__m512d base, __m512d n, __m512d d, __m512d inv) {
  const __m512d one = _mm512_set1_pd(1.0), half = _mm512_set1_pd(0.5);
  const __m512d m = _mm512_roundscale_pd(_mm512_mul_pd(n, inv), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __m512d r = _mm512_sub_pd(n, _mm512_mul_pd(m, d));
  const __m512d q = _mm512_add_pd(m, base);
  const __m512d rest = _mm512_sub_pd(d, r);
  const __m512d h = _mm512_roundscale_pd(_mm512_mul_pd(q, half), _MM_FROUND_TO_NEG_INF | _MM_FROUND_NO_EXC);
  const __mmask8 odd = _mm512_cmp_pd_mask(_mm512_sub_pd(q, _mm512_add_pd(h, h)), _mm512_setzero_pd(), _CMP_NEQ_OQ);
  const __mmask8 up = _mm512_cmp_pd_mask(r, rest, _CMP_GT_OQ) | (_mm512_cmp_pd_mask(r, rest, _CMP_EQ_OQ) & odd);
  return _mm512_mask_add_pd(q, up, q, one);
}
SHD_AVX512 __mmask8 plane8(const Plane8& p, __mmask8 lanes, int S, RowSpans* o) {
  auto load = [lanes](const int64_t* v) SHD_AVX512 { return _mm512_cvtepi64_pd(_mm512_maskz_loadu_epi64(lanes, v)); };
  auto within = [](__m512d v, double lo, double hi) SHD_AVX512 {
    return static_cast<__mmask8>(_mm512_cmp_pd_mask(v, _mm512_set1_pd(lo), _CMP_GE_OQ) &
                                 _mm512_cmp_pd_mask(v, _mm512_set1_pd(hi), _CMP_LE_OQ));
  };
  constexpr double kCoord = 1048576.0, k50 = 1125899906842624.0, lo32 = -2147483648.0, hi32 = 2147483647.0;
  const __m512d dx1 = load(p.dx1), dy1 = load(p.dy1), dx2 = load(p.dx2), dy2 = load(p.dy2);
  const __m512d dcx = load(p.dcx), dcy = load(p.dcy), d = load(p.det);
  // plane's first check: the coordinate differences below 2^20 (and so det below 2^41).
  __mmask8 ok = lanes & _mm512_cmp_pd_mask(_mm512_max_pd(_mm512_max_pd(_mm512_abs_pd(dx1), _mm512_abs_pd(dy1)),
                                                         _mm512_max_pd(_mm512_abs_pd(dx2), _mm512_abs_pd(dy2))),
                                           _mm512_set1_pd(kCoord), _CMP_LT_OQ);
  const __m512d bx = load(p.bx), by = load(p.by), across = load(p.across), down = load(p.down), dx0 = load(p.dx0);
  const __m512d scale = _mm512_set1_pd(static_cast<double>(int64_t{1} << S));
  const __m512d inv = _mm512_div_pd(_mm512_set1_pd(1.0), d), d2 = _mm512_add_pd(d, d);
  const __m512d inv2 = _mm512_mul_pd(inv, _mm512_set1_pd(0.5));
  const __m512d adcx = _mm512_abs_pd(dcx), adcy = _mm512_abs_pd(dcy);
  alignas(64) int64_t first[4][8], gx[4][8], gy[4][8];
  for (size_t k = 0; k < 4; ++k) {
    const __m512d a0 = _mm512_maskz_load_pd(lanes, p.a[0][k]);
    const __m512d a1 = _mm512_maskz_load_pd(lanes, p.a[1][k]), a2 = _mm512_maskz_load_pd(lanes, p.a[2][k]);
    // An attribute constant on every triangle (flat's colours): the numerators are 0, and the
    // steps below give the plane a0 with gradients 0 and change no check (|a0| < 2^31,
    // RowSpansConfig::lim), as planeScalar's shortcut for such an attribute.
    if ((_mm512_cmp_pd_mask(a1, a0, _CMP_EQ_OQ) & _mm512_cmp_pd_mask(a2, a0, _CMP_EQ_OQ)) == 0xFF) {
      _mm512_store_si512(first[k], _mm512_cvtpd_epi64(a0));
      _mm512_store_si512(gx[k], _mm512_setzero_si512());
      _mm512_store_si512(gy[k], _mm512_setzero_si512());
      continue;
    }
    const __m512d da1 = _mm512_sub_pd(a1, a0), da2 = _mm512_sub_pd(a2, a0);
    const __m512d nx = _mm512_sub_pd(_mm512_mul_pd(da1, dy2), _mm512_mul_pd(da2, dy1));
    const __m512d ny = _mm512_sub_pd(_mm512_mul_pd(dx1, da2), _mm512_mul_pd(dx2, da1));
    const __m512d px = _mm512_mul_pd(_mm512_abs_pd(nx), adcx), py = _mm512_mul_pd(_mm512_abs_pd(ny), adcy);
    const __m512d sx = _mm512_mul_pd(nx, scale), sy = _mm512_mul_pd(ny, scale);
    ok &= within(px, -k50, k50) & within(py, -k50, k50) & within(sx, -k50, k50) & within(sy, -k50, k50);
    const __m512d num = _mm512_add_pd(_mm512_mul_pd(nx, dcx), _mm512_mul_pd(ny, dcy));
    const __m512d zero = _mm512_setzero_pd();
    const __m512d didx = roundDivPlus8(zero, sx, d, inv), didy = roundDivPlus8(zero, sy, d, inv);
    const __m512d iref = roundDivPlus8(a0, num, d2, inv2);
    ok &= within(didx, lo32, hi32) & within(didy, lo32, hi32);
    const __m512d corner = _mm512_add_pd(_mm512_add_pd(iref, _mm512_mul_pd(didx, bx)), _mm512_mul_pd(didy, by));
    const __m512d right = _mm512_add_pd(corner, _mm512_mul_pd(didx, across));
    const __m512d below = _mm512_mul_pd(didy, down);
    ok &= within(corner, lo32, hi32) & within(right, lo32, hi32) & within(_mm512_add_pd(corner, below), lo32, hi32) &
          within(_mm512_add_pd(right, below), lo32, hi32);
    // Integers within int32_t where ok (elsewhere whatever the conversion gives, not stored).
    _mm512_store_si512(first[k], _mm512_cvtpd_epi64(_mm512_add_pd(corner, _mm512_mul_pd(didx, dx0))));
    _mm512_store_si512(gx[k], _mm512_cvtpd_epi64(didx));
    _mm512_store_si512(gy[k], _mm512_cvtpd_epi64(didy));
  }
  for (size_t t = 0; t < 8; ++t) {
    if (((ok >> t) & 1) == 0) continue;
    for (size_t k = 0; k < 4; ++k) {
      o[t].a0[k] = first[k][t];
      o[t].didx[k] = gx[k][t];
      o[t].didy[k] = gy[k][t];
    }
  }
  return ok;
}
}  // namespace
#pragma GCC diagnostic pop
#endif

void setupRowSpansBlock(const std::array<RowSpans::Vertex, 3>* v, size_t n, const RowSpansConfig& c, RowSpans* out,
                        RowSpansSetup* got) {
#ifdef SHD_X86_KERNELS
  if (c.vector) {
    for (size_t count; n > 0; v += count, out += count, got += count, n -= count) {
      count = std::min<size_t>(n, 8);
      Front8 f;
      if (c.avx512) {
        front8(v, count, c, f);
      } else {
        front4(v, count, 0, c, f);
        if (count > 4) front4(v, count, 4, c, f);
      }
      Plane8 p;
      __mmask8 planes = 0;  // the triangles whose rows' spans are set, their plane to follow
      for (size_t t = 0; t < count; ++t) {
        const auto bit = [t](__mmask8 m) { return ((m >> t) & 1) != 0; };
        CodesF af;
        if (!planeavx2::snapCodes(v[t], c, af) || bit(f.general)) {
          got[t] = RowSpansSetup::General;
          continue;
        }
        if (bit(f.dropped)) {
          got[t] = RowSpansSetup::Dropped;
          continue;
        }
        if (bit(f.whole)) {
          got[t] = setupRowSpans(v[t], c, out[t]);
          continue;
        }
        Front fr;
        for (size_t i = 0; i < 3; ++i) {
          fr.X[i] = f.X[i][t];
          fr.Y[i] = f.Y[i][t];
          fr.e[i] = {f.q[i][t], f.r[i][t], f.D[i][t], f.k[i][t], f.m[i][t], bit(f.right[i])};
        }
        fr.det = f.det[t];
        fr.r0 = f.r0[t];
        fr.r1 = f.r1[t];
        if (bit(f.swapped)) std::swap(af[1], af[2]);
        PlaneGeom g;
        got[t] = spans(fr, c, out[t], g);
        if (got[t] == RowSpansSetup::Dropped) continue;
        if (!c.avx512) {  // the plane as one triangle's (AVX2, then scalar)
          Codes a;
          got[t] = planeOf(c, a, af, g, out[t]);
          continue;
        }
        planes |= static_cast<__mmask8>(1u << t);
        p.set(t, af, g);
      }
      // The planes in lanes (AVX-512: none wait in AVX2); those that do not fit there as one
      // triangle's (planeOf).
      const __mmask8 done = planes != 0 ? plane8(p, planes, c.S, out) : 0;
      for (size_t t = 0; t < count; ++t) {
        if (((planes & ~done) >> t & 1) == 0) continue;
        Codes a;
        got[t] = planeOf(c, a, p.codes(t), p.geom(t, c.S), out[t]);
      }
    }
    return;
  }
#endif
  for (size_t t = 0; t < n; ++t) got[t] = setupRowSpans(v[t], c, out[t]);
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
