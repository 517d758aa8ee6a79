// The row spans of small triangles (raster/row_spans.h) against setup and the walk: the same
// triangles dropped, the same fragments in the same order with the same values, the same
// cycles, on the generator's triangles and on hand-made edge cases, in every mode of one
// lane-triangle (the paper's units and the full-rate ones).
#include "test_util.h"
#include "raster/desc_stream.h"
#include "raster/row_spans.h"
#include "raster/setup.h"
#include "raster/span_walk.h"
#include "raster/trigen.h"
#include "render/fixed_simd.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <random>

#include <fmt/format.h>

using namespace shd;
using shd::testutil::spanModes;
using shd::testutil::spanParams;

namespace {

// The renderer's raster configuration (render/render.cpp): colour in LSBs with 12 fraction
// bits, depth with 28.
RasterConfig rendererConfig(const std::string& mode, int w = 512, int h = 512) {
  RasterConfig c;
  c.width = w;
  c.height = h;
  c.unit = spanParams(mode);
  c.attr_frac_bits = {12, 12, 12, 28};
  c.validate();
  return c;
}

struct Frag {
  int32_t x, y;
  std::array<int64_t, 4> a;
  bool operator==(const Frag& o) const { return x == o.x && y == o.y && a == o.a; }
};

// Expands runs (and single fragments) into fragments, in order.
struct Collect {
  std::vector<Frag>& out;
  void operator()(int32_t x, int32_t y, const int64_t* a) { out.push_back({x, y, {a[0], a[1], a[2], a[3]}}); }
  void operator()(const RowRun& r) {
    for (int64_t i = 0; i < r.count; ++i)
      out.push_back({static_cast<int32_t>(r.x0 + i * r.dx), r.y,
                     {r.a0[0] + i * r.da[0], r.a0[1] + i * r.da[1], r.a0[2] + i * r.da[2], r.a0[3] + i * r.da[3]}});
  }
};

struct Tally {
  std::map<RowSpansSetup, long> outcome;
  long drawn_by_setup = 0;
};

// One triangle both ways; the streams carry the full-rate unit's timing from triangle to
// triangle. Returns a description of the first difference, or "".
std::string compare(const std::array<SetupVertex, 3>& sv, const RasterConfig& cfg, const RowSpansConfig& rc,
                    SpanStream& walk_stream, SpanStream& spans_stream, Tally& tally) {
  std::array<RowSpans::Vertex, 3> rv;
  for (size_t i = 0; i < 3; ++i) {
    rv[i].x = sv[i].x;
    rv[i].y = sv[i].y;
    for (size_t k = 0; k < 4; ++k) rv[i].attr[k] = sv[i].attr[k];
  }
  RowSpans spans;
  const RowSpansSetup got = setupRowSpans(rv, rc, spans);
  ++tally.outcome[got];
  SetupResult s;
  try {
    s = setupTriangle(sv, 1, cfg);
  } catch (const std::exception& e) {
    return got == RowSpansSetup::General ? "" : fmt::format("setup throws ({}) but the row spans took it", e.what());
  }
  if (s.desc) ++tally.drawn_by_setup;
  if (got == RowSpansSetup::General) {
    // Set up and walked alone, on both streams (the renderer's frame feeds its one stream so).
    auto none = [](int32_t, int32_t, const int64_t*) {};
    if (s.desc && cfg.unit.RowAhead) {
      walkSpanUnit(cfg.unit, *s.desc, none, span_detail::NoRuns{}, &walk_stream);
      walkSpanUnit(cfg.unit, *s.desc, none, span_detail::NoRuns{}, &spans_stream);
    }
    return "";
  }
  if (got == RowSpansSetup::Dropped) return s.desc ? "row spans drop a triangle setup keeps" : "";
  if (!s.desc) return fmt::format("row spans keep a triangle setup drops ({})", s.dropped);
  std::vector<Frag> want, have;
  Collect cw{want}, ch{have};
  SpanStream* ws = cfg.unit.RowAhead ? &walk_stream : nullptr;
  SpanStream* ss = cfg.unit.RowAhead ? &spans_stream : nullptr;
  const SpanWalk w = walkSpanUnit(cfg.unit, *s.desc, cw, cw, ws);
  emitRowSpans(spans, ch);
  const SpanWalk c = countRowSpans(cfg.unit, spans, ss);
  if (want.size() != have.size()) return fmt::format("{} fragments, the walk {}", have.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i)
    if (!(want[i] == have[i]))
      return fmt::format("fragment {}: ({}, {}) [{} {} {} {}], the walk ({}, {}) [{} {} {} {}]", i, have[i].x, have[i].y,
                         have[i].a[0], have[i].a[1], have[i].a[2], have[i].a[3], want[i].x, want[i].y, want[i].a[0],
                         want[i].a[1], want[i].a[2], want[i].a[3]);
  if (c.cycles != w.cycles || c.fragments != w.fragments || c.row_cycles != w.row_cycles || c.span_cycles != w.span_cycles)
    return fmt::format("cycles {} rows {} spans {} fragments {}, the walk {} {} {} {}", c.cycles, c.row_cycles,
                       c.span_cycles, c.fragments, w.cycles, w.row_cycles, w.span_cycles, w.fragments);
  if (s.desc->row_first != spans.y0 || s.desc->row_last != spans.y0 + spans.rows - 1)
    return fmt::format("rows {}..{}, setup {}..{}", spans.y0, spans.y0 + spans.rows - 1, s.desc->row_first,
                       s.desc->row_last);
  for (size_t k = 0; k < 4; ++k)
    if (spans.didx[k] != s.plane.didx[k] || spans.didy[k] != s.plane.didy[k])
      return fmt::format("attribute {}: gradients {} {}, setup {} {}", k, spans.didx[k], spans.didy[k], s.plane.didx[k],
                         s.plane.didy[k]);
  return "";
}

std::string describe(const std::array<SetupVertex, 3>& v) {
  return fmt::format("({}, {}) ({}, {}) ({}, {}) attributes [{} {} {} {}] [{} {} {} {}] [{} {} {} {}]", v[0].x, v[0].y,
                     v[1].x, v[1].y, v[2].x, v[2].y, v[0].attr[0], v[0].attr[1], v[0].attr[2], v[0].attr[3], v[1].attr[0],
                     v[1].attr[1], v[1].attr[2], v[1].attr[3], v[2].attr[0], v[2].attr[1], v[2].attr[2], v[2].attr[3]);
}

// The modes of one lane-triangle, where the row spans apply.
std::vector<std::string> singleLaneModes() {
  std::vector<std::string> out;
  for (const std::string& m : spanModes())
    if (spanParams(m).NumTri == 1) out.push_back(m);
  return out;
}

}  // namespace

TEST(RowSpans, EqualSetupAndTheWalkOnGeneratorTriangles) {
  const std::vector<std::string> modes = singleLaneModes();
  ASSERT_GE(modes.size(), 8u);  // serial, evenodd, seg2, seg4, seg8, and full-rate units
  for (size_t mi = 0; mi < modes.size(); ++mi) {
    const std::string& m = modes[mi];
    const RasterConfig cfg = rendererConfig(m);
    RowSpansConfig rc(cfg);
    ASSERT_TRUE(rc.applies) << m;
    // The scalar plane and row loop, the AVX2 ones, and the AVX-512 row loop, in turn.
    rc.vector = mi % 3 != 0 && fixed_simd::availableAvx2();
    rc.avx512 = mi % 3 == 2 && fixed_simd::available();
    TriangleGenerator gen(31);
    SpanStream ws, ss;
    Tally tally;
    for (int n = 0; n < 20000; ++n) {
      const GenTriangle t = gen.next();
      const std::array<SetupVertex, 3> sv = toSetupVertices(t, 4);
      const std::string diff = compare(sv, cfg, rc, ws, ss, tally);
      ASSERT_EQ(diff, "") << m << " " << t.kind() << " " << describe(sv);
      ASSERT_EQ(ws.end(), ss.end()) << m << " triangle " << n;
    }
    // Most of the generator's triangles are small: the comparison above is not vacuous.
    EXPECT_GT(tally.outcome[RowSpansSetup::Drawn], tally.drawn_by_setup * 9 / 10) << m;
    EXPECT_GT(tally.outcome[RowSpansSetup::Dropped], 500) << m;
    EXPECT_GT(tally.outcome[RowSpansSetup::General], 0) << m;  // the large and the screen class
  }
}

TEST(RowSpans, FullRateStreamOfSmallTrianglesKeepsItsTiming) {
  // Small triangles only, so that every one takes the row spans, the stream's timing carried
  // from each to the next.
  TriGenOptions opt;
  opt.size_weight = {0.4, 0.3, 0.3, 0, 0};
  opt.shape_weight = {0.3, 0, 0.15, 0.05, 0.1, 0.2};  // no slivers (their gradients may leave 32 bits)
  for (const std::string& m : singleLaneModes()) {
    if (spanParams(m).RowAhead == 0) continue;
    const RasterConfig cfg = rendererConfig(m);
    const RowSpansConfig rc(cfg);
    TriangleGenerator gen(32, opt);
    SpanStream ws, ss;
    Tally tally;
    for (int n = 0; n < 5000; ++n) {
      const std::array<SetupVertex, 3> sv = toSetupVertices(gen.next(), 4);
      ASSERT_EQ(compare(sv, cfg, rc, ws, ss, tally), "") << m << " " << describe(sv);
      ASSERT_EQ(ws.end(), ss.end()) << m << " triangle " << n;
    }
    EXPECT_EQ(tally.outcome[RowSpansSetup::General], 0) << m;
    EXPECT_GT(ws.end(), 15000u) << m;  // a stream of thousands of rows
  }
}

TEST(RowSpans, EqualSetupAndTheWalkOnSliversAndViewportEdges) {
  // A small viewport, triangles around and across its edges, on pixel corners and centres,
  // slivers, and every attribute range end.
  std::mt19937_64 rng(33);
  std::uniform_real_distribution<double> u(0, 1);
  for (const std::string& m : {std::string("serial"), std::string("evenodd"), std::string("seg4full")})
    for (const bool avx512 : {false, true}) {
      const RasterConfig cfg = rendererConfig(m, 64, 48);
      RowSpansConfig rc(cfg);
      rc.vector = fixed_simd::availableAvx2();  // the renderer's plane (the scalar one: the test above)
      rc.avx512 = avx512 && fixed_simd::available();  // and its row loop, AVX2 or AVX-512
      SpanStream ws, ss;
      Tally tally;
      for (int n = 0; n < 20000; ++n) {
        const int kind = static_cast<int>(rng() % 5);
        const double cx = u(rng) * 90 - 13, cy = u(rng) * 68 - 10, r = kind == 0 ? 1.5 : (kind == 1 ? 30 : 6);
        std::array<SetupVertex, 3> v;
        for (SetupVertex& x : v) {
          x.x = cx + (u(rng) * 2 - 1) * r;
          x.y = cy + (u(rng) * 2 - 1) * r;
          if (kind == 2) x.x = std::round(x.x), x.y = std::round(x.y);
          if (kind == 3) x.x = std::round(x.x) + 0.5, x.y = std::round(x.y) + 0.5;
          const double ends[] = {0, 255, u(rng) * 255};
          x.attr = {ends[rng() % 3], ends[rng() % 3], ends[rng() % 3], rng() % 2 ? 1.0 : u(rng)};
        }
        if (kind == 4) {  // a sliver: the third vertex a hair off the first edge's midpoint
          v[2].x = v[0].x + (v[1].x - v[0].x) * 0.5 + (u(rng) - 0.5) * 0.05;
          v[2].y = v[0].y + (v[1].y - v[0].y) * 0.5;
        }
        ASSERT_EQ(compare(v, cfg, rc, ws, ss, tally), "") << m << " " << describe(v);
      }
      EXPECT_GT(tally.outcome[RowSpansSetup::Drawn], 8000) << m;
      EXPECT_GT(tally.outcome[RowSpansSetup::Dropped], 1000) << m;
    }
}

// The plane in AVX2 lanes (RowSpansConfig::vector), with the AVX2 row loop and with the AVX-512
// one (RowSpansConfig::avx512, where the CPU has it), against the scalar ones: the same outcome and
// every field of the rows' spans, on triangles small, wide (out to the guard band) and tall (from
// far above into the first rows: few rows, large coordinate differences), with attributes over
// their whole range (the plane's magnitudes beyond where the vector path declines), small
// integers (remainders of exactly half a step: the ties of round-half-even) or the renderer's.
namespace {
// Two triangles' rows' spans the same: their rows, first pixel, fragments and lane groups, plane,
// and every row's span.
testing::AssertionResult sameRowSpans(const RowSpans& a, const RowSpans& b) {
  if (!(a.y0 == b.y0 && a.rows == b.rows && a.x0 == b.x0 && a.fragments == b.fragments && a.groups == b.groups))
    return testing::AssertionFailure() << "rows, first pixel or counts differ";
  if (a.a0 != b.a0 || a.didx != b.didx || a.didy != b.didy) return testing::AssertionFailure() << "planes differ";
  for (int32_t i = 0; i < a.rows; ++i)
    if (a.span[static_cast<size_t>(i)] != b.span[static_cast<size_t>(i)])
      return testing::AssertionFailure() << "row " << i << " differs";
  return testing::AssertionSuccess();
}
// The n triangles v set up by setupRowSpansBlock with c: each outcome want[t], and where Drawn,
// rows' spans the same as ref[t]. first: the number of v[0] among the test's triangles.
testing::AssertionResult blockEquals(const std::array<RowSpans::Vertex, 3>* v, size_t n, const RowSpansConfig& c,
                                     const RowSpans* ref, const RowSpansSetup* want, int first) {
  std::vector<RowSpans> out(n);
  std::vector<RowSpansSetup> got(n);
  setupRowSpansBlock(v, n, c, out.data(), got.data());
  for (size_t t = 0; t < n; ++t) {
    const int number = first + static_cast<int>(t);
    if (got[t] != want[t])
      return testing::AssertionFailure() << "block triangle " << number << ": outcome " << static_cast<int>(got[t])
                                         << ", setupRowSpans " << static_cast<int>(want[t]);
    if (got[t] != RowSpansSetup::Drawn) continue;
    const testing::AssertionResult same = sameRowSpans(ref[t], out[t]);
    if (!same) return testing::AssertionFailure() << "block triangle " << number << ": " << same.message();
  }
  return testing::AssertionSuccess();
}
}  // namespace

TEST(RowSpans, VectorPlaneEqualsTheScalarOne) {
  if (!fixed_simd::availableAvx2()) GTEST_SKIP() << "no AVX2 (or SHD_SCALAR set)";
  const RasterConfig cfg = rendererConfig("serial");
  RowSpansConfig scalar(cfg), vector(cfg), wide(cfg);
  vector.vector = true;
  wide.vector = true;
  wide.avx512 = fixed_simd::available();
  std::mt19937_64 rng(35);
  std::uniform_real_distribution<double> u(0, 1);
  const double lim[4] = {scalar.lim / scalar.scale[0], scalar.lim / scalar.scale[1], scalar.lim / scalar.scale[2],
                         scalar.lim / scalar.scale[3]};
  std::map<RowSpansSetup, long> outcome;
  long exact_planes = 0;
  std::vector<std::array<RowSpans::Vertex, 3>> block_in;
  std::vector<RowSpans> block_ref;
  std::vector<RowSpansSetup> block_got;
  for (int n = 0; n < 300000; ++n) {
    // Where: small, wide (out to the guard band on both sides) or tall (from far above into
    // the first rows); the attributes: over their whole range, small integers, the renderer's,
    // or codes a x + b y + c of the pixel (x, y) with integers a, b, c and the vertices at whole
    // pixels, whose gradients are the exact quotients a and b.
    const int where = static_cast<int>(rng() % 3), what = static_cast<int>(rng() % 4);
    const double r = 1 + u(rng) * 30, cx = 20 + u(rng) * 470, cy = 20 + u(rng) * 470;
    std::array<int64_t, 4> pa{}, pb{}, pc{};  // the codes pa x + pb y + pc
    for (size_t k = 0; k < 4; ++k) {
      const int bits = static_cast<int>(rng() % 18);  // |a|, |b| <= 2^bits (codes past setup's bound: General)
      pa[k] = static_cast<int64_t>(rng() % ((uint64_t{2} << bits) + 1)) - (int64_t{1} << bits);
      pb[k] = static_cast<int64_t>(rng() % ((uint64_t{2} << bits) + 1)) - (int64_t{1} << bits);
      pc[k] = static_cast<int64_t>(rng() % (uint64_t{1} << 28)) - (int64_t{1} << 27);
    }
    std::array<RowSpans::Vertex, 3> v;
    for (size_t i = 0; i < 3; ++i) {
      RowSpans::Vertex& x = v[i];
      x.x = cx + (u(rng) * 2 - 1) * (where == 0 ? r : 8000);
      x.y = where == 1 ? cy + (u(rng) * 2 - 1) * 30 : (where == 2 ? u(rng) * 40 : cy + (u(rng) * 2 - 1) * r);
      if (where == 2 && i == 0) x.y = -8000 * u(rng);
      if (what == 3) {
        x.x = std::round(x.x);
        x.y = std::round(x.y);
      }
      for (size_t k = 0; k < 4; ++k) {
        if (what == 0) x.attr[k] = (u(rng) * 2 - 1) * lim[k];
        else if (what == 1) x.attr[k] = static_cast<double>(rng() % 7) / scalar.scale[k];
        else if (what == 2) x.attr[k] = (k < 3 ? u(rng) * 255 : u(rng));
        else
          x.attr[k] = static_cast<double>(pa[k] * static_cast<int64_t>(x.x) + pb[k] * static_cast<int64_t>(x.y) +
                                          pc[k]) /
                      scalar.scale[k];
      }
    }
    RowSpans a;
    const RowSpansSetup ga = setupRowSpans(v, scalar, a);
    ++outcome[ga];
    for (const RowSpansConfig* c : {&vector, &wide}) {
      RowSpans b;
      const RowSpansSetup gb = setupRowSpans(v, *c, b);
      ASSERT_EQ(ga, gb) << "triangle " << n << (c->avx512 ? " (AVX-512 rows)" : "");
      if (ga != RowSpansSetup::Drawn) continue;
      ASSERT_TRUE(sameRowSpans(a, b)) << "triangle " << n << (c->avx512 ? " (AVX-512 rows)" : "");
      if (what == 3 && c == &vector) {  // the exact quotients
        ASSERT_EQ(b.didx, pa) << "triangle " << n;
        ASSERT_EQ(b.didy, pb) << "triangle " << n;
        ++exact_planes;
      }
    }
    // The same triangles through setupRowSpansBlock, 13 at a time (a block of 8 and one of 5),
    // in AVX2 (vector) and AVX-512 (wide, where the CPU has it).
    block_in.push_back(v);
    block_ref.push_back(a);
    block_got.push_back(ga);
    if (block_in.size() == 13) {
      for (const RowSpansConfig* c : {&vector, &wide})
        ASSERT_TRUE(blockEquals(block_in.data(), block_in.size(), *c, block_ref.data(), block_got.data(), n - 12))
            << (c->avx512 ? "AVX-512" : "AVX2");
      block_in.clear();
      block_ref.clear();
      block_got.clear();
    }
  }
  EXPECT_GT(outcome[RowSpansSetup::Drawn], 100000);
  EXPECT_GT(outcome[RowSpansSetup::General], 1000);  // the whole range: planes beyond 32 bits
  EXPECT_GT(exact_planes, 20000) << "drawn with exact integer gradients";
}

// The plane's bound on the coordinate differences (below 2^20 subpixels), which the renderer's
// configuration (CoordBits 16: a guard band of 2^13 px) never reaches: with CoordBits 27 (2^24 px)
// slivers across the viewport from a million pixels away, whose attribute codes are planes a x +
// b y + c steep enough in x that the numerators' products pass 2^53 (inexact in doubles) while
// the numerators cancel to below the plane's other bounds. The vector plane (AVX2, and the AVX-512
// block) must give up on them and leave them to the scalar one, as its bound says.
TEST(RowSpans, VectorPlaneLeavesWideCoordinatesToTheScalarOne) {
  if (!fixed_simd::availableAvx2()) GTEST_SKIP() << "no AVX2 (or SHD_SCALAR set)";
  RasterConfig cfg = rendererConfig("serial");
  cfg.unit.CoordBits = 27;  // CoordBits + S = 31, setupRowSpans's limit
  RowSpansConfig scalar(cfg), vector(cfg), wide(cfg);
  ASSERT_TRUE(scalar.applies);
  vector.vector = true;
  wide.vector = true;
  wide.avx512 = fixed_simd::available();
  std::mt19937_64 rng(41);
  std::uniform_real_distribution<double> u(0, 1);
  long wide_drawn = 0;
  std::array<std::array<RowSpans::Vertex, 3>, 8> block;
  std::array<RowSpans, 8> ref;
  std::array<RowSpansSetup, 8> ref_got;
  for (int n = 0; n < 40000; ++n) {
    const size_t t = static_cast<size_t>(n % 8);
    std::array<RowSpans::Vertex, 3>& v = block[t];
    const double reach = std::ldexp(1.0, 16 + static_cast<int>(rng() % 8));  // 2^16 .. 2^23 px
    const double y = 10 + u(rng) * 490;
    v[0].x = 10 + u(rng) * 490;
    v[0].y = y;
    v[1].x = -reach * u(rng);
    v[1].y = y + (u(rng) * 2 - 1) * 3;
    v[2].x = reach * u(rng);
    v[2].y = y + (u(rng) * 2 - 1) * 3;
    for (size_t k = 0; k < 4; ++k) {
      const double a = std::round((u(rng) * 2 - 1) * 0x1p31 / reach), b = std::round((u(rng) * 2 - 1) * 4096);
      for (RowSpans::Vertex& x : v) x.attr[k] = std::round(a * x.x + b * x.y) / scalar.scale[k];
    }
    ref_got[t] = setupRowSpans(v, scalar, ref[t]);
    const bool far = std::max({std::fabs(v[1].x), std::fabs(v[2].x)}) * 16 >= 0x1p20;
    wide_drawn += far && ref_got[t] == RowSpansSetup::Drawn;
    RowSpans b;
    ASSERT_EQ(setupRowSpans(v, vector, b), ref_got[t]) << "triangle " << n;
    if (ref_got[t] == RowSpansSetup::Drawn) {
      ASSERT_TRUE(sameRowSpans(ref[t], b)) << "triangle " << n;
    }
    if (t + 1 < block.size()) continue;
    for (const RowSpansConfig* c : {&vector, &wide})  // the block in AVX2, and in AVX-512 where the CPU has it
      ASSERT_TRUE(blockEquals(block.data(), block.size(), *c, ref.data(), ref_got.data(), n - 7))
          << (c->avx512 ? "AVX-512" : "AVX2");
  }
  EXPECT_GT(wide_drawn, 1000) << "drawn with coordinate differences of 2^20 subpixels and more";
  // Triangles 2^17 .. 2^21 px across in x and in y whose near vertex dips into the viewport's
  // first rows (fewer than RowSpans::kMaxRows of them): edge functions and determinants of 2^40
  // to 2^55, which the AVX2 block takes in doubles up to vertex differences of 2^25 subpixels
  // (2^21 px) and leaves to setupRowSpans whole beyond.
  long huge_drawn = 0;
  for (int n = 0; n < 8000; ++n) {
    const size_t t = static_cast<size_t>(n % 8);
    std::array<RowSpans::Vertex, 3>& v = block[t];
    const double reach = std::ldexp(1.0, 17 + static_cast<int>(rng() % 4));
    v[0].x = 10 + u(rng) * 490;
    v[0].y = 5 + u(rng) * 40;
    v[1].x = -reach * (0.25 + u(rng));
    v[1].y = -reach * (0.25 + u(rng));
    v[2].x = reach * (0.25 + u(rng));
    v[2].y = -reach * (0.25 + u(rng));
    for (size_t k = 0; k < 4; ++k)
      for (RowSpans::Vertex& x : v) x.attr[k] = static_cast<double>(rng() % 64) / scalar.scale[k];
    ref_got[t] = setupRowSpans(v, scalar, ref[t]);
    huge_drawn += ref_got[t] == RowSpansSetup::Drawn;
    if (t + 1 < block.size()) continue;
    for (const RowSpansConfig* c : {&vector, &wide})
      ASSERT_TRUE(blockEquals(block.data(), block.size(), *c, ref.data(), ref_got.data(), n - 7))
          << "huge, " << (c->avx512 ? "AVX-512" : "AVX2");
  }
  EXPECT_GT(huge_drawn, 1000) << "drawn, 2^17 px and more across both ways";
}

// The colour kernels straight from the rows' spans (fixed_simd::colourSpansAvx2 and
// colourSpansAvx512, flat and Gouraud's where the CPU has AVX2 or AVX-512, and colourSpansScalar,
// the scalar paths') against what they replace, the rows' runs (emitRowSpans, as the walk hands
// them over) and a run kernel (of the same instructions; AVX2's for the scalar one): the same
// depth, tag and colour buffers and the same counts, on the generator's triangles drawn one over
// another on a 512 x 512 frame (every other one with a triangle buffer), with colours around
// [0, 255] (every fourth triangle of one colour, as flat's) and depth codes over the whole range;
// the colour codes with the renderer's 12 fraction bits, and 9 (the scalar kernel's other path).
namespace {
void colourSpansEqualRuns(fixed_simd::ColourKernel runs_kernel, fixed_simd::ColourSpansKernel spans_kernel,
                          int frac = 12) {
  const RasterConfig cfg = rendererConfig("serial");
  const RowSpansConfig rc(cfg);
  const size_t W = 512, n = W * 512;
  std::mt19937_64 rng(41);
  std::vector<int32_t> depth_a(n), tri_a(n, -1);
  std::vector<uint8_t> rgb_a(3 * n);
  for (int32_t& d : depth_a) d = rng() % 4 == 0 ? 0 : static_cast<int32_t>(rng() % (uint64_t{1} << 28));
  for (uint8_t& b : rgb_a) b = static_cast<uint8_t>(rng());
  std::vector<int32_t> depth_b = depth_a, tri_b = tri_a;
  std::vector<uint8_t> rgb_b = rgb_a;
  TriangleGenerator gen(41);
  fixed_simd::ColourRuns runs;
  runs.frac = frac;
  long drawn = 0, one_colour = 0;
  uint64_t fragments = 0, passed = 0, covered = 0;
  for (int32_t k = 0; k < 20000; ++k) {
    const std::array<SetupVertex, 3> sv = toSetupVertices(gen.next(), 4);
    std::array<RowSpans::Vertex, 3> v;
    for (size_t i = 0; i < 3; ++i) {
      v[i].x = sv[i].x;
      v[i].y = sv[i].y;
      for (size_t ch = 0; ch < 3; ++ch)
        v[i].attr[ch] = k % 4 == 1 && i > 0 ? v[0].attr[ch] : -20.0 + static_cast<double>(rng() % 2950) / 10;
      v[i].attr[3] = sv[i].attr[3];
    }
    RowSpans s;
    if (setupRowSpans(v, rc, s) != RowSpansSetup::Drawn) continue;
    one_colour += (s.didx[0] | s.didx[1] | s.didx[2] | s.didy[0] | s.didy[1] | s.didy[2]) == 0;
    const bool tags = k % 2 == 0;
    const fixed_simd::Target ta{depth_a.data(), tags ? tri_a.data() : nullptr, k, W};
    const fixed_simd::Target tb{depth_b.data(), tags ? tri_b.data() : nullptr, k, W};
    // One run per row with a pixel, its codes mod 2^32; the steps are the triangle's gradients.
    for (size_t ch = 0; ch < 3; ++ch) runs.dc[ch] = static_cast<int32_t>(s.didx[ch]);
    runs.dz = static_cast<uint32_t>(s.didx[3]);
    runs.n = 0;
    auto row = [&](const RowRun& r) {
      fixed_simd::ColourRuns::Row& out = runs.rows[runs.n++];
      out.p = static_cast<size_t>(r.y) * W + static_cast<size_t>(r.x0);
      out.count = static_cast<size_t>(r.count);
      out.room = W - static_cast<size_t>(r.x0);
      out.z = static_cast<uint32_t>(r.a0[3]);
      for (size_t ch = 0; ch < 3; ++ch) out.c[ch] = static_cast<int32_t>(r.a0[ch]);
    };
    emitRowSpans(s, row);
    uint64_t pa = 0, pb = 0;
    const uint64_t ca = runs_kernel(runs, ta, rgb_a.data(), pa);
    const uint64_t cb = spans_kernel(s, W, runs.frac, tb, rgb_b.data(), pb);
    ASSERT_EQ(cb, ca) << "triangle " << k;
    ASSERT_EQ(pb, pa) << "triangle " << k;
    ++drawn;
    fragments += s.fragments;
    passed += pa;
    covered += ca;
  }
  EXPECT_TRUE(depth_b == depth_a);
  EXPECT_TRUE(tri_b == tri_a);
  EXPECT_TRUE(rgb_b == rgb_a);
  // Not vacuous: most triangles drawn, fragments that pass and fragments that fail, pixels
  // covered anew and over.
  EXPECT_GT(drawn, 15000);
  EXPECT_GT(one_colour, drawn / 5);
  EXPECT_LT(one_colour, drawn / 3);
  EXPECT_GT(passed, fragments / 10);
  EXPECT_LT(passed, fragments * 9 / 10);
  EXPECT_GT(covered, passed / 10);
  EXPECT_LT(covered, passed * 9 / 10);
}
}  // namespace

TEST(RowSpans, ColourSpansEqualSpanRowsAndTheRunKernel) {
  if (!fixed_simd::cpuHasAvx2()) GTEST_SKIP() << "no AVX2 here";
  colourSpansEqualRuns(fixed_simd::colourRunsAvx2, fixed_simd::colourSpansAvx2);
  colourSpansEqualRuns(fixed_simd::colourRunsAvx2, fixed_simd::colourSpansScalar);
  colourSpansEqualRuns(fixed_simd::colourRunsAvx2, fixed_simd::colourSpansScalar, 9);  // its shifts at run time
  if (fixed_simd::cpuHasAvx512()) colourSpansEqualRuns(fixed_simd::colourRunsAvx512, fixed_simd::colourSpansAvx512);
}

TEST(RowSpans, DeclineWhatSetupRefusesOrTheyCannotHold) {
  const RasterConfig cfg = rendererConfig("serial");
  const RowSpansConfig rc(cfg);
  auto vtx = [](double x, double y, std::array<double, 4> a = {10, 20, 30, 0.5}) {
    RowSpans::Vertex v;
    v.x = x;
    v.y = y;
    v.attr = a;
    return v;
  };
  RowSpans s;
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, 12), vtx(12, 18)}, rc, s), RowSpansSetup::Drawn);
  EXPECT_EQ(s.y0, 10);
  // 64 rows are held, 65 are not (setup then walks them).
  EXPECT_EQ(setupRowSpans({vtx(10.5, 10), vtx(60, 10), vtx(10.5, 73.9)}, rc, s), RowSpansSetup::Drawn);
  EXPECT_EQ(s.rows, 64);
  EXPECT_EQ(setupRowSpans({vtx(10.5, 10), vtx(60, 10), vtx(10.5, 74.9)}, rc, s), RowSpansSetup::General);
  const double nan = std::numeric_limits<double>::quiet_NaN(), inf = std::numeric_limits<double>::infinity();
  EXPECT_EQ(setupRowSpans({vtx(nan, 10), vtx(20, 12), vtx(12, 18)}, rc, s), RowSpansSetup::General);
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, inf), vtx(12, 18)}, rc, s), RowSpansSetup::General);
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, 12), vtx(9000, 18)}, rc, s), RowSpansSetup::General);  // guard band
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, 12, {10, nan, 30, 0.5}), vtx(12, 18)}, rc, s), RowSpansSetup::General);
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, 12, {1e9, 0, 0, 0.5}), vtx(12, 18)}, rc, s), RowSpansSetup::General);
  EXPECT_EQ(setupRowSpans({vtx(10, 10), vtx(20, 12), vtx(30, 14)}, rc, s), RowSpansSetup::Dropped);  // collinear
  EXPECT_EQ(setupRowSpans({vtx(-30, 10), vtx(-20, 12), vtx(-25, 18)}, rc, s), RowSpansSetup::Dropped);  // off screen
  // A depth gradient of 2^31 codes per pixel or more (a sliver nearly edge-on) is not held.
  EXPECT_EQ(setupRowSpans({vtx(10.5, 10, {0, 0, 0, 0}), vtx(10.5625, 10, {0, 0, 0, 1}), vtx(10.5, 14, {0, 0, 0, 0})}, rc, s),
            RowSpansSetup::General);
  // Units of four lane-triangles, or with other attributes, do not take row spans at all.
  EXPECT_FALSE(RowSpansConfig(rendererConfig("sierpinski")).applies);
  RasterConfig three = cfg;
  three.unit.NumAttr = 3;
  three.attr_frac_bits = {12, 12, 12};
  EXPECT_FALSE(RowSpansConfig(three).applies);
  // setupRowSpansBlock decides these as setupRowSpans does, and a DDA step at the register
  // bound |k| < k_lim: an edge of 2 subpixels' height across 2 k_lim + e subpixels, whose step
  // is the floor of +-(k_lim + e / 2) columns a row: held only for k_lim - 1 (e = -1, +).
  std::vector<std::array<RowSpans::Vertex, 3>> tris = {
      {vtx(10, 10), vtx(20, 12), vtx(12, 18)},           {vtx(10.5, 10), vtx(60, 10), vtx(10.5, 73.9)},
      {vtx(10.5, 10), vtx(60, 10), vtx(10.5, 74.9)},     {vtx(10.5, 10), vtx(60, 11), vtx(10.7, 74.9)},
      {vtx(nan, 10), vtx(20, 12), vtx(12, 18)},
      {vtx(10, 10), vtx(20, inf), vtx(12, 18)},          {vtx(10, 10), vtx(20, 12), vtx(9000, 18)},
      {vtx(10, 10), vtx(20, 12, {10, nan, 30, 0.5}), vtx(12, 18)},
      {vtx(10, 10), vtx(20, 12, {1e9, 0, 0, 0.5}), vtx(12, 18)},
      {vtx(10, 10), vtx(20, 12), vtx(30, 14)},           {vtx(-30, 10), vtx(-20, 12), vtx(-25, 18)},
      {vtx(10.5, 10, {0, 0, 0, 0}), vtx(10.5625, 10, {0, 0, 0, 1}), vtx(10.5, 14, {0, 0, 0, 0})}};
  for (const int e : {-1, 1})
    for (const double sign : {-1.0, 1.0}) {
      const double across = static_cast<double>(2 * rc.k_lim + e) / 16;
      tris.push_back({vtx(4000, 10), vtx(4000 + sign * across, 10.125), vtx(4000, 40)});
      tris.push_back({vtx(4000, 40), vtx(4000 + sign * across, 10.125), vtx(4000, 10)});
    }
  for (const bool avx512 : {false, true}) {  // the block in AVX2, and in AVX-512 where the CPU has it
    RowSpansConfig block = rc;
    block.vector = fixed_simd::availableAvx2();
    block.avx512 = avx512 && block.vector && fixed_simd::available();
    std::vector<RowSpans> out(tris.size());
    std::vector<RowSpansSetup> got(tris.size());
    setupRowSpansBlock(tris.data(), tris.size(), block, out.data(), got.data());
    std::map<RowSpansSetup, int> outcomes;
    for (size_t t = 0; t < tris.size(); ++t) {
      RowSpans ref;
      const RowSpansSetup want = setupRowSpans(tris[t], rc, ref);
      ++outcomes[want];
      EXPECT_EQ(got[t], want) << "triangle " << t << (block.avx512 ? " (AVX-512)" : "");
      if (want == RowSpansSetup::Drawn && got[t] == want) {
        EXPECT_TRUE(ref.y0 == out[t].y0 && ref.rows == out[t].rows && ref.x0 == out[t].x0 && ref.a0 == out[t].a0 &&
                    ref.didx == out[t].didx && ref.didy == out[t].didy)
            << "triangle " << t << (block.avx512 ? " (AVX-512)" : "");
      }
    }
    EXPECT_EQ(outcomes[RowSpansSetup::Drawn], 4);  // the first two, and the two of step k_lim - 1
  }
}
