#include "render/draw.h"

#include "render/fixed_simd.h"
#include "render/methods.h"

namespace shd {

namespace {
// The model's span unit, whose depth and colour codes fit the kernels' int32_t lanes.
bool codesFit32(const SpanParams* walker) { return walker != nullptr && walker->AttrBits <= 32; }
}  // namespace

Frame::Frame(const Scene& scene, const RenderOptions& opt, SpanEngine& span, Framebuffer& fb, RenderStats& st)
    : opt(opt),
      fb(fb),
      st(st),
      W(scene.camera.width),
      H(scene.camera.height),
      proj(scene.camera),
      ctx(makeShadeContext(scene)),
      span(span),
      walker(span.walker()),
      buffer_run(opt.vector_kernel && codesFit32(walker) ? fixed_simd::bufferKernel() : nullptr),
      buffer_spans(buffer_run != nullptr ? fixed_simd::spansBufferKernel() : nullptr),
      colour_kernel(opt.vector_kernel && codesFit32(walker) ? fixed_simd::colourKernel() : nullptr),
      colour_spans(!codesFit32(walker)     ? nullptr
                   : opt.vector_kernel ? fixed_simd::colourSpansKernel()
                                       : fixed_simd::colourSpansScalar),
      avx2(opt.vector_kernel && fixed_simd::availableAvx2()) {}

Frame::~Frame() = default;

MethodUnit& Frame::unit(Method m) {
  for (const auto& u : units_)
    if (u.first == m) return *u.second;
  std::unique_ptr<MethodUnit> made = traits(m).make(*this);  // may make the units it draws with first
  units_.emplace_back(m, std::move(made));
  return *units_.back().second;
}

std::array<double, 3> Frame::shadeNow(Vec3 n, Vec3 p) {
  point_requests_.clear();
  Shade s = obj.shader->shade(n, p, &point_requests_);
  if (!point_requests_.empty()) {
    st.spec_cycles += obj.spec->evaluate(point_requests_, device_out);
    st.spec_evaluations += point_requests_.size();
    for (const SpecRequest& r : point_requests_) st.spec_at_zero += obj.coding.atZero(r.cos);
    for (const auto& d : device_out)
      for (size_t k = 0; k < 3; ++k) s.lsb[k] += d[k];
  }
  return s.lsb;
}

std::array<double, 3> Frame::faceColour(const PVertex& a, const PVertex& b, const PVertex& c) {
  Vec3 fn = normalize(cross(b.cam - a.cam, c.cam - a.cam));
  if (dot(fn, ctx.view) < 0) fn = -fn;  // toward the viewer
  const Vec3 centroid = (1.0 / 3) * (a.cam + b.cam + c.cam);
  return shadeNow(fn, centroid);
}

bool Frame::batchesRequests(Method m) const {
  return traits(m).pixel_lobe && obj.direct == nullptr && isDeviceLobe(obj.lobe);
}

void Frame::collect(const SpanTriangle& t) {
  frags.clear();
  st.span_cycles += span.run(*t.setup->desc, frags).cycles;
  st.fragments += frags.size();
}

void PixelRequests::finish(Frame& f, const PixelWriter& write) {
  RenderStats& st = f.st;
  if (!requests.empty() || memo_requests > 0) {
    const size_t n = requests.size() + memo_requests;
    st.spec_cycles += f.obj.direct != nullptr ? batchCycles(n, f.obj.direct->params().latency())
                                              : f.obj.spec->evaluate(requests, f.device_out);
    st.spec_evaluations += n;
    st.spec_at_zero += zero_requests;
  }
  for (const Pending& pd : pending)
    st.pixels_covered +=
        write(pd.pixel, pd.w, combine(pd.lsb, pd.dev_count ? &f.device_out[pd.dev_first] : nullptr, pd.dev_count));
}

}  // namespace shd
