// adaptive: per triangle Gouraud or Phong by the listing's test of the vertex normals
// (AdaptivGourauAndPhong.selectMetod, with its thresholds as defaults): Gouraud where all pairs
// have N_i.N_j >= adaptive_m, |N_i.H - N_j.H| <= adaptive_q and |N_i.L - N_j.L| <= adaptive_p,
// else Phong. The listing returns Phong when |N_i.N_j| > 0.9, i.e. for nearly equal normals,
// the opposite of its evident intent; shadesim follows the intent. The triangles are drawn by
// the gouraud and phong units; RenderStats::adaptive_gouraud and adaptive_phong count them.
#include <cmath>

#include "render/draw.h"

namespace shd {

namespace {

class AdaptiveUnit final : public MethodUnit {
 public:
  explicit AdaptiveUnit(Frame& f)
      : MethodUnit(Method::Adaptive), f_(f), gouraud_(f.unit(Method::Gouraud)), phong_(f.unit(Method::Phong)) {}

  void parts(const Fan& fan, Parts& out) override {
    for (size_t k = 1; k + 1 < fan.size(); ++k) {
      const std::array<const PVertex*, 3> t{fan[0], fan[k], fan[k + 1]};
      addPart(out, t[0], t[1], t[2], this, gouraudWill(t) ? Method::Gouraud : Method::Phong);
    }
  }
  void draw(const SpanTriangle& t) override {
    const bool gouraud = t.method == Method::Gouraud;
    ++(gouraud ? f_.st.adaptive_gouraud : f_.st.adaptive_phong);
    (gouraud ? gouraud_ : phong_).draw(t);
  }

 private:
  // The listing's vertex test (with the first light): true for Gouraud.
  bool gouraudWill(const std::array<const PVertex*, 3>& t) const {
    const ShadeContext& ctx = f_.ctx;
    const RenderOptions& opt = f_.opt;
    if (ctx.lights.empty()) return true;
    const CameraLight& l = ctx.lights.front();
    std::array<double, 3> q{}, p{};
    for (size_t i = 0; i < 3; ++i) {
      const Vec3 n = normalize(t[i]->n);
      const Vec3 ld = lightDirection(l, t[i]->cam);
      q[i] = dot(n, normalize(ld + ctx.view));
      p[i] = dot(n, ld);
    }
    for (size_t i = 0; i < 3; ++i) {
      const size_t j = (i + 1) % 3;
      if (dot(normalize(t[i]->n), normalize(t[j]->n)) < opt.adaptive_m) return false;
      if (std::fabs(q[i] - q[j]) > opt.adaptive_q || std::fabs(p[i] - p[j]) > opt.adaptive_p) return false;
    }
    return true;
  }

  Frame& f_;
  MethodUnit& gouraud_;
  MethodUnit& phong_;
};

}  // namespace

std::unique_ptr<MethodUnit> makeAdaptiveUnit(Frame& f) { return std::make_unique<AdaptiveUnit>(f); }

}  // namespace shd
