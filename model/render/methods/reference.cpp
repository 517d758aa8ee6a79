// reference: per pixel in double precision, the exact barycentric normal of the pixel centre,
// exact normalisation, exact pow (device lobes: the Blinn lobe they approximate). The pixels are
// those of the span unit's triangle, found by direct edge evaluation (rasterizeReference, no
// span unit cycles). Besides the image it writes the exact colour in LSBs (Framebuffer::lsb)
// and its specular part alone (spec_lsb: less the colour without k_s; highlight masks).
#include <optional>

#include "render/draw.h"

namespace shd {

namespace {

class ReferenceUnit final : public MethodUnit {
 public:
  explicit ReferenceUnit(Frame& f) : MethodUnit(Method::Reference), f_(f) {}

  // The exact lobes, and the same without k_s for the specular part alone.
  void beginObject() override {
    const Material& mat = *f_.obj.material;
    const Lobe lobe = isDeviceLobe(f_.obj.lobe) ? Lobe::Blinn : f_.obj.lobe;
    nospec_ = mat;
    nospec_.ks = 0;
    shader_.emplace(f_.ctx, mat, lobe, nullptr);
    diffuse_.emplace(f_.ctx, nospec_, lobe, nullptr);
  }

  void draw(const SpanTriangle& t) override {
    Framebuffer& fb = f_.fb;
    RenderStats& st = f_.st;
    std::vector<SpanFragment>& frags = f_.frags;
    frags = rasterizeReference(*t.setup, t.raster);
    st.fragments += frags.size();
    const PixelWriter write = f_.writer(t.tag);
    for (const SpanFragment& fr : frags) {
      const size_t p = static_cast<size_t>(fr.y) * f_.W + static_cast<size_t>(fr.x);
      const int64_t wcode = fr.attr[3];
      if (wcode <= fb.depth[p]) {
        ++st.depth_rejected;
        continue;
      }
      const auto l = barycentric(t.v, fr.x, fr.y);
      const Vec3 n = normalize(l[0] * t.v[0]->n + l[1] * t.v[1]->n + l[2] * t.v[2]->n);
      const double w = l[0] * t.v[0]->w + l[1] * t.v[1]->w + l[2] * t.v[2]->w;
      const Vec3 pc = f_.proj.pixelCam(fr.x, fr.y, w);
      const Shade sh = shader_->shade(n, pc, nullptr);
      const Shade dif = diffuse_->shade(n, pc, nullptr);
      for (size_t k = 0; k < 3; ++k) {
        fb.lsb[p * 3 + k] = sh.lsb[k];
        fb.spec_lsb[p * 3 + k] = sh.lsb[k] - dif.lsb[k];
      }
      st.pixels_covered += write(p, wcode, combine(sh.lsb, nullptr, 0));
    }
  }

 private:
  Frame& f_;
  Material nospec_;  // the object's material without k_s (diffuse_ refers to it)
  std::optional<PointShader> shader_, diffuse_;
};

}  // namespace

std::unique_ptr<MethodUnit> makeReferenceUnit(Frame& f) { return std::make_unique<ReferenceUnit>(f); }

}  // namespace shd
