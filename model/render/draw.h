// What the shading methods' units (render/methods/) draw with: the frame and the current
// object's lighting (Frame), a screen triangle set up for the span unit (SpanTriangle), the
// unit interface (MethodUnit), and the pieces of the hot paths that every unit shares: writing
// a pixel (PixelWriter), stepping along a run (RunCursor), walking a triangle's fragments
// (Frame::walk) and a triangle's per-pixel specular-unit requests (PixelRequests).
//
// The fragment paths stay static: a unit hands walkSpanUnit its fragment sink and run
// consumers as closures or function objects (templates), so the dispatch is one virtual call
// per screen triangle (MethodUnit::draw), none per fragment.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "raster/row_spans.h"
#include "raster/setup.h"
#include "raster/span_walk.h"
#include "render/fixed_simd.h"
#include "render/normalize.h"
#include "render/pipeline.h"
#include "render/render.h"
#include "render/shading.h"

namespace shd {

// A screen triangle's span walk done ahead, by a two-thread frame's front end (render.cpp, which
// counts its cycles and fragments), for its back end's Frame::walk to replay: the fragments and
// runs in the walk's order. The renderer's 4 attributes.
struct RecordedWalk {
  struct Event {
    bool run = false;  // a RowRun, or the one fragment at (x0, y) with attributes a0
    int32_t x0 = 0, y = 0, dx = 1;
    int64_t count = 1;
    std::array<int64_t, 4> a0{}, da{};
  };
  std::vector<Event> events;
};

// The rows of a triangle that a side of a two-thread frame draws. Walked ahead
// (TwoThreads::AfterWalk): the screen in bands of 8 rows, kBands to a period, the front end
// taking the first kFrontBands of each period and the back end the others. Split by rows
// (render.cpp, "split by rows"): the rows y0 .. y1 - 1 (Rows). All: every row, one thread. Each
// pixel is then drawn by one side alone, in the triangles' order, as one thread draws it; each
// side counts the pixels it draws. The front end's share is the smaller, as it also culls,
// sets up and walks: of 0 to 4 bands in 8, 3 made phong-fixed's frame on builtin:sphere the
// shortest on a 2-core AMD EPYC VM without AVX-512 (docs/performance.md).
struct RowShare {
  enum class Side : uint8_t { All, Front, Back, Rows };
  Side side = Side::All;
  int32_t y0 = 0, y1 = 0;  // Rows: this side's rows
  static constexpr int kBandShift = 3, kBands = 8, kFrontBands = 3;
  static bool front(int32_t y) { return ((y >> kBandShift) & (kBands - 1)) < kFrontBands; }
  bool mine(int32_t y) const {
    if (side == Side::Rows) return y >= y0 && y < y1;
    return side == Side::All || (side == Side::Front) == front(y);
  }
  // Whether a row of y0 .. y1 (y0 <= y1) is mine.
  bool anyIn(int32_t lo, int32_t hi) const {
    if (side == Side::Rows) return lo < y1 && hi >= y0;
    for (int32_t band = lo >> kBandShift; band <= hi >> kBandShift; ++band)
      if (mine(std::max(lo, band << kBandShift))) return true;
    return false;
  }
  // Whether a row of a triangle's rows' spans is mine.
  bool anyRow(const RowSpans& s) const { return anyIn(s.y0, s.y0 + s.rows - 1); }
  // The rows of s that are mine: bit i for row y0 + i.
  uint64_t rowMask(const RowSpans& s) const {
    uint64_t m = 0;
    for (int32_t i = 0; i < s.rows; ++i) m |= uint64_t{mine(s.y0 + i)} << i;
    return m;
  }
};

// A screen triangle set up for the span unit, with the method that draws it: by setup (a span
// descriptor) or, for a small triangle of a method whose traits allow it, as its rows' spans
// (raster/row_spans.h: the same fragments and cycles).
struct SpanTriangle {
  std::array<const PVertex*, 3> v;  // as set up (the fan's, or a split's)
  Method method;
  const SetupResult* setup;  // setup->desc: its span descriptor; setup->plane: its attribute planes; or null:
  const RowSpans* rows;      //   its rows' spans (MethodTraits::row_spans)
  const RasterConfig& raster;
  uint32_t tag;  // its id: the index in RenderResult::triangles, the framebuffer's tri
  const RecordedWalk* walked = nullptr;  // its walk done ahead, or null: Frame::walk walks it
  bool counted = false;  // rows: its cycles and fragments counted by a two-thread frame's front end
  RowShare share{};      // walked ahead or counted: the rows to draw (Frame::walk)
  // The plane's gradient of attribute k along x (SetupResult::plane.didx).
  int64_t didx(size_t k) const { return rows != nullptr ? rows->didx[k] : setup->plane.didx[k]; }
};

class MethodUnit;

// A screen triangle of a polygon before setup, with the unit and the method that draw it.
struct Part {
  std::array<const PVertex*, 3> v;
  MethodUnit* unit;
  Method method;
  const std::array<double, 3>* colour = nullptr;  // colour attributes: every vertex's (flat), or null: its own
};
using Parts = std::vector<Part>;
// Appends a part, its fields written in place: `out.push_back({...})` built the part on the stack
// from stores of 4 and 8 bytes and copied it with 16-byte loads, which the processor cannot
// forward from those stores (a stall of a dozen cycles per part, 2 % of a frame of small
// triangles: docs/performance.md).
inline void addPart(Parts& out, const PVertex* a, const PVertex* b, const PVertex* c, MethodUnit* unit, Method method,
                    const std::array<double, 3>* colour = nullptr) {
  Part& p = out.emplace_back();
  p.v = {a, b, c};
  p.unit = unit;
  p.method = method;
  p.colour = colour;
}

// One shading method's drawing (render/methods/*.cpp, chosen by Method in the table of
// render/methods.cpp). Per frame one unit per method in use; per object beginObject, then per
// polygon parts(), then per screen triangle that setup keeps draw(), then endObject.
class MethodUnit {
 public:
  explicit MethodUnit(Method m) : method_(m) {}
  virtual ~MethodUnit() = default;
  // The current object's lighting is set (Frame::obj).
  virtual void beginObject() {}
  // The screen triangles to draw of a polygon (a clipped triangle's fan; 3 vertices unless
  // clipped), in order: by default each fan triangle, by this unit.
  virtual void parts(const Fan& fan, Parts& out) {
    for (size_t k = 1; k + 1 < fan.size(); ++k) addPart(out, fan[0], fan[k], fan[k + 1], this, method_);
  }
  // The fragments of a screen triangle: walked, z-tested, shaded and written.
  virtual void draw(const SpanTriangle& t) = 0;
  // After the object's last triangle.
  virtual void endObject() {}
  Method method() const { return method_; }

 private:
  Method method_;
};

// A fragment's write once its z-test has passed: the colour, the depth code and the triangle's
// tag. A written fragment has w > 0 (the z-test), so depth 0 marks a pixel not yet covered:
// returns 1 for a pixel not covered before (for pixels_covered). The pointers are held by
// value: a run's loop writes through a local copy (const auto put = write), whose pointers then
// stay in registers, where an object's members would be read again after each byte store.
struct PixelWriter {
  uint8_t* rgb;
  int32_t* depth;
  int32_t* tri_of;  // null: no triangle buffer (RenderOptions::tags)
  int32_t tag;
  uint64_t operator()(size_t p, int64_t w, const std::array<uint8_t, 3>& c) const {
    for (size_t k = 0; k < 3; ++k) rgb[p * 3 + k] = c[k];
    const uint64_t fresh = depth[p] == 0 ? 1 : 0;
    depth[p] = static_cast<int32_t>(w);
    if (tri_of != nullptr) tri_of[p] = tag;
    return fresh;
  }
};

// A run's pixels in the framebuffer: the index and the depth code of the current one, and
// their steps along the run.
struct RunCursor {
  size_t p, step;
  uint64_t z, dz;
  RunCursor(const RowRun& r, int width)
      : p(static_cast<size_t>(r.y) * static_cast<size_t>(width) + static_cast<size_t>(r.x0)),
        step(static_cast<size_t>(static_cast<ptrdiff_t>(r.dx))),  // +1 or -1 (mod 2^64)
        z(static_cast<uint64_t>(r.a0[3])),
        dz(static_cast<uint64_t>(r.da[3])) {}
  int64_t depth() const { return static_cast<int64_t>(z); }
  void next() {
    p += step;
    z += dz;
  }
};

// Barycentric coordinates of the centre of pixel (x, y) on the unsnapped screen triangle v
// (reference).
inline std::array<double, 3> barycentric(const std::array<const PVertex*, 3>& v, int32_t x, int32_t y) {
  const double px = x + 0.5, py = y + 0.5;
  const double d = area2(*v[0], *v[1], *v[2]);
  const double l1 = ((px - v[0]->x) * (v[2]->y - v[0]->y) - (v[2]->x - v[0]->x) * (py - v[0]->y)) / d;
  const double l2 = ((v[1]->x - v[0]->x) * (py - v[0]->y) - (px - v[0]->x) * (v[1]->y - v[0]->y)) / d;
  return std::array<double, 3>{1 - l1 - l2, l1, l2};
}

// Barycentric coordinates (of the vertices in their order before setup) of the centre of pixel
// (x, y) on the triangle the span unit draws: setup's snapped vertices. Every fragment of the
// triangle is inside it, so the weights lie in [0, 1] even for a sliver whose unsnapped area is
// almost zero, where the unsnapped triangle's weights of a covered pixel reach 10^6
// (biquadratic; test Stiff.BiquadraticSliverStaysWithinItsSamples). Exact: the subpixel
// coordinates and their products fit a double's 53 bits.
inline std::array<double, 3> barycentricSnapped(const SpanTriangle& t, int32_t x, int32_t y) {
  const SnappedTriangle& s = t.setup->tri;
  const double one = static_cast<double>(int64_t{1} << t.raster.subpixel_bits);
  const double px = (x + 0.5) * one, py = (y + 0.5) * one;
  const double x0 = static_cast<double>(s.X[0]), y0 = static_cast<double>(s.Y[0]);
  const double dx1 = static_cast<double>(s.X[1] - s.X[0]), dy1 = static_cast<double>(s.Y[1] - s.Y[0]);
  const double dx2 = static_cast<double>(s.X[2] - s.X[0]), dy2 = static_cast<double>(s.Y[2] - s.Y[0]);
  const double d = static_cast<double>(s.det);
  const double l1 = ((px - x0) * dy2 - dx2 * (py - y0)) / d;
  const double l2 = (dx1 * (py - y0) - (px - x0) * dy1) / d;
  return s.swapped ? std::array<double, 3>{1 - l1 - l2, l2, l1} : std::array<double, 3>{1 - l1 - l2, l1, l2};
}

// phong-incremental, phong-fixed: |N|^2 of the fragments of a triangle, along each run of
// consecutive pixels of a row by the recurrence (normalize.h), restarted (three products) where
// the stream is not the next pixel. The recurrence is exact, so the values do not depend on
// where it restarts.
class SquaredNorms {
 public:
  // dn: the gradients along x of the normal's three attributes.
  explicit SquaredNorms(const std::array<int64_t, 3>& dn) : dn_(dn) {}
  explicit SquaredNorms(const SpanTriangle& t) : SquaredNorms({t.didx(0), t.didx(1), t.didx(2)}) {}
  uint64_t operator()(int32_t x, int32_t y, const int64_t* attr) {
    const uint64_t f = y == run_y_ && x == run_next_x_ ? sqn_.next() : sqn_.start({attr[0], attr[1], attr[2]}, dn_);
    run_y_ = y;
    run_next_x_ = x + 1;
    return f;
  }

 private:
  SquaredNormRecurrence sqn_;
  int32_t run_y_ = -1, run_next_x_ = 0;
  std::array<int64_t, 3> dn_;
};

// The current object's lighting.
struct ObjectShading {
  int index = 0;
  const Material* material = nullptr;
  Lobe lobe = Lobe::Blinn;
  SpecEngine* spec = nullptr;              // the lobe's specular unit, or null
  const SpecUnitModel* direct = nullptr;   // spec's bit-exact model: per-pixel requests evaluated as made
  DeviceCoding coding;                     // the material's requests to spec
  std::optional<PointShader> shader;       // the material and lobe
};

// The frame being drawn: its buffers and statistics, the span engine, the camera, the lights,
// the current object's lighting, and the units of the methods in use.
class Frame {
 public:
  Frame(const Scene& scene, const RenderOptions& opt, SpanEngine& span, Framebuffer& fb, RenderStats& st);
  Frame(const Frame&) = delete;
  Frame& operator=(const Frame&) = delete;
  ~Frame();

  const RenderOptions& opt;
  Framebuffer& fb;
  RenderStats& st;
  const int W, H;
  const Projection proj;
  const ShadeContext ctx;
  SpanEngine& span;
  const SpanParams* const walker;  // span.walker(): fragments shaded as the model's walk produces them
  // phong-fixed's runs of a row to its batch (fixed_simd.h): left to right, with depth codes
  // that fit int32_t (AttrBits <= 32), z-tested into the batch by this kernel
  // (fixed_simd::bufferKernel: AVX-512, AVX2 or plain C++); null (RenderOptions::vector_kernel
  // false): the run loop.
  const fixed_simd::BufferKernel buffer_run;
  // The same kernel's pass over a triangle's rows' spans (fixed_simd::spansBufferKernel), null
  // where buffer_run is.
  const fixed_simd::SpansBufferKernel buffer_spans;
  // The kernel of flat and Gouraud's colour runs, under the same conditions, AVX-512 or AVX2
  // (fixed_simd::colourKernel); null: the scalar loop.
  const fixed_simd::ColourKernel colour_kernel;
  // The colour kernel's pass straight from the rows' spans (fixed_simd::colourSpansKernel; the
  // scalar one, colourSpansScalar, on the scalar paths); null without the model's span unit or
  // where its codes exceed 32 bits.
  const fixed_simd::ColourSpansKernel colour_spans;
  // The AVX2 paths of setup: the vertex transform (transformVertexRange) and the rows' spans'
  // plane (RowSpansConfig::vector), where the CPU has AVX2 and opt.vector_kernel holds.
  const bool avx2;
  ObjectShading obj;

  // The unit drawing method m, made on first use (render/methods.cpp); the units in use.
  MethodUnit& unit(Method m);
  const std::vector<std::pair<Method, std::unique_ptr<MethodUnit>>>& units() const { return units_; }

  // A point's shade, with its device-lobe evaluations done by the specular unit right away
  // (vertices, polygons, split points: few; pixels are batched per triangle, PixelRequests).
  std::array<double, 3> shadeNow(Vec3 n, Vec3 p);
  // A polygon's colour by its face normal (toward the viewer) at the centroid of its vertices
  // a, b, c (MethodTraits::face_colours).
  std::array<double, 3> faceColour(const PVertex& a, const PVertex& b, const PVertex& c);
  // The colour of the polygon being drawn when the drawer lit it ahead (faceColour, in a pass
  // over the object's triangles: lightFaces in render.cpp), else null.
  const std::array<double, 3>* face_colour = nullptr;
  // Fragment writes of a triangle.
  PixelWriter writer(uint32_t tag) const {
    return PixelWriter{fb.rgb.data(), fb.depth.data(), tags(), static_cast<int32_t>(tag)};
  }
  // The triangle buffer, null where the frame has none (RenderOptions::tags).
  int32_t* tags() const { return fb.tri.empty() ? nullptr : fb.tri.data(); }
  // Whether a triangle's per-pixel device requests of method m wait for the triangle's batch
  // (the specular unit is not the model: the RTL's stream).
  bool batchesRequests(Method m) const;

  // The fragments of t, each to sink(x, y, attr), and with the model's walk the runs of rows to
  // runs(const RowRun&) (see walkSpanUnit): shaded as the walk produces them, or without it (the
  // RTL's stream) collected first. The span cycles and fragments counted.
  template <class Sink, class... Runs>
  void walk(const SpanTriangle& t, Sink& sink, Runs&... runs) {
    if (t.walked != nullptr) {
      replay(*t.walked, t.share, sink, runs...);
      return;
    }
    if (t.rows != nullptr) {
      if (!t.counted) countRows(*t.rows);
      const auto mine = [share = t.share](int32_t y) { return share.mine(y); };
      if constexpr (sizeof...(Runs) > 0) {
        emitRowSpans(*t.rows, runs..., mine);
      } else {
        auto fragments = [&sink](const RowRun& r) { runFragments(r, sink); };
        emitRowSpans(*t.rows, fragments, mine);
      }
      return;
    }
    if (walker != nullptr) {
      SpanWalk wk;
      if constexpr (sizeof...(Runs) == 0)
        wk = walkSpanUnit(*walker, *t.setup->desc, sink, span_detail::NoRuns{}, span.streamOrNull());
      else
        wk = walkSpanUnit(*walker, *t.setup->desc, sink, runs..., span.streamOrNull());
      count(wk);
      return;
    }
    collect(t);
    for (const SpanFragment& fr : frags) sink(fr.x, fr.y, fr.attr.data());
  }
  // The fragments of t walked, z-tested and written with the colour colourAt(x, y) (LSBs, no
  // device lobe) gives each that passes: the per-pixel colour methods (gouraud-classical,
  // biquadratic).
  template <class ColourAt>
  void drawColours(const SpanTriangle& t, ColourAt&& colourAt) {
    const PixelWriter write = writer(t.tag);
    auto fragment = [&](int32_t x, int32_t y, const int64_t* attr) {
      const size_t p = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
      if (attr[3] <= fb.depth[p]) {
        ++st.depth_rejected;
        return;
      }
      st.pixels_covered += write(p, attr[3], combine(colourAt(x, y), nullptr, 0));
    };
    walk(t, fragment);
  }
  // A walk done ahead, to the same consumers, its events in the rows of `share`: with no run
  // consumer, a run's fragments one by one, which is what the walk gives such a consumer (a run
  // is a row's fragments in order).
  template <class Sink, class... Runs>
  static void replay(const RecordedWalk& w, RowShare share, Sink& sink, Runs&... runs) {
    for (const RecordedWalk::Event& e : w.events) {
      if (!share.mine(e.y)) continue;
      if (!e.run) {
        sink(e.x0, e.y, static_cast<const int64_t*>(e.a0.data()));
      } else if constexpr (sizeof...(Runs) > 0) {
        (runs(RowRun{e.x0, e.y, e.dx, e.count, e.a0.data(), e.da.data()}), ...);
      } else {
        runFragments(RowRun{e.x0, e.y, e.dx, e.count, e.a0.data(), e.da.data()}, sink);
      }
    }
  }
  // A run's fragments one by one, which is what the walk gives a consumer without runs.
  template <class Sink>
  static void runFragments(const RowRun& r, Sink& sink) {
    std::array<int64_t, 4> a = {r.a0[0], r.a0[1], r.a0[2], r.a0[3]};
    for (int64_t i = 0; i < r.count; ++i) {
      sink(r.x0 + static_cast<int32_t>(i) * r.dx, r.y, static_cast<const int64_t*>(a.data()));
      for (size_t k = 0; k < a.size(); ++k) a[k] += r.da[k];
    }
  }
  // A walk's counts.
  void count(const SpanWalk& wk) {
    st.span_cycles += wk.cycles;
    st.fragments += wk.fragments;
  }
  // A triangle's rows' spans counted as the model's walk counts its descriptor, on the span
  // engine's stream.
  void countRows(const RowSpans& s) { count(countRowSpans(*walker, s, span.streamOrNull())); }
  // The fragments of t from the span engine, in its order, into frags (counted).
  void collect(const SpanTriangle& t);
  std::vector<SpanFragment> frags;
  // The specular unit's results of its last batch.
  std::vector<std::array<uint32_t, 3>> device_out;

 private:
  std::vector<SpecRequest> point_requests_;
  std::vector<std::pair<Method, std::unique_ptr<MethodUnit>>> units_;
};

// A screen triangle's per-pixel device-lobe requests: on the unit's model evaluated as each
// pixel makes them (or answered by its memo, memo_requests) and the unit's cycles counted per
// triangle; otherwise (batched) every pixel waits, as pending, for the triangle's batch.
class PixelRequests {
 public:
  struct Pending {  // a fragment waiting for its specular-unit results
    size_t pixel;
    int64_t w;
    std::array<double, 3> lsb;
    size_t dev_first, dev_count;
  };
  void begin() {
    pending.clear();
    requests.clear();
    memo_requests = 0;
    zero_requests = 0;
  }
  // The batch's cycles and evaluations counted, and the pending fragments written.
  void finish(Frame& f, const PixelWriter& write);

  std::vector<SpecRequest> requests;
  std::vector<Pending> pending;
  size_t memo_requests = 0;  // phong-fixed on the unit's model: requests its memo answered
  size_t zero_requests = 0;  // of all, those at or below the unit's zero (RenderStats::spec_at_zero)
};

}  // namespace shd
