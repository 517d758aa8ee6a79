// flat      one colour per polygon: the face normal at the centroid, shaded once
// gouraud   vertex colours, the constant increment of the span unit (paper 4.1)
//
// Both interpolate colour codes (flat's constant) and write them as they are: per fragment the
// z-test and the codes straight to unorm8 (what combine() gives them); per run of a row the
// same in a loop of its own, or in AVX-512 or AVX2 (fixed_simd::colourKernel); a triangle's
// rows' spans in one call of fixed_simd::colourSpansKernel (AVX-512, AVX2, or plain C++ on the
// scalar paths).
#include <algorithm>
#include <type_traits>

#include "render/draw.h"
#include "render/fixed_simd.h"

namespace shd {

namespace {

// A triangle's left-to-right runs waiting for the vector kernel (fixed_simd::colourKernel), which
// draws them with one call when the triangle's walk ends, or before any other write of the
// triangle (a run from right to left, a single fragment), so that the pixels are written in
// the walk's order.
struct PendingRuns {
  fixed_simd::ColourKernel kernel;  // null: nothing waits, every run takes the loop below
  const fixed_simd::Target& target;
  uint8_t* rgb;
  uint64_t& covered;
  uint64_t& rejected;
  fixed_simd::ColourRuns& runs;  // the unit's, empty between triangles
  bool stepped = false;          // runs.dc and dz are the waiting runs' steps (a run of one pixel has none)

  // Inlined into the walk's rows; the kernel's call (flush) is not.
  [[gnu::always_inline]] void add(const RowRun& r, int W) {
    // The runs of one call share their steps; a run of one pixel takes any.
    const bool same = !stepped || r.count == 1 ||
                      (r.da[0] == runs.dc[0] && r.da[1] == runs.dc[1] && r.da[2] == runs.dc[2] &&
                       static_cast<uint32_t>(r.da[3]) == runs.dz);
    if (runs.n == runs.rows.size() || !same) flush();
    if (!stepped && r.count > 1) {
      for (size_t k = 0; k < 3; ++k) runs.dc[k] = static_cast<int32_t>(r.da[k]);
      runs.dz = static_cast<uint32_t>(r.da[3]);
      stepped = true;
    }
    fixed_simd::ColourRuns::Row& row = runs.rows[runs.n++];
    row.p = static_cast<size_t>(r.y) * static_cast<size_t>(W) + static_cast<size_t>(r.x0);
    row.count = static_cast<size_t>(r.count);
    row.room = static_cast<size_t>(W - r.x0);
    row.z = static_cast<uint32_t>(r.a0[3]);
    for (size_t k = 0; k < 3; ++k) row.c[k] = static_cast<int32_t>(r.a0[k]);
  }
  [[gnu::noinline]] void flush() {
    if (runs.n == 0) return;
    uint64_t passed = 0, fragments = 0;
    for (size_t i = 0; i < runs.n; ++i) fragments += runs.rows[i].count;
    covered += kernel(runs, target, rgb, passed);
    rejected += fragments - passed;
    runs.n = 0;
    stepped = false;
  }
};

// Flat and Gouraud: z-test, then the interpolated colour codes straight to unorm8 (what
// combine() gives them).
struct ColourFragment {
  PixelWriter write;
  int32_t* depth;
  int W;
  uint64_t& covered;
  uint64_t& rejected;
  PendingRuns& pending;
  void operator()(int32_t x, int32_t y, const int64_t* attr) const {
    pending.flush();
    const size_t p = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
    __builtin_prefetch(depth + p + W);  // the row below: most likely this triangle's next
    if (attr[3] <= depth[p]) {
      ++rejected;
      return;
    }
    covered += write(p, attr[3], {unorm8FromCode(attr[0], kColourFrac), unorm8FromCode(attr[1], kColourFrac),
                                  unorm8FromCode(attr[2], kColourFrac)});
  }
};

// The same for a whole run of a row (walkSpanUnit's run consumer): left to right to the vector
// kernel (PendingRuns), else a loop in registers, the newly covered pixels and the rejected
// fragments counted once per run. When the colour codes at both ends of the run lie in
// [0, 255 2^12] so do all between (they are affine), and unorm8FromCode is the rounding shift
// alone.
struct ColourRunLoop {
  PixelWriter write;
  int32_t* depth;
  int W;
  uint64_t& covered;
  uint64_t& rejected;
  PendingRuns& pending;

  [[gnu::always_inline]] void operator()(const RowRun& r) const {
    if (pending.kernel != nullptr && r.dx == 1) pending.add(r, W);
    else loopRun(r);
  }

  [[gnu::noinline]] void loopRun(const RowRun& r) const {
    pending.flush();
    const auto put = write;
    const int64_t count = r.count;  // a local: r may alias the pixels' byte stores
    std::array<uint64_t, 3> a, da;
    bool in_range = true;
    for (size_t k = 0; k < 3; ++k) {
      a[k] = static_cast<uint64_t>(r.a0[k]);
      da[k] = static_cast<uint64_t>(r.da[k]);
      const int64_t end = static_cast<int64_t>(a[k] + da[k] * static_cast<uint64_t>(count - 1));
      in_range = in_range && std::min(r.a0[k], end) >= 0 && std::max(r.a0[k], end) <= (255 << kColourFrac);
    }
    uint64_t newly = 0, passed = 0;
    auto loop = [&](auto clamp) {
      auto unorm8 = [](uint64_t c) {
        if constexpr (decltype(clamp)::value) return unorm8FromCode(static_cast<int64_t>(c), kColourFrac);
        else return static_cast<uint8_t>((c + (1u << (kColourFrac - 1))) >> kColourFrac);
      };
      RunCursor c(r, W);
      for (int64_t i = 0; i < count; ++i, c.next()) {
        __builtin_prefetch(depth + c.p + W);  // as ColourFragment
        if (c.depth() > depth[c.p]) {
          newly += put(c.p, c.depth(), {unorm8(a[0]), unorm8(a[1]), unorm8(a[2])});
          ++passed;
        }
        for (size_t k = 0; k < 3; ++k) a[k] += da[k];
      }
    };
    if (in_range) loop(std::false_type{});
    else loop(std::true_type{});
    covered += newly;
    rejected += static_cast<uint64_t>(count) - passed;
  }
};

// A triangle's rows' spans (raster/row_spans.h) to the colour kernel with one call, without the
// walk (Frame::colour_spans).
// A side of a frame split by rows draws the rows of its RowShare: the slice of them, where the
// triangle has rows of the other side's.
void drawColourSpans(Frame& f, const SpanTriangle& t, const fixed_simd::Target& target) {
  if (!t.counted) f.countRows(*t.rows);
  const RowShare& share = t.share;
  const bool sliced =
      share.side == RowShare::Side::Rows && (t.rows->y0 < share.y0 || t.rows->y0 + t.rows->rows > share.y1);
  RowSpans slice;
  if (sliced && !sliceRowSpans(*t.rows, share.y0, share.y1, slice)) return;
  const RowSpans& s = sliced ? slice : *t.rows;
  uint64_t passed = 0;
  f.st.pixels_covered += f.colour_spans(s, static_cast<size_t>(f.W), kColourFrac, target, f.fb.rgb.data(), passed);
  f.st.depth_rejected += s.fragments - passed;
}

// The colour units' drawing: the walk with the fragment sink and the run loop (runs: the unit's
// buffer of the runs waiting for the vector kernel), or a triangle's rows' spans straight to
// the vector kernel.
void drawColourRuns(Frame& f, const SpanTriangle& t, fixed_simd::ColourRuns& runs) {
  Framebuffer& fb = f.fb;
  const int W = f.W;
  const PixelWriter write = f.writer(t.tag);
  const fixed_simd::Target target{fb.depth.data(), f.tags(), static_cast<int32_t>(t.tag), static_cast<size_t>(W)};
  runs.frac = kColourFrac;
  if (t.rows != nullptr && f.colour_spans != nullptr) return drawColourSpans(f, t, target);
  PendingRuns pending{f.colour_kernel, target, fb.rgb.data(), f.st.pixels_covered, f.st.depth_rejected, runs};
  ColourFragment fragment{write, fb.depth.data(), W, f.st.pixels_covered, f.st.depth_rejected, pending};
  ColourRunLoop run{write, fb.depth.data(), W, f.st.pixels_covered, f.st.depth_rejected, pending};
  f.walk(t, fragment, run);
  pending.flush();
}

class GouraudUnit final : public MethodUnit {
 public:
  explicit GouraudUnit(Frame& f) : MethodUnit(Method::Gouraud), f_(f) {}
  void draw(const SpanTriangle& t) override { drawColourRuns(f_, t, runs_); }

 private:
  Frame& f_;
  fixed_simd::ColourRuns runs_;
};

class FlatUnit final : public MethodUnit {
 public:
  explicit FlatUnit(Frame& f) : MethodUnit(Method::Flat), f_(f) {}
  // The polygon's colour, lit by its first three vertices (Frame::faceColour, or by the drawer
  // ahead): the colour attributes of all its triangles.
  void parts(const Fan& fan, Parts& out) override {
    colour_ = f_.face_colour != nullptr ? *f_.face_colour : f_.faceColour(*fan[0], *fan[1], *fan[2]);
    for (size_t k = 1; k + 1 < fan.size(); ++k) addPart(out, fan[0], fan[k], fan[k + 1], this, method(), &colour_);
  }
  void draw(const SpanTriangle& t) override { drawColourRuns(f_, t, runs_); }

 private:
  Frame& f_;
  std::array<double, 3> colour_{};
  fixed_simd::ColourRuns runs_;
};

}  // namespace

std::unique_ptr<MethodUnit> makeFlatUnit(Frame& f) { return std::make_unique<FlatUnit>(f); }
std::unique_ptr<MethodUnit> makeGouraudUnit(Frame& f) { return std::make_unique<GouraudUnit>(f); }

}  // namespace shd
