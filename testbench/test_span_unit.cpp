// Triangle setup and the span unit model: the DDA walk against direct edge-function evaluation,
// every lane mode against the serial mode, the fill rule on shared edges, the plane's error
// bound, the cycle formula, and stalls.
#include "fixed/fixed.h"
#include "test_util.h"
#include "raster/setup.h"
#include "raster/span_unit.h"
#include "raster/span_walk.h"
#include "raster/desc_stream.h"
#include "raster/exact_int.h"
#include "raster/trigen.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <memory>
#include <random>

#include <fmt/format.h>

using namespace shd;
using shd::testutil::spanModes;
using shd::testutil::spanParams;
using shd::testutil::paperSpanModes;

namespace {

// floor(n / d) and the remainder in [0, d), d > 0, in 128-bit arithmetic: the tests' reference
// for setup's divisions (results within int64_t).
std::pair<int64_t, int64_t> floorDivRef(__int128 n, __int128 d) {
  __int128 q = n / d, r = n % d;
  if (r < 0) {
    q -= 1;
    r += d;
  }
  return {static_cast<int64_t>(q), static_cast<int64_t>(r)};
}
// round-half-even(n / d), d > 0, the same way.
int64_t roundHalfEvenRef(__int128 n, __int128 d) {
  const auto [q, r] = floorDivRef(n, d);
  return 2 * static_cast<__int128>(r) > d || (2 * static_cast<__int128>(r) == d && (q & 1) != 0) ? q + 1 : q;
}

RasterConfig configFor(const std::string& m, int w = 64, int h = 48) {
  RasterConfig c;
  c.width = w;
  c.height = h;
  c.unit = spanParams(m);
  return c;
}

SetupVertex vtx(double x, double y, std::initializer_list<double> a = {0, 0, 0, 0}) {
  SetupVertex v;
  v.x = x;
  v.y = y;
  v.attr = a;
  return v;
}

std::vector<SpanFragment> sorted(std::vector<SpanFragment> f) {
  std::sort(f.begin(), f.end(), [](const SpanFragment& a, const SpanFragment& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  return f;
}

// walkSpanUnit with a run consumer (the renderer's path), its runs expanded into fragments
// (fragment i at x0 + i dx with a0 + i da): the rows it took as runs and fragment by fragment
// are counted.
struct RunWalk {
  SpanWalk walk;
  uint64_t run_rows = 0, fragment_rows = 0;
};
RunWalk walkWithRuns(const SpanParams& p, const SpanDesc& d, std::vector<SpanFragment>& out) {
  RunWalk rw;
  int32_t last_y = INT32_MIN;
  rw.walk = walkSpanUnit(
      p, d,
      [&](int32_t x, int32_t y, const int64_t* attr) {
        if (y != last_y) ++rw.fragment_rows;
        last_y = y;
        // The fragment added without attributes, which are then written in place: one copy
        // of them instead of two (into a local fragment, then into `out`).
        out.push_back({d.tag, x, y, {}});
        AttrVec& fa = out.back().attr;
        for (int a = 0; a < p.NumAttr; ++a) fa.push_back(attr[a]);
      },
      [&](const RowRun& r) {
        ++rw.run_rows;
        last_y = INT32_MIN;
        for (int64_t i = 0; i < r.count; ++i) {
          out.push_back({d.tag, static_cast<int32_t>(r.x0 + i * r.dx), r.y, {}});
          AttrVec& fa = out.back().attr;
          for (int a = 0; a < p.NumAttr; ++a) fa.push_back(r.a0[a] + i * r.da[a]);
        }
      });
  return rw;
}

std::vector<SpanFragment> runMode(const std::string& m, const std::array<SetupVertex, 3>& v, const RasterConfig& base,
                                  SpanRun* run_out = nullptr) {
  RasterConfig c = base;
  c.unit = spanParams(m);
  const SetupResult s = setupTriangle(v, 7, c);
  if (!s.desc) return {};
  SpanUnitModel unit(c.unit);
  SpanRun run = runSpanUnit(unit, *s.desc);
  if (run_out) *run_out = run;
  return run.fragments;
}

// Random triangles of mixed sizes and shapes around a small viewport (a stand-in until the
// generator of raster/trigen.h covers every size class and shape).
std::array<SetupVertex, 3> randomTriangle(std::mt19937_64& rng, int w, int h) {
  std::uniform_real_distribution<double> u(0, 1);
  const int kind = static_cast<int>(rng() % 6);
  auto pt = [&](double cx, double cy, double r) {
    double x = cx + (u(rng) * 2 - 1) * r, y = cy + (u(rng) * 2 - 1) * r;
    if (kind == 3) x = std::round(x), y = std::round(y);           // on pixel corners
    if (kind == 4) x = std::round(x) + 0.5, y = std::round(y) + 0.5;  // on pixel centres
    return std::pair<double, double>{x, y};
  };
  const double cx = u(rng) * w * 1.4 - 0.2 * w, cy = u(rng) * h * 1.4 - 0.2 * h;
  const double r = kind == 0 ? 1.5 : (kind == 1 ? 40 : 8);
  std::array<SetupVertex, 3> v;
  for (size_t i = 0; i < 3; ++i) {
    auto [x, y] = pt(cx, cy, r);
    v[i] = vtx(x, y, {u(rng) * 255, u(rng) * 255, u(rng) * 255, u(rng)});
  }
  if (kind == 5) {  // sliver
    v[2].x = v[0].x + (v[1].x - v[0].x) * 0.5 + 0.01;
    v[2].y = v[0].y + (v[1].y - v[0].y) * 0.5;
  }
  return v;
}

std::string describe(const GenTriangle& t) {
  return fmt::format("triangle {} ({}) ({}, {}) ({}, {}) ({}, {})", t.id, t.kind(), t.v[0].x, t.v[0].y, t.v[1].x,
                     t.v[1].y, t.v[2].x, t.v[2].y);
}

// The functional walker (walkSpanUnit, the renderer's fast path), fragment by fragment and with
// runs, against the cycle-by-cycle model's run of the same descriptor: the same fragments in the
// same order, the same cycles. `walked` is the caller's buffer, cleared here and reused from
// triangle to triangle: a fresh vector per call, grown and freed each time, cost more (in copies
// and page faults) than the walkers themselves.
void checkWalkers(const SpanParams& p, const SpanDesc& d, const SpanRun& run, const char* mode, const GenTriangle& t,
                  std::vector<SpanFragment>& walked) {
  walked.clear();
  const SpanWalk wk = walkSpanUnit(p, d, walked);
  ASSERT_EQ(wk.cycles, run.cycles) << mode << " walker cycles, " << describe(t);
  ASSERT_EQ(wk.row_cycles, run.row_cycles) << mode << " walker ROW cycles, " << describe(t);
  ASSERT_EQ(wk.span_cycles, run.span_cycles) << mode << " walker SPAN cycles, " << describe(t);
  ASSERT_EQ(wk.fragments, run.fragments.size()) << mode << " walker fragment count, " << describe(t);
  ASSERT_EQ(walked.size(), run.fragments.size()) << mode << " walker fragments, " << describe(t);
  for (size_t i = 0; i < walked.size(); ++i) {
    const SpanFragment &a = walked[i], &b = run.fragments[i];
    ASSERT_TRUE(a.tag == b.tag && a.x == b.x && a.y == b.y && a.attr == b.attr)
        << mode << " walker fragment " << i << " (" << a.x << ", " << a.y << ") vs the cycle model's (" << b.x
        << ", " << b.y << "), " << describe(t);
  }
  // The same with runs: setup's descriptors never wrap, so every row of a single
  // lane-triangle is one run (in the same order: x ascending, or descending when flipped).
  walked.clear();
  const RunWalk rw = walkWithRuns(p, d, walked);
  ASSERT_EQ(rw.walk.cycles, run.cycles) << mode << " run walker cycles, " << describe(t);
  ASSERT_EQ(walked.size(), run.fragments.size()) << mode << " run walker fragments, " << describe(t);
  for (size_t i = 0; i < walked.size(); ++i) {
    const SpanFragment &a = walked[i], &b = run.fragments[i];
    ASSERT_TRUE(a.x == b.x && a.y == b.y && a.attr == b.attr)
        << mode << " run walker fragment " << i << " (" << a.x << ", " << a.y << ") vs the cycle model's ("
        << b.x << ", " << b.y << "), " << describe(t);
  }
  if (p.NumTri == 1) ASSERT_EQ(rw.fragment_rows, 0u) << mode << " " << describe(t);
  else ASSERT_EQ(rw.run_rows, 0u) << mode << " " << describe(t);
}

// Every mode against the serial mode on `count` generator triangles: same pixels, same codes
// (matched through a per-pixel index of the serial mode's fragments: each pixel once, in the
// viewport). With check_walkers, in every mode also checkWalkers.
void checkModesAgainstSerial(uint64_t seed, long count, bool check_walkers) {
  RasterConfig c;  // 512 x 512
  c.unit = spanParams("serial");
  TriangleGenerator gen(seed);
  std::vector<SpanUnitModel> units;
  std::vector<RasterConfig> cfgs;
  std::vector<std::string> modes = spanModes();
  std::stable_partition(modes.begin(), modes.end(), [](const std::string& m) { return m == "serial"; });
  ASSERT_EQ(modes.at(0), "serial");
  for (const std::string& m : modes) {
    cfgs.push_back(c);
    cfgs.back().unit = spanParams(m);
    units.emplace_back(cfgs.back().unit);
  }
  long frags = 0;
  // One run for every mode, reused: no allocation per triangle, and two fragment buffers (this
  // and serial's, swapped) instead of one per mode, which a large triangle's fragments in 12
  // buffers pushed out of the caches.
  std::vector<SpanFragment> serial;
  SpanRun run;
  std::vector<SpanFragment> walked;  // checkWalkers' buffer, likewise
  // Per pixel: the last triangle (n + 1) the serial mode drew it in and the index of that
  // fragment; the last (triangle, mode) that drew it. One record per pixel, so that a
  // fragment's checks read one cache line, not one in each of three arrays.
  struct PixelMark {
    uint64_t drawn = 0, seen = 0;
    uint32_t serial_at = 0;
  };
  std::vector<PixelMark> marks(static_cast<size_t>(c.width) * c.height);
  // A mode draws each pixel at most once (checked below), so a triangle has at most one fragment
  // per pixel: with that reserved up front the buffers never grow, where growing copied their
  // fragments and touched fresh pages each time a larger triangle came (untouched capacity
  // costs no memory).
  serial.reserve(marks.size());
  run.fragments.reserve(marks.size());
  if (check_walkers) walked.reserve(marks.size());
  // Serial's attribute codes, K per fragment in its order, when each of its fragments has K
  // (serial_k): a mode's fragment is compared with these 32 bytes instead of serial's 152-byte
  // fragment, whose attribute count lies a cache line past its codes; a difference (or another
  // count) goes to the comparison of the fragments themselves. Left uninitialised, like the
  // reserved buffers: only what the largest triangle writes is ever touched.
  const size_t K = static_cast<size_t>(c.unit.NumAttr);
  const std::unique_ptr<int64_t[]> serial_attr(new int64_t[marks.size() * K]);
  bool serial_k = true;
  uint64_t now = 0;
  for (long n = 0; n < count; ++n) {
    const GenTriangle t = gen.next();
    const auto v = toSetupVertices(t, c.unit.NumAttr);
    serial.clear();
    for (size_t mi = 0; mi < units.size(); ++mi) {
      const char* mode = modes[mi].c_str();
      const SetupResult s = setupTriangle(v, t.id, cfgs[mi]);
      const uint64_t visit = ++now;
      run.fragments.clear();
      if (s.desc) {
        runSpanUnit(units[mi], *s.desc, run);
        if (check_walkers) {
          checkWalkers(cfgs[mi].unit, *s.desc, run, mode, t, walked);
          if (testing::Test::HasFatalFailure()) return;
        }
      }
      if (mi == 0) serial.swap(run.fragments);  // the serial run's memory becomes serial's, and back
      const std::vector<SpanFragment>* got = mi == 0 ? &serial : &run.fragments;
      if (mi > 0) {
        ASSERT_EQ(got->size(), serial.size()) << mode << " seed " << seed << " " << describe(t);
      }
      for (size_t i = 0; i < got->size(); ++i) {
        const SpanFragment& f = (*got)[i];
        // Each check tested plainly first: GoogleTest's assertion objects, made for each of some
        // 10^8 fragments, took a third of the run.
        if (!(f.x >= 0 && f.x < c.width && f.y >= 0 && f.y < c.height)) {
          FAIL() << mode << " fragment (" << f.x << ", " << f.y << ") outside the viewport, " << describe(t);
        }
        const size_t p = static_cast<size_t>(f.y) * c.width + f.x;
        PixelMark& mark = marks[p];
        if (mark.seen == visit) {
          FAIL() << mode << " pixel (" << f.x << ", " << f.y << ") twice, " << describe(t);
        }
        mark.seen = visit;
        if (mi == 0) {
          mark.drawn = static_cast<uint64_t>(n) + 1;
          mark.serial_at = static_cast<uint32_t>(i);
          serial_k = (i == 0 || serial_k) && f.attr.size() == K;
          if (serial_k) std::copy(f.attr.begin(), f.attr.end(), &serial_attr[i * K]);
        } else {
          if (mark.drawn != static_cast<uint64_t>(n) + 1) {
            FAIL() << mode << " pixel (" << f.x << ", " << f.y << ") that serial does not draw, seed " << seed << " "
                   << describe(t);
          }
          const int64_t* sa = &serial_attr[size_t{mark.serial_at} * K];
          bool same = serial_k && f.attr.size() == K;
          for (size_t a = 0; same && a < K; ++a) same = f.attr[a] == sa[a];
          if (!same && f.attr != serial[mark.serial_at].attr) {
            ASSERT_EQ(f.attr, serial[mark.serial_at].attr) << mode << " seed " << seed << " " << describe(t);
          }
        }
      }
      frags += mi == 0 ? static_cast<long>(serial.size()) : 0;
    }
  }
  std::printf("seed %llu: %ld triangles, %ld fragments per mode, every mode equal to serial%s\n",
              static_cast<unsigned long long>(seed), count, frags,
              check_walkers ? ", the walkers equal to the cycle model" : "");
}

}  // namespace

TEST(TriangleSetup, SnapsHalfwayCoordinatesAndAttributesToEven) {
  // Every vertex coordinate and attribute code is rounded half to even, as Fixed::fromDouble
  // with Quant::RoundHalfEven: at S = 4 a coordinate k/32 is a half subpixel.
  RasterConfig c = configFor("serial", 64, 64);
  c.attr_frac_bits = {0, 1, 12, 28};
  const std::vector<double> xs = {1 + 1 / 32.0, 1 + 3 / 32.0, 2 - 1 / 32.0, 40.5 + 5 / 32.0, -1 - 1 / 32.0, -1 - 3 / 32.0};
  const std::vector<double> as = {2.5, 3.5, -2.5, 0.25, 0.75, 1 + std::ldexp(1.0, -13), std::ldexp(3.0, -29)};
  for (double x : xs)
    for (double a : as) {
      const SetupResult s = setupTriangle({vtx(x, 1, {a, a, a, 0}), vtx(x + 20, 3, {0, 0, 0, a}), vtx(x + 3, 30, {0, 0, 0, 0})}, 1, c);
      const FixedFormat fx = FixedFormat::s(c.unit.CoordBits, c.subpixel_bits);
      EXPECT_EQ(s.tri.X[0], Fixed::fromDouble(x, fx, Quant::RoundHalfEven, Overflow::Error).raw()) << x;
      EXPECT_EQ(s.tri.Y[0], Fixed::fromDouble(1, fx, Quant::RoundHalfEven, Overflow::Error).raw());
      for (int k = 0; k < 3; ++k) {
        const int F = c.attr_frac_bits[static_cast<size_t>(k)];
        const FixedFormat fa = FixedFormat::s(c.unit.AttrBits - F, F);
        EXPECT_EQ(s.tri.a[static_cast<size_t>(k)][0], Fixed::fromDouble(a, fa, Quant::RoundHalfEven, Overflow::Error).raw())
            << "attribute " << k << " value " << a;
      }
    }
  // The halfway cases themselves: 1 + 1/32 -> 16.5 subpixels -> 16; 1 + 3/32 -> 17.5 -> 18.
  EXPECT_EQ(setupTriangle({vtx(1 + 1 / 32.0, 1), vtx(20, 3), vtx(4, 30)}, 1, c).tri.X[0], 16);
  EXPECT_EQ(setupTriangle({vtx(1 + 3 / 32.0, 1), vtx(20, 3), vtx(4, 30)}, 1, c).tri.X[0], 18);
  // Setup rounds below 2^51 by adding and subtracting 1.5 * 2^52, above through nearbyint:
  // ties on both sides of the switch, both signs, up to the widest attribute (AttrBits 62).
  RasterConfig wide = configFor("serial", 64, 64);
  wide.unit.AttrBits = 62;
  wide.attr_frac_bits = {0, 1, 0, 28};
  for (double a : {0x1p51 - 0.5, 0x1p51 - 1.5, 0x1p51 + 0.5, 0x1p51 + 1.5, 0x1p51 + 1, 0x1p51 + 3, -(0x1p51 - 0.5),
                   -(0x1p51 + 0.5), -(0x1p51 + 1), 0x1p52 + 1, 0x1p52 + 2,
                   -0x1p57, 0x1p50 + 0.5, 0x1p50 + 0.25}) {
    const SetupResult s = setupTriangle({vtx(1, 1, {a, a / 2, 0, 0}), vtx(21, 3, {0, 0, 0, 0}), vtx(4, 30, {0, 0, 0, 0})}, 1, wide);
    EXPECT_EQ(s.tri.a[0][0], Fixed::fromDouble(a, FixedFormat::s(62, 0), Quant::RoundHalfEven, Overflow::Error).raw())
        << std::hexfloat << a;
    EXPECT_EQ(s.tri.a[1][0], Fixed::fromDouble(a / 2, FixedFormat::s(61, 1), Quant::RoundHalfEven, Overflow::Error).raw())
        << std::hexfloat << a;
  }
}

TEST(TriangleSetup, TopLeftBiasAndPlaneOfAHandTriangle) {
  RasterConfig c = configFor("serial", 8, 8);
  // Right triangle with legs on pixel-centre lines: (0.5,0.5) (4.5,0.5) (0.5,4.5).
  const SetupResult s = setupTriangle({vtx(0.5, 0.5, {0, 0, 0, 0}), vtx(4.5, 0.5, {64, 0, 0, 0}), vtx(0.5, 4.5, {0, 32, 0, 0})}, 1, c);
  ASSERT_TRUE(s.desc);
  // The top edge (horizontal, interior below) and the left edge are inclusive; the hypotenuse
  // x + y = 5 (pixel centres) is a right edge, exclusive: row 0 has pixels 0..3, row 3 has 0.
  const auto ref = rasterizeReference(s, c);
  std::map<int, int> per_row;
  for (const auto& f : ref) ++per_row[f.y];
  EXPECT_EQ(per_row[0], 4);
  EXPECT_EQ(per_row[1], 3);
  EXPECT_EQ(per_row[3], 1);
  EXPECT_EQ(per_row.count(4), 0u);
  // a0 = 0 rising by 16 per pixel in x, 8 per pixel in y (F = 12 fraction bits for 8x8: 1+5... )
  const int F = c.attrFracBits(0);
  EXPECT_EQ(s.plane.didx[0], int64_t{16} << F);
  EXPECT_EQ(s.plane.didy[1], int64_t{8} << F);
  EXPECT_EQ(s.plane.at(0, 2, 1), int64_t{32} << F);
}

TEST(TriangleSetup, DegenerateAndOutsideAreDroppedWithAReason) {
  const RasterConfig c = configFor("serial");
  EXPECT_EQ(setupTriangle({vtx(1, 1), vtx(1, 1), vtx(5, 9)}, 1, c).dropped, "zero area");
  EXPECT_EQ(setupTriangle({vtx(1, 1), vtx(3, 3), vtx(7, 7)}, 1, c).dropped, "zero area");
  EXPECT_EQ(setupTriangle({vtx(-20, -20), vtx(-10, -20), vtx(-20, -5)}, 1, c).dropped,
            "no pixel centre of its bounding box in the viewport");
  // A sliver whose box holds pixel centre rows and columns, but no centre between its edges.
  EXPECT_EQ(setupTriangle({vtx(0, 0.1), vtx(3, 1.1), vtx(3, 1.3)}, 1, c).dropped,
            "no pixel centre inside it in the viewport");
  EXPECT_THROW(setupTriangle({vtx(NAN, 1), vtx(3, 3), vtx(7, 1)}, 1, c), std::invalid_argument);
  EXPECT_THROW(setupTriangle({vtx(1e6, 1), vtx(3, 3), vtx(7, 1)}, 1, c), std::invalid_argument);
  EXPECT_THROW(setupTriangle({vtx(1, 1, {1e30, 0, 0, 0}), vtx(3, 3), vtx(7, 1)}, 1, c), std::invalid_argument);
}

// setupTriangle into a result that held another triangle (the renderer's two-thread frame sets
// up each triangle in a reused ring slot) gives what a fresh result gets: the same drop reason,
// snapped triangle, edges, plane and a descriptor that walks to the same fragments and cycles,
// on 20,000 generator triangles of every size class (drops, slivers, the 1-pixel ones among
// them) in the serial unit and the interleaving Sierpinski unit.
TEST(TriangleSetup, AResultReusedInPlaceEqualsAFreshOne) {
  for (const char* mode : {"serial", "sierpinskifull"}) {
    RasterConfig c;  // 512 x 512
    c.unit = spanParams(mode);
    TriangleGenerator gen(31);
    SetupResult reused;
    std::vector<SpanFragment> a, b;
    int drawn = 0, dropped = 0;
    for (int n = 0; n < 20000; ++n) {
      const GenTriangle g = gen.next();
      const auto v = toSetupVertices(g, c.unit.NumAttr);
      const SetupResult fresh = setupTriangle(v, g.id, c);
      setupTriangle(v, g.id, c, reused);
      const std::string what = fmt::format("{} triangle {}", mode, n);
      ASSERT_EQ(reused.dropped, fresh.dropped) << what;
      ASSERT_EQ(reused.desc.has_value(), fresh.desc.has_value()) << what;
      ASSERT_EQ(reused.tri.X, fresh.tri.X) << what;
      ASSERT_EQ(reused.tri.Y, fresh.tri.Y) << what;
      ASSERT_TRUE(reused.tri.a == fresh.tri.a) << what;
      ASSERT_EQ(reused.tri.swapped, fresh.tri.swapped) << what;
      ASSERT_EQ(reused.tri.det, fresh.tri.det) << what;
      for (size_t e = 0; e < 3; ++e) {
        ASSERT_EQ(reused.edges[e].A, fresh.edges[e].A) << what;
        ASSERT_EQ(reused.edges[e].B, fresh.edges[e].B) << what;
        ASSERT_EQ(reused.edges[e].C, fresh.edges[e].C) << what;
        ASSERT_EQ(reused.edges[e].topLeft, fresh.edges[e].topLeft) << what;
      }
      ASSERT_EQ(reused.plane.xref, fresh.plane.xref) << what;
      ASSERT_EQ(reused.plane.yref, fresh.plane.yref) << what;
      ASSERT_TRUE(reused.plane.iref == fresh.plane.iref && reused.plane.didx == fresh.plane.didx &&
                  reused.plane.didy == fresh.plane.didy)
          << what;
      if (!fresh.desc) {
        ++dropped;
        continue;
      }
      ++drawn;
      ASSERT_EQ(reused.desc->interleave, fresh.desc->interleave) << what;
      a.clear();
      b.clear();
      const SpanWalk wa = walkSpanUnit(c.unit, *reused.desc, a, static_cast<SpanStream*>(nullptr));
      const SpanWalk wb = walkSpanUnit(c.unit, *fresh.desc, b, static_cast<SpanStream*>(nullptr));
      ASSERT_EQ(wa.cycles, wb.cycles) << what;
      ASSERT_EQ(a.size(), b.size()) << what;
      for (size_t i = 0; i < a.size(); ++i) {
        ASSERT_EQ(a[i].x, b[i].x) << what;
        ASSERT_EQ(a[i].y, b[i].y) << what;
        ASSERT_TRUE(a[i].attr == b[i].attr) << what;
      }
    }
    EXPECT_GT(drawn, 10000) << mode;
    EXPECT_GT(dropped, 100) << mode;
  }
}

TEST(SpanUnitModel, SerialWalkEqualsDirectEdgeEvaluation) {
  const RasterConfig c = configFor("serial");
  std::mt19937_64 rng(11);
  long frags = 0;
  for (int n = 0; n < 20000; ++n) {
    const auto v = randomTriangle(rng, c.width, c.height);
    const SetupResult s = setupTriangle(v, static_cast<uint32_t>(n), c);
    const auto ref = rasterizeReference(s, c);
    const auto got = sorted(runMode("serial", v, c));
    ASSERT_EQ(got.size(), ref.size()) << "triangle " << n << " (" << v[0].x << "," << v[0].y << ") (" << v[1].x << ","
                                      << v[1].y << ") (" << v[2].x << "," << v[2].y << ")";
    for (size_t i = 0; i < ref.size(); ++i) {
      ASSERT_EQ(got[i].x, ref[i].x) << "triangle " << n;
      ASSERT_EQ(got[i].y, ref[i].y) << "triangle " << n;
      ASSERT_EQ(got[i].attr, ref[i].attr) << "triangle " << n << " pixel " << ref[i].x << "," << ref[i].y;
    }
    frags += static_cast<long>(ref.size());
  }
  EXPECT_GT(frags, 100000);
}

TEST(SpanUnitModel, EveryModeEqualsSerial) {
  const RasterConfig c = configFor("serial");
  std::mt19937_64 rng(12);
  // Under AddressSanitizer 5,000 triangles (19 s for 20,000 there): the sanitizers look for
  // memory errors on the same paths; the release build runs all 20,000 and the slow variants
  // 10^5 and 10^6.
#if defined(__SANITIZE_ADDRESS__)
  constexpr int kTriangles = 5000;
#else
  constexpr int kTriangles = 20000;
#endif
  for (int n = 0; n < kTriangles; ++n) {
    const auto v = randomTriangle(rng, c.width, c.height);
    const auto serial = sorted(runMode("serial", v, c));
    for (const std::string& m : spanModes()) {
      const auto got = sorted(runMode(m, v, c));
      ASSERT_EQ(got.size(), serial.size()) << m << " triangle " << n << " (" << v[0].x << "," << v[0].y
                                           << ") (" << v[1].x << "," << v[1].y << ") (" << v[2].x << "," << v[2].y << ")";
      for (size_t i = 0; i < got.size(); ++i) {
        ASSERT_EQ(got[i].x, serial[i].x) << m << " triangle " << n;
        ASSERT_EQ(got[i].y, serial[i].y) << m << " triangle " << n;
        ASSERT_EQ(got[i].attr, serial[i].attr) << m << " triangle " << n;
      }
    }
  }
}

TEST(SpanUnitModel, CycleCountFollowsTheFormula) {  // the paper's unit (the full-rate unit: FullRate* below)
  const RasterConfig c = configFor("serial");
  std::mt19937_64 rng(13);
  for (const std::string& m : paperSpanModes()) {
    RasterConfig cm = c;
    cm.unit = spanParams(m);
    for (int n = 0; n < 2000; ++n) {
      const auto v = randomTriangle(rng, c.width, c.height);
      const SetupResult s = setupTriangle(v, 1, cm);
      if (!s.desc) continue;
      SpanUnitModel unit(cm.unit);
      const SpanRun run = runSpanUnit(unit, *s.desc);
      EXPECT_EQ(run.cycles, 1 + run.row_cycles + run.span_cycles);
      EXPECT_EQ(run.row_cycles, static_cast<uint64_t>(s.desc->row_last - s.desc->row_first + 1));
      EXPECT_LE(run.valid_lanes, run.span_cycles * static_cast<uint64_t>(cm.unit.lanes()));
    }
  }
}

TEST(SpanUnitModel, StalledConsumerLosesNothing) {
  const RasterConfig c = configFor("seg4");
  std::mt19937_64 rng(14);
  for (int n = 0; n < 500; ++n) {
    const auto v = randomTriangle(rng, c.width, c.height);
    const SetupResult s = setupTriangle(v, 1, c);
    if (!s.desc) continue;
    SpanUnitModel a(c.unit), b(c.unit);
    const SpanRun free_run = runSpanUnit(a, *s.desc);
    // The same descriptor with out_ready dropped at random.
    std::vector<SpanFragment> got;
    SpanIn in;
    in.desc_valid = true;
    in.desc = &*s.desc;
    bool accepted = false;
    uint64_t cycles = 0;
    for (;;) {
      in.out_ready = (rng() % 3) != 0;
      const SpanOut o = b.tick(in);
      ++cycles;
      if (!accepted) {
        accepted = o.desc_ready;
        in.desc_valid = false;
        continue;
      }
      if (o.out_valid && in.out_ready)
        for (const auto& l : o.lane)
          if (l.valid) got.push_back({o.tag, l.x, l.y, l.attr});
      if (b.idle()) break;
    }
    ASSERT_EQ(got.size(), free_run.fragments.size());
    for (size_t i = 0; i < got.size(); ++i) {
      ASSERT_EQ(got[i].x, free_run.fragments[i].x);
      ASSERT_EQ(got[i].y, free_run.fragments[i].y);
      ASSERT_EQ(got[i].attr, free_run.fragments[i].attr);
    }
    EXPECT_GE(cycles, free_run.cycles);
  }
}

TEST(TriangleSetup, PlaneWithinTheDerivedBoundOfTheExactPlane) {
  const RasterConfig c = configFor("serial");
  std::mt19937_64 rng(15);
  double worst = 0;  // in units of the bound
  for (int n = 0; n < 3000; ++n) {
    const auto v = randomTriangle(rng, c.width, c.height);
    const SetupResult s = setupTriangle(v, 1, c);
    for (const auto& f : rasterizeReference(s, c))
      for (int k = 0; k < c.unit.NumAttr; ++k) {
        const double bound = 0.5 * (1 + std::abs(f.x - s.plane.xref) + std::abs(f.y - s.plane.yref));
        const double err = std::fabs(static_cast<double>(f.attr[static_cast<size_t>(k)]) - exactPlane(s, c, k, f.x, f.y));
        ASSERT_LE(err, bound + 1e-6) << "attribute " << k << " at " << f.x << "," << f.y;
        worst = std::max(worst, err / bound);
      }
  }
  RecordProperty("worst_error_over_bound", std::to_string(worst));
}

// Setup trims each lane-triangle's rows to the first and the last that hold a pixel (a row whose
// centre lies within the vertical extent can hold none: a sliver's tip), so that the unit spends
// no cycle on them. Checked with the walker's own ROW logic: the bounds at the first row from
// the descriptor's edges, at the last row after the DDA steps through every row.
TEST(TriangleSetup, EveryLaneTrianglesFirstAndLastRowsHoldAPixel) {
  for (const std::string& m : paperSpanModes()) {
    RasterConfig c;
    c.unit = spanParams(m);
    DescriptorStream stream(23, 20000, c);
    SpanDesc d;
    long lanes = 0;
    while (stream.next(d)) {
      for (const SpanLaneTri& t : d.tri) {
        if (t.row_first > t.row_last) continue;
        ++lanes;
        std::array<SpanDdaState, 3> e;
        for (size_t s = 0; s < 3; ++s) e[s] = {t.edge[s].q, t.edge[s].r};
        int64_t lo = 0, hi = 0;
        ASSERT_TRUE(span_detail::laneRowBounds(t, t.row_first, e.data(), lo, hi))
            << m << ": first row " << t.row_first << " without a pixel, " << describe(stream.last());
        for (int64_t w = t.row_first; w < t.row_last; ++w) span_detail::stepEdges(t, w, e.data(), c.unit.CoordBits);
        ASSERT_TRUE(span_detail::laneRowBounds(t, t.row_last, e.data(), lo, hi))
            << m << ": last row " << t.row_last << " without a pixel, " << describe(stream.last());
      }
    }
    EXPECT_GT(lanes, 15000) << m;
  }
}

TEST(SpanUnitModel, SerialEqualsDirectEvaluationOnGeneratorClasses) {
  // Every size class and shape of raster/trigen.h, 512 x 512, against direct edge evaluation.
  RasterConfig c;
  c.unit = spanParams("serial");
  TriangleGenerator gen(21);
  SpanUnitModel unit(c.unit);
  std::map<std::string, long> seen;
  for (int n = 0; n < 100000; ++n) {
    const GenTriangle t = gen.next();
    const SetupResult s = setupTriangle(toSetupVertices(t, c.unit.NumAttr), t.id, c);
    const auto ref = rasterizeReference(s, c);
    const auto got = s.desc ? sorted(runSpanUnit(unit, *s.desc).fragments) : std::vector<SpanFragment>{};
    ASSERT_EQ(got.size(), ref.size()) << describe(t);
    for (size_t i = 0; i < ref.size(); ++i) {
      ASSERT_EQ(got[i].x, ref[i].x) << describe(t);
      ASSERT_EQ(got[i].y, ref[i].y) << describe(t);
      ASSERT_EQ(got[i].attr, ref[i].attr) << describe(t);
    }
    ++seen[t.kind()];
  }
  EXPECT_GE(seen.size(), 20u);  // the classes x shapes the generator mixes
}

TEST(SpanUnitModel, EveryModeEqualsSerialOnGeneratorTriangles) { checkModesAgainstSerial(22, 100000, true); }

// A million triangles per mode, the cycle models only (slow label, as the 10^5 above: the
// walkers are checked there, and under the sanitizers by the walker tests below).
TEST(SpanUnitModel, EveryModeEqualsSerialOnAMillionTriangles) { checkModesAgainstSerial(20261122, 1000000, false); }

// Setup's descriptors never make a shown value wrap; other descriptors must still wrap in the
// walker exactly as in the cycle model (and the RTL). The generator's descriptors run here on
// units of narrower AttrBits, where colour codes (up to 2^20) and depth codes (up to 2^28)
// overflow, and with the single lane-triangle of the serial and lane modes flipped.
TEST(SpanUnitModel, WalkerWrapsLikeTheCycleModelBeyondSetupsBound) {
  for (const std::string& m : spanModes()) {
    RasterConfig c;
    c.unit = spanParams(m);
    DescriptorStream stream(5, 2000, c);
    uint64_t fragments = 0, wrapped = 0, run_rows = 0, fragment_rows = 0;
    SpanDesc d;
    std::vector<SpanFragment> walked, wide;
    while (stream.next(d)) {
      for (int bits : {16, 24}) {
        for (bool flip : {false, true}) {
          SpanParams p = c.unit;
          p.AttrBits = bits;
          SpanDesc x = d;
          if (flip && p.NumTri == 1) {
            x.tri[0].flip = true;
            x.tri[0].ox = 600;
            x.tri[0].oy = 500;
          }
          SpanUnitModel unit(p);
          const SpanRun run = runSpanUnit(unit, x);
          walked.clear();
          walkSpanUnit(p, x, walked);
          wide.clear();
          walkSpanUnit(c.unit, x, wide);  // AttrBits 32: nothing wraps
          ASSERT_EQ(walked.size(), run.fragments.size()) << m << " AttrBits " << bits;
          for (size_t i = 0; i < walked.size(); ++i) {
            ASSERT_TRUE(walked[i].x == run.fragments[i].x && walked[i].y == run.fragments[i].y &&
                        walked[i].attr == run.fragments[i].attr)
                << m << " AttrBits " << bits << " flip " << flip << " fragment " << i << " of triangle "
                << d.tag;
            wrapped += walked[i].attr != wide[i].attr ? 1 : 0;
          }
          fragments += walked.size();
          // With runs: a row whose values wrap inside it goes fragment by fragment; one whose
          // values all lie in one window of 2^AttrBits (wrapped or not) is a run.
          walked.clear();
          const RunWalk rw = walkWithRuns(p, x, walked);
          run_rows += rw.run_rows;
          fragment_rows += rw.fragment_rows;
          ASSERT_EQ(walked.size(), run.fragments.size()) << m << " AttrBits " << bits << " runs";
          for (size_t i = 0; i < walked.size(); ++i)
            ASSERT_TRUE(walked[i].x == run.fragments[i].x && walked[i].y == run.fragments[i].y &&
                        walked[i].attr == run.fragments[i].attr)
                << m << " AttrBits " << bits << " flip " << flip << " run fragment " << i << " of triangle "
                << d.tag;
        }
      }
    }
    EXPECT_GT(wrapped, fragments / 2) << m;  // both loops ran: most rows wrap, some fit
    EXPECT_LT(wrapped, fragments) << m;
    if (c.unit.NumTri == 1) {  // both paths ran: rows within one window and rows across windows
      EXPECT_GT(run_rows, 0u) << m;
      EXPECT_GT(fragment_rows, 0u) << m;
    }
  }
}

// Setup's divisions (raster/exact_int.h) against 128-bit integer arithmetic: operands around
// 2^53 and at the edges of int64_t, quotients just below, at and above integers, exact halves
// (round half to even, the parity base's plus the quotient's), random ones of every magnitude.
TEST(ExactInt, DivisionsEqualThe128BitOnes) {
  std::vector<int64_t> ds = {1, 2, 3, 7, 1000003};
  std::vector<int64_t> ns;
  const int64_t k53 = int64_t{1} << 53;
  for (int64_t e : {k53, int64_t{1} << 62, INT64_MAX}) {
    for (int64_t k = 0; k < 4; ++k) {
      ds.push_back(e - k);
      ns.push_back(e - k);
      ns.push_back(-(e - k));
    }
  }
  ds.push_back(k53 + 1);
  ns.push_back(k53 + 1);
  ns.push_back(-k53 - 1);
  ns.push_back(INT64_MIN);
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200000; ++i) {
    const int bits = 1 + static_cast<int>(rng() % 62);
    ds.push_back(static_cast<int64_t>(rng() >> (64 - bits)) + 1);
    const int q_bits = static_cast<int>(rng() % 54);  // the quotient below 2^q_bits
    const int64_t q = (q_bits == 0 ? 0 : static_cast<int64_t>(rng() >> (64 - q_bits))) * (rng() % 2 != 0 ? 1 : -1);
    const int64_t d = ds.back();
    int64_t n = 0;
    // Just below, at, above an integer quotient and at a half: n = q d + {-1, 0, 1, d / 2}.
    if (!__builtin_mul_overflow(q, d, &n))
      for (int64_t off : {int64_t{-1}, int64_t{0}, int64_t{1}, d / 2}) {
        int64_t v = 0;
        if (!__builtin_add_overflow(n, off, &v)) ns.push_back(v);
      }
    ns.push_back(static_cast<int64_t>(rng()));
  }
  uint64_t checked = 0;
  for (size_t i = 0; i < ns.size(); ++i) {
    const int64_t n = ns[i];
    for (int64_t d : {ds[i % ds.size()], ds[(i * 7 + 3) % ds.size()], int64_t{1}, k53 - 1}) {
      const auto [qr, rr] = floorDivRef(n, d);
      ASSERT_EQ(exact::ceilDiv64(n, d), rr != 0 ? qr + 1 : qr) << n << " / " << d;
      ASSERT_EQ(exact::floorDiv(n, d), qr) << n << " / " << d;
      ASSERT_EQ(static_cast<int64_t>(exact::roundDiv(n, d)), roundHalfEvenRef(n, d)) << n << " / " << d;
      if (n > -(int64_t{1} << 61) && n < (int64_t{1} << 61)) {
        const int64_t base = static_cast<int64_t>(rng() % (uint64_t{1} << 40)) - (int64_t{1} << 39);
        // round-half-even(base + n / d): the parity at a half is base's plus the quotient's
        ASSERT_EQ(exact::roundDivPlus(base, n, d), roundHalfEvenRef(static_cast<__int128>(base) * d + n, d))
            << base << " + " << n << " / " << d;
      }
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000000u);
}

// The plane codes are the exact rationals of setup.h rounded half to even: didx = 2^S nx / det,
// didy = 2^S ny / det, iref = the plane at the reference pixel centre, recomputed here in
// 128-bit integers, on generator triangles with the renderer's fraction bits (numerators below
// 2^52: setup's reciprocal estimate) and with 40-bit colour fractions on AttrBits 62
// (numerators beyond 2^52: its exact division).
TEST(TriangleSetup, PlaneCodesAreTheExactRationalsRoundedHalfToEven) {
  using i128 = __int128;
  for (const std::vector<int>& frac : {std::vector<int>{12, 12, 12, 28}, std::vector<int>{40, 40, 40, 28}}) {
    RasterConfig c;  // 512 x 512
    c.unit = spanParams("serial");
    c.unit.AttrBits = frac[0] > 30 ? 62 : 32;
    c.attr_frac_bits = frac;
    TriangleGenerator gen(31);
    uint64_t planes = 0, wide = 0;
    for (int n = 0; n < 100000; ++n) {
      const GenTriangle g = gen.next();
      const SetupResult s = setupTriangle(toSetupVertices(g, 4), g.id, c);
      if (s.tri.det == 0) continue;
      const SnappedTriangle& t = s.tri;
      const int S = c.subpixel_bits;
      for (size_t k = 0; k < 4; ++k) {
        const auto& a = t.a[k];
        const i128 nx = static_cast<i128>(a[1] - a[0]) * (t.Y[2] - t.Y[0]) - static_cast<i128>(a[2] - a[0]) * (t.Y[1] - t.Y[0]);
        const i128 ny = static_cast<i128>(t.X[1] - t.X[0]) * (a[2] - a[0]) - static_cast<i128>(t.X[2] - t.X[0]) * (a[1] - a[0]);
        const i128 one = i128{1} << S;  // multiplied, not shifted: nx, ny may be negative
        ASSERT_EQ(s.plane.didx[k], roundHalfEvenRef(nx * one, t.det)) << g.kind() << " attribute " << k;
        ASSERT_EQ(s.plane.didy[k], roundHalfEvenRef(ny * one, t.det)) << g.kind() << " attribute " << k;
        const i128 cx = (2 * static_cast<i128>(s.plane.xref) + 1) << S, cy = (2 * static_cast<i128>(s.plane.yref) + 1) << S;
        const i128 num = 2 * static_cast<i128>(t.det) * a[0] + nx * (cx - 2 * t.X[0]) + ny * (cy - 2 * t.Y[0]);
        ASSERT_EQ(s.plane.iref[k], roundHalfEvenRef(num, 2 * static_cast<i128>(t.det))) << g.kind() << " attribute " << k;
        ++planes;
        const i128 lim = i128{1} << 52;
        wide += nx * one >= lim || nx * one <= -lim || num >= lim || num <= -lim ? 1 : 0;
      }
    }
    EXPECT_GT(planes, 300000u);
    if (frac[0] > 30) EXPECT_GT(wide, planes / 2);  // the exact-division path ran
    else EXPECT_LT(wide, planes / 100);             // the reciprocal path ran
  }
}

TEST(SpanUnitModel, SharedEdgesOfMeshesDrawnExactlyOnce) {
  // Grid and fan meshes: every pixel whose centre lies strictly inside the meshed region is
  // drawn exactly once, in every mode; no pixel twice anywhere.
  std::mt19937_64 rng(23);
  TriGenOptions opt;
  for (const std::string& m : spanModes()) {
    RasterConfig c;
    c.unit = spanParams(m);
    SpanUnitModel unit(c.unit);
    for (int trial = 0; trial < 6; ++trial) {
      MeshGenOptions mo;
      mo.x0 = 10.25 + trial * 3.1;
      mo.y0 = 7.5 + trial;
      mo.x1 = mo.x0 + 200 + trial * 17;
      mo.y1 = mo.y0 + 150 + trial * 9;
      mo.snap_share = 0.5;
      const bool fan = trial % 2 == 1;
      const double cx = (mo.x0 + mo.x1) / 2, cy = (mo.y0 + mo.y1) / 2, radius = 90;
      const std::vector<GenTriangle> mesh = fan ? makeFanMesh(rng, opt, cx, cy, radius, 37 + trial, mo)
                                                : makeSharedEdgeMesh(rng, opt, 13 + trial, 9 + trial, mo);
      std::vector<int> hits(static_cast<size_t>(c.width) * c.height, 0);
      for (const GenTriangle& t : mesh) {
        const SetupResult s = setupTriangle(toSetupVertices(t, c.unit.NumAttr), t.id, c);
        if (!s.desc) continue;
        for (const SpanFragment& f : runSpanUnit(unit, *s.desc).fragments)
          ++hits[static_cast<size_t>(f.y) * c.width + f.x];
      }
      long inside = 0;
      for (int y = 0; y < c.height; ++y)
        for (int x = 0; x < c.width; ++x) {
          const int h = hits[static_cast<size_t>(y) * c.width + x];
          ASSERT_LE(h, 1) << m << " pixel " << x << "," << y << " drawn twice";
          const double px = x + 0.5, py = y + 0.5;
          // Interior of the region. Fan: ring vertices lie at radii in [radius/2, radius] and
          // angular gaps below 1.6 times the mean (jitter 0.3), so the disc of radius
          // radius/2 * cos(0.8 * 2 pi / segments) is inside the fan.
          const bool in = fan ? std::hypot(px - cx, py - cy) < 0.5 * radius * std::cos(1.6 * M_PI / (37 + trial)) - 1e-9
                              : (px > mo.x0 && px < mo.x1 && py > mo.y0 && py < mo.y1);
          if (in) {
            ASSERT_EQ(h, 1) << m << (fan ? " fan" : " grid") << " gap at pixel " << x << "," << y;
            ++inside;
          }
        }
      EXPECT_GT(inside, fan ? 5000 : 10000);
    }
  }
}

namespace {

// The full-rate variant of a lane mode's unit (RowAhead = 1).
SpanParams fullRate(const std::string& mode) {
  SpanParams p = spanParams(mode);
  p.RowAhead = 1;
  return p;
}

bool sameFragment(const SpanFragment& a, const SpanFragment& b) {
  return a.tag == b.tag && a.x == b.x && a.y == b.y && a.attr == b.attr;
}

// The generator's descriptors for a mode's unit (tags 0, 1, ...).
std::vector<SpanDesc> generatorDescriptors(const SpanParams& unit, uint64_t seed, int count) {
  RasterConfig c;  // 512 x 512
  c.unit = unit;
  TriangleGenerator gen(seed);
  std::vector<SpanDesc> out;
  while (static_cast<int>(out.size()) < count) {
    const GenTriangle t = gen.next();
    const SetupResult s = setupTriangle(toSetupVertices(t, c.unit.NumAttr), static_cast<uint32_t>(out.size()), c);
    if (s.desc) out.push_back(*s.desc);
  }
  return out;
}

// descs through the cycle model as a stream: each presented from the cycle after the one before
// was taken (after a random gap when gaps), out_ready dropped at random when stalls. The
// fragments in output order and the cycles until the unit is idle after the last.
struct Streamed {
  std::vector<SpanFragment> fragments;
  uint64_t cycles = 0;
};
Streamed streamThrough(const SpanParams& p, const std::vector<SpanDesc>& descs, std::mt19937_64* rng) {
  SpanUnitModel m(p);
  Streamed s;
  SpanIn in;
  SpanOut o;
  size_t next = 0;
  while (next < descs.size() || !m.idle()) {
    in.desc_valid = next < descs.size() && (rng == nullptr || (*rng)() % 4 != 0);
    in.desc = in.desc_valid ? &descs[next] : nullptr;
    in.out_ready = rng == nullptr || (*rng)() % 3 != 0;
    m.tick(in, o);
    ++s.cycles;
    if (in.desc_valid && o.desc_ready) ++next;
    if (o.out_valid && in.out_ready)
      for (const SpanLaneOut& l : o.lane)
        if (l.valid) s.fragments.push_back({o.tag, l.x, l.y, l.attr});
  }
  return s;
}

}  // namespace

// The full-rate unit against the paper's, in every lane mode on generator triangles, each
// descriptor alone: the same fragments in the same order, the same rows and lane groups, never
// more cycles; and the walker equal to its cycle model, cycles included.
TEST(SpanUnitModel, FullRateUnitGivesThePapersFragments) {
  // The registry holds each lane mode as both units: <mode>full is <mode> with RowAhead 1, and
  // with Interleave 1 where it has four lane-triangles (BalancedSierpinski... below; given the
  // paper's descriptors here, which do not interleave).
  for (const std::string& m : spanModes()) {
    if (spanParams(m).RowAhead) {
      EXPECT_EQ(m.substr(m.size() - 4), "full");
    }
  }
  for (const std::string& m : paperSpanModes()) {
    SpanParams registered = spanParams(m + "full");
    EXPECT_EQ(registered.Interleave, registered.NumTri == 4 ? 1 : 0) << m;
    registered.Interleave = 0;
    ASSERT_EQ(registered.toJson(), fullRate(m).toJson()) << m;
    const SpanParams paper_p = spanParams(m), full_p = fullRate(m);
    SpanUnitModel paper(paper_p), full(full_p);
    SpanRun a, b;
    uint64_t paper_cycles = 0, full_cycles = 0, groups = 0;
    for (const SpanDesc& d : generatorDescriptors(paper_p, 31, 20000)) {
      runSpanUnit(paper, d, a);
      runSpanUnit(full, d, b);
      ASSERT_EQ(b.fragments.size(), a.fragments.size()) << m << " triangle " << d.tag;
      for (size_t i = 0; i < a.fragments.size(); ++i)
        ASSERT_TRUE(sameFragment(a.fragments[i], b.fragments[i])) << m << " triangle " << d.tag << " fragment " << i;
      ASSERT_EQ(b.span_cycles, a.span_cycles) << m << " triangle " << d.tag;
      ASSERT_EQ(b.row_cycles, a.row_cycles) << m << " triangle " << d.tag;
      ASSERT_LE(b.cycles, a.cycles) << m << " triangle " << d.tag;
      std::vector<SpanFragment> walked;
      const SpanWalk wk = walkSpanUnit(full_p, d, walked);
      ASSERT_EQ(wk.cycles, b.cycles) << m << " walker, triangle " << d.tag;
      ASSERT_EQ(walked.size(), b.fragments.size()) << m << " walker, triangle " << d.tag;
      paper_cycles += a.cycles;
      full_cycles += b.cycles;
      groups += a.span_cycles;
    }
    std::printf("%s, each triangle alone: paper %llu cycles, full rate %llu (%.3fx), lane groups %llu\n", m.c_str(),
                static_cast<unsigned long long>(paper_cycles), static_cast<unsigned long long>(full_cycles),
                static_cast<double>(full_cycles) / static_cast<double>(paper_cycles),
                static_cast<unsigned long long>(groups));
  }
}

// A stream of generator descriptors back to back through the full-rate unit, out_ready always 1:
// the cycles until it is idle are the walker's (SpanStream, descriptor by descriptor) and every
// descriptor's fragments come in order, as alone. With descriptors held back and out_ready
// dropped at random: the same fragments in the same order. The paper's unit takes a stream in
// the sum of its descriptors' cycles alone (it cannot overlap them).
TEST(SpanUnitModel, FullRateStreamKeepsItsTiming) {
  std::mt19937_64 rng(32);
  for (const std::string& m : paperSpanModes()) {
    const SpanParams full_p = fullRate(m), paper_p = spanParams(m);
    const std::vector<SpanDesc> descs = generatorDescriptors(paper_p, 33, 3000);
    std::vector<SpanFragment> alone;
    SpanStream stream;
    uint64_t walked_cycles = 0, paper_cycles = 0, groups = 0;
    for (const SpanDesc& d : descs) {
      const SpanWalk wk = walkSpanUnit(full_p, d, alone, &stream);
      walked_cycles += wk.cycles;
      groups += wk.span_cycles;
      std::vector<SpanFragment> scratch;
      paper_cycles += walkSpanUnit(paper_p, d, scratch).cycles;
    }
    ASSERT_EQ(walked_cycles, stream.end()) << m;
    const Streamed fast = streamThrough(full_p, descs, nullptr);
    EXPECT_EQ(fast.cycles, walked_cycles) << m;
    EXPECT_EQ(streamThrough(paper_p, descs, nullptr).cycles, paper_cycles) << m;
    const Streamed slow = streamThrough(full_p, descs, &rng);
    EXPECT_GT(slow.cycles, fast.cycles) << m;
    for (const Streamed* s : {&fast, &slow}) {
      ASSERT_EQ(s->fragments.size(), alone.size()) << m;
      for (size_t i = 0; i < alone.size(); ++i)
        ASSERT_TRUE(sameFragment(s->fragments[i], alone[i])) << m << " fragment " << i << " of the stream";
    }
    std::printf("%s, 3000 triangles back to back: paper %llu cycles, full rate %llu (%.3fx); lane groups %llu "
                "(full rate %.3fx of them)\n",
                m.c_str(), static_cast<unsigned long long>(paper_cycles), static_cast<unsigned long long>(fast.cycles),
                static_cast<double>(fast.cycles) / static_cast<double>(paper_cycles), static_cast<unsigned long long>(groups),
                static_cast<double>(fast.cycles) / static_cast<double>(groups));
  }
}

// The balanced Sierpinski unit (sierpinskifull, Interleave 1): setup chooses per triangle between
// the 4-way split and the row interleave. On generator triangles of every size class: both
// occur; the choice never takes more cycles than the split (each descriptor alone, the cycle
// model's count); an interleaving descriptor's lane j shows only the screen rows 4 w + j, and
// its fragments are the serial unit's, pixel for pixel and code for code, as a set (each lane
// in row order, the rows' lane groups in x order: the unit's order, checked against the walker
// in EveryModeEqualsSerialOnGeneratorTriangles).
TEST(SpanUnitModel, BalancedSierpinskiNeverTakesMoreCyclesThanTheSplit) {
  const SpanParams bal = spanParams("sierpinskifull");
  ASSERT_EQ(bal.Interleave, 1);
  SpanParams split = bal;
  split.Interleave = 0;
  RasterConfig cb, cs, c1;  // 512 x 512
  cb.unit = bal;
  cs.unit = split;
  c1.unit = spanParams("serial");
  SpanUnitModel ub(bal), us(split), u1(c1.unit);
  TriangleGenerator gen(41);
  SpanRun rb, rs, r1;
  uint64_t interleaved = 0, drawn = 0, cyc_b = 0, cyc_s = 0;
  for (int n = 0; n < 30000; ++n) {
    const GenTriangle t = gen.next();
    const auto v = toSetupVertices(t, bal.NumAttr);
    const SetupResult sb = setupTriangle(v, t.id, cb), ss = setupTriangle(v, t.id, cs), s1 = setupTriangle(v, t.id, c1);
    ASSERT_EQ(sb.desc.has_value(), ss.desc.has_value()) << describe(t);
    if (!sb.desc) continue;
    ASSERT_FALSE(ss.desc->interleave);
    ++drawn;
    runSpanUnit(ub, *sb.desc, rb);
    runSpanUnit(us, *ss.desc, rs);
    runSpanUnit(u1, *s1.desc, r1);
    ASSERT_LE(rb.cycles, rs.cycles) << describe(t);
    cyc_b += rb.cycles;
    cyc_s += rs.cycles;
    if (!sb.desc->interleave) {
      ASSERT_EQ(rb.cycles, rs.cycles) << describe(t);
      continue;
    }
    ++interleaved;
    ASSERT_LT(rb.cycles, rs.cycles) << "interleaved on a tie, " << describe(t);
    const std::vector<SpanFragment> a = sorted(rb.fragments), b = sorted(r1.fragments);
    ASSERT_EQ(a.size(), b.size()) << describe(t);
    for (size_t i = 0; i < a.size(); ++i)
      ASSERT_TRUE(sameFragment(a[i], b[i])) << "fragment " << i << ", " << describe(t);
    // Lane j's fragments lie on the rows 4 w + j: in the model's outputs, cycle by cycle.
    SpanUnitModel m(bal);
    SpanIn in;
    in.desc_valid = true;
    in.desc = &*sb.desc;
    SpanOut o;
    do {
      m.tick(in, o);
      in.desc_valid = false;
      for (size_t j = 0; j < o.lane.size(); ++j) {
        if (o.lane[j].valid) {
          ASSERT_EQ(o.lane[j].y % 4, static_cast<int32_t>(j)) << describe(t);
        }
      }
    } while (!m.idle());
  }
  EXPECT_GT(interleaved, drawn / 20);
  EXPECT_LT(interleaved, drawn);
  std::printf("%llu of %llu triangles interleaved; each alone %llu cycles against the split's %llu (%.3fx)\n",
              static_cast<unsigned long long>(interleaved), static_cast<unsigned long long>(drawn),
              static_cast<unsigned long long>(cyc_b), static_cast<unsigned long long>(cyc_s),
              static_cast<double>(cyc_b) / static_cast<double>(cyc_s));
}
