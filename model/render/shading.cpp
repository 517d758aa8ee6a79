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

LightFactors lightFactors(const ShadeContext& ctx, const Material& m) {
  LightFactors f;
  const std::array<double, 3> base{m.colour.x, m.colour.y, m.colour.z};
  const std::array<double, 3> amb{ctx.ambient.x, ctx.ambient.y, ctx.ambient.z};
  for (size_t k = 0; k < 3; ++k) f.ambient[k] = 255.0 * amb[k] * base[k];
  for (const CameraLight& l : ctx.lights) {
    const std::array<double, 3> lc{l.colour.x, l.colour.y, l.colour.z};
    LightFactors::Light fl;
    fl.point = l.point;
    for (size_t k = 0; k < 3; ++k) {
      fl.diffuse[k] = 255.0 * m.kd * base[k] * lc[k];
      fl.specular[k] = 255.0 * m.ks * lc[k];
      fl.device[k] = deviceLightCode(m.ks * lc[k]);
    }
    f.lights.push_back(fl);
  }
  return f;
}

PointShader::PointShader(const ShadeContext& ctx, const Material& m, Lobe lobe, const DeviceCoding* coding)
    : ctx_(ctx), m_(m), lobe_(lobe), device_lobe_(isDeviceLobe(lobe)) {
  if (coding != nullptr) coding_ = *coding;
  const LightFactors f = lightFactors(ctx, m);
  ambient_ = f.ambient;
  for (const LightFactors::Light& l : f.lights) {
    needs_position_ = needs_position_ || l.point;
    lights_.push_back({l.diffuse, l.specular, l.device});
  }
}

Shade PointShader::shade(Vec3 n, Vec3 p_cam, std::vector<SpecRequest>* device) const {
  Shade s;
  s.lsb = ambient_;
  for (size_t li = 0; li < lights_.size(); ++li) {
    const CameraLight& l = ctx_.lights[li];
    const PerLight& pl = lights_[li];
    const Vec3 ld = lightDirection(l, p_cam);
    const double nl = dot(n, ld);
    if (nl <= 0) continue;  // the surface faces away from this light
    for (size_t k = 0; k < 3; ++k) s.lsb[k] += pl.diffuse[k] * nl;
    if (device_lobe_) {
      if (!coding_ || device == nullptr)
        throw std::logic_error("PointShader: a device lobe needs the specular unit's coding and a request list");
      const double nh = std::clamp(dot(n, l.point ? normalize(ld + ctx_.view) : l.half), 0.0, 1.0);
      // round(nh 2^F), half away from zero (lround) for nh >= 0, without libm: the scaling by
      // 2^F is exact, and so is the fraction x - trunc(x).
      const double x = nh * static_cast<double>(int64_t{1} << coding_->cos_frac_bits);
      SpecRequest r;
      r.cos = static_cast<uint32_t>(x);
      if (x - r.cos >= 0.5) ++r.cos;
      r.shin = coding_->shin;
      r.light = pl.device_light;
      device->push_back(r);
    } else {
      const double f = lobeValue(lobe_, m_, n, ld, ctx_.view, l.point ? normalize(ld + ctx_.view) : l.half);
      for (size_t k = 0; k < 3; ++k) s.lsb[k] += pl.specular[k] * f;
    }
  }
  return s;
}

}  // namespace shd
