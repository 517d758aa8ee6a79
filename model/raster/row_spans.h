// Small screen triangles set up straight to the rows the span unit shows: for a unit of a single
// lane-triangle (NumTri 1: serial, evenodd, the segments, and their full-rate units) with 4
// attributes of 32 bits, the renderer's unit, a triangle of at most RowSpans::kMaxRows rows is
// set up to its rows' spans [lo, hi] and its attribute plane, instead of a span descriptor
// (raster/setup.h) that the walk (raster/span_walk.h) then turns into the same rows.
//
// The same fragments, values and cycles, by construction:
//   - the vertices, the attribute codes, the edge functions with their top-left bias and the
//     plane's codes are setup's (the same exact integer operations, raster/exact_int.h);
//   - a row's span is every pixel of the viewport whose centre passes the three biased edge
//     functions (raster/setup.h: rasterizeReference's set), each edge's bound found by its DDA
//     from the first row. The unit tests only the edges active in a row (whose vertical extent
//     holds the row's centre); the third one's half-plane holds the span of the other two,
//     since a centre on the row inside both and on the third edge's line would lie on that
//     edge, so within its extent: the same pixels. (Its extended line's bound may lie far away;
//     the DDA's values are exact in 64 bits here, where the unit's registers would wrap.)
//   - the rows are trimmed to the first and the last with a pixel, as setup trims them; rows
//     in between without a pixel stay (a ROW cycle each);
//   - a covered pixel's attribute is the plane there, exactly: the triangle is taken only when
//     the plane fits 32 bits at the corners of its pixels' bounding box (so at every covered
//     pixel, the plane being affine), where the unit's values mod 2^32 are these;
//   - the cycles (countRowSpans) are the walk's: a ROW cycle per row, the lane groups of each
//     row, the IDLE cycle, or the full-rate unit's stream fed row by row.
// setupRowSpans declines (General) whatever it does not settle itself: a vertex or attribute
// setup refuses (the caller's setupTriangle then says why), a larger triangle, a plane or a
// DDA step that does not fit its narrow formats. Test RowSpans.* compares it with setup and the
// walk on the generator's triangles and on slivers, and Render.RowSpansEqualTheSpanWalk whole
// frames.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>

#include "raster/setup.h"
#include "raster/span_unit.h"

namespace shd {

struct RowSpans {
  static constexpr int kMaxRows = 64;
  struct Vertex {
    double x = 0, y = 0;         // pixels, y down
    std::array<double, 4> attr;  // in the attribute's units, as SetupVertex::attr
  };
  int32_t y0 = 0, rows = 0;  // screen rows y0 .. y0 + rows - 1; the first and the last hold a pixel
  int32_t x0 = 0;            // span[0]'s lo: the first pixel, (x0, y0)
  std::array<int64_t, 4> a0;            // the attribute codes at the first pixel
  std::array<int64_t, 4> didx, didy;    // the plane's gradients (SetupResult::plane's), within int32_t
  uint32_t fragments = 0;  // the pixels of the rows
  uint32_t groups = 0;     // the unit's lane groups (SPAN cycles of the paper's unit) over the rows
  std::array<std::array<int16_t, 2>, kMaxRows> span;  // [lo, hi] of row y0 + i; lo > hi: no pixel
  // Attribute k at pixel x of row y0 + i, a pixel of the triangle: exact, the plane fitting
  // int32_t there.
  int64_t at(size_t k, int64_t x, int32_t i) const { return a0[k] + didx[k] * (x - x0) + didy[k] * i; }
};

// What setupRowSpans needs of a raster configuration, once per frame.
struct RowSpansConfig {
  // The unit is of one lane-triangle with 4 attributes of 32 bits, and the viewport and the
  // guard band are within the bounds setupRowSpans's arithmetic assumes (int16_t columns,
  // subpixel coordinates below 2^29).
  bool applies = false;
  int S = 4, W = 0, H = 0;
  int lane_shift = 0;        // log2 LanesPerTri
  bool align_lanes = false;  // AlignLanes
  int64_t k_lim = 0;                 // |DDA step k| < 2^(CoordBits - 1): setup's register bound
  double guard = 0;                  // setup's guard band, px
  std::array<int, 4> frac{};         // the attributes' fraction bits
  std::array<double, 4> scale{};     // 2^frac
  double lim = 0;                    // setup's bound of |attribute 2^frac|
  // The plane of the 4 attributes in AVX2 lanes, where the magnitudes allow (the same integers;
  // set only where the CPU has AVX2: the renderer's Frame::avx2).
  bool vector = false;
  // Its row loop in AVX-512 as well (set only where the CPU has AVX-512 and vector holds).
  bool avx512 = false;
  explicit RowSpansConfig(const RasterConfig& cfg);
};

enum class RowSpansSetup {
  Drawn,    // `out` holds it
  Dropped,  // setup drops it: zero area, or no pixel centre inside it in the viewport
  General,  // not settled here: set it up with setupTriangle
};
RowSpansSetup setupRowSpans(const std::array<RowSpans::Vertex, 3>& v, const RowSpansConfig& c, RowSpans& out);
// setupRowSpans of the n triangles v[0 .. n - 1] into out[i] and got[i]: the same outcomes and
// rows' spans. Where the vector kernels run (RowSpansConfig::vector), 8 triangles at a time up to
// their edges' DDAs, one in each 64-bit lane of AVX-512 (RowSpansConfig::avx512: in integers,
// then their planes together) or 4 in each pass of AVX2 (in doubles, where they hold the
// integers exactly; then the planes one triangle at a time).
void setupRowSpansBlock(const std::array<RowSpans::Vertex, 3>* v, size_t n, const RowSpansConfig& c, RowSpans* out,
                        RowSpansSetup* got);

// The cycles and fragments walkSpanUnit counts for the descriptor setup makes of the same
// triangle (p: the unit, NumTri 1), the full-rate unit's on `stream` (as walkSpanUnit's).
SpanWalk countRowSpans(const SpanParams& p, const RowSpans& s, SpanStream* stream);

// The rows y0 .. y1 - 1 of s as rows' spans of their own (the same pixels and attribute codes
// there; groups left 0: for drawing, not for counting): false when none of them holds a pixel.
// The rows past out.rows, to the next multiple of 8, hold no pixel.
inline bool sliceRowSpans(const RowSpans& s, int32_t y0, int32_t y1, RowSpans& out) {
  auto empty = [&s](int32_t i) { return s.span[static_cast<size_t>(i)][0] > s.span[static_cast<size_t>(i)][1]; };
  int32_t a = std::max(y0 - s.y0, 0), b = std::min(y1 - s.y0, s.rows);  // rows a .. b - 1 of s
  while (a < b && empty(a)) ++a;
  while (b > a && empty(b - 1)) --b;
  if (a >= b) return false;
  out.y0 = s.y0 + a;
  out.rows = b - a;
  out.x0 = s.span[static_cast<size_t>(a)][0];
  for (size_t k = 0; k < 4; ++k) out.a0[k] = s.at(k, out.x0, a);
  out.didx = s.didx;
  out.didy = s.didy;
  out.fragments = 0;
  out.groups = 0;
  for (int32_t i = a; i < b; ++i) {
    const auto& sp = s.span[static_cast<size_t>(i)];
    out.span[static_cast<size_t>(i - a)] = sp;
    if (sp[0] <= sp[1]) out.fragments += static_cast<uint32_t>(sp[1] - sp[0] + 1);
  }
  for (int32_t i = out.rows; i % 8 != 0; ++i) out.span[static_cast<size_t>(i)] = {1, 0};
  return true;
}

// The rows' fragments as walkSpanUnit hands them to a run consumer: one RowRun per row with a
// pixel, top to bottom, each left to right; only the screen rows y where keep(y) holds.
struct AllRows {
  bool operator()(int32_t) const { return true; }
};
template <class RunSink, class Keep = AllRows>
inline void emitRowSpans(const RowSpans& s, RunSink& run, Keep keep = {}) {
  std::array<int64_t, 4> a, da;
  for (int32_t i = 0; i < s.rows; ++i) {
    const int64_t lo = s.span[static_cast<size_t>(i)][0], hi = s.span[static_cast<size_t>(i)][1];
    if (lo > hi || !keep(s.y0 + i)) continue;
    for (size_t k = 0; k < 4; ++k) {
      a[k] = s.at(k, lo, i);
      da[k] = hi > lo ? s.didx[k] : 0;
    }
    run(RowRun{static_cast<int32_t>(lo), s.y0 + i, 1, hi - lo + 1, a.data(), da.data()});
  }
}

}  // namespace shd
