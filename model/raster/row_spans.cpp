#include "raster/row_spans.h"

#include <algorithm>
#include <cmath>

#include "raster/exact_int.h"
#include "raster/span_walk.h"

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

}  // namespace

RowSpansSetup setupRowSpans(const std::array<RowSpans::Vertex, 3>& v, const RowSpansConfig& c, RowSpans& o) {
  const int S = c.S;
  // Snapped as setup snaps them (snapVertices); what it refuses, setupTriangle refuses, naming it.
  // Within these bounds |x 2^S| < 2^29 and |a 2^frac| < 2^31: snapSmall's range. The checks
  // are summed into one test, the rare refusal being the one branch.
  std::array<int64_t, 3> X, Y;
  std::array<std::array<int64_t, 3>, 4> a;
  bool ok = true;
  const double pixel_scale = static_cast<double>(int64_t{1} << S);
  for (size_t i = 0; i < 3; ++i) {
    ok &= std::fabs(v[i].x) <= c.guard;
    ok &= std::fabs(v[i].y) <= c.guard;
    for (size_t k = 0; k < 4; ++k) ok &= std::fabs(v[i].attr[k] * c.scale[k]) <= c.lim;
  }
  if (!ok) return RowSpansSetup::General;
  for (size_t i = 0; i < 3; ++i) {
    X[i] = snapSmall(v[i].x * pixel_scale);
    Y[i] = snapSmall(v[i].y * pixel_scale);
    for (size_t k = 0; k < 4; ++k) a[k][i] = snapSmall(v[i].attr[k] * c.scale[k]);
  }
  int64_t det = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
  if (det == 0) return RowSpansSetup::Dropped;  // zero area
  if (det < 0) {
    std::swap(X[1], X[2]);
    std::swap(Y[1], Y[2]);
    for (auto& ak : a) std::swap(ak[1], ak[2]);
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
  // The plane (setup's setPlane, its 64-bit path), and its values at the corners of the pixels'
  // bounding box within int32_t (then at every pixel: the plane is affine).
  const int64_t xref = std::clamp<int64_t>(std::min({X[0], X[1], X[2]}) >> S, 0, c.W - 1);
  const int64_t yref = std::clamp<int64_t>(std::min({Y[0], Y[1], Y[2]}) >> S, 0, c.H - 1);
  const int64_t dcx = ((2 * xref + 1) << S) - xu[0], dcy = ((2 * yref + 1) << S) - yu[0];
  const int64_t dx1 = X[1] - X[0], dy1 = Y[1] - Y[0], dx2 = X[2] - X[0], dy2 = Y[2] - Y[0];
  for (size_t k = 0; k < 4; ++k) {
    int64_t sx = 0, sy = 0, num = 0;
    if (!planeNumerators64(a[k], dx1, dy1, dx2, dy2, dcx, dcy, S, sx, sy, num)) return RowSpansSetup::General;
    // A constant attribute (flat's colour) has the numerators 0: no division (what it would give).
    const bool constant = a[k][0] == a[k][1] && a[k][0] == a[k][2];
    const int64_t didx = constant ? 0 : roundDivPlus(0, sx, det), didy = constant ? 0 : roundDivPlus(0, sy, det);
    const int64_t iref = constant ? a[k][0] : roundDivPlus(a[k][0], num, 2 * det);
    int64_t corner = 0;
    if (!fits32(didx) || !fits32(didy) || !planeAt(iref, didx, didy, xmin - xref, o.y0 - yref, corner))
      return RowSpansSetup::General;
    // |didx|, |didy| < 2^31 and the box's sides below 2^15: exact in int64_t from its corner.
    const int64_t across = didx * (xmax - xmin), down = didy * (o.rows - 1);
    if (!fits32(corner) || !fits32(corner + across) || !fits32(corner + down) || !fits32(corner + across + down))
      return RowSpansSetup::General;
    o.a0[k] = corner + didx * (o.x0 - xmin);
    o.didx[k] = didx;
    o.didy[k] = didy;
  }
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
