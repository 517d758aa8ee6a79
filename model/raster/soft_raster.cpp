#include "raster/soft_raster.h"

#include <algorithm>
#include <cmath>

namespace shd {

namespace {

// An edge stepped once per raster line (one division per edge, at setup, in both methods).
struct EdgeStep {
  float x, a, dx, da;
  EdgeStep(const SoftVertex& p, const SoftVertex& q, float yc) {
    const float dy = q.y - p.y;
    dx = dy != 0 ? (q.x - p.x) / dy : 0;
    da = dy != 0 ? (q.a - p.a) / dy : 0;
    x = p.x + (yc - p.y) * dx;
    a = p.a + (yc - p.y) * da;
  }
  void step() {
    x += dx;
    a += da;
  }
};

template <bool kClassical>
void raster(std::array<SoftVertex, 3> v, SoftFramebuffer& fb, SoftStats& st) {
  std::sort(v.begin(), v.end(), [](const SoftVertex& p, const SoftVertex& q) { return p.y < q.y; });
  const float det = (v[1].x - v[0].x) * (v[2].y - v[0].y) - (v[2].x - v[0].x) * (v[1].y - v[0].y);
  if (det == 0 || v[2].y == v[0].y) return;  // zero area: nothing to draw
  // The constant increment: the plane gradient, once per triangle.
  const float dadx = ((v[1].a - v[0].a) * (v[2].y - v[0].y) - (v[2].a - v[0].a) * (v[1].y - v[0].y)) / det;
  const int y0 = std::max(0, static_cast<int>(std::ceil(v[0].y - 0.5f)));
  const int y2 = std::min(fb.height, static_cast<int>(std::ceil(v[2].y - 0.5f)));
  // The long edge v0-v2 is on the right when v1 lies left of it (det < 0 with y down... use the
  // sign of the middle vertex against the long edge).
  const bool long_right = det < 0;
  for (int half = 0; half < 2; ++half) {
    const SoftVertex& s0 = half == 0 ? v[0] : v[1];
    const SoftVertex& s1 = half == 0 ? v[1] : v[2];
    const int ya = half == 0 ? y0 : std::max(y0, static_cast<int>(std::ceil(v[1].y - 0.5f)));
    const int yb = half == 0 ? std::min(y2, static_cast<int>(std::ceil(v[1].y - 0.5f))) : y2;
    if (ya >= yb) continue;
    const float yc = static_cast<float>(ya) + 0.5f;
    EdgeStep lng(v[0], v[2], yc), sht(s0, s1, yc);
    EdgeStep& left = long_right ? sht : lng;
    EdgeStep& right = long_right ? lng : sht;
    for (int y = ya; y < yb; ++y) {
      ++st.lines;
      const int xa = std::max(0, static_cast<int>(std::ceil(left.x - 0.5f)));
      const int xb = std::min(fb.width, static_cast<int>(std::ceil(right.x - 0.5f)));
      if (xa >= xb) {
        left.step();
        right.step();
        continue;
      }
      float step;
      if constexpr (kClassical) {
        // Per line: both edge values and a division by the span length.
        const float len = right.x - left.x;
        step = len > 0 ? (right.a - left.a) / len : 0;
        ++st.divisions;
      } else {
        step = dadx;
      }
      float a = left.a + (static_cast<float>(xa) + 0.5f - left.x) * step;
      int32_t* row = &fb.px[static_cast<size_t>(y) * static_cast<size_t>(fb.width)];
      for (int x = xa; x < xb; ++x, a += step) row[x] = static_cast<int32_t>(std::lround(a));
      st.pixels += static_cast<uint64_t>(xb - xa);
      left.step();
      right.x += right.dx;
      if constexpr (kClassical) right.a += right.da;  // only the classical method needs I_R
    }
  }
}

}  // namespace

void rasterClassical(const std::array<SoftVertex, 3>& v, SoftFramebuffer& fb, SoftStats& st) {
  raster<true>(v, fb, st);
}

void rasterConstantIncrement(const std::array<SoftVertex, 3>& v, SoftFramebuffer& fb, SoftStats& st) {
  raster<false>(v, fb, st);
}

}  // namespace shd
