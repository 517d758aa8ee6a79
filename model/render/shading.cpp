#include "render/shading.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "approx/brdf.h"

namespace shd {

ShadeContext makeShadeContext(const Scene& s) {
  ShadeContext c;
  c.ambient = s.ambient;
  const CameraBasis b = cameraBasis(s.camera);
  for (const Light& l : s.lights) {
    CameraLight cl;
    cl.colour = l.colour;
    if (l.kind == Light::Kind::Directional) {
      cl.dir = normalize(toCameraDirection(b, l.direction));
      cl.half = normalize(cl.dir + c.view);
    } else {
      cl.point = true;
      cl.pos = toCameraSpace(b, s.camera, l.position);
    }
    c.lights.push_back(cl);
  }
  return c;
}

namespace {
struct LobeName {
  Lobe lobe;
  const char* name;
};
constexpr LobeName kLobes[] = {{Lobe::Phong, "phong"},       {Lobe::Blinn, "blinn"},
                               {Lobe::NormalizedBlinn, "normalized-blinn"}, {Lobe::Schlick, "schlick"},
                               {Lobe::Quadratic, "quadratic"}, {Lobe::Cubic, "cubic"},
                               {Lobe::CookTorrance, "cook-torrance"}, {Lobe::Pow, "pow"}};
}  // namespace

Lobe parseLobe(const std::string& s) {
  for (const LobeName& l : kLobes)
    if (s == l.name) return l.lobe;
  throw std::invalid_argument(fmt::format(
      "unknown brdf '{}' (expected phong, blinn, normalized-blinn, schlick, quadratic, cubic, cook-torrance or pow)", s));
}

const char* toString(Lobe lobe) {
  for (const LobeName& l : kLobes)
    if (lobe == l.lobe) return l.name;
  return "?";
}

bool isDeviceLobe(Lobe l) { return l == Lobe::Quadratic || l == Lobe::Cubic; }

Vec3 lightDirection(const CameraLight& l, Vec3 p_cam) {
  if (!l.point) return l.dir;
  const Vec3 d = l.pos - p_cam;
  const double len = length(d);
  return len > 0 ? (1.0 / len) * d : Vec3{0, 0, -1};
}

double lobeValue(Lobe lobe, const Material& m, Vec3 n, Vec3 l, Vec3 v) { return lobeValue(lobe, m, n, l, v, normalize(l + v)); }

double lobeValue(Lobe lobe, const Material& m, Vec3 n, Vec3 l, Vec3 v, Vec3 h) {
  const double nh = dot(n, h), nl = dot(n, l), nv = dot(n, v);
  switch (lobe) {
    case Lobe::Phong: {
      const Vec3 r = 2 * nl * n - l;  // reflection of L about N
      return phongLobe(dot(r, v), m.shininess);
    }
    case Lobe::Blinn:
    case Lobe::Pow: return blinnLobe(nh, m.shininess);
    case Lobe::NormalizedBlinn: return normalizedBlinn(nh, m.shininess);
    case Lobe::Schlick: return schlickLobe(std::max(0.0, nh), m.shininess);
    case Lobe::CookTorrance:
      return cookTorrance(nl, nv, nh, dot(v, h), CookTorranceParams{m.roughness, m.f0});
    case Lobe::Quadratic:
    case Lobe::Cubic: break;
  }
  throw std::logic_error("lobeValue: device lobes are evaluated by the specular unit");
}

Shade shadePoint(const ShadeContext& ctx, const Material& m, Lobe lobe, Vec3 n, Vec3 p_cam, const DeviceCoding* coding,
                 std::vector<SpecRequest>* device) {
  Shade s;
  for (int k = 0; k < 3; ++k) {
    const double base = k == 0 ? m.colour.x : (k == 1 ? m.colour.y : m.colour.z);
    const double amb = k == 0 ? ctx.ambient.x : (k == 1 ? ctx.ambient.y : ctx.ambient.z);
    s.lsb[static_cast<size_t>(k)] = 255.0 * amb * base;
  }
  for (const CameraLight& l : ctx.lights) {
    const Vec3 ld = lightDirection(l, p_cam);
    const double nl = dot(n, ld);
    if (nl <= 0) continue;  // the surface faces away from this light
    const std::array<double, 3> lc{l.colour.x, l.colour.y, l.colour.z};
    const std::array<double, 3> base{m.colour.x, m.colour.y, m.colour.z};
    for (size_t k = 0; k < 3; ++k) s.lsb[k] += 255.0 * m.kd * base[k] * lc[k] * nl;
    if (isDeviceLobe(lobe)) {
      if (coding == nullptr || device == nullptr)
        throw std::logic_error("shadePoint: a device lobe needs the specular unit's coding and a request list");
      const double nh = std::clamp(dot(n, l.point ? normalize(ld + ctx.view) : l.half), 0.0, 1.0);
      SpecRequest r;
      r.cos = static_cast<uint32_t>(std::lround(std::ldexp(nh, coding->cos_frac_bits)));
      r.shin = coding->shin;
      for (size_t k = 0; k < 3; ++k)
        r.light[k] = static_cast<uint32_t>(std::lround(255.0 * std::clamp(m.ks * lc[k], 0.0, 1.0)));
      device->push_back(r);
    } else {
      const double f = lobeValue(lobe, m, n, ld, ctx.view, l.point ? normalize(ld + ctx.view) : l.half);
      for (size_t k = 0; k < 3; ++k) s.lsb[k] += 255.0 * m.ks * lc[k] * f;
    }
  }
  return s;
}

std::array<uint8_t, 3> combine(const std::array<double, 3>& lsb, const std::array<uint32_t, 3>* device_rgb, size_t count) {
  std::array<uint8_t, 3> out{};
  for (size_t k = 0; k < 3; ++k) {
    // round(clamp(lsb, 0, 255)), half away from zero, without a libm call: the fraction of a
    // value in [0, 255] is exact in double.
    if (std::isnan(lsb[k])) throw std::logic_error("combine: a NaN colour (a shading bug)");
    const double c = std::clamp(lsb[k], 0.0, 255.0);
    uint32_t v = static_cast<uint32_t>(c);
    if (c - v >= 0.5) ++v;
    for (size_t i = 0; i < count; ++i) v += device_rgb[i][k];
    out[k] = static_cast<uint8_t>(std::min<uint32_t>(255, v));
  }
  return out;
}

}  // namespace shd
