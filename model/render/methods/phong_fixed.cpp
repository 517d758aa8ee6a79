// phong-fixed: the normals and the squared-norm recurrence of phong-incremental, and the whole
// per-pixel lighting as a fixed-point datapath (render/fixed_shading.h): unit normal, L, H, V in
// Q1.16, integer dot products, the diffuse and specular factors as codes, the lobe from a table
// over its cosine (16 fraction bits) or the specular unit; no floating point and no pow per
// pixel with directional lights.
//
// Three paths, the same colours:
//   fragments  one at a time (FixedPointShader::shade): point lights, the RTL's specular unit
//              (requests batched per triangle), rows that are not runs, the RTL's span unit;
//   runs       a whole run of a row by the shader's run kernel: the dot products stepped by
//              constant increments (directional lights, device lobes on the unit's memo);
//   batch      one directional light and a lobe of N.H, where the frame has a batch kernel
//              (Frame::buffer_run: AVX-512, AVX2 or plain C++): the runs of an object's
//              triangles z-tested and buffered (fixed_simd::bufferKernel; a triangle's rows'
//              spans all with one call, fixed_simd::spansBufferKernel) and shaded 8 at a time
//              (fixed_simd::nhKernel). The groups are independent, so the processor overlaps
//              them, where one group per row of 5 or 6 pixels would wait out its own latency.
#include <algorithm>
#include <cmath>
#include <optional>
#include <type_traits>

#include "render/draw.h"
#include "render/fixed_shading.h"
#include "render/fixed_simd.h"

namespace shd {

namespace {

// What the paths of one triangle share.
struct FixedTriangle {
  FixedTriangle(Frame& frame, FixedPointShader& sh, fixed_simd::Batch& b, PixelRequests& r, const SpanTriangle& tri)
      : f(frame),
        shader(sh),
        batch(b),
        req(r),
        st(frame.st),
        depth(frame.fb.depth.data()),
        W(frame.W),
        batched(frame.batchesRequests(Method::PhongFixed)),
        write(frame.writer(tri.tag)),
        target{depth, frame.tags(), static_cast<int32_t>(tri.tag), static_cast<size_t>(W)},
        squared_norm(tri) {}
  Frame& f;
  FixedPointShader& shader;
  fixed_simd::Batch& batch;
  PixelRequests& req;
  RenderStats& st;
  int32_t* depth;
  int W;
  bool batched;  // device requests wait for the triangle's batch (PixelRequests)
  PixelWriter write;
  fixed_simd::Target target;
  SquaredNorms squared_norm;
};

// One fragment: the recurrence (before the z-test, as the hardware runs it on every fragment),
// the z-test, the fixed-point datapath, write.
inline void fixedFragment(FixedTriangle& t, int32_t x, int32_t y, const int64_t* attr) {
  const uint64_t sqnorm = t.squared_norm(x, y, attr);
  const size_t p = static_cast<size_t>(y) * t.W + static_cast<size_t>(x);
  const int64_t wcode = attr[3];
  __builtin_prefetch(t.depth + p + t.W);  // the row below: most likely this triangle's next
  if (wcode <= t.depth[p]) {
    ++t.st.depth_rejected;
    return;
  }
  const Vec3 pc = t.shader.needsPosition() ? t.f.proj.pixelCam(x, y, static_cast<double>(wcode) * kUnitLsb) : Vec3{};
  std::vector<SpecRequest>& requests = t.req.requests;
  const size_t first = requests.size();
  const FixedShade fs = t.shader.shade(attr, sqnorm, pc, &requests);
  t.req.zero_requests += fs.device_zero;
  if (t.batched) {
    std::array<double, 3> lsb{};  // exact: the codes are far below 2^53
    for (size_t k = 0; k < 3; ++k) lsb[k] = std::ldexp(static_cast<double>(fs.code[k]), -kFixedColourFrac);
    t.req.pending.push_back({p, wcode, lsb, first, requests.size() - first});
    return;
  }
  t.req.memo_requests += fs.device_requests;
  t.st.pixels_covered += t.write(p, wcode, fixedColour(fs));
}

// A whole run: the recurrence and the dot products stepped along it by the shader's run kernel,
// the same colours as fixedFragment's. The kernel is held by value in the walker's run consumer
// (one copy per triangle), so that its constants stay in registers across the stores of the
// pixels; so are the writer's pointers, in put.
template <class Kernel>
inline void fixedRun(FixedTriangle& t, Kernel& kernel, const RowRun& r) {
  int32_t* const depth = t.depth;
  const int W = t.W;
  const int64_t count = r.count;
  SquaredNormRecurrence run_sqn;
  uint64_t sqnorm = run_sqn.start({r.a0[0], r.a0[1], r.a0[2]}, {r.da[0], r.da[1], r.da[2]});
  RunCursor c(r, W);
  size_t requests_answered = 0, at_zero = 0;
  uint64_t newly = 0, rejected = 0;
  const auto put = t.write;
  kernel.start(r.a0, r.da);
  for (int64_t i = 0;;) {
    __builtin_prefetch(depth + c.p + W);  // as fixedFragment
    if (c.depth() > depth[c.p]) {
      const FixedShade fs = kernel.shade(sqnorm);
      requests_answered += fs.device_requests;
      at_zero += fs.device_zero;
      newly += put(c.p, c.depth(), fixedColour(fs));
    } else {
      ++rejected;
    }
    if (++i == count) break;
    sqnorm = run_sqn.next();
    kernel.step();
    c.next();
  }
  t.req.memo_requests += requests_answered;
  t.req.zero_requests += at_zero;
  t.st.pixels_covered += newly;
  t.st.depth_rejected += rejected;
}

// The batch: shaded 8 at a time, the colours written (bufferRun has z-tested its fragments and
// written their depth and tag). It collects the runs of several triangles of an object (the
// same shader constants), in the order they were z-tested: where two of them cover a pixel,
// the second passed the test against the first's depth and its colour is written last.
// Everything else that writes a colour at once flushes it first.
template <class Kernel>
void flushBatch(fixed_simd::Batch& b, uint8_t* const out, Kernel& kernel) {
  uint32_t* const rgb = b.rgb.data();
  const size_t n = b.n;  // a local: the pixels' byte stores may alias the batch
  const uint64_t declined = kernel.shadeBatch(b.sq.data(), b.l.data(), b.h.data(), n, rgb);
  for (uint64_t g = declined; g != 0; g &= g - 1)
    for (size_t f = 8 * static_cast<size_t>(__builtin_ctzll(g)), e = std::min(f + 8, n); f < e; ++f)
      rgb[f] = fixed_simd::packedRgb(fixedColour(kernel.shadeRaw(b.sq[f], b.l[f], b.h[f])));
  for (size_t f = 0; f < n; ++f) {
    uint8_t* const px = out + 3 * size_t{b.pixel[f]};
    const uint32_t c = rgb[f];
    px[0] = static_cast<uint8_t>(c);
    px[1] = static_cast<uint8_t>(c >> 8);
    px[2] = static_cast<uint8_t>(c >> 16);
  }
  b.n = 0;
}

// Fragments into the batch by buffer() (true: all of them in), the batch shaded each time it
// fills before the end; returns the fragments buffered (those that passed the z-test).
template <class Kernel, class Buffer>
uint64_t bufferAll(FixedTriangle& t, Kernel& kernel, Buffer buffer) {
  for (uint64_t passed = 0;;) {
    const size_t before = t.batch.n;
    const bool done = buffer();
    passed += t.batch.n - before;
    if (done) return passed;
    flushBatch(t.batch, t.f.fb.rgb.data(), kernel);
  }
}

// A run into the batch: z-tested, its depth codes written, its passing fragments' squared
// norms and dot products buffered (Frame::buffer_run, which the batch's case has). Runs right to
// left take fixedRun.
template <class Kernel>
void batchRun(FixedTriangle& t, Kernel& kernel, const RowRun& r) {
  if (r.dx != 1) {
    if (t.batch.n > 0) flushBatch(t.batch, t.f.fb.rgb.data(), kernel);
    fixedRun(t, kernel, r);
    return;
  }
  kernel.start(r.a0, r.da);
  const auto sq = SquaredNormRecurrence::terms({r.a0[0], r.a0[1], r.a0[2]}, {r.da[0], r.da[1], r.da[2]});
  // Every member given (no zeroing of the whole object first).
  const fixed_simd::Run run{{static_cast<size_t>(r.y) * static_cast<size_t>(t.W) + static_cast<size_t>(r.x0),
                             static_cast<size_t>(r.count), static_cast<uint32_t>(r.a0[3]), static_cast<uint32_t>(r.da[3])},
                            sq.a,
                            sq.two_b,
                            sq.c,
                            kernel.dotL(),
                            kernel.stepL(),
                            kernel.dotH(),
                            kernel.stepH(),
                            static_cast<size_t>(t.W - r.x0)};
  uint64_t newly = 0;
  size_t k = 0;
  const uint64_t passed = bufferAll(t, kernel, [&] {
    k = t.f.buffer_run(run, k, t.target, t.batch, newly);
    return k >= run.px.count;
  });
  t.st.pixels_covered += newly;
  t.st.depth_rejected += run.px.count - passed;
}

// The fragments of the rows of s in `rows` (bit i: row y0 + i).
inline uint64_t fragmentsOf(const RowSpans& s, uint64_t rows) {
  uint64_t n = 0;
  for (int32_t i = 0; i < s.rows; ++i) {
    const std::array<int16_t, 2>& sp = s.span[static_cast<size_t>(i)];
    if (((rows >> i) & 1) != 0 && sp[0] <= sp[1]) n += static_cast<uint64_t>(sp[1] - sp[0] + 1);
  }
  return n;
}

// A triangle's rows' spans into the batch without the walk (Frame::buffer_spans): the runs
// batchRun would take, row by row, in one pass; the rows of tri.share.
template <class Kernel>
void batchSpans(FixedTriangle& t, const SpanTriangle& tri, Kernel& kernel) {
  const RowSpans& s = *tri.rows;
  if (!tri.counted) t.f.countRows(s);
  const bool all = tri.share.side == RowShare::Side::All;
  const fixed_simd::NhSpans r{&s, all ? ~uint64_t{0} : tri.share.rowMask(s), kernel.lightL(), kernel.lightH(),
                              static_cast<size_t>(t.W)};
  const uint64_t fragments = all ? s.fragments : fragmentsOf(s, r.rows);
  fixed_simd::SpanCursor at;
  uint64_t newly = 0;
  const uint64_t passed = bufferAll(t, kernel, [&] { return t.f.buffer_spans(r, at, t.target, t.batch, newly); });
  t.st.pixels_covered += newly;
  t.st.depth_rejected += fragments - passed;
}

// The walk with the batch, or the rows' spans without it.
template <class Kernel>
void walkBatched(FixedTriangle& t, const SpanTriangle& tri, Kernel& kernel) {
  if (tri.rows != nullptr && tri.walked == nullptr && t.f.buffer_spans != nullptr) return batchSpans(t, tri, kernel);
  auto fragment = [&t, &kernel](int32_t x, int32_t y, const int64_t* attr) {
    if (t.batch.n > 0) flushBatch(t.batch, t.f.fb.rgb.data(), kernel);
    fixedFragment(t, x, y, attr);
  };
  auto runs = [&t, &kernel](const RowRun& r) { batchRun(t, kernel, r); };
  t.f.walk(tri, fragment, runs);
}

// The walk with the run kernel's runs (fixedRun).
template <class Kernel>
[[gnu::noinline]] void walkRuns(FixedTriangle& t, const SpanTriangle& tri, Kernel& kernel) {
  auto fragment = [&t](int32_t x, int32_t y, const int64_t* attr) { fixedFragment(t, x, y, attr); };
  auto runs = [&t, kernel](const RowRun& r) mutable { fixedRun(t, kernel, r); };
  t.f.walk(tri, fragment, runs);
}

class PhongFixedUnit final : public MethodUnit {
 public:
  explicit PhongFixedUnit(Frame& f)
      : MethodUnit(Method::PhongFixed), f_(f), batch_(std::make_unique<fixed_simd::Batch>()) {}

  void beginObject() override {
    const ObjectShading& o = f_.obj;
    group_.reset();  // the previous object's: it refers to its shader
    fixed_.emplace(f_.ctx, *o.material, o.lobe, &o.coding, o.spec != nullptr ? o.spec->memo() : nullptr);
    // The batch's case: its run kernel built once for all of the object's triangles (built per
    // triangle, its copies of the constants took 3 % of a frame).
    if (f_.buffer_run != nullptr && fixed_->takesRuns())
      fixed_->withRunKernel([&](auto& kernel) {
        if constexpr (std::decay_t<decltype(kernel)>::kGroups) group_.emplace(kernel);
      });
  }

  void draw(const SpanTriangle& tri) override {
    req_.begin();
    FixedTriangle t(f_, *fixed_, *batch_, req_, tri);
    // Runs where the shader takes them (directional lights; device lobes on the memo).
    if (f_.walker != nullptr && !t.batched && fixed_->takesRuns()) {
      if (group_)
        walkBatched(t, tri, *group_);
      else
        fixed_->withRunKernel([&](auto& kernel) { walkRuns(t, tri, kernel); });
    } else {
      auto fragment = [&t](int32_t x, int32_t y, const int64_t* attr) { fixedFragment(t, x, y, attr); };
      f_.walk(tri, fragment);
    }
    req_.finish(f_, t.write);
  }

  // The object's fragments still in the batch (the batch's case).
  void endObject() override {
    if (batch_->n > 0 && group_) flushBatch(*batch_, f_.fb.rgb.data(), *group_);
    if (batch_->n > 0) throw std::logic_error("render: fragments left in the batch of another shader");
  }

 private:
  Frame& f_;
  std::optional<FixedPointShader> fixed_;  // the object's
  std::optional<FixedPointShader::RunKernel<FixedCosine::NH, 1>> group_;  // the batch's case
  std::unique_ptr<fixed_simd::Batch> batch_;
  PixelRequests req_;
};

}  // namespace

std::unique_ptr<MethodUnit> makePhongWidthsUnit(Frame& f);  // phong_fixed_widths.cpp

// At runtime widths (RenderOptions::phong_widths) the scalar datapath of fixed_widths.h; else
// this file's unit, as ever.
std::unique_ptr<MethodUnit> makePhongFixedUnit(Frame& f) {
  if (f.opt.phong_widths) return makePhongWidthsUnit(f);
  return std::make_unique<PhongFixedUnit>(f);
}

}  // namespace shd
