// biquadratic: the listing GouraudRasterizer4's intent, a quadratic colour surface I(x, y)
// through six exactly shaded points, the vertices and the edge midpoints. The listing solves a
// 6x6 system by Cramer's rule (singular when sample points coincide, and its right-hand side
// averaged the vertex colours, which makes the surface linear); its exact solution is the
// quadratic Lagrange basis on barycentric coordinates,
// I = sum c_i l_i (2 l_i - 1) + sum 4 c_ij l_i l_j, evaluated here directly: no solve, no
// conditioning problem. Per pixel (not a span-unit increment: a quadratic has no constant
// step); coverage and depth from the span unit, fragment by fragment, and the barycentric
// coordinates on the triangle it draws (the snapped one: a sliver's stay in [0, 1]).
#include <algorithm>

#include "render/draw.h"

namespace shd {

namespace {

class BiquadraticUnit final : public MethodUnit {
 public:
  explicit BiquadraticUnit(Frame& f) : MethodUnit(Method::Biquadratic), f_(f) {}

  void draw(const SpanTriangle& t) override {
    // The exactly shaded colours at the edge midpoints (screen space); edge e = vertex e..e+1.
    std::array<std::array<double, 3>, 3> mid{};
    for (size_t e = 0; e < 3; ++e) {
      const PVertex mv = lerp(*t.v[e], *t.v[(e + 1) % 3], 0.5);
      mid[e] = f_.shadeNow(normalize(mv.n), f_.proj.vertexCam(mv));
    }
    // The quadratic Lagrange basis: vertices c_i, edge midpoints c_ij.
    f_.drawColours(t, [&](int32_t x, int32_t y) {
      const std::array<double, 3> l = barycentricSnapped(t, x, y);
      std::array<double, 3> lsb{};
      for (size_t k = 0; k < 3; ++k) {
        double v = 0;
        for (size_t i = 0; i < 3; ++i) v += std::clamp(t.v[i]->colour[k], 0.0, 255.0) * l[i] * (2 * l[i] - 1);
        for (size_t e = 0; e < 3; ++e) v += 4 * mid[e][k] * l[e] * l[(e + 1) % 3];
        lsb[k] = v;
      }
      return lsb;
    });
  }

 private:
  Frame& f_;
};

}  // namespace

std::unique_ptr<MethodUnit> makeBiquadraticUnit(Frame& f) { return std::make_unique<BiquadraticUnit>(f); }

}  // namespace shd
