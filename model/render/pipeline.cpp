#include "render/pipeline.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

#include "render/fixed_simd.h"
#include "render/x86_targets.h"

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

ClearRect prepareClear(Framebuffer& fb, int W, int H, bool exact, bool tags) {
  const size_t n = static_cast<size_t>(W) * H, n_lsb = exact ? 3 * n : 0;
  const bool same = fb.width == W && fb.height == H && fb.rgb.size() == 3 * n && fb.tri.size() == (tags ? n : 0) &&
                    fb.depth.size() == n && fb.lsb.size() == n_lsb && fb.spec_lsb.size() == n_lsb;
  const ClearRect r{fb.drawn_x0, fb.drawn_y0, fb.drawn_x1, fb.drawn_y1, exact};
  fb.markNothingDrawn();
  // The same frame again (a benchmark, an animation): the buffers are clear outside the
  // rectangle drawn since the last clear.
  if (same) return r;
  fb.width = W;
  fb.height = H;
  // Depth last: every fragment reads it, so it is the buffer to find in the cache.
  fb.rgb.assign(static_cast<size_t>(W) * H * 3, 0);
  fb.tri.resize(tags ? n : 0);  // all -1: every byte 0xFF (memset, where assign fills a loop)
  if (tags) std::memset(fb.tri.data(), 0xFF, n * sizeof(int32_t));
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
    if (!fb.tri.empty()) std::memset(fb.tri.data() + p, 0xFF, w * sizeof(int32_t));
    std::memset(fb.depth.data() + p, 0, w * sizeof(int32_t));
    if (r.exact) {
      std::fill_n(fb.lsb.data() + 3 * p, 3 * w, 0.0);
      std::fill_n(fb.spec_lsb.data() + 3 * p, 3 * w, 0.0);
    }
  }
}

namespace {

// Vertex i's normal in camera space, unit length (a zero normal stays 0).
inline Vec3 cameraNormal(const SceneObject& obj, const CameraBasis& basis, const NormalTransform& to_world, size_t i) {
  return normalize(toCameraDirection(basis, to_world(obj.mesh.normals[i])));
}

// Vertex i of obj in camera space and, in front of the near plane, projected (v as PVertex{}
// leaves it: the colour is the method's).
inline void transformVertex(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                            const NormalTransform& to_world, size_t i, bool normals, PVertex& v) {
  v.cam = toCameraSpace(basis, cam, obj.transform.point(obj.mesh.positions[i]));
  v.n = normals ? cameraNormal(obj, basis, to_world, i) : Vec3{0, 0, 0};
  if (v.cam.z >= cam.z_near) proj.project(v);
}

#ifdef SHD_X86_KERNELS
// Four vertices at a time in AVX2 lanes: each lane runs transformVertex's operations on one
// vertex, the same IEEE operations in the same order (products, sums, divisions and square roots
// correctly rounded, as the scalar ones; no FMA: target avx2 alone, and the build's -ffp-contract=off),
// so every field equals transformVertex's bit for bit (test RenderPipeline.VectorTransformEqualsTheScalarOne).
namespace avx2 {

struct V3 {
  __m256d x, y, z;
};

SHD_AVX2 inline __m256d dot(const Vec3& a, const V3& b) {  // Vec3 dot's order: (x + y) + z
  return _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(_mm256_set1_pd(a.x), b.x), _mm256_mul_pd(_mm256_set1_pd(a.y), b.y)),
                       _mm256_mul_pd(_mm256_set1_pd(a.z), b.z));
}
SHD_AVX2 inline V3 rows(const double (*m)[3], const V3& v) {  // NormalTransform's rows
  return {dot(Vec3{m[0][0], m[0][1], m[0][2]}, v), dot(Vec3{m[1][0], m[1][1], m[1][2]}, v),
          dot(Vec3{m[2][0], m[2][1], m[2][2]}, v)};
}
SHD_AVX2 inline V3 normalize(const V3& a) {  // vec.h's normalize: (1 / len) a, a zero vector kept
  const __m256d len = _mm256_sqrt_pd(
      _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(a.x, a.x), _mm256_mul_pd(a.y, a.y)), _mm256_mul_pd(a.z, a.z)));
  const __m256d inv = _mm256_div_pd(_mm256_set1_pd(1.0), len);
  const __m256d zero = _mm256_cmp_pd(len, _mm256_setzero_pd(), _CMP_EQ_OQ);
  return {_mm256_blendv_pd(_mm256_mul_pd(inv, a.x), a.x, zero), _mm256_blendv_pd(_mm256_mul_pd(inv, a.y), a.y, zero),
          _mm256_blendv_pd(_mm256_mul_pd(inv, a.z), a.z, zero)};
}
SHD_AVX2 inline V3 load(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {  // a in lane 0
  return {_mm256_set_pd(d.x, c.x, b.x, a.x), _mm256_set_pd(d.y, c.y, b.y, a.y), _mm256_set_pd(d.z, c.z, b.z, a.z)};
}
SHD_AVX2 inline V3 load(const Vec3* p) { return load(p[0], p[1], p[2], p[3]); }
SHD_AVX2 inline V3 loadAt(const Vec3* p, const uint32_t* idx) { return load(p[idx[0]], p[idx[1]], p[idx[2]], p[idx[3]]); }
SHD_AVX2 inline void store(const V3& v, double (&x)[4], double (&y)[4], double (&z)[4]) {
  _mm256_storeu_pd(x, v.x);
  _mm256_storeu_pd(y, v.y);
  _mm256_storeu_pd(z, v.z);
}

SHD_AVX2 inline __m256d pointLessEye(const double* row, const V3& p, double eye) {  // Mat4::point's row - eye
  return _mm256_sub_pd(_mm256_add_pd(dot(Vec3{row[0], row[1], row[2]}, p), _mm256_set1_pd(row[3])), _mm256_set1_pd(eye));
}

// cameraNormal of the 4 mesh normals in the lanes: NormalTransform, then toCameraDirection and
// normalize.
SHD_AVX2 inline V3 cameraNormals(const CameraBasis& basis, const NormalTransform& to_world, const V3& mesh_normals) {
  V3 r = rows(to_world.c, mesh_normals);
  if (to_world.mirror) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    r = {_mm256_xor_pd(r.x, sign), _mm256_xor_pd(r.y, sign), _mm256_xor_pd(r.z, sign)};
  }
  const V3 w = normalize(r);
  return normalize(V3{dot(basis.right, w), dot(basis.up, w), dot(basis.forward, w)});
}

// The normals of the vertices idx[0] .. idx[3].
SHD_AVX2 void normals4(const SceneObject& obj, const CameraBasis& basis, const NormalTransform& to_world,
                       const uint32_t* idx, PVertex* verts) {
  double nx[4], ny[4], nz[4];
  store(cameraNormals(basis, to_world, loadAt(obj.mesh.normals.data(), idx)), nx, ny, nz);
  for (size_t k = 0; k < 4; ++k) verts[idx[k]].n = {nx[k], ny[k], nz[k]};
}

template <bool kNormals>
SHD_AVX2 void transform4(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                            const NormalTransform& to_world, size_t i, PVertex* out) {
  const double (*m)[4] = obj.transform.m;
  const V3 p = load(&obj.mesh.positions[i]);
  // Mat4::point: direction(p) + translation, then toCameraSpace: the basis's dots with it - eye.
  const V3 rel{pointLessEye(m[0], p, cam.eye.x), pointLessEye(m[1], p, cam.eye.y), pointLessEye(m[2], p, cam.eye.z)};
  const V3 c{dot(basis.right, rel), dot(basis.up, rel), dot(basis.forward, rel)};
  // Without kNormals, 0.
  V3 n{_mm256_setzero_pd(), _mm256_setzero_pd(), _mm256_setzero_pd()};
  if constexpr (kNormals) n = cameraNormals(basis, to_world, load(&obj.mesh.normals[i]));
  // Projection::project where Z >= z_near; elsewhere x, y and w stay 0.
  const __m256d f = _mm256_set1_pd(proj.f);
  const __m256d in = _mm256_cmp_pd(c.z, _mm256_set1_pd(cam.z_near), _CMP_GE_OQ);
  const __m256d sx = _mm256_add_pd(_mm256_set1_pd(proj.cx), _mm256_div_pd(_mm256_mul_pd(f, c.x), c.z));
  const __m256d sy = _mm256_sub_pd(_mm256_set1_pd(proj.cy), _mm256_div_pd(_mm256_mul_pd(f, c.y), c.z));
  const __m256d sw = _mm256_div_pd(_mm256_set1_pd(proj.z_near), c.z);
  double cx[4], cy[4], cz[4], nx[4], ny[4], nz[4], x[4], y[4], pw[4];
  store(c, cx, cy, cz);
  store(n, nx, ny, nz);
  store(V3{_mm256_and_pd(in, sx), _mm256_and_pd(in, sy), _mm256_and_pd(in, sw)}, x, y, pw);
  for (size_t k = 0; k < 4; ++k) {
    PVertex& v = out[i + k];
    v.cam = {cx[k], cy[k], cz[k]};
    v.n = {nx[k], ny[k], nz[k]};
    v.x = x[k];
    v.y = y[k];
    v.w = pw[k];
    v.colour = {};
  }
}

}  // namespace avx2
#endif

}  // namespace

size_t keptTriangles(const std::vector<PVertex>& verts, const std::vector<std::array<uint32_t, 3>>& tris, double z_near,
                     std::vector<uint32_t>& kept) {
  kept.resize(tris.size());
  size_t n = 0;
  for (size_t i = 0; i < tris.size(); ++i) {
    kept[n] = static_cast<uint32_t>(i);
    n += culledEarly(viewTriangle(verts, tris[i], z_near)) ? 0 : 1;  // without a branch
  }
  kept.resize(n);
  return tris.size() - n;
}

void transformVertexRange(const SceneObject& obj, const CameraBasis& basis, const Camera& cam, const Projection& proj,
                          PVertex* verts, size_t begin, size_t end, bool vector, bool normals) {
  const NormalTransform to_world(obj.transform);
#ifdef SHD_X86_KERNELS
  if (vector && fixed_simd::availableAvx2()) {
    if (normals)
      for (; begin + 4 <= end; begin += 4) avx2::transform4<true>(obj, basis, cam, proj, to_world, begin, verts);
    else
      for (; begin + 4 <= end; begin += 4) avx2::transform4<false>(obj, basis, cam, proj, to_world, begin, verts);
  }
#else
  (void)vector;
#endif
  for (size_t i = begin; i < end; ++i) {
    // The fields transformVertex may leave as they are reset one by one (clearing the whole
    // vertex first was a `rep stos` per vertex).
    PVertex& v = verts[i];
    v.x = v.y = v.w = 0;
    v.colour = {};
    transformVertex(obj, basis, cam, proj, to_world, i, normals, v);
  }
}

void triangleNormals(const SceneObject& obj, const CameraBasis& basis, const std::vector<uint32_t>& kept,
                     PVertex* verts, std::vector<uint8_t>& mark, std::vector<uint32_t>& idx, bool vector) {
  const size_t n = obj.mesh.positions.size();
  mark.assign(n, 0);
  for (const uint32_t t : kept)
    for (const uint32_t i : obj.mesh.triangles[t]) mark[i] = 1;
  idx.resize(n);
  size_t m = 0;
  for (size_t i = 0; i < n; ++i) {
    idx[m] = static_cast<uint32_t>(i);
    m += mark[i];  // without a branch
  }
  vertexNormals(obj, basis, idx.data(), m, verts, vector);
}

void vertexNormals(const SceneObject& obj, const CameraBasis& basis, const uint32_t* idx, size_t m, PVertex* verts,
                   bool vector) {
  const NormalTransform to_world(obj.transform);
  size_t j = 0;
#ifdef SHD_X86_KERNELS
  if (vector && fixed_simd::availableAvx2())
    for (; j + 4 <= m; j += 4) avx2::normals4(obj, basis, to_world, idx + j, verts);
#else
  (void)vector;
#endif
  for (; j < m; ++j) verts[idx[j]].n = cameraNormal(obj, basis, to_world, idx[j]);
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
