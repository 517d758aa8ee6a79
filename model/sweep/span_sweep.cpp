#include "sweep/span_sweep.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <stdexcept>
#include <tuple>
#include <utility>

#include <fmt/format.h>

#include "raster/setup.h"
#include "raster/span_walk.h"
#include "render/pipeline.h"
#include "render/render.h"
#include "scene/scene.h"
#include "sweep/area.h"

namespace shd {

namespace {

using i128 = __int128;

constexpr const char* kRasterNames[] = {"SubpixelBits", "ColourFracBits", "DepthFracBits"};

// ---------------------------------------------------------------------------------------------
// The base, read once per unit (validate() builds a point per grid point).

struct SpanBase {
  std::string config;
  SpanParams rtl;
  SpanPoint raster;  // its raster widths (rtl unused)
  int width = 512, height = 512;
  uint64_t triangles = kSpanSweepTriangles, seed = kSpanSweepSeed;
  std::vector<std::string> scenes;
};

// The names' form (the files are looked up when a scene is loaded: a merge, which evaluates
// nothing, needs none).
void checkSceneNames(const std::vector<std::string>& scenes) {
  if (scenes.empty())
    throw std::invalid_argument("a span sweep needs a scene: its viewport is the triangle set's, and each scene's "
                                "cycles are recorded");
  std::set<std::string> seen;
  for (const std::string& s : scenes) {
    if (!isSceneName(s))
      throw std::invalid_argument(fmt::format("scene \"{}\": a bundled scene's name (lower-case letters, digits, '_')", s));
    if (!seen.insert(s).second) throw std::invalid_argument(fmt::format("scene {} named twice", s));
  }
}

void checkTriangleCount(uint64_t n) {
  if (n < 1 || n > kMaxSpanSweepTriangles)
    throw std::invalid_argument(fmt::format("{} triangles: the set takes 1..{}", n, kMaxSpanSweepTriangles));
}

// std::invalid_argument for a malformed base (a plan's is checked by its hash; this names what
// is wrong with one edited by hand).
SpanBase readBase(const nlohmann::json& j) {
  SpanBase b;
  try {
    b.config = j.at("config").get<std::string>();
    b.rtl = SpanParams::fromJson(j.at("rtl"), "the sweep's base");
    const nlohmann::json& r = j.at("raster");
    b.raster.SubpixelBits = r.at("SubpixelBits").get<int>();
    b.raster.ColourFracBits = r.at("ColourFracBits").get<int>();
    b.raster.DepthFracBits = r.at("DepthFracBits").get<int>();
    b.width = j.at("viewport").at("width").get<int>();
    b.height = j.at("viewport").at("height").get<int>();
    b.triangles = j.at("triangles").get<uint64_t>();
    b.seed = j.at("seed").get<uint64_t>();
    b.scenes = j.at("scenes").get<std::vector<std::string>>();
  } catch (const nlohmann::json::exception& e) {
    throw std::invalid_argument(fmt::format("the span sweep's base: {}", e.what()));
  }
  checkTriangleCount(b.triangles);
  checkSceneNames(b.scenes);
  if (b.width < 1 || b.height < 1 || b.width > (1 << 20) || b.height > (1 << 20))
    throw std::invalid_argument(fmt::format("the span sweep's base: a viewport of {}x{}", b.width, b.height));
  return b;
}

// ---------------------------------------------------------------------------------------------
// A point and the derivations its evaluation rests on.

// The largest code of a value `top` with F fraction bits that setup accepts at AttrBits A:
// |top 2^F| <= 2^(A-1) - 1 - ((1 + W + H) / 2 + 2) (setupTriangle: room for the plane's
// rounding at any pixel of the viewport).
bool codeFits(int64_t top, int F, int A, int W, int H) {
  if (F > 62) return false;  // above any AttrBits (<= 62); and the shift below stays defined
  const i128 code = static_cast<i128>(top) << F;
  const i128 lim = (i128{1} << (A - 1)) - 1 - ((1 + int64_t{W} + H) / 2 + 2);
  return code <= lim;
}

// The AttrBits the codes of `top` at F fraction bits need (63: none up to 62).
int attrBitsFor(int64_t top, int F, int W, int H) {
  int a = 8;
  while (a <= 62 && !codeFits(top, F, a, W, H)) ++a;
  return a;
}

// The vertices' reach beyond the viewport: the triangle set's (TriGenOptions::guard_band, never
// beyond kTriGenMaxCoord) and the renderer's, which clips to kGuard px beyond it
// (render/pipeline.h). Setup's guard band 2^(CoordBits-3) px must hold both.
int64_t vertexReach(const SpanBase& b) {
  const int64_t side = std::max(b.width, b.height);
  const int64_t set = std::min<int64_t>(side + static_cast<int64_t>(TriGenOptions{}.guard_band),
                                        static_cast<int64_t>(kTriGenMaxCoord));
  return std::max({set, side + static_cast<int64_t>(kGuard), 2 * side});
}

void checkDerivations(const SpanPoint& p, const SpanBase& b, const std::string& where) {
  const SpanParams& r = p.rtl;
  auto refuse = [&](const std::string& rule) { throw std::invalid_argument(fmt::format("{}: {}", where, rule)); };
  if (p.SubpixelBits < 1 || p.SubpixelBits > 8)
    refuse(fmt::format("SubpixelBits = {}: setup snaps vertices to 1..8 fraction bits", p.SubpixelBits));
  if (r.NumAttr < kSpanEvalAttrs)
    refuse(fmt::format("NumAttr = {}: the evaluation carries {} attributes (colour 0..2, depth 3), NumAttr >= {}",
                       r.NumAttr, kSpanEvalAttrs, kSpanEvalAttrs));
  if (std::max(b.width, b.height) > (int64_t{1} << r.PixBits))
    refuse(fmt::format("PixBits = {}: the viewport {}x{} needs pixel coordinates below 2^PixBits", r.PixBits, b.width,
                       b.height));
  const int64_t reach = vertexReach(b), band = int64_t{1} << (r.CoordBits - 3);
  if (reach > band) {
    int need = r.CoordBits;
    while ((int64_t{1} << (need - 3)) < reach) ++need;
    refuse(fmt::format("CoordBits = {}: setup's guard band 2^(CoordBits-3) = {} px must hold every vertex, up to {} "
                       "px from the origin (the triangle set's guard band, the renderer's clip at {} px beyond the "
                       "viewport, twice the viewport): CoordBits >= {}",
                       r.CoordBits, band, reach, kGuard, need));
  }
  if (r.RemBits < r.CoordBits + 2 * p.SubpixelBits + 1)
    refuse(fmt::format("RemBits = {}: the edge divisor across the guard band needs RemBits >= CoordBits + 2 "
                       "SubpixelBits + 1 = {}",
                       r.RemBits, r.CoordBits + 2 * p.SubpixelBits + 1));
  const struct {
    const char* name;
    int F;
    int64_t top;  // the largest value: colour 255 (LSBs), depth 1
  } kinds[] = {{"ColourFracBits", p.ColourFracBits, 255}, {"DepthFracBits", p.DepthFracBits, 1}};
  for (const auto& k : kinds) {
    if (k.F < 0) refuse(fmt::format("{} = {}: attribute fraction bits are at least 0", k.name, k.F));
    if (!codeFits(k.top, k.F, r.AttrBits, b.width, b.height)) {
      const int need = attrBitsFor(k.top, k.F, b.width, b.height);
      refuse(fmt::format("AttrBits = {}: codes up to {} * 2^{} (with setup's room of (1 + W + H) / 2 + 2 codes for "
                         "the plane's rounding) need {}",
                         r.AttrBits, k.top, k.name,
                         need <= 62 ? fmt::format("AttrBits >= {}", need) : std::string("more than AttrBits 62")));
    }
    if (k.F > r.AttrBits - 2)  // implied by the codes' fit; setup's own rule (RasterConfig::validate)
      refuse(fmt::format("{} = {}: attribute fraction bits must be in 0..AttrBits-2 = {}", k.name, k.F, r.AttrBits - 2));
  }
}

// Setup's configuration of the point: attributes 0..2 colour, 3 depth, further ones (carrying
// zeros, not evaluated) as colour, as defaultAttrFracBitsFor has them.
RasterConfig rasterOf(const SpanPoint& p, const SpanBase& b) {
  RasterConfig rc;
  rc.width = b.width;
  rc.height = b.height;
  rc.subpixel_bits = p.SubpixelBits;
  rc.unit = p.rtl;
  rc.attr_frac_bits.assign(static_cast<size_t>(p.rtl.NumAttr), p.ColourFracBits);
  rc.attr_frac_bits[3] = p.DepthFracBits;
  return rc;
}

SpanPoint pointOf(const SpanBase& b, const PointValues& values, const std::string& where) {
  nlohmann::json rtl = b.rtl.toJson();
  SpanPoint p = b.raster;
  for (const auto& [name, value] : values) {
    if (name == "SubpixelBits") p.SubpixelBits = value;
    else if (name == "ColourFracBits") p.ColourFracBits = value;
    else if (name == "DepthFracBits") p.DepthFracBits = value;
    else rtl[name] = value;
  }
  p.rtl = SpanParams::fromJson(rtl, where);  // the parameters' own ranges (SpanParams::validate)
  checkDerivations(p, b, where);
  try {  // setup's own checks, should it gain one the rules above miss
    rasterOf(p, b).validate();
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(fmt::format("{}: {}", where, e.what()));
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// The scenes, loaded once per unit when first needed, shared by the evaluating threads.

class SceneCache {
 public:
  const Scene& get(const std::string& name) {
    std::lock_guard<std::mutex> lock(m_);
    auto it = loaded_.find(name);
    if (it != loaded_.end()) return *it->second;
    auto sc = std::make_unique<const Scene>(loadScene(sweepSceneFile(name)));
    RenderOptions ro;
    ro.method = Method::Gouraud;
    if (!deviceLobesUsed(*sc, ro).empty())
      throw std::invalid_argument(fmt::format("scene {}: a material evaluates its lobe with the specular unit; a span "
                                              "sweep renders with the span unit alone",
                                              name));
    return *loaded_.emplace(name, std::move(sc)).first->second;
  }

 private:
  std::mutex m_;
  std::map<std::string, std::unique_ptr<const Scene>> loaded_;  // never erased: references stay valid
};

// ---------------------------------------------------------------------------------------------
// The exact error of one triangle. Attribute a's exact plane at pixel (px, py), scaled by det
// (the snapped triangle's determinant, > 0), is the integer
//   det E(px, py) = q0 + qx px + qy py,  qx = gx 2^S, qy = gy 2^S,
//   q0 = det a0 + gx (2^(S-1) - X0) + gy (2^(S-1) - Y0)
// with gx, gy exactPlane's numerators (the pixel centre is (p + 1/2) 2^S subpixel units), so
// the unit's code c there errs by n / det codes, n = c det - det E, an integer.

[[noreturn]] __attribute__((noinline, cold)) void tooWide(const char* what) {
  throw std::logic_error(fmt::format("span sweep: {} leaves 128 bits (a width beyond the guard band's derivations)", what));
}
i128 mulChecked(i128 a, i128 b) {
  i128 r;
  if (__builtin_mul_overflow(a, b, &r)) tooWide("an exact error");
  return r;
}
i128 addChecked(i128 a, i128 b) {
  i128 r;
  if (__builtin_add_overflow(a, b, &r)) tooWide("an exact error");
  return r;
}
i128 absOf(i128 v) { return v < 0 ? -v : v; }

// One attribute kind's figures within a triangle (colour: attributes 0..2; depth: 3), exact.
struct KindTri {
  i128 worst = -1;  // the largest |n|; -1: no fragment
  int32_t x = 0, y = 0;
  int attr = 0;
  i128 sumsq = 0;                     // of n^2
  i128 ratio_num = 0, ratio_den = 1;  // the largest 2|n| / (det (1 + |px - xref| + |py - yref|))
  uint64_t values = 0, mismatches = 0;

  // Ties to the least (y, x, attribute): the same pixel whatever order the lanes emit in.
  void offer(i128 absn, int32_t px, int32_t py, int a) {
    if (absn > worst || (absn == worst && std::tie(py, px, a) < std::tie(y, x, attr))) {
      worst = absn;
      x = px;
      y = py;
      attr = a;
    }
  }
  // By cross multiplication (in long double only beyond 128 bits, which the guard band's
  // derivations keep far off).
  void offerRatio(i128 num, i128 den) {
    i128 l = 0, r = 0;
    const bool greater = !__builtin_mul_overflow(num, ratio_den, &l) && !__builtin_mul_overflow(ratio_num, den, &r)
                             ? l > r
                             : static_cast<long double>(num) / static_cast<long double>(den) >
                                   static_cast<long double>(ratio_num) / static_cast<long double>(ratio_den);
    if (greater) {
      ratio_num = num;
      ratio_den = den;
    }
  }
  // The largest ratio as a double, from the reduced fraction: equal ratios reached at other
  // pixels (another lane mode's candidates) give the same double.
  double ratio() const {
    i128 a = ratio_num, b = ratio_den;
    while (b != 0) a = std::exchange(b, a % b);
    return a == 0 ? 0.0 : static_cast<double>(ratio_num / a) / static_cast<double>(ratio_den / a);
  }
};

class TriangleErrors {
 public:
  TriangleErrors(const SetupResult& s, const RasterConfig& rc);
  void fragment(int32_t x, int32_t y, const int64_t* attr);
  void run(const RowRun& r);
  const KindTri& kind(int k) const { return kinds_[k]; }
  i128 det() const { return det_; }

 private:
  struct Plane {
    i128 q0 = 0, qx = 0, qy = 0;
  };
  i128 errorAt(int a, i128 code, int64_t x, int64_t y) const {
    const Plane& p = pl_[static_cast<size_t>(a)];
    return code * det_ - (p.q0 + p.qx * x + p.qy * y);
  }
  // det times setup's bound at the pixel, in half codes: det (1 + |px - xref| + |py - yref|).
  i128 boundDen(int64_t x, int64_t y) const {
    return det_ * (1 + std::abs(x - s_.plane.xref) + std::abs(y - s_.plane.yref));
  }
  // The error numerator n at pixel (x, y) of attribute a, offered as the kind's worst and as a
  // ratio to setup's bound.
  void offerPixel(int a, i128 n, int64_t x, int64_t y);

  const SetupResult& s_;
  i128 det_;
  std::array<Plane, kSpanEvalAttrs> pl_;
  KindTri kinds_[2];
};

TriangleErrors::TriangleErrors(const SetupResult& s, const RasterConfig& rc) : s_(s), det_(s.tri.det) {
  const SnappedTriangle& t = s.tri;
  const int S = rc.subpixel_bits;
  const i128 half = i128{1} << (S - 1);
  // The largest |n| any fragment can give, for the unchecked products of fragment(): codes
  // below 2^(AttrBits-1), pixels below 2^PixBits.
  long double bound = std::ldexp(static_cast<long double>(t.det), rc.unit.AttrBits - 1);
  for (size_t a = 0; a < pl_.size(); ++a) {
    const auto& c = t.a[a];
    const i128 gx = static_cast<i128>(c[1] - c[0]) * (t.Y[2] - t.Y[0]) - static_cast<i128>(c[2] - c[0]) * (t.Y[1] - t.Y[0]);
    const i128 gy = static_cast<i128>(t.X[1] - t.X[0]) * (c[2] - c[0]) - static_cast<i128>(t.X[2] - t.X[0]) * (c[1] - c[0]);
    Plane& p = pl_[a];
    p.qx = mulChecked(gx, i128{1} << S);
    p.qy = mulChecked(gy, i128{1} << S);
    p.q0 = addChecked(addChecked(mulChecked(det_, c[0]), mulChecked(gx, half - t.X[0])), mulChecked(gy, half - t.Y[0]));
    const long double pix = std::ldexp(1.0L, rc.unit.PixBits);
    bound = std::max(bound, std::ldexp(static_cast<long double>(t.det), rc.unit.AttrBits - 1) +
                                std::fabs(static_cast<long double>(p.q0)) +
                                (std::fabs(static_cast<long double>(p.qx)) + std::fabs(static_cast<long double>(p.qy))) * pix);
  }
  if (bound >= std::ldexp(1.0L, 124)) tooWide("the triangle's exact plane");  // then |n| < 2^125
}

void TriangleErrors::offerPixel(int a, i128 n, int64_t x, int64_t y) {
  KindTri& k = kinds_[a == 3 ? 1 : 0];
  const i128 absn = absOf(n);
  k.offer(absn, static_cast<int32_t>(x), static_cast<int32_t>(y), a);
  k.offerRatio(2 * absn, boundDen(x, y));
}

void TriangleErrors::fragment(int32_t x, int32_t y, const int64_t* attr) {
  for (int a = 0; a < kSpanEvalAttrs; ++a) {
    KindTri& k = kinds_[a == 3 ? 1 : 0];
    const i128 n = errorAt(a, attr[a], x, y);
    k.sumsq = addChecked(k.sumsq, mulChecked(n, n));
    ++k.values;
    k.mismatches += attr[a] != s_.plane.at(a, x, y) ? 1 : 0;
    offerPixel(a, n, x, y);
  }
}

// A run: fragment i (0 <= i < N) at x0 + i dx shows a0 + i da, so its error numerator
// c + i d is affine in i: the sum of squares in closed form, the largest |error| at an end,
// the largest ratio to setup's bound at an end or at xref (on either side of xref the bound is
// affine too, and an affine function over a positive affine one is monotonic), the codes equal
// to setup's integer plane where (a0 - P(x0)) + i (da - dx didx) is 0.
void TriangleErrors::run(const RowRun& r) {
  const i128 N = r.count, S1 = N * (N - 1) / 2, S2 = (N - 1) * N * (2 * N - 1) / 6;
  const int64_t x_end = r.x0 + (r.count - 1) * r.dx;
  for (int a = 0; a < kSpanEvalAttrs; ++a) {
    const size_t ai = static_cast<size_t>(a);
    KindTri& k = kinds_[a == 3 ? 1 : 0];
    const i128 c = errorAt(a, r.a0[ai], r.x0, r.y);
    const i128 d = r.count > 1 ? static_cast<i128>(r.da[ai]) * det_ - r.dx * pl_[ai].qx : 0;  // a run of one: no step
    const i128 sq = addChecked(addChecked(mulChecked(N, mulChecked(c, c)), mulChecked(2 * S1, mulChecked(c, d))),
                               mulChecked(S2, mulChecked(d, d)));
    k.sumsq = addChecked(k.sumsq, sq);
    k.values += static_cast<uint64_t>(r.count);
    const i128 a_end = static_cast<i128>(r.a0[ai]) + static_cast<i128>(r.count - 1) * r.da[ai];
    offerPixel(a, c, r.x0, r.y);
    offerPixel(a, errorAt(a, a_end, x_end, r.y), x_end, r.y);
    const int64_t xref = s_.plane.xref;
    if ((xref - r.x0) * r.dx > 0 && (x_end - xref) * r.dx > 0) {  // strictly inside the run
      const int64_t i = (xref - r.x0) * r.dx;
      const i128 n = absOf(errorAt(a, static_cast<i128>(r.a0[ai]) + static_cast<i128>(i) * r.da[ai], xref, r.y));
      k.offerRatio(2 * n, boundDen(xref, r.y));
    }
    const i128 m0 = static_cast<i128>(r.a0[ai]) - s_.plane.at(a, r.x0, r.y);
    const i128 ms = r.count > 1 ? static_cast<i128>(r.da[ai]) - static_cast<i128>(r.dx) * s_.plane.didx[ai] : 0;
    uint64_t equal = 0;  // the i with m0 + i ms = 0
    if (ms == 0) equal = m0 == 0 ? static_cast<uint64_t>(r.count) : 0;
    else if (m0 % ms == 0 && -m0 / ms >= 0 && -m0 / ms < N) equal = 1;
    k.mismatches += static_cast<uint64_t>(r.count) - equal;
  }
}

// ---------------------------------------------------------------------------------------------
// The set's figures.

// One attribute kind over the set: worst in codes (across triangles by value; ties keep the
// earlier triangle), sums of squares in codes^2.
struct KindSet {
  double worst = -1;
  int64_t tri = -1;
  int32_t x = -1, y = -1;
  int attr = -1;
  double sumsq = 0, ratio = 0;
  uint64_t values = 0, mismatches = 0;

  void add(const KindTri& t, i128 det, uint32_t id) {
    if (t.values == 0) return;
    const double dd = static_cast<double>(det);
    const double v = static_cast<double>(t.worst) / dd;
    if (v > worst) {
      worst = v;
      tri = id;
      x = t.x;
      y = t.y;
      attr = t.attr;
    }
    sumsq += static_cast<double>(t.sumsq) / (dd * dd);
    ratio = std::max(ratio, t.ratio());
    values += t.values;
    mismatches += t.mismatches;
  }
};

struct SetFigures {
  KindSet colour, depth;
  uint64_t drawn = 0, dropped = 0, rejected = 0, fragments = 0, cycles = 0;
};

std::array<SetupVertex, 3> setupVertices(const GenTriangle& t, int num_attr) {
  std::array<SetupVertex, 3> v;
  for (size_t i = 0; i < 3; ++i) {
    v[i].x = t.v[i].x;
    v[i].y = t.v[i].y;
    for (int k = 0; k < num_attr; ++k) v[i].attr.push_back(k < kSpanEvalAttrs ? t.v[i].attr[static_cast<size_t>(k)] : 0.0);
  }
  return v;
}

TriGenOptions triangleOptions(const SpanBase& b) {
  TriGenOptions g;
  g.width = b.width;
  g.height = b.height;
  g.subpixel_bits = b.raster.SubpixelBits;
  g.num_attr = kSpanEvalAttrs;
  return g;
}

// Every triangle of the set through setup and the unit's walk, every fragment's error.
SetFigures evaluateSet(const SpanPoint& p, const SpanBase& b) {
  const RasterConfig rc = rasterOf(p, b);
  TriangleGenerator gen(b.seed, triangleOptions(b));
  SetFigures f;
  std::optional<SetupResult> s;
  SpanStream stream;  // the full-rate unit's: the set's triangles back to back
  for (uint64_t i = 0; i < b.triangles; ++i) {
    const GenTriangle t = gen.next();
    try {
      s.emplace(setupTriangle(setupVertices(t, p.rtl.NumAttr), t.id, rc));
    } catch (const std::logic_error&) {  // a vertex or code the widths cannot hold (std::invalid_argument too)
      ++f.rejected;
      continue;
    }
    if (!s->desc) {
      ++f.dropped;
      continue;
    }
    ++f.drawn;
    TriangleErrors e(*s, rc);
    const SpanWalk w = walkSpanUnit(
        p.rtl, *s->desc, [&e](int32_t x, int32_t y, const int64_t* a) { e.fragment(x, y, a); },
        [&e](const RowRun& r) { e.run(r); }, p.rtl.RowAhead ? &stream : nullptr);
    f.cycles += w.cycles;
    f.fragments += w.fragments;
    f.colour.add(e.kind(0), e.det(), t.id);
    f.depth.add(e.kind(1), e.det(), t.id);
  }
  return f;
}

// A scene's span cycles and fragments, rendered with the gouraud method as scripts/regress.py
// and `shadesim render` count them. The renderer codes its own attributes (4 of them,
// render/pipeline.h's fraction bits, which AttrBits 32 holds), so the scene runs through the
// point's lane layout and coordinate widths with NumAttr 4 and AttrBits 32: the walk's rows and
// spans read edges alone, never attribute values, so cycles and fragments do not depend on them.
std::pair<uint64_t, uint64_t> sceneCycles(const Scene& sc, const SpanPoint& p) {
  SpanParams unit = p.rtl;
  unit.NumAttr = 4;
  unit.AttrBits = 32;
  ModelSpanEngine engine(unit);
  RenderOptions ro;
  ro.method = Method::Gouraud;
  ro.subpixel_bits = p.SubpixelBits;
  const RenderResult r = render(sc, ro, engine, SpecEngines{});
  return {r.stats.span_cycles, r.stats.fragments};
}

void putKind(nlohmann::json& err, const char* kind, const KindSet& k, int frac, int out_frac) {
  const double lsb = std::ldexp(1.0, out_frac - frac);  // output LSBs per code
  const std::string n(kind);
  err[n + "_max_lsb"] = k.worst < 0 ? 0.0 : k.worst * lsb;
  err[n + "_rms_lsb"] = k.values ? std::sqrt(k.sumsq / static_cast<double>(k.values)) * lsb : 0.0;
  err[n + "_worst_triangle"] = k.tri;
  err[n + "_worst_x"] = k.x;
  err[n + "_worst_y"] = k.y;
  err[n + "_worst_attr"] = k.attr;
  err[n + "_bound_ratio"] = k.ratio;
}

nlohmann::json evaluateSpanPoint(uint64_t index, const SpanPoint& p, const SpanBase& b, SceneCache& scenes) {
  const SetFigures f = evaluateSet(p, b);
  nlohmann::json err;
  putKind(err, "colour", f.colour, p.ColourFracBits, kSpanColourOutFrac);
  putKind(err, "depth", f.depth, p.DepthFracBits, kSpanDepthOutFrac);
  err["max_lsb"] = std::max(err["colour_max_lsb"].get<double>(), err["depth_max_lsb"].get<double>());
  err["plane_mismatches"] = f.colour.mismatches + f.depth.mismatches;
  nlohmann::json j;
  j["index"] = index;
  j["params"] = p.toJson();
  j["hash"] = textHash(j["params"].dump());
  j["error"] = std::move(err);
  j["triangles"] = b.triangles;
  j["drawn"] = f.drawn;
  j["dropped"] = f.dropped;
  j["rejected"] = f.rejected;
  j["fragments"] = f.fragments;
  j["cycles"] = f.cycles;
  j["lanes"] = p.rtl.lanes();
  for (const std::string& name : b.scenes) {
    const auto [cycles, fragments] = sceneCycles(scenes.get(name), p);
    j["cycles_" + name] = cycles;
    j["fragments_" + name] = fragments;
  }
  return j;
}

}  // namespace

nlohmann::json SpanPoint::toJson() const {
  nlohmann::json j = rtl.toJson();
  j["SubpixelBits"] = SubpixelBits;
  j["ColourFracBits"] = ColourFracBits;
  j["DepthFracBits"] = DepthFracBits;
  return j;
}

std::vector<std::string> spanParamNames() {
  const nlohmann::json rtl = SpanParams{}.toJson();
  std::vector<std::string> names;
  for (auto it = rtl.begin(); it != rtl.end(); ++it) names.push_back(it.key());
  names.insert(names.end(), std::begin(kRasterNames), std::end(kRasterNames));
  return names;
}

nlohmann::json spanSweepBase(const SpanUnitConfig& cfg, uint64_t triangles, uint64_t seed,
                             const std::vector<std::string>& scenes) {
  checkTriangleCount(triangles);
  checkSceneNames(scenes);
  // The viewport: the scenes' (one for all); loading them finds their files.
  SceneCache cache;
  const Camera& cam = cache.get(scenes.front()).camera;
  for (const std::string& s : scenes) {
    const Camera& c = cache.get(s).camera;
    if (c.width != cam.width || c.height != cam.height)
      throw std::invalid_argument(fmt::format("scenes {} ({}x{}) and {} ({}x{}): a span sweep's scenes share one viewport",
                                              scenes.front(), cam.width, cam.height, s, c.width, c.height));
  }
  const std::vector<int> frac = defaultAttrFracBitsFor(cam.width, cam.height, kSpanEvalAttrs);
  return {{"unit", "span"},
          {"config", cfg.ref()},
          {"rtl", cfg.rtl.toJson()},
          {"raster", {{"SubpixelBits", RasterConfig{}.subpixel_bits}, {"ColourFracBits", frac[0]}, {"DepthFracBits", frac[3]}}},
          {"viewport", {{"width", cam.width}, {"height", cam.height}}},
          {"triangles", triangles},
          {"seed", seed},
          {"scenes", scenes}};
}

SpanPoint spanPointParams(const nlohmann::json& base, const PointValues& values) {
  return pointOf(readBase(base), values, "point " + describePoint(values));
}

TriGenOptions spanSweepTriangleOptions(const nlohmann::json& base) { return triangleOptions(readBase(base)); }

SweepUnit spanSweepUnit(const nlohmann::json& base_json) {
  const SpanBase b = readBase(base_json);
  const auto scenes = std::make_shared<SceneCache>();
  SweepUnit u;
  u.name = "span";
  u.base = base_json;
  std::string scene_list;
  for (const std::string& s : b.scenes) scene_list += (scene_list.empty() ? "" : ",") + s;
  u.base_options = fmt::format("--config {} --triangles {} --seed {} --scene {}", b.config, b.triangles, b.seed, scene_list);
  u.params = spanParamNames();
  u.params_member = "params";
  u.front_error = "max_lsb";
  u.front_costs = {"cycles", "lanes"};
  u.validate = [b, scenes](const Grid& grid) {
    for (uint64_t k = 0; k < grid.size(); ++k) {
      const PointValues values = grid.point(k);
      pointOf(b, values, fmt::format("point {} ({})", k, describePoint(values)));
    }
    // The scenes load, and are still of the base's viewport (the installation's files).
    for (const std::string& name : b.scenes) {
      const Camera& c = scenes->get(name).camera;
      if (c.width != b.width || c.height != b.height)
        throw std::invalid_argument(fmt::format("scene {} is {}x{}, the sweep's viewport {}x{}", name, c.width, c.height,
                                                b.width, b.height));
    }
  };
  u.evaluate = [b, scenes](uint64_t index, const PointValues& values) {
    return evaluateSpanPoint(index, pointOf(b, values, "point " + describePoint(values)), b, *scenes);
  };
  u.area = [b](const PointValues& values, const SynthTool& tool) {
    return unitPointArea("span", pointOf(b, values, "point " + describePoint(values)).rtl.toJson(), {},
                         nlohmann::json::object(), tool);
  };
  u.rtl = [b](const PointValues& values) { return pointOf(b, values, "point " + describePoint(values)).rtl.toJson(); };
  return u;
}

}  // namespace shd
