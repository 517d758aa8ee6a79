// gouraud-classical: vertex colours; per raster line the colour is interpolated along both edges
// and divided by the span length (one division per line, float, as the idx3d listings). The
// span unit gives the coverage and the depth, fragment by fragment; RenderStats::divisions
// counts the raster lines with a division.
#include <algorithm>

#include "render/draw.h"

namespace shd {

namespace {

class GouraudClassicalUnit final : public MethodUnit {
 public:
  explicit GouraudClassicalUnit(Frame& f)
      : MethodUnit(Method::GouraudClassical), f_(f), row_divided_(static_cast<size_t>(f.H), 0) {}
  void draw(const SpanTriangle& t) override;

 private:
  // The colour at pixel (x, y) of the triangle's line y.
  std::array<double, 3> colourAt(const SpanTriangle& t, int32_t x, int32_t y);

  Frame& f_;
  std::vector<uint8_t> row_divided_;  // the triangle's lines counted in divisions
  std::vector<int32_t> divided_rows_;
};

std::array<double, 3> GouraudClassicalUnit::colourAt(const SpanTriangle& t, int32_t x, int32_t y) {
  // The classical loop: along both edges, then one division per raster line (float).
  const float yc = static_cast<float>(y) + 0.5f;
  float xl = 1e30f, xr = -1e30f;
  std::array<float, 3> cl{}, cr{};
  for (size_t e = 0; e < 3; ++e) {
    const PVertex& a = *t.v[e];
    const PVertex& b = *t.v[(e + 1) % 3];
    const float ya = static_cast<float>(a.y), yb = static_cast<float>(b.y);
    if ((yc < std::min(ya, yb)) || (yc > std::max(ya, yb)) || ya == yb) continue;
    const float s = (yc - ya) / (yb - ya);
    const float xe = static_cast<float>(a.x) + s * static_cast<float>(b.x - a.x);
    std::array<float, 3> ce{};
    for (size_t k = 0; k < 3; ++k)
      ce[k] = static_cast<float>(std::clamp(a.colour[k], 0.0, 255.0)) +
              s * static_cast<float>(std::clamp(b.colour[k], 0.0, 255.0) - std::clamp(a.colour[k], 0.0, 255.0));
    if (xe < xl) {
      xl = xe;
      cl = ce;
    }
    if (xe > xr) {
      xr = xe;
      cr = ce;
    }
  }
  const float len = xr - xl;
  const size_t row = static_cast<size_t>(y);
  if (len > 0 && !row_divided_[row]) {
    row_divided_[row] = 1;
    divided_rows_.push_back(y);
    ++f_.st.divisions;
  }
  std::array<double, 3> lsb{};
  for (size_t k = 0; k < 3; ++k) {
    const float step = len > 0 ? (cr[k] - cl[k]) / len : 0.0f;
    lsb[k] = cl[k] + step * (static_cast<float>(x) + 0.5f - xl);
  }
  return lsb;
}

void GouraudClassicalUnit::draw(const SpanTriangle& t) {
  f_.drawColours(t, [&](int32_t x, int32_t y) { return colourAt(t, x, y); });
  for (int32_t row : divided_rows_) row_divided_[static_cast<size_t>(row)] = 0;
  divided_rows_.clear();
}

}  // namespace

std::unique_ptr<MethodUnit> makeGouraudClassicalUnit(Frame& f) { return std::make_unique<GouraudClassicalUnit>(f); }

}  // namespace shd
