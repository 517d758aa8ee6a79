// The span unit's functional walk (raster/span_unit.h: walkSpanUnit), as a template over the
// consumer of the fragments, so that a renderer can shade each fragment as the walk produces
// it; and the ROW logic it shares with the cycle-by-cycle SpanUnitModel.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>
#include <type_traits>

#include "raster/span_unit.h"

namespace shd {

namespace span_detail {

// Two's complement wrap to `bits` (< 64) bits: the value mod 2^bits, sign-extended. The
// callers form sums and products in uint64_t, which is exact mod 2^64 and so mod 2^bits.
inline int64_t wrapTo(uint64_t v, int bits) {
  const int sh = 64 - bits;
  return static_cast<int64_t>(v << sh) >> sh;  // arithmetic shift: defined on GCC/Clang, C++20
}

inline uint64_t u(int64_t v) { return static_cast<uint64_t>(v); }

// The ROW cycle, combinational part, for one lane-triangle at walker row w with its edges'
// current quotients: the span [lo, hi]; returns ne (the lane-triangle has pixels on the row).
// Always inlined: once per row of every triangle, and GCC's size heuristics otherwise leave it
// out of a walk whose sink has grown (a call per row cost 4 % of a Gouraud frame).
[[gnu::always_inline]] inline bool laneRowBounds(const SpanLaneTri& t, int64_t w, const SpanDdaState* e, int64_t& lo, int64_t& hi) {
  lo = t.clip_x0;
  hi = t.clip_x1;
  for (int s = 0; s < 3; ++s) {
    const SpanEdge& g = t.edge[s];
    if (w < g.row_first || w > g.row_last) continue;
    if (g.right) hi = std::min(hi, -e[s].q);
    else lo = std::max(lo, e[s].q);
  }
  return t.row_first <= w && w <= t.row_last && lo <= hi;
}

// The first lane group's column of a row whose span starts at xs: xs, or with AlignLanes the
// column below it that is a multiple of LanesPerTri (floor modulo).
inline int64_t firstGroup(const SpanParams& p, int64_t xs) {
  const int L = p.LanesPerTri;
  return p.AlignLanes ? xs - (((xs % L) + L) % L) : xs;
}

// The ROW cycle over every lane-triangle (T of them, edges e[3 j + s]): each one's [lo, hi]
// and ne, and the union [xs, xe] of the non-empty ones; returns whether there is one.
[[gnu::always_inline]] inline bool unionRowBounds(const SpanLaneTri* tri, int T, int64_t w, const SpanDdaState* e,
                                                  int64_t* lo, int64_t* hi, bool* ne, int64_t& xs, int64_t& xe) {
  bool any = false;
  for (int j = 0; j < T; ++j) {
    const size_t ju = static_cast<size_t>(j);
    ne[ju] = laneRowBounds(tri[ju], w, &e[ju * 3], lo[ju], hi[ju]);
    if (!ne[ju]) continue;
    xs = any ? std::min(xs, lo[ju]) : lo[ju];
    xe = any ? std::max(xe, hi[ju]) : hi[ju];
    any = true;
  }
  return any;
}

// One DDA step of edge g's state st.
[[gnu::always_inline]] inline void stepEdge(const SpanEdge& g, SpanDdaState& st, int coord_bits) {
  const int64_t r = st.r - g.m;
  const int64_t borrow = r < 0 ? 1 : 0;  // without a branch: r's sign is data, not a pattern
  st.r = r + (g.div & -borrow);
  st.q = wrapTo(u(st.q + g.k + borrow), coord_bits);
}

// The ROW cycle's register update of one lane-triangle's edges: the DDA step of every edge
// active at w that stays active at w + 1.
inline void stepEdges(const SpanLaneTri& t, int64_t w, SpanDdaState* e, int coord_bits) {
  for (int s = 0; s < 3; ++s) {
    const SpanEdge& g = t.edge[s];
    if (w < g.row_first || w >= g.row_last) continue;
    stepEdge(g, e[s], coord_bits);
  }
}

inline void checkDescriptor(const SpanParams& p, const SpanDesc& d) {
  if (static_cast<int>(d.tri.size()) != p.NumTri || static_cast<int>(d.iref.size()) != p.NumAttr)
    throw std::invalid_argument("span descriptor does not match the unit's NumTri/NumAttr");
  if (d.row_first > d.row_last)  // the RTL would walk until w wraps
    throw std::invalid_argument("span descriptor without rows: setup drops such triangles");
  if (d.interleave && !p.Interleave)
    throw std::invalid_argument("span descriptor interleaves rows; the unit's Interleave is 0");
}

// The screen row (before the PixBits mask) of lane-triangle t's pixels in walker row w.
inline int64_t laneRowY(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t, int64_t w) {
  const int64_t y = d.interleave ? w * p.NumTri : w;
  return t.flip ? t.oy - y : y + t.oy;
}

// The lane fragment at walker column x of row wspan, attribute base icur + i*didx (lane i).
inline void laneFragment(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t, int64_t x, int64_t wspan,
                         const int64_t* icur, int i, int32_t& px_out, int32_t& py_out, int64_t* attr) {
  const int64_t px = t.flip ? t.ox - x : x + t.ox;
  const int64_t py = laneRowY(p, d, t, wspan);
  const int64_t pix_mask = (int64_t{1} << p.PixBits) - 1;
  px_out = static_cast<int32_t>(px & pix_mask);
  py_out = static_cast<int32_t>(py & pix_mask);
  for (int a = 0; a < p.NumAttr; ++a) {
    const size_t ai = static_cast<size_t>(a);
    const uint64_t v = u(icur[ai]) + static_cast<uint64_t>(i) * u(d.didx[ai]);
    attr[ai] = wrapTo(t.flip ? u(t.aoff[ai]) - v : v + u(t.aoff[ai]), p.AttrBits);
  }
}

// The fragments of a row of a single lane-triangle (T == 1), x = lo..hi in order: one
// accumulator acc = I_w(x, w) stepped by didx, mapped by the lane's output map. KC and AB:
// NumAttr and AttrBits known at compile time (4 and 32, the renderer's unit), or 0 for
// p.NumAttr and p.AttrBits.
template <int KC, int AB, class Sink>
inline void singleRow(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t, int64_t w, int64_t lo, int64_t hi,
                      const int64_t* irow, Sink& emit) {
  const int K = KC > 0 ? KC : p.NumAttr, bits = AB > 0 ? AB : p.AttrBits;
  std::array<uint64_t, kMaxAttr> acc, step, off;  // the first K are set and read
  std::array<int64_t, kMaxAttr> attr;
  for (int a = 0; a < K; ++a) {
    const size_t ai = static_cast<size_t>(a);
    acc[ai] = u(irow[ai]) + u(d.didx[ai]) * u(lo - d.xref);
    step[ai] = u(d.didx[ai]);
    off[ai] = u(t.aoff[ai]);
  }
  const int64_t pix_mask = (int64_t{1} << p.PixBits) - 1;
  const int32_t py = static_cast<int32_t>(laneRowY(p, d, t, w) & pix_mask);
  // The loop instantiated per output map (flip is constant over the triangle).
  auto row = [&](auto flip) {
    constexpr bool kFlip = decltype(flip)::value;
    for (int64_t x = lo; x <= hi; ++x) {
      for (int a = 0; a < K; ++a) {
        const size_t ai = static_cast<size_t>(a);
        attr[ai] = wrapTo(kFlip ? off[ai] - acc[ai] : acc[ai] + off[ai], bits);
        acc[ai] += step[ai];
      }
      emit(static_cast<int32_t>((kFlip ? t.ox - x : x + t.ox) & pix_mask), py, static_cast<const int64_t*>(attr.data()));
    }
  };
  if (t.flip) row(std::true_type{});
  else row(std::false_type{});
}

// singleRow's fragments as one RowRun when they form one: the value singleRow emits at x = lo
// plus (hi - lo) times the step, in exact integers, fits AttrBits. The emitted value is the
// plane (affine in x) mod 2^AttrBits, so that end is then the value emitted at x = hi, and both
// ends lie in the same window of 2^AttrBits values; the plane being monotonic, so does every
// value in between, and fragment i shows a0 + i da with no further wrap. (Setup makes every
// value fit, so a row that is not one run is a descriptor that setup would not make.) Pixel
// coordinates: both ends within PixBits, so that the mask changes none.
template <int KC, int AB, class RunSink>
inline bool runRow(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t, int64_t w, int64_t lo, int64_t hi,
                   const int64_t* irow, RunSink& emit_run) {
  const int K = KC > 0 ? KC : p.NumAttr, bits = AB > 0 ? AB : p.AttrBits;
  const int64_t pix_lim = int64_t{1} << p.PixBits;
  const int64_t px_lo = t.flip ? t.ox - lo : lo + t.ox, px_hi = t.flip ? t.ox - hi : hi + t.ox;
  const int64_t py = laneRowY(p, d, t, w);
  if (px_lo < 0 || px_lo >= pix_lim || px_hi < 0 || px_hi >= pix_lim || py < 0 || py >= pix_lim) return false;
  const int64_t n1 = hi - lo;
  std::array<int64_t, kMaxAttr> a0, da;  // the first K are set
  for (int a = 0; a < K; ++a) {
    const size_t ai = static_cast<size_t>(a);
    const uint64_t acc = u(irow[ai]) + u(d.didx[ai]) * u(lo - d.xref);
    const uint64_t step = t.flip ? 0 - u(d.didx[ai]) : u(d.didx[ai]);  // in emission order
    const int64_t v_lo = wrapTo(t.flip ? u(t.aoff[ai]) - acc : acc + u(t.aoff[ai]), bits);
    // The progression's end v_lo + step n1, exactly, lies in the AttrBits range.
    int64_t span = 0, end = 0;
    if (__builtin_mul_overflow(static_cast<int64_t>(step), n1, &span) || __builtin_add_overflow(v_lo, span, &end) ||
        end != wrapTo(u(end), bits))
      return false;
    a0[ai] = v_lo;
    da[ai] = n1 > 0 ? static_cast<int64_t>(step) : 0;
  }
  emit_run(RowRun{static_cast<int32_t>(px_lo), static_cast<int32_t>(py), t.flip ? -1 : 1, n1 + 1, a0.data(),
                  da.data()});
  return true;
}

// No run consumer: every row fragment by fragment.
struct NoRuns {};

// Whether walkSpanUnit may walk descriptor d (a single lane-triangle t) by stretches of rows
// (plainRows), the renderer's 4 attributes of 32 bits being known: t neither flipped nor
// interleaved, the walk's rows within CoordBits (so w + 1 never wraps), every pixel of t's rows
// and columns within PixBits (runRow's check, once per triangle), and every didx within 32 bits
// (so that runRow's end of a row, v_lo + didx n1 with |n1| < 2^32, is exact in int64_t).
inline bool plainWalk(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t) {
  const int64_t lim = int64_t{1} << (p.CoordBits - 1), pix_lim = int64_t{1} << p.PixBits;
  bool ok = !t.flip && !d.interleave && d.row_first >= -lim && d.row_last < lim && t.clip_x0 + int64_t{t.ox} >= 0 &&
            t.clip_x1 + int64_t{t.ox} < pix_lim && t.row_first + int64_t{t.oy} >= 0 && t.row_last + int64_t{t.oy} < pix_lim;
  for (int a = 0; a < 4; ++a) ok = ok && d.didx[static_cast<size_t>(a)] == wrapTo(u(d.didx[static_cast<size_t>(a)]), 32);
  return ok;
}

// A stretch of walker rows [first, last] of a single lane-triangle t over which the same edges
// bound its span and the same edges step; left, right: the bounding edges when they are one
// left and one right edge and the rows are t's (else -1).
struct RowStretch {
  int64_t last = 0;
  int left = -1, right = -1;
  bool step_left = false, step_right = false;
};
inline RowStretch rowStretch(const SpanLaneTri& t, int64_t first, int64_t row_last) {
  RowStretch s;
  s.last = row_last;
  auto cut = [&](int64_t r) {  // what held changes at row r
    if (r > first && r - 1 < s.last) s.last = r - 1;
  };
  cut(t.row_first);
  cut(int64_t{t.row_last} + 1);
  const bool in_t = t.row_first <= first && first <= t.row_last;
  int lefts = 0, rights = 0;
  for (int k = 0; k < 3; ++k) {
    const SpanEdge& g = t.edge[k];
    if (g.row_first > g.row_last) continue;  // an unused slot
    cut(g.row_first);
    cut(g.row_last);  // its last row bounds without a step
    cut(int64_t{g.row_last} + 1);
    if (first < g.row_first || first > g.row_last) continue;
    (g.right ? s.right : s.left) = k;
    ++(g.right ? rights : lefts);
    (g.right ? s.step_right : s.step_left) = first < g.row_last;
  }
  if (!in_t || lefts != 1 || rights != 1) s.left = s.right = -1;
  return s;
}

// walkSpanUnit's rows w .. s.last of a single lane-triangle t that plainWalk accepts, over a
// stretch with one left and one right edge: the same ROW cycles, runs, fragments and counts
// as its row-by-row walk, without the tests that the stretch and plainWalk settle once. The
// run's values are runRow's for flip 0 and 32-bit attributes, written out: calling runRow
// itself here made a Gouraud frame 4-9 % slower (interleaved, 4 rounds).
template <class Sink, class RunSink>
void plainRows(const SpanParams& p, const SpanDesc& d, const SpanLaneTri& t, const RowStretch& s, int64_t w,
               SpanDdaState* e, int64_t* irow, SpanWalk& walk, SpanStream& timing, Sink& emit, RunSink& emit_run) {
  const SpanEdge &gl = t.edge[s.left], &gr = t.edge[s.right];
  SpanDdaState &el = e[s.left], &er = e[s.right];
  const int L = p.LanesPerTri;
  std::array<int64_t, 4> a0, da;
  for (; w <= s.last; ++w) {
    ++walk.row_cycles;
    uint64_t groups = 0;
    const int64_t lo = std::max<int64_t>(t.clip_x0, el.q), hi = std::min<int64_t>(t.clip_x1, -er.q);
    if (lo <= hi) {
      const int64_t xg0 = firstGroup(p, lo), n1 = hi - lo;
      groups = static_cast<uint64_t>(L == 1 ? hi - xg0 + 1 : (hi - xg0) / L + 1);
      walk.span_cycles += groups;
      bool whole = true;  // runRow's test: the row's end value fits 32 bits
      for (size_t a = 0; a < 4; ++a) {
        a0[a] = wrapTo(u(irow[a]) + u(d.didx[a]) * u(lo - d.xref) + u(t.aoff[a]), 32);
        const int64_t end = a0[a] + d.didx[a] * n1;  // exact: |didx| <= 2^31, 0 <= n1 < 2^32
        whole = whole && end == wrapTo(u(end), 32);
        da[a] = n1 > 0 ? d.didx[a] : 0;
      }
      if (whole)
        emit_run(RowRun{static_cast<int32_t>(lo + t.ox), static_cast<int32_t>(w + t.oy), 1, n1 + 1, a0.data(), da.data()});
      else
        singleRow<4, 32>(p, d, t, w, lo, hi, irow, emit);
      walk.fragments += static_cast<uint64_t>(n1 + 1);
    }
    if (p.RowAhead) timing.row(groups);
    if (s.step_left) stepEdge(gl, el, p.CoordBits);
    if (s.step_right) stepEdge(gr, er, p.CoordBits);
    for (size_t a = 0; a < 4; ++a) irow[a] = wrapTo(u(irow[a]) + u(d.didy[a]), 32);
  }
}

}  // namespace span_detail

// The fragments of one descriptor, in the order SpanUnitModel hands them over with out_ready
// always 1, each passed to emit(x, y, attr) (attr: NumAttr codes, valid during the call), and
// the cycles counted as runSpanUnit counts them. See walkSpanUnit in raster/span_unit.h. The
// full-rate unit (RowAhead): the cycles are those the descriptor adds to `stream` (a stream of
// descriptors back to back), or without one those of the descriptor alone.
// With a run consumer, a row of a single lane-triangle (serial, evenodd, segments) whose
// values provably do not wrap goes to run_consumer(const RowRun&) instead, as one run (the
// same fragments; the consumer's own loop over them; see RowRun); other rows as above.
template <class Sink, class RunSink = span_detail::NoRuns>
SpanWalk walkSpanUnit(const SpanParams& p, const SpanDesc& d, Sink&& consumer, RunSink&& run_consumer = {},
                      SpanStream* stream = nullptr) {
  using namespace span_detail;
  // A local copy of the consumer (a closure of pointers and references): the compiler may then
  // keep what it captured in registers across the consumer's own stores (a byte store may
  // alias any object whose address has escaped, such as the caller's closure).
  std::decay_t<Sink> emit(consumer);
  std::decay_t<RunSink> emit_run(run_consumer);
  checkDescriptor(p, d);
  const int L = p.LanesPerTri, T = p.NumTri, K = p.NumAttr;
  SpanWalk walk;
  SpanStream alone;
  SpanStream& timing = stream != nullptr ? *stream : alone;
  const uint64_t stream_end = timing.end();
  uint64_t groups = 0;  // the lane groups (SPAN cycles) of the current row
  std::array<SpanDdaState, kMaxLaneTri * 3> e;  // the first 3 T set here, the rest left uninitialised
  for (int j = 0; j < T; ++j)
    for (int s = 0; s < 3; ++s) {
      const SpanEdge& g = d.tri[static_cast<size_t>(j)].edge[s];
      e[static_cast<size_t>(j * 3 + s)] = {g.q, g.r};
    }
  std::array<int64_t, kMaxAttr> irow;  // the first K set here
  std::copy(d.iref.begin(), d.iref.end(), irow.begin());
  // The ROW cycle's updates: the edges, the row's attribute base. KC and AB as in singleRow.
  auto stepRow = [&](int64_t w, auto kc, auto ab) {
    constexpr int KC = decltype(kc)::value, AB = decltype(ab)::value;
    for (int j = 0; j < T; ++j)
      stepEdges(d.tri[static_cast<size_t>(j)], w, &e[static_cast<size_t>(j) * 3], p.CoordBits);
    for (int a = 0; a < (KC > 0 ? KC : K); ++a) {
      const size_t ai = static_cast<size_t>(a);
      irow[ai] = wrapTo(u(irow[ai]) + u(d.didy[ai]), AB > 0 ? AB : p.AttrBits);
    }
  };
  // One lane-triangle (serial, evenodd, segments): the lanes of successive cycles take
  // successive columns, so the fragments come in x order, and lane i of the cycle at xg shows
  // the plane at x = xg + i (icur + i didx, all mod 2^AttrBits): one accumulator.
  auto singleLaneRow = [&](int64_t w, auto kc, auto ab) {
    constexpr int KC = decltype(kc)::value, AB = decltype(ab)::value;
    const SpanLaneTri& t = d.tri[0];
    int64_t lo = 0, hi = 0;
    if (!laneRowBounds(t, w, e.data(), lo, hi)) return;
    const int64_t xg0 = firstGroup(p, lo);
    groups = static_cast<uint64_t>(L == 1 ? hi - xg0 + 1 : (hi - xg0) / L + 1);  // no division in serial
    walk.span_cycles += groups;
    bool ran = false;
    if constexpr (!std::is_same_v<std::decay_t<RunSink>, NoRuns>)
      ran = runRow<KC, AB>(p, d, t, w, lo, hi, irow.data(), emit_run);
    if (!ran) singleRow<KC, AB>(p, d, t, w, lo, hi, irow.data(), emit);
    walk.fragments += static_cast<uint64_t>(hi - lo + 1);
  };
  // Several lane-triangles (sierpinski): lane by lane, cycle by cycle.
  std::array<int64_t, kMaxLaneTri> lo{}, hi{};
  std::array<bool, kMaxLaneTri> ne{};
  std::array<int64_t, kMaxAttr> attr;
  auto laneTrianglesRow = [&](int64_t w) {
    int64_t xs = 0, xe = 0;
    if (!unionRowBounds(d.tri.data(), T, w, e.data(), lo.data(), hi.data(), ne.data(), xs, xe)) return;
    int64_t xg = firstGroup(p, xs);
    // The first K set here (zeroed per row here, not per descriptor: that costs more than a
    // row of one lane-triangle).
    std::array<int64_t, kMaxAttr> icur{};
    for (int a = 0; a < K; ++a) {
      const size_t ai = static_cast<size_t>(a);
      icur[ai] = wrapTo(u(irow[ai]) + u(d.didx[ai]) * u(xg - d.xref), p.AttrBits);
    }
    for (;;) {  // SPAN cycles
      ++walk.span_cycles;
      ++groups;
      for (int j = 0; j < T; ++j) {
        const size_t ju = static_cast<size_t>(j);
        if (!ne[ju]) continue;
        for (int i = 0; i < L; ++i) {
          const int64_t x = xg + i;
          if (x < lo[ju] || x > hi[ju]) continue;
          int32_t px = 0, py = 0;
          laneFragment(p, d, d.tri[ju], x, w, icur.data(), i, px, py, attr.data());
          emit(px, py, static_cast<const int64_t*>(attr.data()));
          ++walk.fragments;
        }
      }
      if (xg + L > xe) break;
      xg += L;
      for (int a = 0; a < K; ++a) {
        const size_t ai = static_cast<size_t>(a);
        icur[ai] = wrapTo(u(icur[ai]) + static_cast<uint64_t>(L) * u(d.didx[ai]), p.AttrBits);
      }
    }
  };
  // The ROW cycles, with NumAttr and AttrBits known at compile time when they are the
  // renderer's 4 and 32 (the wraps become sign extensions of the low word).
  // A single lane-triangle with runs (the renderer's serial, evenodd and segment units) by
  // stretches of rows where plainWalk allows it (plainRows), else row by row.
  auto rows = [&](auto kc, auto ab) {
    constexpr bool kPlain = decltype(kc)::value == 4 && decltype(ab)::value == 32 && !std::is_same_v<std::decay_t<RunSink>, NoRuns>;
    const bool plain = kPlain && T == 1 && plainWalk(p, d, d.tri[0]);
    for (int64_t w = d.row_first;; w = wrapTo(u(w + 1), p.CoordBits)) {
      if constexpr (kPlain) {
        const RowStretch s = plain ? rowStretch(d.tri[0], w, d.row_last) : RowStretch{};
        if (s.left >= 0) {
          plainRows(p, d, d.tri[0], s, w, e.data(), irow.data(), walk, timing, emit, emit_run);
          if (s.last == d.row_last) break;
          w = s.last;
          continue;
        }
      }
      ++walk.row_cycles;
      groups = 0;
      if (T == 1) singleLaneRow(w, kc, ab);
      else laneTrianglesRow(w);
      if (p.RowAhead) timing.row(groups);
      stepRow(w, kc, ab);
      if (w == d.row_last) break;
    }
  };
  if (K == 4 && p.AttrBits == 32) rows(std::integral_constant<int, 4>{}, std::integral_constant<int, 32>{});
  else rows(std::integral_constant<int, 0>{}, std::integral_constant<int, 0>{});
  // The paper's unit: the IDLE cycle accepting the descriptor, its ROW and SPAN cycles.
  walk.cycles = p.RowAhead ? timing.end() - stream_end : 1 + walk.row_cycles + walk.span_cycles;
  return walk;
}

}  // namespace shd
