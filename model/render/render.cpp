#include "render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "approx/brdf.h"
#include "raster/span_walk.h"
#include "render/fixed_shading.h"
#include "render/normalize.h"

namespace shd {

namespace {

struct MethodName {
  Method m;
  const char* name;
};
constexpr MethodName kMethods[] = {{Method::Flat, "flat"},
                                   {Method::Gouraud, "gouraud"},
                                   {Method::GouraudClassical, "gouraud-classical"},
                                   {Method::Phong, "phong"},
                                   {Method::PhongIncremental, "phong-incremental"},
                                   {Method::PhongFixed, "phong-fixed"},
                                   {Method::NormalBisection, "normal-bisection"},
                                   {Method::Biquadratic, "biquadratic"},
                                   {Method::ModifiedGouraud, "modified-gouraud"},
                                   {Method::Adaptive, "adaptive"},
                                   {Method::Reference, "reference"}};

constexpr int kColourFrac = 12;  // colour attributes in LSBs: 0..255 with 12 fraction bits
constexpr int kUnitFrac = 28;    // normals and depth in [-1, 1]
constexpr double kUnitLsb = 1.0 / (1 << kUnitFrac);  // 2^-28: code * kUnitLsb == ldexp(code, -28) exactly
constexpr double kGuard = 2048;  // guard band (px beyond the viewport) before 2D clipping

// A vertex on its way through the pipeline. cam and n are camera space; colour is the Gouraud
// vertex colour in LSBs (device lobes included).
struct PVertex {
  Vec3 cam{0, 0, 0}, n{0, 0, 1};
  double x = 0, y = 0, w = 0;
  std::array<double, 3> colour{};
};

PVertex lerp(const PVertex& a, const PVertex& b, double t) {
  PVertex r;
  r.cam = a.cam + t * (b.cam - a.cam);
  r.n = a.n + t * (b.n - a.n);
  r.x = a.x + t * (b.x - a.x);
  r.y = a.y + t * (b.y - a.y);
  r.w = a.w + t * (b.w - a.w);
  for (size_t k = 0; k < 3; ++k) r.colour[k] = a.colour[k] + t * (b.colour[k] - a.colour[k]);
  return r;
}

// A polygon of the clipper: a triangle cut by the near plane and the four guard-band planes
// has at most 3 + 5 vertices.
using Poly = InlineVec<PVertex, 8>;

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

double area2(const PVertex& a, const PVertex& b, const PVertex& c) {
  return (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
}

// A run's pixels in the framebuffer: the index and the depth code of the current one, and
// their steps along the run.
struct RunCursor {
  size_t p, step;
  uint64_t z, dz;
  RunCursor(const RowRun& r, int width)
      : p(static_cast<size_t>(r.y) * static_cast<size_t>(width) + static_cast<size_t>(r.x0)),
        step(static_cast<size_t>(static_cast<ptrdiff_t>(r.dx))),  // +1 or -1 (mod 2^64)
        z(static_cast<uint64_t>(r.a0[3])),
        dz(static_cast<uint64_t>(r.da[3])) {}
  int64_t depth() const { return static_cast<int64_t>(z); }
  void next() {
    p += step;
    z += dz;
  }
};

// A screen triangle to draw: its vertices (in the object's vertex array, the clipped polygon
// or a split) and the method that draws it.
struct Part {
  std::array<const PVertex*, 3> v;
  Method method;
};

using ShadeFn = std::function<std::array<double, 3>(Vec3 n, Vec3 p)>;

// Modified Gouraud: the triangle split at its edges' specular maxima (see render.h).
std::vector<std::array<PVertex, 3>> splitAtEdgeMaxima(const std::array<PVertex, 3>& t, const ShadeContext& ctx,
                                                      double threshold, const ShadeFn& shade,
                                                      const std::function<Vec3(const PVertex&)>& camOf) {
  std::array<bool, 3> has{};
  std::array<PVertex, 3> pt;
  for (size_t e = 0; e < 3; ++e) {
    const PVertex& a = t[e];
    const PVertex& b = t[(e + 1) % 3];
    double best_gain = threshold;
    for (const CameraLight& l : ctx.lights) {
      const Vec3 mid = 0.5 * (a.cam + b.cam);
      const Vec3 h = normalize(lightDirection(l, mid) + ctx.view);
      const double tm = edgeMaximumT(normalize(a.n), normalize(b.n), h);
      if (tm < 0) continue;
      PVertex v = lerp(a, b, tm);
      v.cam = camOf(v);
      v.n = normalize(v.n);
      v.colour = shade(v.n, v.cam);
      double gain = 0;
      for (size_t k = 0; k < 3; ++k)
        gain = std::max(gain, v.colour[k] - (a.colour[k] + tm * (b.colour[k] - a.colour[k])));
      if (gain > best_gain) {
        best_gain = gain;
        pt[e] = v;
        has[e] = true;
      }
    }
  }
  const int count = has[0] + has[1] + has[2];
  if (count == 0) return {t};
  if (count == 3)
    return {std::array<PVertex, 3>{t[0], pt[0], pt[2]}, std::array<PVertex, 3>{pt[0], t[1], pt[1]},
            std::array<PVertex, 3>{pt[2], pt[1], t[2]}, std::array<PVertex, 3>{pt[0], pt[1], pt[2]}};
  // Rotate so that the split edges come first: edge 0 (and edge 1 for two points).
  size_t r = 0;
  if (count == 1) r = has[0] ? 0 : (has[1] ? 1 : 2);
  else r = !has[2] ? 0 : (!has[0] ? 1 : 2);  // the unsplit edge becomes edge 2
  const PVertex &v0 = t[r], &v1 = t[(r + 1) % 3], &v2 = t[(r + 2) % 3];
  const PVertex& P = pt[r];
  if (count == 1) return {std::array<PVertex, 3>{v0, P, v2}, std::array<PVertex, 3>{P, v1, v2}};
  const PVertex& Q = pt[(r + 1) % 3];
  return {std::array<PVertex, 3>{P, v1, Q}, std::array<PVertex, 3>{v0, P, Q}, std::array<PVertex, 3>{v0, Q, v2}};
}

// Adaptive: Gouraud (true) or Phong, by the listing's vertex test (see render.h).
bool adaptiveChoice(const std::array<PVertex, 3>& t, const ShadeContext& ctx, const RenderOptions& opt) {
  if (ctx.lights.empty()) return true;
  const CameraLight& l = ctx.lights.front();
  std::array<double, 3> q{}, p{};
  for (size_t i = 0; i < 3; ++i) {
    const Vec3 n = normalize(t[i].n);
    const Vec3 ld = lightDirection(l, t[i].cam);
    q[i] = dot(n, normalize(ld + ctx.view));
    p[i] = dot(n, ld);
  }
  for (size_t i = 0; i < 3; ++i) {
    const size_t j = (i + 1) % 3;
    if (dot(normalize(t[i].n), normalize(t[j].n)) < opt.adaptive_m) return false;
    if (std::fabs(q[i] - q[j]) > opt.adaptive_q || std::fabs(p[i] - p[j]) > opt.adaptive_p) return false;
  }
  return true;
}

// normal-bisection (see render.h): the normal used at each fragment, row by row in x order.
// The interpolated (unnormalised) normal of a fragment, from attributes 0..2.
Vec3 rawNormal(const int64_t* attr) {
  return Vec3{static_cast<double>(attr[0]) * kUnitLsb, static_cast<double>(attr[1]) * kUnitLsb,
              static_cast<double>(attr[2]) * kUnitLsb};
}

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

}  // namespace

double edgeMaximumT(Vec3 na, Vec3 nb, Vec3 h) {
  const double cchi = dot(na, h), calpha = dot(nb, h), cpsi = dot(na, nb);
  if (1 - cpsi < 1e-12) return -1;    // equal normals: the cosine is constant along the edge
  if (1 + cpsi < 1e-12) return -1;    // opposite normals: N(t) vanishes at t = 1/2
  if (calpha + cchi <= 0) return -1;  // the root is a minimum (or none): the maximum is an end
  const double t = (cchi * cpsi - calpha) / ((cpsi - 1) * (calpha + cchi));
  return t > 0 && t < 1 ? t : -1;
}

Method parseMethod(const std::string& s) {
  for (const MethodName& m : kMethods)
    if (s == m.name) return m.m;
  throw std::invalid_argument(fmt::format(
      "unknown method '{}' (expected flat, gouraud, gouraud-classical, phong, phong-incremental, phong-fixed, "
      "normal-bisection, "
      "biquadratic, modified-gouraud, adaptive or reference)",
      s));
}

const char* toString(Method m) {
  for (const MethodName& n : kMethods)
    if (n.m == m) return n.name;
  return "?";
}

std::vector<Method> allMethods() {
  std::vector<Method> v;
  for (const MethodName& m : kMethods) v.push_back(m.m);
  return v;
}

uint64_t ModelSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.resize(in.size());
  for (size_t i = 0; i < in.size(); ++i) out[i] = unit_.evaluate(in[i].shin, in[i].cos, in[i].light).rgb;
  return batchCycles(in.size(), unit_.params().latency());
}

std::vector<Lobe> deviceLobesUsed(const Scene& scene, const RenderOptions& opt) {
  std::vector<Lobe> used;
  if (opt.method == Method::Reference) return used;  // the reference uses the exact lobes
  for (const SceneObject& o : scene.objects) {
    const Lobe l = parseLobe(opt.brdf.empty() ? scene.materials.at(static_cast<size_t>(o.material)).brdf : opt.brdf);
    if (isDeviceLobe(l) && std::find(used.begin(), used.end(), l) == used.end()) used.push_back(l);
  }
  return used;
}

RenderResult render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines) {
  RenderResult res;
  render(scene, opt, span, engines, res);
  return res;
}

void render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines, RenderResult& res) {
  const auto t0 = std::chrono::steady_clock::now();
  res.stats = RenderStats{};
  res.triangles.clear();
  RenderStats& st = res.stats;
  const Camera& cam = scene.camera;
  const int W = cam.width, H = cam.height;
  Framebuffer& fb = res.fb;
  fb.width = W;
  fb.height = H;
  // Depth last: every fragment reads it, so it is the buffer to find in the cache.
  fb.rgb.assign(static_cast<size_t>(W) * H * 3, 0);
  fb.tri.resize(static_cast<size_t>(W) * H);  // all -1: every byte 0xFF (memset, where assign fills a loop)
  std::memset(fb.tri.data(), 0xFF, fb.tri.size() * sizeof(int32_t));
  fb.depth.assign(static_cast<size_t>(W) * H, 0);
  const bool reference = opt.method == Method::Reference;
  if (reference) {
    fb.lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
    fb.spec_lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
  } else {
    fb.lsb.clear();
    fb.spec_lsb.clear();
  }
  const CameraBasis basis = cameraBasis(cam);
  const ShadeContext ctx = makeShadeContext(scene);
  const double cx = 0.5 * W, cy = 0.5 * H, f = cam.px_per_unit;

  RasterConfig rc;
  rc.width = W;
  rc.height = H;
  rc.subpixel_bits = opt.subpixel_bits;
  rc.unit = span.params();
  if (rc.unit.NumAttr != 4) throw std::invalid_argument("render: the span unit must carry 4 attributes");
  rc.attr_frac_bits = {kColourFrac, kColourFrac, kColourFrac, kUnitFrac};  // per triangle below
  rc.validate();

  // The coding of a device lobe's requests for the specular unit of a material.
  auto codingFor = [](SpecEngine* e, const Material& m) {
    DeviceCoding c;
    if (e == nullptr) return c;
    const PromTable& t = e->table();
    c.cos_frac_bits = t.unit.CosFracBits;
    const int a = t.addressOf(std::round(m.shininess));
    if (a < 0)
      throw std::invalid_argument(
          fmt::format("shininess {} is not in the specular unit's PROM (n = {})", m.shininess, t.request.n.text));
    c.shin = static_cast<uint32_t>(a);
    return c;
  };
  std::vector<std::array<uint32_t, 3>> device_out;
  std::vector<SpecRequest> point_requests;
  SpecEngine* spec = nullptr;  // the current object's
  DeviceCoding coding;
  std::optional<PointShader> shader;  // the current object's material and lobe
  std::optional<FixedPointShader> fixed;  // the same, phong-fixed

  // A point's shade, with its device-lobe evaluations done by the specular unit right away
  // (vertices: few; pixels are batched per triangle below, or evaluated one by one on the model).
  auto shadeNow = [&](Vec3 n, Vec3 p) {
    point_requests.clear();
    Shade s = shader->shade(n, p, &point_requests);
    if (!point_requests.empty()) {
      st.spec_cycles += spec->evaluate(point_requests, device_out);
      st.spec_evaluations += point_requests.size();
      for (const auto& d : device_out)
        for (size_t k = 0; k < 3; ++k) s.lsb[k] += d[k];
    }
    return s.lsb;
  };

  // Camera space -> screen (pixels, y down) and w = z_near / Z, for Z >= z_near.
  auto project = [&](PVertex& v) {
    v.x = cx + f * v.cam.x / v.cam.z;
    v.y = cy - f * v.cam.y / v.cam.z;
    v.w = cam.z_near / v.cam.z;
  };
  // Pixel centre -> camera space point of the surface, from w = z_near / Z.
  auto pixelCam = [&](double px, double py, double w) {
    const double Z = cam.z_near / w;
    return Vec3{(px + 0.5 - cx) * Z / f, -(py + 0.5 - cy) * Z / f, Z};
  };

  // Per-triangle buffers, reused across the frame (no allocation per triangle or fragment once
  // they have grown).
  std::vector<PVertex> verts;
  std::vector<uint8_t> lit;  // verts[i].colour is computed
  Poly poly;                 // a clipped triangle
  InlineVec<const PVertex*, Poly::capacity()> fan;  // the polygon to draw: 3 vertices unless clipped
  std::vector<std::array<PVertex, 3>> splits;       // modified-gouraud's parts
  std::vector<Part> parts;
  std::vector<SpanFragment> frags;
  struct Pending {  // a fragment waiting for its specular-unit results
    size_t pixel;
    int64_t w;
    std::array<double, 3> lsb;
    size_t dev_first, dev_count;
  };
  std::vector<Pending> pend;
  // phong-fixed's fragments in the shader's vector case (one light, a lobe of N.H), z-tested
  // and buffered from the runs of an object's triangles and shaded 8 at a time (fixed_simd.h):
  // the groups are independent, so the processor overlaps them, where one group per row of 5
  // or 6 pixels would wait out its own latency.
  auto batch = std::make_unique<fixed_simd::Batch>();
  // The batch: shaded 8 at a time, the colours written (bufferRun has z-tested its fragments
  // and written their depth and tag). It collects the runs of several triangles of an object
  // (the same shader constants), in the order they were z-tested: where two of them cover a
  // pixel, the second passed the test against the first's depth and its colour is written
  // last. Everything else that writes a colour at once flushes it first.
  auto flushBatch = [&](auto& kernel) {
    fixed_simd::Batch& b = *batch;
    uint8_t* const rgb[3] = {b.rgb[0].data(), b.rgb[1].data(), b.rgb[2].data()};
    const size_t n = b.n;  // a local: the pixels' byte stores may alias the batch
    const uint64_t declined = kernel.shadeBatch(b.sq.data(), b.l.data(), b.h.data(), n, rgb);
    for (uint64_t g = declined; g != 0; g &= g - 1)
      for (size_t f = 8 * static_cast<size_t>(__builtin_ctzll(g)), e = std::min(f + 8, n); f < e; ++f) {
        const std::array<uint8_t, 3> c = fixedColour(kernel.shadeRaw(b.sq[f], b.l[f], b.h[f]));
        for (size_t k = 0; k < 3; ++k) rgb[k][f] = c[k];
      }
    uint8_t* const out = fb.rgb.data();
    for (size_t f = 0; f < n; ++f) {
      const size_t p = b.pixel[f];
      for (size_t k = 0; k < 3; ++k) out[p * 3 + k] = rgb[k][f];
    }
    b.n = 0;
  };
  std::vector<SpecRequest> requests;
  std::vector<size_t> order;
  std::vector<Vec3> bisected;
  std::vector<uint8_t> row_divided(static_cast<size_t>(H), 0);
  std::vector<int32_t> divided_rows;
  RasterConfig rc_colour = rc, rc_unit = rc;
  rc_colour.attr_frac_bits = {kColourFrac, kColourFrac, kColourFrac, kUnitFrac};
  rc_unit.attr_frac_bits = {kUnitFrac, kUnitFrac, kUnitFrac, kUnitFrac};

  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const SceneObject& obj = scene.objects[oi];
    const Material& mat = scene.materials.at(static_cast<size_t>(obj.material));
    const Lobe lobe = parseLobe(opt.brdf.empty() ? mat.brdf : opt.brdf);
    spec = engines.forLobe(lobe);
    if (isDeviceLobe(lobe) && spec == nullptr && !reference)
      throw std::invalid_argument(fmt::format("object '{}': brdf {} needs the specular unit", obj.name, toString(lobe)));
    coding = codingFor(spec, mat);
    shader.emplace(ctx, mat, lobe, &coding);
    // Per-pixel device lobes on the model: each request evaluated as it is made.
    const SpecUnitModel* direct = spec != nullptr ? spec->model() : nullptr;
    if (opt.method == Method::PhongFixed) fixed.emplace(ctx, mat, lobe, &coding, spec != nullptr ? spec->memo() : nullptr);
    // The reference: the exact lobes (the Blinn lobe a device lobe approximates), and the same
    // without k_s for the specular part alone (highlight masks).
    const Lobe ref_lobe = isDeviceLobe(lobe) ? Lobe::Blinn : lobe;
    Material nospec = mat;
    nospec.ks = 0;
    const PointShader ref_shader(ctx, mat, ref_lobe, nullptr), ref_diffuse(ctx, nospec, ref_lobe, nullptr);
    // Object -> camera space and the projection of the vertices in front of the near plane.
    verts.assign(obj.mesh.positions.size(), PVertex{});
    const NormalTransform to_world(obj.transform);
    for (size_t i = 0; i < verts.size(); ++i) {
      PVertex& v = verts[i];
      v.cam = toCameraSpace(basis, cam, obj.transform.point(obj.mesh.positions[i]));
      v.n = normalize(toCameraDirection(basis, to_world(obj.mesh.normals[i])));
      if (v.cam.z >= cam.z_near) project(v);
    }
    // Gouraud vertex colours: computed when a triangle that is not culled first needs them.
    const bool vertex_colours = opt.method == Method::Gouraud || opt.method == Method::GouraudClassical ||
                                opt.method == Method::Biquadratic || opt.method == Method::ModifiedGouraud ||
                                opt.method == Method::Adaptive;
    lit.assign(verts.size(), 0);

    for (size_t ti = 0; ti < obj.mesh.triangles.size(); ++ti) {
      ++st.triangles;
      const auto& tri = obj.mesh.triangles[ti];
      const PVertex &v0 = verts[tri[0]], &v1 = verts[tri[1]], &v2 = verts[tri[2]];
      const bool all_in = v0.cam.z >= cam.z_near && v1.cam.z >= cam.z_near && v2.cam.z >= cam.z_near;
      // Back faces: the idx3d front face has a negative screen area (y down), see sphere.h.
      // A triangle wholly in front of the near plane is culled before anything is copied.
      if (all_in && !(area2(v0, v1, v2) < 0)) {
        ++st.culled;
        continue;
      }
      if (vertex_colours)
        for (const uint32_t i : tri)
          if (!lit[i]) {
            verts[i].colour = shadeNow(verts[i].n, verts[i].cam);
            lit[i] = 1;
          }
      auto inGuard = [&](const PVertex& v) {
        return v.x >= -kGuard && v.x <= W + kGuard && v.y >= -kGuard && v.y <= H + kGuard;
      };
      fan.clear();
      if (all_in && inGuard(v0) && inGuard(v1) && inGuard(v2)) {
        fan = {&v0, &v1, &v2};  // the common case: drawn from the vertex array, nothing copied
      } else {
        poly = {v0, v1, v2};
        if (!all_in) {  // near plane, camera space
          poly = clipPolygon(poly, [&](const PVertex& v) { return v.cam.z - cam.z_near; });
          if (poly.size() < 3) {
            ++st.culled;
            continue;
          }
          ++st.clipped;
          for (PVertex& v : poly) project(v);
          if (!(area2(poly[0], poly[1], poly[2]) < 0)) {
            ++st.culled;
            continue;
          }
        }
        // Guard band, screen space (attributes interpolate linearly there, as in the span unit).
        if (!std::all_of(poly.begin(), poly.end(), inGuard)) {
          poly = clipPolygon(poly, [&](const PVertex& v) { return v.x + kGuard; });
          poly = clipPolygon(poly, [&](const PVertex& v) { return W + kGuard - v.x; });
          poly = clipPolygon(poly, [&](const PVertex& v) { return v.y + kGuard; });
          poly = clipPolygon(poly, [&](const PVertex& v) { return H + kGuard - v.y; });
          if (poly.size() < 3) {
            ++st.culled;
            continue;
          }
          for (PVertex& v : poly) v.cam = pixelCam(v.x - 0.5, v.y - 0.5, v.w);
          ++st.clipped;
        }
        for (const PVertex& v : poly) fan.push_back(&v);
      }
      // Flat: one colour from the face normal at the centroid.
      std::array<double, 3> flat{};
      if (opt.method == Method::Flat) {
        Vec3 fn = normalize(cross(fan[1]->cam - fan[0]->cam, fan[2]->cam - fan[0]->cam));
        if (dot(fn, ctx.view) < 0) fn = -fn;  // toward the viewer
        const Vec3 centroid = (1.0 / 3) * (fan[0]->cam + fan[1]->cam + fan[2]->cam);
        flat = shadeNow(fn, centroid);
      }
      // The screen triangles to draw (a fan of the clipped polygon), each with the method that
      // draws it: modified Gouraud may split one into parts, adaptive picks per triangle.
      parts.clear();
      splits.clear();
      splits.reserve(4 * fan.size());  // at most 4 parts per fan triangle: no reallocation below
      for (size_t k = 1; k + 1 < fan.size(); ++k) {
        const std::array<const PVertex*, 3> t{fan[0], fan[k], fan[k + 1]};
        if (opt.method == Method::ModifiedGouraud) {
          const auto subs = splitAtEdgeMaxima(
              {*t[0], *t[1], *t[2]}, ctx, opt.modified_threshold_lsb,
              [&](Vec3 n, Vec3 p) { return shadeNow(n, p); },
              [&](const PVertex& v) { return pixelCam(v.x - 0.5, v.y - 0.5, v.w); });
          if (subs.size() > 1) st.split_parts += subs.size();
          for (const auto& sub : subs) {
            splits.push_back(sub);
            parts.push_back({{&splits.back()[0], &splits.back()[1], &splits.back()[2]}, Method::Gouraud});
          }
        } else if (opt.method == Method::Adaptive) {
          parts.push_back({t, adaptiveChoice({*t[0], *t[1], *t[2]}, ctx, opt) ? Method::Gouraud : Method::Phong});
        } else {
          parts.push_back({t, opt.method});
        }
      }
      for (const Part& part : parts) {
        const Method m = part.method;
        const std::array<const PVertex*, 3>& tv = part.v;
        const bool colour_attrs_m =
            m == Method::Flat || m == Method::Gouraud || m == Method::GouraudClassical || m == Method::Biquadratic;
        const RasterConfig& rcm = colour_attrs_m ? rc_colour : rc_unit;
        std::array<SetupVertex, 3> sv;
        for (size_t i = 0; i < 3; ++i) {
          const PVertex& v = *tv[i];
          sv[i].x = v.x;
          sv[i].y = v.y;
          if (colour_attrs_m) {
            const std::array<double, 3> c = m == Method::Flat ? flat : v.colour;
            sv[i].attr = {std::clamp(c[0], 0.0, 255.0), std::clamp(c[1], 0.0, 255.0), std::clamp(c[2], 0.0, 255.0), v.w};
          } else {
            sv[i].attr = {v.n.x, v.n.y, v.n.z, v.w};
          }
        }
        const uint32_t tag = static_cast<uint32_t>(res.triangles.size());
        const SetupResult s = setupTriangle(sv, tag, rcm);
        if (!s.desc) {
          ++st.culled;
          continue;
        }
        ScreenTriangleInfo info;
        info.object = static_cast<int>(oi);
        info.mesh_triangle = static_cast<uint32_t>(ti);
        for (size_t i = 0; i < 3; ++i) info.xy[i] = {tv[i]->x, tv[i]->y};
        res.triangles.push_back(info);
        ++st.drawn;
        if (opt.method == Method::Adaptive) ++(m == Method::Gouraud ? st.adaptive_gouraud : st.adaptive_phong);

        // A fragment's colour is written at once, or (per-pixel device lobes) once the specular
        // unit has evaluated the triangle's batch of requests.
        const bool batched = !reference && direct == nullptr && isDeviceLobe(lobe) &&
                             (m == Method::Phong || m == Method::PhongIncremental || m == Method::PhongFixed ||
                              m == Method::NormalBisection);
        pend.clear();
        requests.clear();
        size_t memo_requests = 0;  // phong-fixed on the unit's model: requests its memo answered
        // A written fragment has w > 0 (the z-test), so depth 0 marks a pixel not yet covered.
        // Returns 1 for a pixel not covered before (for pixels_covered). A run's loop writes
        // through a local copy (const auto put = write): its pointers then stay in registers,
        // where the closure's members would be read again after each byte store.
        const auto write = [rgb = fb.rgb.data(), depth = fb.depth.data(), tri_of = fb.tri.data(),
                            tag = static_cast<int32_t>(tag)](size_t p, int64_t w, const std::array<uint8_t, 3>& c) {
          for (size_t k = 0; k < 3; ++k) rgb[p * 3 + k] = c[k];
          const uint64_t fresh = depth[p] == 0 ? 1 : 0;
          depth[p] = static_cast<int32_t>(w);
          tri_of[p] = tag;
          return fresh;
        };
        // The runs of a row in the vector kernel (fixed_simd.h): left to right, with depth codes
        // that fit int32_t (AttrBits <= 32).
        const SpanParams* walker = span.walker();
        const bool vector_runs = opt.vector_kernel && fixed_simd::available() && walker != nullptr && walker->AttrBits <= 32;
        const fixed_simd::Target target{fb.depth.data(), fb.tri.data(), static_cast<int32_t>(tag), static_cast<size_t>(W)};
        // Flat and Gouraud: z-test, then the interpolated colour codes straight to unorm8 (what
        // combine() gives them).
        auto colourFragment = [write, depth = fb.depth.data(), W, &covered = st.pixels_covered](int32_t x, int32_t y,
                                                                                                const int64_t* attr) {
          const size_t p = static_cast<size_t>(y) * static_cast<size_t>(W) + static_cast<size_t>(x);
          __builtin_prefetch(depth + p + W);  // the row below: most likely this triangle's next
          if (attr[3] <= depth[p]) return;
          covered += write(p, attr[3], {unorm8FromCode(attr[0], kColourFrac), unorm8FromCode(attr[1], kColourFrac),
                                        unorm8FromCode(attr[2], kColourFrac)});
        };
        // The same for a whole run of a row (walkSpanUnit's run consumer): the loop in
        // registers, the newly covered pixels counted once per run. When the colour codes at
        // both ends of the run lie in [0, 255 2^12] so do all between (they are affine), and
        // unorm8FromCode is the rounding shift alone.
        auto colourRun = [write, depth = fb.depth.data(), W, &covered = st.pixels_covered, vector_runs, &target,
                          rgb = fb.rgb.data()](const RowRun& r) {
          if (vector_runs && r.dx == 1) {
            fixed_simd::ColourRun run;
            run.px = {static_cast<size_t>(r.y) * static_cast<size_t>(W) + static_cast<size_t>(r.x0),
                      static_cast<size_t>(r.count), static_cast<uint32_t>(r.a0[3]), static_cast<uint32_t>(r.da[3])};
            for (size_t k = 0; k < 3; ++k) {
              run.c[k] = static_cast<int32_t>(r.a0[k]);
              run.dc[k] = static_cast<int32_t>(r.da[k]);
            }
            run.frac = kColourFrac;
            covered += fixed_simd::colourRun(run, target, rgb);
            return;
          }
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
          uint64_t newly = 0;
          auto loop = [&](auto clamp) {
            auto unorm8 = [](uint64_t c) {
              if constexpr (decltype(clamp)::value) return unorm8FromCode(static_cast<int64_t>(c), kColourFrac);
              else return static_cast<uint8_t>((c + (1u << (kColourFrac - 1))) >> kColourFrac);
            };
            RunCursor c(r, W);
            for (int64_t i = 0; i < count; ++i, c.next()) {
              __builtin_prefetch(depth + c.p + W);  // as colourFragment
              if (c.depth() > depth[c.p]) newly += put(c.p, c.depth(), {unorm8(a[0]), unorm8(a[1]), unorm8(a[2])});
              for (size_t k = 0; k < 3; ++k) a[k] += da[k];
            }
          };
          if (in_range) loop(std::false_type{});
          else loop(std::true_type{});
          covered += newly;
        };
        // phong-incremental, phong-fixed: |N|^2 along each run of consecutive pixels of a row
        // by the recurrence, restarted (three products) where the stream is not the next pixel.
        // The recurrence is exact, so the values do not depend on where it restarts.
        SquaredNormRecurrence sqn;
        int32_t run_y = -1, run_next_x = 0;
        const std::array<int64_t, 3> dn{s.plane.didx[0], s.plane.didx[1], s.plane.didx[2]};
        auto squaredNorm = [&](int32_t x, int32_t y, const int64_t* attr) {
          const uint64_t f = y == run_y && x == run_next_x ? sqn.next() : sqn.start({attr[0], attr[1], attr[2]}, dn);
          run_y = y;
          run_next_x = x + 1;
          return f;
        };
        // phong-fixed: the recurrence (before the z-test, as the hardware runs it on every
        // fragment), the z-test, the fixed-point datapath, write.
        auto fixedFragment = [&](int32_t x, int32_t y, const int64_t* attr) {
          const uint64_t sqnorm = squaredNorm(x, y, attr);
          const size_t p = static_cast<size_t>(y) * W + static_cast<size_t>(x);
          const int64_t wcode = attr[3];
          __builtin_prefetch(fb.depth.data() + p + W);  // as colourFragment
          if (wcode <= fb.depth[p]) return;
          const Vec3 pc = fixed->needsPosition() ? pixelCam(x, y, static_cast<double>(wcode) * kUnitLsb) : Vec3{};
          const size_t first = requests.size();
          const FixedShade fs = fixed->shade(attr, sqnorm, pc, &requests);
          if (batched) {
            std::array<double, 3> lsb{};  // exact: the codes are far below 2^53
            for (size_t k = 0; k < 3; ++k) lsb[k] = std::ldexp(static_cast<double>(fs.code[k]), -kFixedColourFrac);
            pend.push_back({p, wcode, lsb, first, requests.size() - first});
            return;
          }
          memo_requests += fs.device_requests;
          st.pixels_covered += write(p, wcode, fixedColour(fs));
        };
        // phong-fixed for a whole run: the recurrence and the dot products stepped along it
        // by the shader's run kernel, the same colours as fixedFragment's. The kernel is held by
        // value in the walker's run consumer (one copy per triangle), so that its constants stay
        // in registers across the stores of the pixels.
        auto fixedRun = [&](auto& kernel, const RowRun& r) {
          int32_t* const depth = fb.depth.data();
          const int64_t count = r.count;
          SquaredNormRecurrence run_sqn;
          uint64_t sqnorm = run_sqn.start({r.a0[0], r.a0[1], r.a0[2]}, {r.da[0], r.da[1], r.da[2]});
          RunCursor c(r, W);
          size_t requests_answered = 0;
          uint64_t newly = 0;
          const auto put = write;
          kernel.start(r.a0, r.da);
          for (int64_t i = 0;;) {
            __builtin_prefetch(depth + c.p + W);  // as colourFragment
            if (c.depth() > depth[c.p]) {
              const FixedShade fs = kernel.shade(sqnorm);
              requests_answered += fs.device_requests;
              newly += put(c.p, c.depth(), fixedColour(fs));
            }
            if (++i == count) break;
            sqnorm = run_sqn.next();
            kernel.step();
            c.next();
          }
          memo_requests += requests_answered;
          st.pixels_covered += newly;
        };
        // A run into the batch: z-tested, its depth codes written, its passing fragments'
        // squared norms and dot products buffered (fixed_simd::bufferRun). Other runs (see
        // vector_runs) take fixedRun.
        auto batchRun = [&](auto& kernel, const RowRun& r) {
          if (!vector_runs || r.dx != 1) {
            if (batch->n > 0) flushBatch(kernel);
            fixedRun(kernel, r);
            return;
          }
          kernel.start(r.a0, r.da);
          const auto sq = SquaredNormRecurrence::terms({r.a0[0], r.a0[1], r.a0[2]}, {r.da[0], r.da[1], r.da[2]});
          fixed_simd::Run run;
          run.px = {static_cast<size_t>(r.y) * static_cast<size_t>(W) + static_cast<size_t>(r.x0),
                    static_cast<size_t>(r.count), static_cast<uint32_t>(r.a0[3]), static_cast<uint32_t>(r.da[3])};
          run.a = sq.a;
          run.two_b = sq.two_b;
          run.c = sq.c;
          run.l = kernel.dotL();
          run.dl = kernel.stepL();
          run.h = kernel.dotH();
          run.dh = kernel.stepH();
          uint64_t newly = 0;
          for (size_t k = 0; (k = fixed_simd::bufferRun(run, k, target, *batch, newly)) < run.px.count;) flushBatch(kernel);
          st.pixels_covered += newly;
        };
        // biquadratic: the exactly shaded colours at the edge midpoints (screen space).
        std::array<std::array<double, 3>, 3> mid_colour{};
        if (m == Method::Biquadratic)
          for (size_t e = 0; e < 3; ++e) {
            PVertex mv = lerp(*tv[e], *tv[(e + 1) % 3], 0.5);
            mid_colour[e] = shadeNow(normalize(mv.n), pixelCam(mv.x - 0.5, mv.y - 0.5, mv.w));
          }
        // Barycentric coordinates of a pixel centre on the unsnapped screen triangle.
        auto barycentric = [&](int32_t x, int32_t y) {
          const double px = x + 0.5, py = y + 0.5;
          const double d = area2(*tv[0], *tv[1], *tv[2]);
          const double l1 = ((px - tv[0]->x) * (tv[2]->y - tv[0]->y) - (tv[2]->x - tv[0]->x) * (py - tv[0]->y)) / d;
          const double l2 = ((tv[1]->x - tv[0]->x) * (py - tv[0]->y) - (px - tv[0]->x) * (tv[1]->y - tv[0]->y)) / d;
          return std::array<double, 3>{1 - l1 - l2, l1, l2};
        };

        // One fragment: z-test against the triangles drawn before this one, shade, write.
        // (bisected: normal-bisection's normal of this fragment.)
        auto shadeFragment = [&](int32_t x, int32_t y, const int64_t* attr, const Vec3* bisected_n) {
          const uint64_t sqnorm = m == Method::PhongIncremental ? squaredNorm(x, y, attr) : 0;
          const size_t p = static_cast<size_t>(y) * W + static_cast<size_t>(x);
          const int64_t wcode = attr[3];
          if (wcode <= fb.depth[p]) return;
          std::array<double, 3> lsb{};
          switch (m) {
            case Method::Flat:
            case Method::Gouraud:
              colourFragment(x, y, attr);
              return;
            case Method::GouraudClassical: {
              // The classical loop: along both edges, then one division per raster line (float).
              const float yc = static_cast<float>(y) + 0.5f;
              float xl = 1e30f, xr = -1e30f;
              std::array<float, 3> cl{}, cr{};
              for (size_t e = 0; e < 3; ++e) {
                const PVertex& a = *tv[e];
                const PVertex& b = *tv[(e + 1) % 3];
                const float ya = static_cast<float>(a.y), yb = static_cast<float>(b.y);
                if ((yc < std::min(ya, yb)) || (yc > std::max(ya, yb)) || ya == yb) continue;
                const float t = (yc - ya) / (yb - ya);
                const float xe = static_cast<float>(a.x) + t * static_cast<float>(b.x - a.x);
                std::array<float, 3> ce{};
                for (size_t k = 0; k < 3; ++k)
                  ce[k] = static_cast<float>(std::clamp(a.colour[k], 0.0, 255.0)) +
                          t * static_cast<float>(std::clamp(b.colour[k], 0.0, 255.0) - std::clamp(a.colour[k], 0.0, 255.0));
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
              if (len > 0 && !row_divided[row]) {
                row_divided[row] = 1;
                divided_rows.push_back(y);
                ++st.divisions;
              }
              for (size_t k = 0; k < 3; ++k) {
                const float step = len > 0 ? (cr[k] - cl[k]) / len : 0.0f;
                lsb[k] = cl[k] + step * (static_cast<float>(x) + 0.5f - xl);
              }
              break;
            }
            case Method::Phong:
            case Method::PhongIncremental:
            case Method::NormalBisection: {
              const Vec3 nraw = rawNormal(attr);
              Vec3 n;
              if (m == Method::Phong) {
                n = normalize(nraw);
              } else if (m == Method::NormalBisection) {
                n = *bisected_n;
              } else {
                // |N|^2 from the recurrence (exact integers), then the fixed-point 1/sqrt.
                n = rsqrtFixed(sqnorm, 2 * kUnitFrac) * nraw;
              }
              const Vec3 pc = shader->needsPosition() ? pixelCam(x, y, static_cast<double>(wcode) * kUnitLsb) : Vec3{};
              const size_t first = requests.size();
              lsb = shader->shade(n, pc, &requests).lsb;
              const size_t count = requests.size() - first;
              if (batched) {
                pend.push_back({p, wcode, lsb, first, count});
                return;
              }
              if (count > 0) {  // the model's results now (the cycles are counted per triangle below)
                device_out.resize(count);
                for (size_t i = 0; i < count; ++i) {
                  const SpecRequest& r = requests[first + i];
                  device_out[i] = direct->evaluate(r.shin, r.cos, r.light).rgb;
                }
                st.pixels_covered += write(p, wcode, combine(lsb, device_out.data(), count));
                return;
              }
              break;
            }
            case Method::ModifiedGouraud:
            case Method::Adaptive:
              throw std::logic_error("render: split and adaptive triangles are drawn as gouraud or phong");
            case Method::PhongFixed: throw std::logic_error("render: phong-fixed fragments are drawn by fixedFragment");
            case Method::Biquadratic: {
              // The quadratic Lagrange basis: vertices c_i, edge midpoints c_ij (edge e = i..i+1).
              const auto l = barycentric(x, y);
              for (size_t k = 0; k < 3; ++k) {
                double v = 0;
                for (size_t i = 0; i < 3; ++i) v += std::clamp(tv[i]->colour[k], 0.0, 255.0) * l[i] * (2 * l[i] - 1);
                for (size_t e = 0; e < 3; ++e) v += 4 * mid_colour[e][k] * l[e] * l[(e + 1) % 3];
                lsb[k] = v;
              }
              break;
            }
            case Method::Reference: {
              const auto lb = barycentric(x, y);
              const double l0 = lb[0], l1 = lb[1], l2 = lb[2];
              const Vec3 n = normalize(l0 * tv[0]->n + l1 * tv[1]->n + l2 * tv[2]->n);
              const double w = l0 * tv[0]->w + l1 * tv[1]->w + l2 * tv[2]->w;
              const Vec3 pc = pixelCam(x, y, w);
              const Shade sh = ref_shader.shade(n, pc, nullptr);
              lsb = sh.lsb;
              const Shade dif = ref_diffuse.shade(n, pc, nullptr);
              for (size_t k = 0; k < 3; ++k) {
                fb.lsb[p * 3 + k] = sh.lsb[k];
                fb.spec_lsb[p * 3 + k] = sh.lsb[k] - dif.lsb[k];
              }
              break;
            }
          }
          st.pixels_covered += write(p, wcode, combine(lsb, nullptr, 0));
        };

        // The fragments: shaded as the model's walk produces them, or collected first (the
        // reference walks the same pixel set by direct edge evaluation; the RTL's stream;
        // normal-bisection needs whole rows).
        auto walkWith = [&](auto&& sink, auto&&... runs) {
          const SpanWalk wk = walkSpanUnit(*walker, *s.desc, sink, runs...);
          st.span_cycles += wk.cycles;
          st.fragments += wk.fragments;
        };
        if (!reference && walker != nullptr && (m == Method::Flat || m == Method::Gouraud)) {
          walkWith(colourFragment, colourRun);
        } else if (!reference && walker != nullptr && m == Method::PhongFixed) {
          // Runs where the shader takes them (directional lights; device lobes on the memo).
          if (batched || !fixed->takesRuns())
            walkWith(fixedFragment);
          else
            fixed->withRunKernel([&](auto& kernel) {
              if constexpr (std::decay_t<decltype(kernel)>::kGroups)
                if (opt.vector_kernel && kernel.vectorised()) {
                  walkWith(
                      [&](int32_t x, int32_t y, const int64_t* attr) {
                        if (batch->n > 0) flushBatch(kernel);
                        fixedFragment(x, y, attr);
                      },
                      [&batchRun, &kernel](const RowRun& r) { batchRun(kernel, r); });
                  return;
                }
              walkWith(fixedFragment, [&fixedRun, kernel](const RowRun& r) mutable { fixedRun(kernel, r); });
            });
        } else if (!reference && walker != nullptr && m != Method::NormalBisection) {
          walkWith([&](int32_t x, int32_t y, const int64_t* attr) { shadeFragment(x, y, attr, nullptr); });
        } else {
          frags.clear();
          if (reference) frags = rasterizeReference(s, rcm);
          else st.span_cycles += span.run(*s.desc, frags).cycles;
          st.fragments += frags.size();
          if (m == Method::NormalBisection) bisectNormals(frags, opt.bisection_threshold, order, bisected, st.normalisations);
          for (size_t fi = 0; fi < frags.size(); ++fi) {
            const SpanFragment& fr = frags[fi];
            if (m == Method::PhongFixed) fixedFragment(fr.x, fr.y, fr.attr.data());
            else shadeFragment(fr.x, fr.y, fr.attr.data(), m == Method::NormalBisection ? &bisected[fi] : nullptr);
          }
        }
        for (int32_t row : divided_rows) row_divided[static_cast<size_t>(row)] = 0;
        divided_rows.clear();
        if (!requests.empty() || memo_requests > 0) {
          const size_t n = requests.size() + memo_requests;
          st.spec_cycles += direct != nullptr ? batchCycles(n, direct->params().latency()) : spec->evaluate(requests, device_out);
          st.spec_evaluations += n;
        }
        for (const Pending& pd : pend)
          st.pixels_covered +=
              write(pd.pixel, pd.w, combine(pd.lsb, pd.dev_count ? &device_out[pd.dev_first] : nullptr, pd.dev_count));
      }
    }
    // The object's fragments still in the batch (phong-fixed's vector case: its kernel).
    if (batch->n > 0)
      fixed->withRunKernel([&](auto& kernel) {
        if constexpr (std::decay_t<decltype(kernel)>::kGroups) flushBatch(kernel);
      });
    if (batch->n > 0) throw std::logic_error("render: fragments left in the batch of another shader");
  }
  st.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace shd
