#include "render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <set>
#include <stdexcept>

#include <fmt/format.h>

#include "approx/brdf.h"
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
                                   {Method::Reference, "reference"}};

constexpr int kColourFrac = 12;  // colour attributes in LSBs: 0..255 with 12 fraction bits
constexpr int kUnitFrac = 28;    // normals and depth in [-1, 1]
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

// Sutherland-Hodgman against one half-plane dist(v) >= 0.
template <class Dist>
std::vector<PVertex> clipPolygon(const std::vector<PVertex>& in, Dist dist) {
  std::vector<PVertex> out;
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

}  // namespace

Method parseMethod(const std::string& s) {
  for (const MethodName& m : kMethods)
    if (s == m.name) return m.m;
  throw std::invalid_argument(fmt::format(
      "unknown method '{}' (expected flat, gouraud, gouraud-classical, phong, phong-incremental or reference)", s));
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

std::string specConfigForLobe(Lobe l) { return l == Lobe::Cubic ? "cubic" : "default"; }

uint64_t ModelSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.resize(in.size());
  for (size_t i = 0; i < in.size(); ++i) out[i] = unit_.evaluate(in[i].shin, in[i].cos, in[i].light).rgb;
  // Pipelined: the last of n results leaves latency - 1 cycles after the n-th input cycle.
  return in.empty() ? 0 : in.size() + static_cast<uint64_t>(unit_.params().latency()) - 1;
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
  const auto t0 = std::chrono::steady_clock::now();
  RenderResult res;
  RenderStats& st = res.stats;
  const Camera& cam = scene.camera;
  const int W = cam.width, H = cam.height;
  Framebuffer& fb = res.fb;
  fb.width = W;
  fb.height = H;
  fb.rgb.assign(static_cast<size_t>(W) * H * 3, 0);
  fb.depth.assign(static_cast<size_t>(W) * H, 0);
  fb.tri.assign(static_cast<size_t>(W) * H, -1);
  const bool reference = opt.method == Method::Reference;
  if (reference) {
    fb.lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
    fb.spec_lsb.assign(static_cast<size_t>(W) * H * 3, 0.0);
  }
  const CameraBasis basis = cameraBasis(cam);
  const ShadeContext ctx = makeShadeContext(scene);
  const double cx = 0.5 * W, cy = 0.5 * H, f = cam.px_per_unit;
  const bool colour_attrs = opt.method == Method::Flat || opt.method == Method::Gouraud ||
                            opt.method == Method::GouraudClassical;

  RasterConfig rc;
  rc.width = W;
  rc.height = H;
  rc.subpixel_bits = opt.subpixel_bits;
  rc.unit = span.params();
  if (rc.unit.NumAttr != 4) throw std::invalid_argument("render: the span unit must carry 4 attributes");
  rc.attr_frac_bits = colour_attrs ? std::vector<int>{kColourFrac, kColourFrac, kColourFrac, kUnitFrac}
                                   : std::vector<int>{kUnitFrac, kUnitFrac, kUnitFrac, kUnitFrac};
  rc.validate();

  // The coding of a device lobe's requests for its specular unit.
  auto codingFor = [](SpecEngine* e) {
    DeviceCoding c;
    if (e == nullptr) return c;
    c.cos_frac_bits = e->table().unit.CosFracBits;
    c.shin_code = [t = &e->table()](double n) {
      const int a = t->addressOf(std::round(n));
      if (a < 0)
        throw std::invalid_argument(
            fmt::format("shininess {} is not in the specular unit's PROM (n = {})", n, t->request.n.text));
      return static_cast<uint32_t>(a);
    };
    return c;
  };
  std::vector<std::array<uint32_t, 3>> device_out;
  SpecEngine* spec = nullptr;  // the current object's
  DeviceCoding coding;

  // A point's shade, with its device-lobe evaluations done by the specular unit right away
  // (vertices: few; pixels are batched per triangle below).
  auto shadeNow = [&](const Material& m, Lobe lobe, Vec3 n, Vec3 p) {
    Shade s = shadePoint(ctx, m, lobe, n, p, isDeviceLobe(lobe) ? &coding : nullptr);
    if (!s.device.empty()) {
      st.spec_cycles += spec->evaluate(s.device, device_out);
      st.spec_evaluations += s.device.size();
      for (const auto& d : device_out)
        for (size_t k = 0; k < 3; ++k) s.lsb[k] += d[k];
    }
    return s.lsb;
  };

  // Pixel centre -> camera space point of the surface, from w = z_near / Z.
  auto pixelCam = [&](double px, double py, double w) {
    const double Z = cam.z_near / w;
    return Vec3{(px + 0.5 - cx) * Z / f, -(py + 0.5 - cy) * Z / f, Z};
  };

  for (size_t oi = 0; oi < scene.objects.size(); ++oi) {
    const SceneObject& obj = scene.objects[oi];
    const Material& mat = scene.materials.at(static_cast<size_t>(obj.material));
    const Lobe lobe = parseLobe(opt.brdf.empty() ? mat.brdf : opt.brdf);
    spec = engines.forLobe(lobe);
    if (isDeviceLobe(lobe) && spec == nullptr && !reference)
      throw std::invalid_argument(fmt::format("object '{}': brdf {} needs the specular unit", obj.name, toString(lobe)));
    coding = codingFor(spec);
    // Object -> camera space, and the Gouraud vertex colours.
    std::vector<PVertex> verts(obj.mesh.positions.size());
    for (size_t i = 0; i < verts.size(); ++i) {
      PVertex& v = verts[i];
      v.cam = toCameraSpace(basis, cam, obj.transform.point(obj.mesh.positions[i]));
      v.n = normalize(toCameraDirection(basis, obj.transform.normal(obj.mesh.normals[i])));
    }
    if (opt.method == Method::Gouraud || opt.method == Method::GouraudClassical)
      for (PVertex& v : verts) v.colour = shadeNow(mat, lobe, v.n, v.cam);

    for (size_t ti = 0; ti < obj.mesh.triangles.size(); ++ti) {
      ++st.triangles;
      const auto& tri = obj.mesh.triangles[ti];
      std::vector<PVertex> poly{verts[tri[0]], verts[tri[1]], verts[tri[2]]};
      // Near plane, camera space.
      const bool all_in = std::all_of(poly.begin(), poly.end(), [&](const PVertex& v) { return v.cam.z >= cam.z_near; });
      if (!all_in) {
        poly = clipPolygon(poly, [&](const PVertex& v) { return v.cam.z - cam.z_near; });
        if (poly.size() < 3) {
          ++st.culled;
          continue;
        }
        ++st.clipped;
      }
      for (PVertex& v : poly) {
        v.x = cx + f * v.cam.x / v.cam.z;
        v.y = cy - f * v.cam.y / v.cam.z;
        v.w = cam.z_near / v.cam.z;
      }
      // Back faces: the idx3d front face has a negative screen area (y down), see sphere.h.
      if (!(area2(poly[0], poly[1], poly[2]) < 0)) {
        ++st.culled;
        continue;
      }
      // Guard band, screen space (attributes interpolate linearly there, as in the span unit).
      const bool in_guard = std::all_of(poly.begin(), poly.end(), [&](const PVertex& v) {
        return v.x >= -kGuard && v.x <= W + kGuard && v.y >= -kGuard && v.y <= H + kGuard;
      });
      if (!in_guard) {
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
      // Flat: one colour from the face normal at the centroid.
      std::array<double, 3> flat{};
      if (opt.method == Method::Flat) {
        Vec3 fn = normalize(cross(poly[1].cam - poly[0].cam, poly[2].cam - poly[0].cam));
        if (dot(fn, ctx.view) < 0) fn = -fn;  // toward the viewer
        const Vec3 centroid = (1.0 / 3) * (poly[0].cam + poly[1].cam + poly[2].cam);
        flat = shadeNow(mat, lobe, fn, centroid);
      }
      for (size_t k = 1; k + 1 < poly.size(); ++k) {  // fan
        const std::array<const PVertex*, 3> tv{&poly[0], &poly[k], &poly[k + 1]};
        std::array<SetupVertex, 3> sv;
        for (size_t i = 0; i < 3; ++i) {
          const PVertex& v = *tv[i];
          sv[i].x = v.x;
          sv[i].y = v.y;
          if (colour_attrs) {
            const std::array<double, 3> c = opt.method == Method::Flat ? flat : v.colour;
            sv[i].attr = {std::clamp(c[0], 0.0, 255.0), std::clamp(c[1], 0.0, 255.0), std::clamp(c[2], 0.0, 255.0), v.w};
          } else {
            sv[i].attr = {v.n.x, v.n.y, v.n.z, v.w};
          }
        }
        const uint32_t tag = static_cast<uint32_t>(res.triangles.size());
        SetupResult s = setupTriangle(sv, tag, rc);
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

        // Fragments: the reference walks the same pixel set by direct edge evaluation.
        std::vector<SpanFragment> frags;
        if (reference) {
          frags = rasterizeReference(s, rc);
        } else {
          SpanRun run = span.run(*s.desc);
          st.span_cycles += run.cycles;
          frags = std::move(run.fragments);
        }
        st.fragments += frags.size();

        // Z-test against the triangles drawn before this one.
        struct Pending {
          size_t pixel;
          int64_t w;
          std::array<double, 3> lsb;
          size_t dev_first, dev_count;
          double spec_lsb[3];
        };
        std::vector<Pending> pend;
        std::vector<SpecRequest> requests;
        // phong-incremental: |N|^2 of every fragment by the span recurrence, row by row in x
        // order (lane modes emit a row's pixels out of order).
        std::vector<uint64_t> sqnorm;
        if (opt.method == Method::PhongIncremental) {
          std::vector<size_t> order(frags.size());
          for (size_t i = 0; i < order.size(); ++i) order[i] = i;
          std::sort(order.begin(), order.end(), [&](size_t a, size_t b) {
            return frags[a].y != frags[b].y ? frags[a].y < frags[b].y : frags[a].x < frags[b].x;
          });
          sqnorm.assign(frags.size(), 0);
          const std::array<int64_t, 3> dn{s.plane.didx[0], s.plane.didx[1], s.plane.didx[2]};
          for (size_t i = 0; i < order.size();) {
            size_t j = i;
            while (j < order.size() && frags[order[j]].y == frags[order[i]].y) ++j;
            const SpanFragment& first = frags[order[i]];
            const auto f = squaredNormsAlongSpan({first.attr[0], first.attr[1], first.attr[2]}, dn, j - i);
            for (size_t k = i; k < j; ++k) sqnorm[order[k]] = f[k - i];
            i = j;
          }
        }
        size_t frag_index = 0;
        std::set<int32_t> divided_rows;  // gouraud-classical: rows that paid a division
        for (const SpanFragment& fr : frags) {
          const size_t fi = frag_index++;
          const size_t p = static_cast<size_t>(fr.y) * W + fr.x;
          const int64_t wcode = fr.attr[3];
          if (wcode <= fb.depth[p]) continue;
          Pending pd{p, wcode, {}, requests.size(), 0, {0, 0, 0}};
          switch (opt.method) {
            case Method::Flat:
            case Method::Gouraud:
              for (size_t k = 0; k < 3; ++k) pd.lsb[k] = std::ldexp(static_cast<double>(fr.attr[k]), -kColourFrac);
              break;
            case Method::GouraudClassical: {
              // The classical loop: along both edges, then one division per raster line (float).
              const float yc = static_cast<float>(fr.y) + 0.5f;
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
              if (len > 0 && divided_rows.insert(fr.y).second) ++st.divisions;
              for (size_t k = 0; k < 3; ++k) {
                const float step = len > 0 ? (cr[k] - cl[k]) / len : 0.0f;
                pd.lsb[k] = cl[k] + step * (static_cast<float>(fr.x) + 0.5f - xl);
              }
              break;
            }
            case Method::Phong:
            case Method::PhongIncremental: {
              const Vec3 nraw{std::ldexp(static_cast<double>(fr.attr[0]), -kUnitFrac),
                              std::ldexp(static_cast<double>(fr.attr[1]), -kUnitFrac),
                              std::ldexp(static_cast<double>(fr.attr[2]), -kUnitFrac)};
              Vec3 n;
              if (opt.method == Method::Phong) {
                n = normalize(nraw);
              } else {
                // |N|^2 from the recurrence (exact integers), then the fixed-point 1/sqrt.
                n = rsqrtFixed(sqnorm[fi], 2 * kUnitFrac) * nraw;
              }
              const Vec3 pc = pixelCam(fr.x, fr.y, std::ldexp(static_cast<double>(wcode), -kUnitFrac));
              Shade sh = shadePoint(ctx, mat, lobe, n, pc, isDeviceLobe(lobe) ? &coding : nullptr);
              pd.lsb = sh.lsb;
              pd.dev_count = sh.device.size();
              requests.insert(requests.end(), sh.device.begin(), sh.device.end());
              break;
            }
            case Method::Reference: {
              // Exact barycentrics of the pixel centre on the unsnapped screen triangle.
              const double px = fr.x + 0.5, py = fr.y + 0.5;
              const double d = area2(*tv[0], *tv[1], *tv[2]);
              const double l1 = ((px - tv[0]->x) * (tv[2]->y - tv[0]->y) - (tv[2]->x - tv[0]->x) * (py - tv[0]->y)) / d;
              const double l2 = ((tv[1]->x - tv[0]->x) * (py - tv[0]->y) - (px - tv[0]->x) * (tv[1]->y - tv[0]->y)) / d;
              const double l0 = 1 - l1 - l2;
              const Vec3 n = normalize(l0 * tv[0]->n + l1 * tv[1]->n + l2 * tv[2]->n);
              const double w = l0 * tv[0]->w + l1 * tv[1]->w + l2 * tv[2]->w;
              const Vec3 pc = pixelCam(fr.x, fr.y, w);
              const Lobe ref_lobe = isDeviceLobe(lobe) ? Lobe::Blinn : lobe;
              const Shade sh = shadePoint(ctx, mat, ref_lobe, n, pc, nullptr);
              pd.lsb = sh.lsb;
              // The specular part alone, for highlight masks.
              Material nospec = mat;
              nospec.ks = 0;
              const Shade dif = shadePoint(ctx, nospec, ref_lobe, n, pc, nullptr);
              for (size_t k = 0; k < 3; ++k) pd.spec_lsb[k] = sh.lsb[k] - dif.lsb[k];
              break;
            }
          }
          pend.push_back(pd);
        }
        if (!requests.empty()) {
          st.spec_cycles += spec->evaluate(requests, device_out);
          st.spec_evaluations += requests.size();
        }
        for (const Pending& pd : pend) {
          std::vector<std::array<uint32_t, 3>> dev(device_out.begin() + static_cast<long>(pd.dev_first),
                                                   device_out.begin() + static_cast<long>(pd.dev_first + pd.dev_count));
          const std::array<uint8_t, 3> c = combine(pd.lsb, dev);
          for (size_t k = 0; k < 3; ++k) fb.rgb[pd.pixel * 3 + k] = c[k];
          fb.depth[pd.pixel] = pd.w;
          fb.tri[pd.pixel] = static_cast<int32_t>(tag);
          if (reference)
            for (size_t k = 0; k < 3; ++k) {
              fb.lsb[pd.pixel * 3 + k] = pd.lsb[k];
              fb.spec_lsb[pd.pixel * 3 + k] = pd.spec_lsb[k];
            }
        }
      }
    }
  }
  for (int32_t t : fb.tri) st.pixels_covered += t >= 0 ? 1 : 0;
  st.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  return res;
}

}  // namespace shd
