// Whole-scene rendering: transform, near-plane clip, project, back-face cull, guard-band clip,
// triangle setup, the span unit, per-pixel shading and a z-buffer.
//
// The span unit and the specular unit are engines: their bit-exact models here, or their
// verilated RTL (sim/cosim/render_rtl.h), with the same interface, so the same scene rendered either
// way must give the same framebuffer, pixel for pixel. Everything else is shared code.
//
// Attributes through the span unit (interpolated linearly in screen space, as the paper's
// hardware does): 0..2 the colour (Gouraud, flat; in output LSBs, 12 fraction bits) or the
// normal (Phong; camera space, 28 fraction bits), 3 the depth w = z_near / Z in (0, 1] with 28
// fraction bits. w is linear in screen space for a planar triangle, so the z-test is exact and
// the camera-space position of a pixel follows from (x, y, w) (point lights, Phong).
// Z-test: a fragment is written where its w is strictly greater (closer) than the stored one;
// triangles are drawn in scene order, so the image does not depend on the lane mode.
//
// The code: render/render.cpp drives a frame (object by object, triangle by triangle);
// render/pipeline.h holds the geometry every method shares (transform, culling, clipping);
// render/methods.h the table of the methods (name, traits, the unit that draws each);
// render/draw.h what the units share; render/methods/*.cpp one unit per method family, each
// described there:
//   flat, gouraud       methods/colour_runs.cpp
//   gouraud-classical   methods/gouraud_classical.cpp
//   phong, phong-incremental, normal-bisection   methods/phong.cpp
//   phong-fixed         methods/phong_fixed.cpp (the datapath: render/fixed_shading.h; at
//                       runtime widths methods/phong_fixed_widths.cpp, render/fixed_widths.h)
//   biquadratic         methods/biquadratic.cpp
//   modified-gouraud    methods/modified_gouraud.cpp (splits, then gouraud)
//   adaptive            methods/adaptive.cpp (gouraud or phong per triangle)
//   reference           methods/reference.cpp
// (The vertex colours of every Gouraud-type method are computed once per vertex, and only for
// vertices of triangles that survive back-face culling. With the model's span unit of one
// lane-triangle, a small screen triangle is set up straight to its rows' spans,
// raster/row_spans.h, instead of a descriptor and its walk: the same fragments and cycles.)
#pragma once

#include <algorithm>
#include <array>
#include <climits>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "device/prom.h"
#include "device/spec_unit.h"
#include "image/image.h"
#include "raster/setup.h"
#include "render/fixed_shading.h"
#include "render/phong_widths.h"
#include "render/shading.h"
#include "scene/scene.h"

namespace shd {

enum class Method {
  Flat,
  Gouraud,
  GouraudClassical,
  Phong,
  PhongIncremental,
  PhongFixed,
  NormalBisection,
  Biquadratic,
  ModifiedGouraud,
  Adaptive,
  Reference
};
Method parseMethod(const std::string& s);  // std::invalid_argument naming the choices
const char* toString(Method m);
std::vector<Method> allMethods();
// The methods a frame may draw on two threads (RenderOptions::threads), named in a list.
std::string twoThreadMethods();

// The span unit: the fragments of one descriptor, appended to `out` in the unit's output order,
// and the cycles they took, the consumer always ready. A frame's descriptors go to the unit back
// to back: the paper's unit takes each from IDLE to IDLE; the full-rate unit (RowAhead)
// overlaps them, and run() gives each descriptor's share of the frame's stream (streamOrNull(),
// SpanStream), so the frame's cycles are the stream's. render() calls beginFrame() before the
// frame's first descriptor and endFrame() after its last.
class SpanEngine {
 public:
  virtual ~SpanEngine() = default;
  virtual const SpanParams& params() const = 0;
  virtual SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) = 0;
  // Non-null when the engine is the model's walk (walkSpanUnit) with these parameters: the
  // renderer may then walk descriptors itself and shade each fragment as it is produced, with
  // streamOrNull() as the walk's stream.
  virtual const SpanParams* walker() const { return nullptr; }
  virtual void beginFrame() { stream_ = SpanStream{}; }
  virtual void endFrame() {}
  // The frame's stream for the full-rate unit; null for the paper's unit.
  SpanStream* streamOrNull() { return params().RowAhead ? &stream_ : nullptr; }

 private:
  SpanStream stream_;
};

// The model: walkSpanUnit, bit- and cycle-exact to the cycle-by-cycle SpanUnitModel.
class ModelSpanEngine final : public SpanEngine {
 public:
  explicit ModelSpanEngine(SpanParams p) : p_(p) { p_.validate(); }
  const SpanParams& params() const override { return p_; }
  SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override {
    return walkSpanUnit(p_, d, out, streamOrNull());
  }
  const SpanParams* walker() const override { return &p_; }

 private:
  SpanParams p_;
};

// The specular unit: a batch of evaluations streamed one per cycle.
class SpecEngine {
 public:
  virtual ~SpecEngine() = default;
  virtual const PromTable& table() const = 0;
  // out[i] = the unorm8 RGB of in[i]; returns the cycles the batch took (with the pipeline fill).
  virtual uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) = 0;
  // Non-null when the engine is the bit-exact model: the renderer may then evaluate each
  // request as it is made (the results are the same; batchCycles() counts the cycles).
  virtual const SpecUnitModel* model() const { return nullptr; }
  // Non-null with model(): its results by request, kept from frame to frame (phong-fixed).
  virtual SpecResultMemo* memo() { return nullptr; }
  // SpecUnitModel::zeroCode of shininess code shin, found once per code on model() or, for an
  // engine without one (the RTL), on a model of table(): the renderer answers a request at or
  // below it 0 without evaluating it, and counts it (RenderStats::spec_at_zero).
  int64_t zeroCode(uint32_t shin);

 private:
  std::unique_ptr<SpecUnitModel> table_model_;  // zeroCode() of an engine without model()
  std::vector<int64_t> zero_;                   // by shin; kUnknown until found
};

// The cycles of a batch of n requests through a pipelined unit of the given latency: the last
// result leaves latency - 1 cycles after the n-th input cycle (0 for an empty batch).
inline uint64_t batchCycles(size_t n, int latency) { return n == 0 ? 0 : n + static_cast<uint64_t>(latency) - 1; }

class ModelSpecEngine final : public SpecEngine {
 public:
  explicit ModelSpecEngine(PromTable t) : t_(std::move(t)), unit_(t_.unit, t_.words, t_.seg_words), memo_(unit_) {}
  ModelSpecEngine(const ModelSpecEngine&) = delete;  // memo_ refers to unit_
  ModelSpecEngine& operator=(const ModelSpecEngine&) = delete;
  const PromTable& table() const override { return t_; }
  uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override;
  const SpecUnitModel* model() const override { return &unit_; }
  SpecResultMemo* memo() override { return &memo_; }
  // SpecUnitModel::limitCosines of its model.
  void limitCosines(std::vector<uint32_t> least, std::string origin) { unit_.limitCosines(std::move(least), std::move(origin)); }

 private:
  PromTable t_;
  SpecUnitModel unit_;
  SpecResultMemo memo_;
};

struct RenderOptions {
  Method method = Method::Gouraud;
  std::string brdf;  // "" : each material's own
  int subpixel_bits = 4;
  double modified_threshold_lsb = 4;  // modified-gouraud: split where exact - Gouraud exceeds this
  double bisection_threshold = 0.02;  // normal-bisection: the listing's error bound per segment
  double adaptive_m = 0.9, adaptive_q = 0.004, adaptive_p = 0.008;  // the listing's opt_m, opt_q, opt_p
  // The AVX-512 and AVX2 paths (render/fixed_simd.h, the vertex transform of render/pipeline.h)
  // where the CPU has them, and phong-fixed's batch (in plain C++ where neither runs); false:
  // the scalar paths alone, phong-fixed's run loop without the batch (the same images: test
  // Render.VectorPathsEqualTheScalarPaths compares them).
  bool vector_kernel = true;
  // Small triangles set up straight to their rows' spans (raster/row_spans.h) where the method
  // and the model's span unit allow; false: setup and the walk for every triangle (the same
  // images and counts: test Render.RowSpansEqualTheSpanWalk compares them).
  bool row_spans = true;
  // The triangle buffer (Framebuffer::tri: which screen triangle wrote each pixel), for a report
  // that names the triangle at a pixel (the RTL-in-the-loop check); false: left empty, neither
  // written nor cleared, which spares a frame a third of its buffer traffic (the same image,
  // depths and counts: test Render.TagsAndTriangleListLeftOutChangeNothingElse).
  bool tags = true;
  // Where each screen triangle came from (RenderResult::triangles), for a report that names the
  // triangle at a pixel (with tags) or sorts the frame's triangles by size; false: left empty,
  // which spares a frame split by rows its sides' ranking and placing where tags are left out
  // too (the same image, depths, tags and counts: test
  // Render.TagsAndTriangleListLeftOutChangeNothingElse).
  bool triangles = true;
  // phong-fixed only (std::invalid_argument with another method or invalid widths): absent, the
  // fixed datapath of render/fixed_shading.h with its run and vector kernels; present, the same
  // datapath at these widths, fragment by fragment (render/fixed_widths.h), the span unit
  // interpolating the normal at their NormalFracBits. PhongWidths{} gives the same images.
  std::optional<PhongWidths> phong_widths;
  // 1, or 2: the frame on two threads, the same bytes and counts as on one (render.cpp): split
  // by rows (each thread draws every triangle's pixels in its rows of the screen), or into a
  // front end, which culls, clips and sets up the triangles (or hands some to the other before
  // setup), and a back end, which walks, shades and writes them, in order (`split`). For the
  // methods whose traits allow it (MethodTraits::two_threads) with the model's span unit
  // (SpanEngine::walker); otherwise std::invalid_argument.
  int threads = 1;
  // How two threads split a frame. By rows only where no count depends on the order of the
  // frame's triangles (no device lobe, the paper's span unit), else into front and back end.
  // Auto: the faster of the two, measured over the frames drawn into one RenderResult
  // (SplitChoice, split_choice.h); its first frame by rows. Every choice gives the same bytes
  // and counts (the tests compare each with one thread); RenderResult::split_by_rows says which
  // way a frame went.
  enum class Split { Auto, Rows, FrontBack };
  Split split = Split::Auto;
  // A frame split by rows: the first row of the bottom side (from 0, all rows the bottom's, to
  // the height, all the top's); -1: where the frame before found both sides would take as long
  // (half the screen on the first). Any row gives the same bytes and counts.
  int split_row = -1;
  // Two threads, flat and gouraud: the back end also sets up a mesh triangle that the front end
  // culled and clipped while fewer than this many jobs wait for it (render.cpp, DrawJob); 0:
  // never, SIZE_MAX: always. Every value gives the same bytes and counts (test
  // Render.TwoThreadsSetUpOnEitherSide); the default is the fastest of those measured
  // (docs/performance.md, "Two threads").
  size_t hand_off_below = 32;
};

struct RenderStats {
  uint64_t triangles = 0;       // input triangles of every object
  // Input triangles of which nothing is drawn, by reason (culled() is their sum):
  uint64_t culled_back = 0;     //   back faces (and zero-area triangles), before any clipping
                                //   or after the near plane
  uint64_t culled_outside = 0;  //   nothing left after the near plane or the guard band
  uint64_t culled_no_pixel = 0; //   on screen within the guard band but no pixel centre inside
                                //   (off the viewport, or too small); dropped by setup
  uint64_t culled() const { return culled_back + culled_outside + culled_no_pixel; }
  uint64_t clipped = 0;         // triangles cut by the near plane or the guard band
  uint64_t drawn = 0;           // screen triangles sent to the span unit
  uint64_t row_spans = 0;       //   of which set up straight to their rows' spans (raster/row_spans.h:
                                //   the model's own way to the same fragments and cycles; not in the JSON)
  uint64_t fragments = 0;
  uint64_t pixels_covered = 0;  // pixels of the final image some triangle wrote
  uint64_t span_cycles = 0;     // span unit cycles over the frame
  uint64_t spec_cycles = 0;     // specular unit cycles (0 when no device lobe is used)
  uint64_t spec_evaluations = 0;
  uint64_t spec_at_zero = 0;    // of those, requests whose N.H code lies at or below the unit's
                                //   zero for their shininess (SpecEngine::zeroCode): result 0,
                                //   which the model gives without evaluating (the unit as built
                                //   evaluates every request: spec_cycles count them all)
  uint64_t depth_rejected = 0;  // fragments that failed the z-test, tested before shading (early):
                                //   never shaded, no specular request (docs/rendering.md)
  uint64_t divisions = 0;       // gouraud-classical: raster lines with a division
  uint64_t split_parts = 0;     // modified-gouraud: triangles drawn after splitting
  uint64_t normalisations = 0;  // normal-bisection: exact normalisations (nodes)
  uint64_t adaptive_gouraud = 0, adaptive_phong = 0;  // adaptive: the choices
  double ms = 0;
  // Adds o's counts (not ms): the two threads' halves of a frame.
  RenderStats& operator+=(const RenderStats& o);
};

struct Framebuffer {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;    // unorm8, row-major, top row first
  std::vector<int32_t> depth;  // w code (28 fraction bits, <= 2^28) of the visible fragment, 0: none
  std::vector<int32_t> tri;    // id of the screen triangle that wrote the pixel, -1 none; empty
                               // when the frame was drawn without RenderOptions::tags
  std::vector<double> lsb;     // reference only: the exact colour in LSBs (3 per pixel)
  std::vector<double> spec_lsb;  // reference only: the specular part (highlight masks)
  // A fragment was written there: it passed the z-test, its code above the buffer's (0 when clear).
  bool covered(int x, int y) const { return depth[static_cast<size_t>(y) * width + x] > 0; }
  // The pixels drawn since the buffers were last cleared lie in this rectangle (x0 > x1: none):
  // the next clear of a frame of the same size and kind clears it alone (prepareClear, clearRect).
  // (A cache line of their own: a two-thread frame's front end marks them per triangle while
  // its back end reads the buffers' addresses above.)
  alignas(64) int drawn_x0 = INT_MAX, drawn_y0 = INT_MAX, drawn_x1 = INT_MIN, drawn_y1 = INT_MIN;
  // Adds the pixels whose centres lie within [xmin, xmax] x [ymin, ymax] (screen pixels).
  void markDrawn(double xmin, double ymin, double xmax, double ymax);
  // Adds another buffer's drawn rectangle (of the same size: a side of a frame split by rows).
  void markDrawn(const Framebuffer& o) {
    drawn_x0 = std::min(drawn_x0, o.drawn_x0);
    drawn_y0 = std::min(drawn_y0, o.drawn_y0);
    drawn_x1 = std::max(drawn_x1, o.drawn_x1);
    drawn_y1 = std::max(drawn_y1, o.drawn_y1);
  }
  void markNothingDrawn() {
    drawn_x0 = drawn_y0 = INT_MAX;
    drawn_x1 = drawn_y1 = INT_MIN;
  }
};

// A frame as an image (its rgb), the mask of its covered pixels, and the reference method's
// exact colour clamped to 0..255 (what a display shows: an over-exposed highlight is 255, not
// its unclamped value), the image an error is measured against.
Image frameImage(const Framebuffer& fb);
PixelMask coveredPixels(const Framebuffer& fb);
ImageF exactImage(const Framebuffer& reference);

// The corrected 4.4 edge maximum of the specular cosine between unit normals na and nb for the
// half vector h: t in (0, 1), or -1 when the edge has no interior maximum.
double edgeMaximumT(Vec3 na, Vec3 nb, Vec3 h);

// Where each screen triangle came from (for "the triangle that wrote pixel (x, y)").
struct ScreenTriangleInfo {
  int object = 0;
  uint32_t mesh_triangle = 0;
  std::array<std::array<double, 2>, 3> xy{};
};

// Buffers a frame reuses from the frame before it in the same RenderResult (render.cpp: an
// object's vertices), so that a frame loop allocates and clears none of them after its first
// frame (the 4,160 vertices of builtin:sphere, 430 KB, were made and cleared per frame). A
// copy of a result holds none of them: its next frame makes its own.
struct RenderScratch;
class ScratchBuffers {
 public:
  ScratchBuffers();
  ~ScratchBuffers();
  ScratchBuffers(const ScratchBuffers&);
  ScratchBuffers& operator=(const ScratchBuffers&);
  RenderScratch& get() { return *p_; }

 private:
  std::unique_ptr<RenderScratch> p_;
};

struct RenderResult {
  Framebuffer fb;
  RenderStats stats;
  std::vector<ScreenTriangleInfo> triangles;
  bool split_by_rows = false;  // the last frame ran on two threads split by rows
  ScratchBuffers scratch;
};

// The specular units of the device lobes (null where the scene does not use the lobe).
struct SpecEngines {
  SpecEngine* quadratic = nullptr;  // a degree-2 unit
  SpecEngine* cubic = nullptr;      // a degree-3 unit
  SpecEngine* forLobe(Lobe l) const { return l == Lobe::Cubic ? cubic : (l == Lobe::Quadratic ? quadratic : nullptr); }
  void set(Lobe l, SpecEngine* e) { (l == Lobe::Cubic ? cubic : quadratic) = e; }  // a device lobe's
};

// The device lobes the scene uses with these options (to build only the engines needed).
std::vector<Lobe> deviceLobesUsed(const Scene& scene, const RenderOptions& opt);
// Whether a two-thread frame of the scene with these options on this span unit may split by rows
// (RenderOptions::split: Rows, or Auto where it measures), else always into a front and a back end.
bool splitsByRows(const Scene& scene, const RenderOptions& opt, SpanEngine& span);

// Throws std::invalid_argument for an unknown brdf, a shininess the specular unit's PROM does
// not hold, or a scene the pipeline cannot take (named).
RenderResult render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& spec);
// The same into `res`, reusing its buffers (a frame loop allocates nothing after the first frame).
void render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& spec, RenderResult& res);

}  // namespace shd
