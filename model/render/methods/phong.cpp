// The Phong family: vertex normals interpolated by the span unit, each pixel lit by the
// object's shader (PointShader, double precision) with the normal the method gives it:
//
// phong              normalised exactly per pixel
// phong-incremental  |N|^2 along each span by the corrected recurrence of the paper's 4.1
//                    (docs/paper-corrections.md)
//                    (F_{i+1} = F_i + 2B + C_{i+1}, C_{i+1} = C_i + 2C, C_1 = C: additions only)
//                    and a fixed-point reciprocal square root (table + one Newton step)
// normal-bisection   the listing NormalVector: along each span the unit normal is computed
//                    exactly only at nodes found by recursive bisection (ends first, then the
//                    middle of a segment while 1 - |(N_a + N_b)/2|, the listing's error
//                    1 - sqrt(2 + 2 cos W)/2, exceeds bisection_threshold); between nodes the
//                    normal is interpolated linearly and used unnormalised. Whole rows are
//                    needed, so the span engine's fragments are collected first.
//
// Device lobes: one specular-unit request per lit light and pixel, evaluated at once on the
// unit's model, else (the RTL) batched per triangle (PixelRequests).
#include <algorithm>
#include <functional>

#include "render/draw.h"

namespace shd {

namespace {

// The interpolated (unnormalised) normal of a fragment, from attributes 0..2.
Vec3 rawNormal(const int64_t* attr) {
  return Vec3{static_cast<double>(attr[0]) * kUnitLsb, static_cast<double>(attr[1]) * kUnitLsb,
              static_cast<double>(attr[2]) * kUnitLsb};
}

// A fragment that passed the z-test, lit with normal n and written (or left pending).
struct PixelLighting {
  Frame& f;
  PixelRequests& req;
  const PixelWriter& write;
  bool batched;
  void operator()(size_t p, int32_t x, int32_t y, int64_t wcode, Vec3 n) const {
    const PointShader& shader = *f.obj.shader;
    const Vec3 pc = shader.needsPosition() ? f.proj.pixelCam(x, y, static_cast<double>(wcode) * kUnitLsb) : Vec3{};
    std::vector<SpecRequest>& requests = req.requests;
    const size_t first = requests.size();
    const std::array<double, 3> lsb = shader.shade(n, pc, &requests).lsb;
    const size_t count = requests.size() - first;
    for (size_t i = first; i < requests.size(); ++i) req.zero_requests += f.obj.coding.atZero(requests[i].cos);
    if (batched) {
      req.pending.push_back({p, wcode, lsb, first, count});
      return;
    }
    if (count > 0) {  // the model's results now (the cycles are counted per triangle)
      f.device_out.resize(count);
      for (size_t i = 0; i < count; ++i) {
        const SpecRequest& r = requests[first + i];
        f.obj.direct->checkCosine(r.shin, r.cos);
        f.device_out[i] = f.obj.coding.atZero(r.cos) ? std::array<uint32_t, 3>{} : f.obj.direct->evaluate(r.shin, r.cos, r.light).rgb;
      }
      f.st.pixels_covered += write(p, wcode, combine(lsb, f.device_out.data(), count));
      return;
    }
    f.st.pixels_covered += write(p, wcode, combine(lsb, nullptr, 0));
  }
};

// normal-bisection: the normal used at each fragment, row by row in x order.
void bisectNormals(const std::vector<SpanFragment>& frags, double threshold, std::vector<size_t>& order,
                   std::vector<Vec3>& bisected, uint64_t& normalisations) {
  order.resize(frags.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return frags[a].y != frags[b].y ? frags[a].y < frags[b].y : frags[a].x < frags[b].x;
  });
  bisected.assign(frags.size(), Vec3{0, 0, 0});
  std::vector<Vec3> n;
  std::vector<bool> node;
  for (size_t i = 0; i < order.size();) {
    size_t j = i;
    while (j < order.size() && frags[order[j]].y == frags[order[i]].y) ++j;
    // Nodes at the ends, then recursive bisection (positions within the row i..j-1).
    n.assign(j - i, Vec3{0, 0, 0});
    node.assign(j - i, false);
    auto exact = [&](size_t k) {
      n[k] = normalize(rawNormal(frags[order[i + k]].attr.data()));
      node[k] = true;
      ++normalisations;
    };
    exact(0);
    if (j - i > 1) exact(j - i - 1);
    std::function<void(size_t, size_t)> bisect = [&](size_t a, size_t b) {
      if (b - a < 2) return;
      const double err = 1 - length(0.5 * (n[a] + n[b]));  // 1 - cos(W/2)
      if (err <= threshold) return;
      const size_t mid = (a + b) / 2;
      exact(mid);
      bisect(a, mid);
      bisect(mid, b);
    };
    bisect(0, j - i - 1);
    // Between nodes: linear interpolation, not normalised.
    size_t a = 0;
    for (size_t k = 0; k < j - i; ++k) {
      if (node[k]) {
        a = k;
        bisected[order[i + k]] = n[k];
        continue;
      }
      size_t b = k;
      while (!node[b]) ++b;
      const double t = static_cast<double>(k - a) / static_cast<double>(b - a);
      bisected[order[i + k]] = n[a] + t * (n[b] - n[a]);
    }
    i = j;
  }
}

template <Method M>
class PhongUnit final : public MethodUnit {
 public:
  explicit PhongUnit(Frame& f) : MethodUnit(M), f_(f) {}
  void draw(const SpanTriangle& t) override {
    req_.begin();
    const PixelWriter write = f_.writer(t.tag);
    const PixelLighting light{f_, req_, write, f_.batchesRequests(M)};
    if constexpr (M == Method::NormalBisection) drawBisected(t, light);
    else drawWalked(t, light);
    req_.finish(f_, write);
  }

 private:
  // phong and phong-incremental, as the walk produces the fragments.
  void drawWalked(const SpanTriangle& t, const PixelLighting& light) {
    const int32_t* const depth = f_.fb.depth.data();
    const int W = f_.W;
    SquaredNorms squaredNorm(t);
    auto fragment = [&](int32_t x, int32_t y, const int64_t* attr) {
      // phong-incremental: the recurrence runs on every fragment, before the z-test.
      const uint64_t sqnorm = M == Method::PhongIncremental ? squaredNorm(x, y, attr) : 0;
      const size_t p = static_cast<size_t>(y) * W + static_cast<size_t>(x);
      const int64_t wcode = attr[3];
      if (wcode <= depth[p]) {
        ++f_.st.depth_rejected;
        return;
      }
      const Vec3 nraw = rawNormal(attr);
      // phong-incremental: |N|^2 from the recurrence (exact integers), then the fixed-point 1/sqrt.
      light(p, x, y, wcode, M == Method::Phong ? normalize(nraw) : rsqrtFixed(sqnorm, 2 * kUnitFrac) * nraw);
    };
    f_.walk(t, fragment);
  }
  // normal-bisection: the fragments collected, their normals bisected along each row.
  void drawBisected(const SpanTriangle& t, const PixelLighting& light) {
    f_.collect(t);
    const std::vector<SpanFragment>& frags = f_.frags;
    bisectNormals(frags, f_.opt.bisection_threshold, order_, bisected_, f_.st.normalisations);
    for (size_t fi = 0; fi < frags.size(); ++fi) {
      const SpanFragment& fr = frags[fi];
      const size_t p = static_cast<size_t>(fr.y) * f_.W + static_cast<size_t>(fr.x);
      const int64_t wcode = fr.attr[3];
      if (wcode <= f_.fb.depth[p]) {
        ++f_.st.depth_rejected;
        continue;
      }
      light(p, fr.x, fr.y, wcode, bisected_[fi]);
    }
  }

  Frame& f_;
  PixelRequests req_;
  std::vector<size_t> order_;   // normal-bisection's
  std::vector<Vec3> bisected_;  // normal-bisection's
};

}  // namespace

std::unique_ptr<MethodUnit> makePhongUnit(Frame& f) { return std::make_unique<PhongUnit<Method::Phong>>(f); }
std::unique_ptr<MethodUnit> makePhongIncrementalUnit(Frame& f) {
  return std::make_unique<PhongUnit<Method::PhongIncremental>>(f);
}
std::unique_ptr<MethodUnit> makeNormalBisectionUnit(Frame& f) {
  return std::make_unique<PhongUnit<Method::NormalBisection>>(f);
}

}  // namespace shd
