#include "raster/setup.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "raster/exact_int.h"
#include "raster/span_walk.h"


namespace shd {

namespace {

using i128 = __int128;
using namespace exact;

// A triangle in one frame: vertices in u units and its three biased edge functions in that
// frame's pixel coordinates (edge s runs from vertex s to vertex s+1).
struct Geom {
  std::array<int64_t, 3> xu{}, yu{};
  std::array<EdgeFunction, 3> e;
};

Geom screenGeom(const std::array<int64_t, 3>& xu, const std::array<int64_t, 3>& yu, int S) {
  Geom g;
  g.xu = xu;
  g.yu = yu;
  const int64_t half = int64_t{1} << S, step = int64_t{1} << (S + 1);
  for (int s = 0; s < 3; ++s) {
    const size_t p = static_cast<size_t>(s), q = static_cast<size_t>((s + 1) % 3);
    const int64_t dx = xu[q] - xu[p], dy = yu[q] - yu[p];
    EdgeFunction& e = g.e[p];
    e.A = -dy * step;
    e.B = dx * step;
    e.C = dx * (half - yu[p]) - dy * (half - xu[p]);
    e.topLeft = e.A > 0 || (e.A == 0 && e.B > 0);
    if (!e.topLeft) e.C -= 1;
  }
  return g;
}

// The same triangle seen from a walker frame: lane pixel = walker pixel + (tx, ty).
Geom translated(const Geom& g, int64_t tx, int64_t ty, int S) {
  Geom w = g;
  const int64_t step = int64_t{1} << (S + 1);
  for (size_t i = 0; i < 3; ++i) {
    w.xu[i] -= tx * step;
    w.yu[i] -= ty * step;
    w.e[i].C += w.e[i].A * tx + w.e[i].B * ty;
  }
  return w;
}

// Point-reflected: lane pixel = (ox - walker x, oy - walker y).
Geom reflected(const Geom& g, int64_t ox, int64_t oy, int S) {
  Geom w = g;
  const int64_t step = int64_t{1} << (S + 1);
  for (size_t i = 0; i < 3; ++i) {
    w.xu[i] = (ox + 1) * step - g.xu[i];
    w.yu[i] = (oy + 1) * step - g.yu[i];
    w.e[i].C = g.e[i].C + g.e[i].A * ox + g.e[i].B * oy;
    w.e[i].A = -g.e[i].A;
    w.e[i].B = -g.e[i].B;
  }
  return w;
}


[[noreturn]] __attribute__((noinline, cold)) void coordDoesNotFit(int64_t v, const SpanParams& p, const char* what) {
  throw std::logic_error(fmt::format("setup: {} = {} does not fit CoordBits {}", what, v, p.CoordBits));
}
inline void requireCoord(int64_t v, const SpanParams& p, const char* what) {
  const int64_t lim = int64_t{1} << (p.CoordBits - 1);
  if (v < -lim || v >= lim) coordDoesNotFit(v, p, what);
}

// Trims a lane-triangle's rows to the first and the last that hold a pixel. A row whose pixel
// centre lies within the vertical extent can hold no pixel centre between the edges (a
// sliver's tip): on builtin:sphere 676 of the 2,086 triangles drawn began with such a row and
// 676 ended with one. The unit would spend a cycle forming each. First rows: the edges' DDA
// stepped as the walker steps them (raster/span_walk.h), so the state at the new first row is
// the walker's; last rows: each active edge's bound there from its first row's, one division
// per edge. An edge active only in trimmed rows becomes an unused slot.
void trimEmptyRows(SpanLaneTri& t, const SpanParams& p) {
  std::array<SpanDdaState, 3> e;
  for (size_t s = 0; s < 3; ++s) e[s] = {t.edge[s].q, t.edge[s].r};
  int64_t lo = 0, hi = 0;
  int64_t r0 = t.row_first;
  while (r0 <= t.row_last && !span_detail::laneRowBounds(t, r0, e.data(), lo, hi))
    span_detail::stepEdges(t, r0++, e.data(), p.CoordBits);
  int64_t r1 = t.row_last;
  for (; r1 > r0; --r1) {
    // n DDA steps from the edge's first row in one: N grows by n (k D + m), so
    // q = q0 + n k + ceil((n m - r0) / D) (ceilDiv: a 64-bit division where it fits).
    std::array<SpanDdaState, 3> at{};
    for (size_t s = 0; s < 3; ++s) {
      const SpanEdge& g = t.edge[s];
      if (r1 < g.row_first || r1 > g.row_last) continue;
      const int64_t n = r1 - g.row_first;
      at[s].q = g.q + n * g.k + ceilDivOfProduct(n, g.m, g.r, g.div);
    }
    if (span_detail::laneRowBounds(t, r1, at.data(), lo, hi)) break;
  }
  if (r0 == t.row_first && r1 == t.row_last) return;  // nothing to trim: most triangles
  if (r0 > t.row_last) {  // no pixel at all (the viewport or the top-left rule takes them all)
    t.row_first = 1;
    t.row_last = 0;
    for (SpanEdge& g : t.edge) g = SpanEdge{};
    return;
  }
  for (size_t s = 0; s < 3; ++s) {
    SpanEdge& g = t.edge[s];
    if (g.row_first > g.row_last) continue;
    if (g.row_last < r0 || g.row_first > r1) {
      g = SpanEdge{};
      continue;
    }
    if (g.row_first < r0) {  // stepped to r0
      g.row_first = static_cast<int32_t>(r0);
      g.q = static_cast<int32_t>(e[s].q);
      g.r = e[s].r;
    }
    g.row_last = static_cast<int32_t>(std::min<int64_t>(g.row_last, r1));
  }
  t.row_first = static_cast<int32_t>(r0);
  t.row_last = static_cast<int32_t>(r1);
}

// Appends the lane-triangle of g to `lanes` (built in place). g is given in a frame whose pixel
// (x, y) is screen pixel (x + ox, y + oy), or (ox - x, oy - y) when flipped; the walker row w is
// the frame's row stride w + phase (stride 1, phase 0 but for interleaved rows). False when no
// pixel centre row and column of its bounding box lies in the viewport (then it has no rows).
bool buildLaneTri(InlineVec<SpanLaneTri, kMaxLaneTri>& lanes, const Geom& g, bool flip, int64_t ox, int64_t oy,
                  const RasterConfig& cfg, int64_t stride = 1, int64_t phase = 0) {
  const int S = cfg.subpixel_bits;
  const SpanParams& p = cfg.unit;
  SpanLaneTri& t = lanes.emplace_back();
  t.flip = flip;
  t.ox = static_cast<int32_t>(ox);
  t.oy = static_cast<int32_t>(oy + phase);
  // The walker rows of the frame rows [a, b].
  auto walkerRows = [&](int64_t a, int64_t b) -> std::pair<int64_t, int64_t> {
    if (stride == 1) return {a, b};
    return {ceilDiv(a - phase, stride), floorDiv(b - phase, stride)};
  };
  // Rows: pixel centres within the vertical extent, then the horizontal edge, then the viewport.
  auto [r0, r1] = centreRows(*std::min_element(g.yu.begin(), g.yu.end()), *std::max_element(g.yu.begin(), g.yu.end()), S);
  for (const EdgeFunction& e : g.e) {
    if (e.A != 0) continue;
    if (e.B > 0) r0 = std::max(r0, ceilDiv(-static_cast<i128>(e.C), e.B));
    else r1 = std::min(r1, floorDiv(e.C, -e.B));
  }
  const int64_t W = cfg.width, H = cfg.height;
  if (flip) {
    r0 = std::max(r0, oy - (H - 1));
    r1 = std::min(r1, oy);
    t.clip_x0 = static_cast<int32_t>(ox - (W - 1));
    t.clip_x1 = static_cast<int32_t>(ox);
  } else {
    r0 = std::max(r0, -oy);
    r1 = std::min(r1, H - 1 - oy);
    t.clip_x0 = static_cast<int32_t>(-ox);
    t.clip_x1 = static_cast<int32_t>(W - 1 - ox);
  }
  // Columns the same way: a triangle wholly left or right of the viewport has no pixel in it.
  const auto [c0, c1] = centreRows(*std::min_element(g.xu.begin(), g.xu.end()), *std::max_element(g.xu.begin(), g.xu.end()), S);
  if (r0 > r1 || c1 < t.clip_x0 || c0 > t.clip_x1) return false;  // no rows: row_first > row_last
  const int64_t f0 = r0, f1 = r1;  // frame rows
  std::tie(r0, r1) = walkerRows(r0, r1);
  if (r0 > r1) return true;  // interleaved: none of the rows is this lane-triangle's
  requireCoord(r0, p, "lane-triangle first row");
  requireCoord(r1, p, "lane-triangle last row");
  t.row_first = static_cast<int32_t>(r0);
  t.row_last = static_cast<int32_t>(r1);
  int slot = 0;
  for (int s = 0; s < 3; ++s) {
    const EdgeFunction& e = g.e[static_cast<size_t>(s)];
    if (e.A == 0) continue;
    const size_t a = static_cast<size_t>(s), b = static_cast<size_t>((s + 1) % 3);
    auto [ea, eb] = centreRows(std::min(g.yu[a], g.yu[b]), std::max(g.yu[a], g.yu[b]), S);
    std::tie(ea, eb) = walkerRows(std::max(ea, f0), std::min(eb, f1));
    SpanEdge& d = t.edge[slot++];
    if (ea > eb) continue;  // never active: stays an unused slot
    d.row_first = static_cast<int32_t>(ea);
    d.row_last = static_cast<int32_t>(eb);
    d.right = e.A < 0;
    const int64_t D = e.A < 0 ? -e.A : e.A;
    // In the walker frame: E = A x + B (stride w + phase) + C (stride 1: the frame's own).
    const i128 B = stride == 1 ? e.B : static_cast<i128>(e.B) * stride;
    const i128 C = stride == 1 ? e.C : e.C + static_cast<i128>(e.B) * phase;
    // N = -(B ea + C): x >= N/D (left), x <= -N/D (right). The start q = ceil(N / D) and
    // r = q D - N (in [0, D): exact mod 2^64), in 64 bits where B ea + C fits (stride 1, the
    // common case), else in 128.
    int64_t q = 0, r = 0, bea = 0, nn = 0;
    if (stride == 1 && !__builtin_mul_overflow(e.B, ea, &bea) && !__builtin_add_overflow(bea, e.C, &nn) && nn != INT64_MIN) {
      q = ceilDiv64(-nn, D);
      r = static_cast<int64_t>(static_cast<uint64_t>(q) * static_cast<uint64_t>(D) + static_cast<uint64_t>(nn));
    } else {
      const i128 N = -(B * ea + C);
      q = ceilDiv(N, D);
      r = static_cast<int64_t>(static_cast<i128>(q) * D - N);
    }
    d.q = static_cast<int32_t>(q);
    d.r = r;
    d.div = D;
    if (eb > ea) {  // the DDA steps: -B = k D + m (m in [0, D): exact mod 2^64)
      const int64_t k = floorDiv(-B, D);
      requireCoord(k, p, "edge DDA step k");
      d.k = static_cast<int32_t>(k);
      d.m = static_cast<int64_t>(0 - static_cast<uint64_t>(B) - static_cast<uint64_t>(k) * static_cast<uint64_t>(D));
    }
    // While active the bound lies within the edge's horizontal extent (+-1): it fits.
    requireCoord(q, p, "edge DDA quotient");
    if (D >= (int64_t{1} << p.RemBits))
      throw std::logic_error(fmt::format("setup: edge divisor {} does not fit RemBits {}", D, p.RemBits));
  }
  trimEmptyRows(t, p);
  return true;
}

// The cycles the unit takes for a descriptor of these lane-triangles alone, out_ready always 1:
// the paper's unit an IDLE cycle, a ROW cycle per walker row and the lane groups; the full-rate
// unit as SpanStream counts them. What setup compares to choose the lanes' assignment.
uint64_t laneCycles(const InlineVec<SpanLaneTri, kMaxLaneTri>& lanes, const SpanParams& p) {
  int64_t w0 = 0, w1 = -1;
  bool any = false;
  std::array<SpanDdaState, kMaxLaneTri * 3> e{};
  for (size_t j = 0; j < lanes.size(); ++j) {
    const SpanLaneTri& t = lanes[j];
    for (size_t s = 0; s < 3; ++s) e[j * 3 + s] = {t.edge[s].q, t.edge[s].r};
    if (t.row_first > t.row_last) continue;
    w0 = any ? std::min<int64_t>(w0, t.row_first) : t.row_first;
    w1 = any ? std::max<int64_t>(w1, t.row_last) : t.row_last;
    any = true;
  }
  const int T = static_cast<int>(lanes.size()), L = p.LanesPerTri;
  std::array<int64_t, kMaxLaneTri> lo{}, hi{};
  std::array<bool, kMaxLaneTri> ne{};
  SpanStream stream;
  uint64_t paper = 1;
  for (int64_t w = w0; w <= w1; ++w) {
    int64_t xs = 0, xe = 0;
    uint64_t groups = 0;
    if (span_detail::unionRowBounds(lanes.data(), T, w, e.data(), lo.data(), hi.data(), ne.data(), xs, xe)) {
      groups = static_cast<uint64_t>((xe - span_detail::firstGroup(p, xs)) / L + 1);
    }
    stream.row(groups);
    paper += 1 + groups;
    for (int j = 0; j < T; ++j) span_detail::stepEdges(lanes[static_cast<size_t>(j)], w, &e[static_cast<size_t>(j) * 3], p.CoordBits);
  }
  return p.RowAhead ? stream.end() : paper;
}

}  // namespace

int defaultAttrFracBits(int width, int height, int out_frac) {
  int lg = 0;
  while ((int64_t{1} << lg) < int64_t{1} + width + height) ++lg;
  return out_frac + 1 + lg;
}

// Output fraction bits of attribute k by default: colour channels integer codes, depth 16.
static int defaultOutFrac(int k) { return k == 3 ? 16 : 0; }

std::vector<int> defaultAttrFracBitsFor(int width, int height, int num_attr) {
  std::vector<int> f;
  for (int k = 0; k < num_attr; ++k) f.push_back(defaultAttrFracBits(width, height, defaultOutFrac(k)));
  return f;
}

void RasterConfig::validate() const {
  unit.validate();
  const int64_t lim = int64_t{1} << unit.PixBits;
  if (width < 1 || width > lim || height < 1 || height > lim)
    throw std::invalid_argument(fmt::format("viewport {}x{} must fit PixBits {} (1..{})", width, height, unit.PixBits, lim));
  if (int64_t{2} * std::max(width, height) > (int64_t{1} << (unit.CoordBits - 3)))
    throw std::invalid_argument(fmt::format("viewport {}x{} too large for the guard band of CoordBits {}", width,
                                            height, unit.CoordBits));
  if (subpixel_bits < 1 || subpixel_bits > 8)
    throw std::invalid_argument(fmt::format("subpixel_bits {} must be in 1..8", subpixel_bits));
  // An edge divisor D = |dY| 2^(S+1) (u units) reaches 2^(CoordBits + 2S) across the guard band.
  if (unit.CoordBits + 2 * subpixel_bits + 1 > unit.RemBits)
    throw std::invalid_argument(fmt::format("subpixel_bits {} needs RemBits >= CoordBits + 2 S + 1 = {} (the edge divisor "
                                            "across the guard band); RemBits is {}",
                                            subpixel_bits, unit.CoordBits + 2 * subpixel_bits + 1, unit.RemBits));
  if (!attr_frac_bits.empty() && static_cast<int>(attr_frac_bits.size()) != unit.NumAttr)
    throw std::invalid_argument(fmt::format("attr_frac_bits has {} entries, NumAttr is {}", attr_frac_bits.size(), unit.NumAttr));
  for (int k = 0; k < unit.NumAttr; ++k)
    if (attrFracBits(k) < 0 || attrFracBits(k) > unit.AttrBits - 2)
      throw std::invalid_argument(fmt::format("attribute {} fraction bits {} must be in 0..AttrBits-2", k, attrFracBits(k)));
}

int RasterConfig::attrFracBits(int k) const {
  if (attr_frac_bits.empty()) return defaultAttrFracBits(width, height, defaultOutFrac(k));
  return attr_frac_bits[static_cast<size_t>(k)];
}

namespace {

// The vertices snapped to the subpixel grid and the attributes to their codes, half to even, in
// t's X, Y and a; std::invalid_argument naming the triangle for what cannot be set up.
void snapVertices(const std::array<SetupVertex, 3>& v, uint32_t tag, const RasterConfig& cfg, SnappedTriangle& t) {
  const SpanParams& p = cfg.unit;
  const int S = cfg.subpixel_bits, K = p.NumAttr;
  // The guard band bounds every width downstream.
  const double guard = static_cast<double>(int64_t{1} << (p.CoordBits - 3));
  for (size_t i = 0; i < 3; ++i) {
    if (!std::isfinite(v[i].x) || !std::isfinite(v[i].y))
      throw std::invalid_argument(fmt::format("triangle {}: vertex {} has a non-finite coordinate ({}, {})", tag, i, v[i].x, v[i].y));
    if (std::fabs(v[i].x) > guard || std::fabs(v[i].y) > guard)
      throw std::invalid_argument(fmt::format("triangle {}: vertex {} at ({}, {}) lies outside the guard band +-{} px: "
                                              "clip first",
                                              tag, i, v[i].x, v[i].y, guard));
    if (static_cast<int>(v[i].attr.size()) != K)
      throw std::invalid_argument(fmt::format("triangle {}: vertex {} has {} attributes, the unit takes {}", tag, i, v[i].attr.size(), K));
    t.X[i] = snapHalfEven(v[i].x, S);
    t.Y[i] = snapHalfEven(v[i].y, S);
  }
  t.a.resizeForOverwrite(static_cast<size_t>(K));  // every code written below
  const int64_t err_bound = (1 + int64_t{cfg.width} + cfg.height) / 2 + 2;  // codes, see header
  const int64_t lim = (int64_t{1} << (p.AttrBits - 1)) - 1 - err_bound;
  for (int k = 0; k < K; ++k) {
    const int F = cfg.attrFracBits(k);
    const double scale = static_cast<double>(int64_t{1} << F);  // 2^F, exact: val * scale == ldexp(val, F)
    for (size_t i = 0; i < 3; ++i) {
      const double val = v[i].attr[static_cast<size_t>(k)];
      if (!std::isfinite(val) || std::fabs(val * scale) > static_cast<double>(lim))
        throw std::invalid_argument(fmt::format(
            "triangle {}: attribute {} = {} at vertex {} does not fit AttrBits {} with {} fraction bits", tag, k, val, i,
            p.AttrBits, F));
      t.a[static_cast<size_t>(k)][i] = snapHalfEven(val, F);
    }
  }
}

// The attribute planes' codes (see the header and planeNumerators64): in 64-bit integers where
// every product and sum provably fits (checked: the common case), else in 128 bits.
void setPlane(const SnappedTriangle& t, int S, int64_t u0, int64_t v0, AttributePlane& pl) {
  const int64_t det2 = 2 * t.det;
  const int64_t dx1 = t.X[1] - t.X[0], dy1 = t.Y[1] - t.Y[0], dx2 = t.X[2] - t.X[0], dy2 = t.Y[2] - t.Y[0];
  const int64_t dcx = ((2 * pl.xref + 1) << S) - u0, dcy = ((2 * pl.yref + 1) << S) - v0;
  const size_t K = t.a.size();
  pl.didx.resizeForOverwrite(K);  // each written below
  pl.didy.resizeForOverwrite(K);
  pl.iref.resizeForOverwrite(K);
  for (size_t k = 0; k < K; ++k) {
    const auto& a = t.a[k];
    int64_t sx = 0, sy = 0, num = 0;
    if (planeNumerators64(a, dx1, dy1, dx2, dy2, dcx, dcy, S, sx, sy, num)) {
      pl.didx[k] = roundDivPlus(0, sx, t.det);  // per pixel = per subpixel * 2^S
      pl.didy[k] = roundDivPlus(0, sy, t.det);
      pl.iref[k] = roundDivPlus(a[0], num, det2);
      continue;
    }
    const int64_t da1 = a[1] - a[0], da2 = a[2] - a[0];  // |a| < 2^61: no overflow
    const i128 nx128 = static_cast<i128>(da1) * dy2 - static_cast<i128>(da2) * dy1;
    const i128 ny128 = static_cast<i128>(dx1) * da2 - static_cast<i128>(dx2) * da1;
    pl.didx[k] = static_cast<int64_t>(roundDiv(nx128 * (i128{1} << S), t.det));
    pl.didy[k] = static_cast<int64_t>(roundDiv(ny128 * (i128{1} << S), t.det));
    pl.iref[k] = static_cast<int64_t>(roundDiv(static_cast<i128>(det2) * a[0] + nx128 * dcx + ny128 * dcy, det2));
  }
}

}  // namespace

SetupResult setupTriangle(const std::array<SetupVertex, 3>& v, uint32_t tag, const RasterConfig& cfg) {
  SetupResult res;
  setupTriangle(v, tag, cfg, res);
  return res;
}

void setupTriangle(const std::array<SetupVertex, 3>& v, uint32_t tag, const RasterConfig& cfg, SetupResult& res) {
  const SpanParams& p = cfg.unit;
  const int S = cfg.subpixel_bits, K = p.NumAttr;
  // What res held and is not overwritten below (every other field is).
  res.desc.reset();
  res.dropped.clear();
  res.tri.swapped = false;
  res.plane.iref.clear();
  res.plane.didx.clear();
  res.plane.didy.clear();
  SnappedTriangle& t = res.tri;
  snapVertices(v, tag, cfg, t);
  t.det = (t.X[1] - t.X[0]) * (t.Y[2] - t.Y[0]) - (t.X[2] - t.X[0]) * (t.Y[1] - t.Y[0]);
  if (t.det == 0) {
    res.dropped = "zero area";
    res.edges = {};
    res.plane.xref = res.plane.yref = 0;
    return;
  }
  if (t.det < 0) {  // one orientation downstream: inside is E >= 0
    std::swap(t.X[1], t.X[2]);
    std::swap(t.Y[1], t.Y[2]);
    for (auto& a : t.a) std::swap(a[1], a[2]);
    t.swapped = true;
    t.det = -t.det;
  }
  const std::array<int64_t, 3> xu = {2 * t.X[0], 2 * t.X[1], 2 * t.X[2]}, yu = {2 * t.Y[0], 2 * t.Y[1], 2 * t.Y[2]};
  const Geom whole = screenGeom(xu, yu, S);
  res.edges = whole.e;

  // The attribute plane in screen pixels, referenced inside the viewport (see the error bound).
  AttributePlane& pl = res.plane;
  // floor(v / 2^S) as an arithmetic shift (floor for either sign), without a division
  const int64_t px_min = *std::min_element(t.X.begin(), t.X.end()) >> S;
  const int64_t py_min = *std::min_element(t.Y.begin(), t.Y.end()) >> S;
  pl.xref = std::clamp<int64_t>(px_min, 0, cfg.width - 1);
  pl.yref = std::clamp<int64_t>(py_min, 0, cfg.height - 1);
  setPlane(t, S, xu[0], yu[0], pl);

  // Lane-triangles in the walker frame, built in place in the descriptor.
  SpanDesc& d = res.desc.emplace();
  auto& lanes = d.tri;
  bool boxed = false;  // some lane-triangle's box has a pixel centre in the viewport
  if (p.NumTri == 1) {
    boxed = buildLaneTri(lanes, whole, false, 0, 0, cfg);
  } else {
    // Split at the edge midpoints (exact in u units): T0 = (V0, M01, M20) is the walker frame,
    // T1 = (M01, V1, M12) and T2 = (M20, M12, V2) are its translates by (V1-V0)/2 and
    // (V2-V0)/2, T3 = (M12, M20, M01) its point reflection through (M01 + M20)/2.
    const std::array<int64_t, 3> mx = {t.X[0] + t.X[1], t.X[1] + t.X[2], t.X[2] + t.X[0]};  // M01, M12, M20
    const std::array<int64_t, 3> my = {t.Y[0] + t.Y[1], t.Y[1] + t.Y[2], t.Y[2] + t.Y[0]};
    const Geom g0 = screenGeom({xu[0], mx[0], mx[2]}, {yu[0], my[0], my[2]}, S);
    const Geom g1 = screenGeom({mx[0], xu[1], mx[1]}, {my[0], yu[1], my[1]}, S);
    const Geom g2 = screenGeom({mx[2], mx[1], xu[2]}, {my[2], my[1], yu[2]}, S);
    const Geom g3 = screenGeom({mx[1], mx[2], mx[0]}, {my[1], my[2], my[0]}, S);
    const int64_t step = int64_t{1} << (S + 1);
    // Integer pixel offsets, rounded: a half-pixel remainder is a "cut point", absorbed by the
    // lane's own exact edges.
    const int64_t t1x = static_cast<int64_t>(roundDiv(t.X[1] - t.X[0], step)), t1y = static_cast<int64_t>(roundDiv(t.Y[1] - t.Y[0], step));
    const int64_t t2x = static_cast<int64_t>(roundDiv(t.X[2] - t.X[0], step)), t2y = static_cast<int64_t>(roundDiv(t.Y[2] - t.Y[0], step));
    const int64_t ox = static_cast<int64_t>(roundDiv(mx[0] + mx[2], step)) - 1, oy = static_cast<int64_t>(roundDiv(my[0] + my[2], step)) - 1;
    boxed = buildLaneTri(lanes, g0, false, 0, 0, cfg);
    boxed = buildLaneTri(lanes, translated(g1, t1x, t1y, S), false, t1x, t1y, cfg) || boxed;
    boxed = buildLaneTri(lanes, translated(g2, t2x, t2y, S), false, t2x, t2y, cfg) || boxed;
    boxed = buildLaneTri(lanes, reflected(g3, ox, oy, S), true, ox, oy, cfg) || boxed;
    if (p.Interleave && boxed) {
      // Rows interleaved instead: lane-triangle j takes the screen rows NumTri w + j. The
      // split's four sub-triangles share the walker, so its cycles follow the widest of them
      // and, on a triangle the viewport clips, the lanes whose sub-triangle is off screen idle;
      // four adjacent rows of a triangle instead leave together, but span more columns than one
      // when the edges slope. The one with fewer cycles is kept (the split on a tie).
      InlineVec<SpanLaneTri, kMaxLaneTri> rows;
      for (int j = 0; j < p.NumTri; ++j) buildLaneTri(rows, whole, false, 0, 0, cfg, p.NumTri, j);
      if (laneCycles(rows, p) < laneCycles(lanes, p)) {
        lanes = rows;
        d.interleave = true;
      }
    }
  }
  int64_t row_first = 0, row_last = -1;
  bool any = false;
  for (const SpanLaneTri& l : lanes) {
    if (l.row_first > l.row_last) continue;
    row_first = any ? std::min<int64_t>(row_first, l.row_first) : l.row_first;
    row_last = any ? std::max<int64_t>(row_last, l.row_last) : l.row_last;
    any = true;
  }
  if (!any) {
    res.desc.reset();
    res.dropped = boxed ? "no pixel centre inside it in the viewport" : "no pixel centre of its bounding box in the viewport";
    return;
  }
  d.tag = tag;
  d.row_first = static_cast<int32_t>(row_first);
  d.row_last = static_cast<int32_t>(row_last);
  d.xref = static_cast<int32_t>(pl.xref);
  // Every code the unit takes is mod 2^AttrBits (AttrBits < 64): formed mod 2^64 in uint64_t,
  // which equals the exact value mod 2^64, then wrapped.
  auto wrap = [&](uint64_t x) { return span_detail::wrapTo(x, p.AttrBits); };
  auto u = [](int64_t x) { return static_cast<uint64_t>(x); };
  auto planeAt = [&](size_t k, int64_t px, int64_t py) {  // AttributePlane::at mod 2^64
    return u(pl.iref[k]) + u(pl.didx[k]) * u(px - pl.xref) + u(pl.didy[k]) * u(py - pl.yref);
  };
  // The walker plane I_w(x, w) is the screen plane at (x, ystride w).
  const int64_t ystride = d.interleave ? p.NumTri : 1;
  const size_t Ku = static_cast<size_t>(K);
  d.iref.resizeForOverwrite(Ku);  // each written below
  d.didx.resizeForOverwrite(Ku);
  d.didy.resizeForOverwrite(Ku);
  for (size_t k = 0; k < Ku; ++k) {
    d.iref[k] = wrap(planeAt(k, d.xref, ystride * d.row_first));
    d.didx[k] = wrap(u(pl.didx[k]));
    d.didy[k] = wrap(u(pl.didy[k]) * u(ystride));
  }
  for (SpanLaneTri& l : lanes) {
    // Lane attribute = I_w + aoff, or aoff - I_w when flipped, with I_w the walker plane: the
    // lane's pixel (x + ox, ystride w + oy) has the value I_w(x, w) + didx ox + didy oy.
    l.aoff.resizeForOverwrite(Ku);
    for (size_t k = 0; k < Ku; ++k)
      l.aoff[k] = wrap(l.flip ? planeAt(k, 0, 0) + planeAt(k, l.ox, l.oy) : u(pl.didx[k]) * u(l.ox) + u(pl.didy[k]) * u(l.oy));
  }
}

std::vector<SpanFragment> rasterizeReference(const SetupResult& s, const RasterConfig& cfg) {
  std::vector<SpanFragment> out;
  if (s.tri.det == 0) return out;
  const int S = cfg.subpixel_bits;
  const int64_t one = int64_t{1} << S;
  const int64_t x0 = std::max<int64_t>(0, floorDiv(*std::min_element(s.tri.X.begin(), s.tri.X.end()), one) - 1);
  const int64_t x1 = std::min<int64_t>(cfg.width - 1, floorDiv(*std::max_element(s.tri.X.begin(), s.tri.X.end()), one) + 1);
  const int64_t y0 = std::max<int64_t>(0, floorDiv(*std::min_element(s.tri.Y.begin(), s.tri.Y.end()), one) - 1);
  const int64_t y1 = std::min<int64_t>(cfg.height - 1, floorDiv(*std::max_element(s.tri.Y.begin(), s.tri.Y.end()), one) + 1);
  const uint32_t tag = s.desc ? s.desc->tag : 0;
  for (int64_t py = y0; py <= y1; ++py)
    for (int64_t px = x0; px <= x1; ++px) {
      bool in = true;
      for (const EdgeFunction& e : s.edges) in = in && e.eval(px, py) >= 0;
      if (!in) continue;
      SpanFragment f;
      f.tag = tag;
      f.x = static_cast<int32_t>(px);
      f.y = static_cast<int32_t>(py);
      for (int k = 0; k < cfg.unit.NumAttr; ++k) f.attr.push_back(s.plane.at(k, px, py));
      out.push_back(std::move(f));
    }
  return out;
}

double exactPlane(const SetupResult& s, const RasterConfig& cfg, int k, int64_t px, int64_t py) {
  const SnappedTriangle& t = s.tri;
  const auto& a = t.a[static_cast<size_t>(k)];
  // In subpixel units: I = a0 + gx (cx - X0) + gy (cy - Y0), pixel centre c = (p + 0.5) 2^S.
  const long double det = static_cast<long double>(t.det);
  const long double gx = (static_cast<long double>(a[1] - a[0]) * (t.Y[2] - t.Y[0]) -
                          static_cast<long double>(a[2] - a[0]) * (t.Y[1] - t.Y[0])) / det;
  const long double gy = (static_cast<long double>(t.X[1] - t.X[0]) * (a[2] - a[0]) -
                          static_cast<long double>(t.X[2] - t.X[0]) * (a[1] - a[0])) / det;
  const long double one = std::ldexp(1.0L, cfg.subpixel_bits);
  const long double cx = (px + 0.5L) * one, cy = (py + 0.5L) * one;
  return static_cast<double>(a[0] + gx * (cx - t.X[0]) + gy * (cy - t.Y[0]));
}

}  // namespace shd
