#include "render/pipeline.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace shd {

namespace {

// Sutherland-Hodgman against one half-plane dist(v) >= 0.
template <class Dist>
Poly clipPolygon(const Poly& in, Dist dist) {
  Poly out;
  for (size_t i = 0; i < in.size(); ++i) {
    const PVertex& a = in[i];
    const PVertex& b = in[(i + 1) % in.size()];
    const double da = dist(a), db = dist(b);
    if (da >= 0) out.push_back(a);
    if ((da >= 0) != (db >= 0)) out.push_back(lerp(a, b, da / (da - db)));
  }
  return out;
}

}  // namespace

void Framebuffer::markDrawn(double xmin, double ymin, double xmax, double ymax) {
  // A pixel (x, y) whose centre lies in the box: x in [xmin - 0.5, xmax - 0.5], so within
  // [floor(xmin) - 1, ceil(xmax)], which [trunc(xmin) - 2, trunc(xmax) + 1] holds (trunc is
  // within 1 of floor and of ceil; the coordinates lie in the guard band); clamped to the frame.
  auto lo = [](double v, int n) { return std::clamp(static_cast<int>(v) - 2, 0, n - 1); };
  auto hi = [](double v, int n) { return std::clamp(static_cast<int>(v) + 1, 0, n - 1); };
  drawn_x0 = std::min(drawn_x0, lo(xmin, width));
  drawn_y0 = std::min(drawn_y0, lo(ymin, height));
  drawn_x1 = std::max(drawn_x1, hi(xmax, width));
  drawn_y1 = std::max(drawn_y1, hi(ymax, height));
}

ClearRect prepareClear(Framebuffer& fb, int W, int H, bool exact) {
  const size_t n = static_cast<size_t>(W) * H, n_lsb = exact ? 3 * n : 0;
  const bool same = fb.width == W && fb.height == H && fb.rgb.size() == 3 * n && fb.tri.size() == n &&
                    fb.depth.size() == n && fb.lsb.size() == n_lsb && fb.spec_lsb.size() == n_lsb;
  const ClearRect r{fb.drawn_x0, fb.drawn_y0, fb.drawn_x1, fb.drawn_y1, exact};
  fb.drawn_x0 = fb.drawn_y0 = INT_MAX;  // nothing drawn
  fb.drawn_x1 = fb.drawn_y1 = INT_MIN;
  // The same frame again (a benchmark, an animation): the buffers are clear outside the
  // rectangle drawn since the last clear.
  if (same) return r;
  fb.width = W;
  fb.height = H;
  // Depth last: every fragment reads it, so it is the buffer to find in the cache.
  fb.rgb.assign(static_cast<size_t>(W) * H * 3, 0);
  fb.tri.resize(static_cast<size_t>(W) * H);  // all -1: every byte 0xFF (memset, where assign fills a loop)
  std::memset(fb.tri.data(), 0xFF, fb.tri.size() * sizeof(int32_t));
  fb.depth.assign(static_cast<size_t>(W) * H, 0);
  if (exact) {
    fb.lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
    fb.spec_lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
  } else {
    fb.lsb.clear();
    fb.spec_lsb.clear();
  }
  return ClearRect{1, 1, 0, 0, exact};  // nothing left to clear
}

void clearRect(Framebuffer& fb, const ClearRect& r) {
  const size_t W = static_cast<size_t>(fb.width);
  const size_t w = r.x0 <= r.x1 ? static_cast<size_t>(r.x1 - r.x0 + 1) : 0;
  for (int y = r.y0; w > 0 && y <= r.y1; ++y) {
    const size_t p = static_cast<size_t>(y) * W + static_cast<size_t>(r.x0);
    std::memset(fb.rgb.data() + 3 * p, 0, 3 * w);
    std::memset(fb.tri.data() + p, 0xFF, w * sizeof(int32_t));
    std::memset(fb.depth.data() + p, 0, w * sizeof(int32_t));
    if (r.exact) {
      std::fill_n(fb.lsb.data() + 3 * p, 3 * w, 0.0);
      std::fill_n(fb.spec_lsb.data() + 3 * p, 3 * w, 0.0);
    }
  }
}

namespace {

// Vertex i of obj in camera space and, in front of the near plane, projected (v as PVertex{}
// leaves it: the colour is the method's).
inline void transformVertex(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                            const NormalTransform& to_world, size_t i, PVertex& v) {
  v.cam = toCameraSpace(basis, cam, obj.transform.point(obj.mesh.positions[i]));
  v.n = normalize(toCameraDirection(basis, to_world(obj.mesh.normals[i])));
  if (v.cam.z >= cam.z_near) proj.project(v);
}

}  // namespace

void transformVertexRange(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                          PVertex* verts, size_t begin, size_t end) {
  const NormalTransform to_world(obj.transform);
  for (size_t i = begin; i < end; ++i) {
    // The fields transformVertex may leave as they are reset one by one (clearing the whole
    // vertex first was a `rep stos` per vertex).
    PVertex& v = verts[i];
    v.x = v.y = v.w = 0;
    v.colour = {};
    transformVertex(obj, basis, cam, proj, to_world, i, v);
  }
}

bool clipToFan(const TriangleView& t, const Projection& proj, int W, int H, Poly& poly, Fan& fan, RenderStats& st) {
  auto inGuard = [&](const PVertex& v) {
    return v.x >= -kGuard && v.x <= W + kGuard && v.y >= -kGuard && v.y <= H + kGuard;
  };
  fan.clear();
  if (t.all_in && inGuard(*t.v0) && inGuard(*t.v1) && inGuard(*t.v2)) {
    fan = {t.v0, t.v1, t.v2};  // the common case: drawn from the vertex array, nothing copied
    return true;
  }
  poly = {*t.v0, *t.v1, *t.v2};
  if (!t.all_in) {  // near plane, camera space
    poly = clipPolygon(poly, [&](const PVertex& v) { return v.cam.z - proj.z_near; });
    if (poly.size() < 3) {
      ++st.culled_outside;
      return false;
    }
    ++st.clipped;
    for (PVertex& v : poly) proj.project(v);
    if (!(area2(poly[0], poly[1], poly[2]) < 0)) {
      ++st.culled_back;
      return false;
    }
  }
  // Guard band, screen space.
  if (!std::all_of(poly.begin(), poly.end(), inGuard)) {
    for (const PVertex& v : poly)
      if (!(std::abs(v.x) <= kMaxClipCoord && std::abs(v.y) <= kMaxClipCoord))
        throw std::range_error(fmt::format(
            "a vertex projects to ({:.3g}, {:.3g}) px, beyond the +-2^40 px within which the clipper is exact to "
            "1/4096 px (lower camera.px_per_unit, raise camera.z_near or move the camera)",
            v.x, v.y));
    poly = clipPolygon(poly, [&](const PVertex& v) { return v.x + kGuard; });
    poly = clipPolygon(poly, [&](const PVertex& v) { return W + kGuard - v.x; });
    poly = clipPolygon(poly, [&](const PVertex& v) { return v.y + kGuard; });
    poly = clipPolygon(poly, [&](const PVertex& v) { return H + kGuard - v.y; });
    if (poly.size() < 3) {
      ++st.culled_outside;
      return false;
    }
    for (PVertex& v : poly) v.cam = proj.vertexCam(v);
    ++st.clipped;
  }
  for (const PVertex& v : poly) fan.push_back(&v);
  return true;
}

}  // namespace shd
