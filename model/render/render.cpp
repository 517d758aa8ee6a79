// render(): the frame, object by object and triangle by triangle. The geometry is
// render/pipeline.h's, the drawing of each screen triangle the method's unit's
// (render/methods.h, render/methods/*.cpp); what is left here is the order: per object its
// lighting and vertices, per mesh triangle culling, the vertex colours, clipping, the method's
// parts of the polygon, and per part the span unit's setup.
#include "render/render.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "render/draw.h"
#include "render/methods.h"
#include "render/pipeline.h"

namespace shd {

namespace {

// The coding of a device lobe's requests for the specular unit of a material.
DeviceCoding codingFor(SpecEngine* e, const Material& m) {
  DeviceCoding c;
  if (e == nullptr) return c;
  const PromTable& t = e->table();
  c.cos_frac_bits = t.unit.CosFracBits;
  const int a = t.addressOf(std::round(m.shininess));
  if (a < 0)
    throw std::invalid_argument(
        fmt::format("shininess {} is not in the specular unit's PROM (n = {})", m.shininess, t.request.n.text));
  c.shin = static_cast<uint32_t>(a);
  c.zero = e->zeroCode(c.shin);
  return c;
}

// The objects of a frame, drawn by the unit of the frame's method, with the buffers of the
// per-triangle work reused across the frame (no allocation per triangle once they have grown).
class SceneDrawer {
 public:
  SceneDrawer(Frame& f, const Scene& scene, const SpecEngines& engines, std::vector<ScreenTriangleInfo>& triangles);
  void drawObject(size_t oi);

 private:
  void lightObject(size_t oi);
  void lightVertices(const std::array<uint32_t, 3>& tri);
  void drawMeshTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti);
  void drawPart(const Part& part, uint32_t ti);

  Frame& f_;
  const Scene& scene_;
  const SpecEngines& engines_;
  std::vector<ScreenTriangleInfo>& triangles_;  // the result's: where each screen triangle came from
  const CameraBasis basis_;
  MethodUnit& unit_;                  // the frame's method's
  const bool vertex_colours_;         // the method's
  RasterConfig rc_colour_, rc_unit_;  // setup of colour or normal attributes (and depth)
  std::vector<PVertex> verts_;        // the object's
  std::vector<uint8_t> lit_;          // verts_[i].colour is computed
  Poly poly_;                         // a clipped triangle
  Fan fan_;                           // the polygon to draw
  Parts parts_;                       // its screen triangles
};

SceneDrawer::SceneDrawer(Frame& f, const Scene& scene, const SpecEngines& engines,
                         std::vector<ScreenTriangleInfo>& triangles)
    : f_(f),
      scene_(scene),
      engines_(engines),
      triangles_(triangles),
      basis_(cameraBasis(scene.camera)),
      unit_(f.unit(f.opt.method)),
      vertex_colours_(traits(f.opt.method).vertex_colours) {
  RasterConfig rc;
  rc.width = f.W;
  rc.height = f.H;
  rc.subpixel_bits = f.opt.subpixel_bits;
  rc.unit = f.span.params();
  if (rc.unit.NumAttr != 4) throw std::invalid_argument("render: the span unit must carry 4 attributes");
  rc.attr_frac_bits = {kColourFrac, kColourFrac, kColourFrac, kUnitFrac};
  rc.validate();
  rc_colour_ = rc_unit_ = rc;
  // The normal at phong-fixed's NormalFracBits when it runs at runtime widths; the depth as ever.
  const int normal_frac = f.opt.phong_widths ? f.opt.phong_widths->NormalFracBits : kUnitFrac;
  rc_unit_.attr_frac_bits = {normal_frac, normal_frac, normal_frac, kUnitFrac};
}

// The object's material, lobe and specular unit (Frame::obj).
void SceneDrawer::lightObject(size_t oi) {
  const SceneObject& obj = scene_.objects[oi];
  const Material& mat = scene_.materials.at(static_cast<size_t>(obj.material));
  ObjectShading& o = f_.obj;
  o.index = static_cast<int>(oi);
  o.material = &mat;
  o.lobe = parseLobe(f_.opt.brdf.empty() ? mat.brdf : f_.opt.brdf);
  o.spec = engines_.forLobe(o.lobe);
  if (isDeviceLobe(o.lobe) && o.spec == nullptr && !traits(f_.opt.method).exact)
    throw std::invalid_argument(fmt::format("object '{}': brdf {} needs the specular unit", obj.name, toString(o.lobe)));
  o.coding = codingFor(o.spec, mat);
  o.shader.emplace(f_.ctx, mat, o.lobe, &o.coding);
  o.direct = o.spec != nullptr ? o.spec->model() : nullptr;
}

void SceneDrawer::drawObject(size_t oi) {
  const SceneObject& obj = scene_.objects[oi];
  lightObject(oi);
  for (const auto& u : f_.units()) u.second->beginObject();
  transformVertices(obj, basis_, scene_.camera, f_.proj, verts_);
  lit_.assign(verts_.size(), 0);
  size_t ti = 0;
  try {
    for (; ti < obj.mesh.triangles.size(); ++ti) drawMeshTriangle(obj.mesh.triangles[ti], static_cast<uint32_t>(ti));
  } catch (const std::range_error& e) {
    throw std::range_error(fmt::format("{}: object '{}' triangle {}: {}", scene_.name, obj.name, ti, e.what()));
  }
  for (const auto& u : f_.units()) u.second->endObject();
}

// Gouraud vertex colours: computed when a triangle that is not culled first needs them.
void SceneDrawer::lightVertices(const std::array<uint32_t, 3>& tri) {
  for (const uint32_t i : tri)
    if (!lit_[i]) {
      verts_[i].colour = f_.shadeNow(verts_[i].n, verts_[i].cam);
      lit_[i] = 1;
    }
}

void SceneDrawer::drawMeshTriangle(const std::array<uint32_t, 3>& tri, uint32_t ti) {
  RenderStats& st = f_.st;
  ++st.triangles;
  const TriangleView tv = viewTriangle(verts_, tri, f_.proj.z_near);
  if (culledEarly(tv)) {
    ++st.culled_back;
    return;
  }
  if (vertex_colours_) lightVertices(tri);
  if (!clipToFan(tv, f_.proj, f_.W, f_.H, poly_, fan_, st)) return;
  // The screen triangles to draw (a fan of the polygon), each with the unit that draws it:
  // modified Gouraud may split one into parts, adaptive picks per triangle.
  parts_.clear();
  unit_.parts(fan_, parts_);
  const uint64_t drawn_before = st.drawn;
  for (const Part& part : parts_) drawPart(part, ti);
  if (st.drawn == drawn_before) ++st.culled_no_pixel;  // every part dropped by setup: nothing on screen
}

// A part through the span unit's setup (dropped: culled), recorded, and drawn by its unit.
void SceneDrawer::drawPart(const Part& part, uint32_t ti) {
  const bool colour_attrs = traits(part.method).attributes == Attributes::Colour;
  const RasterConfig& rc = colour_attrs ? rc_colour_ : rc_unit_;
  std::array<SetupVertex, 3> sv;
  for (size_t i = 0; i < 3; ++i) {
    const PVertex& v = *part.v[i];
    sv[i].x = v.x;
    sv[i].y = v.y;
    if (colour_attrs) {
      const std::array<double, 3>& c = part.colour != nullptr ? *part.colour : v.colour;
      sv[i].attr = {std::clamp(c[0], 0.0, 255.0), std::clamp(c[1], 0.0, 255.0), std::clamp(c[2], 0.0, 255.0), v.w};
    } else {
      sv[i].attr = {v.n.x, v.n.y, v.n.z, v.w};
    }
  }
  const uint32_t tag = static_cast<uint32_t>(triangles_.size());
  const SetupResult s = setupTriangle(sv, tag, rc);
  if (!s.desc) return;  // no pixel centre inside (drawMeshTriangle counts the triangle culled)
  ScreenTriangleInfo info;
  info.object = f_.obj.index;
  info.mesh_triangle = ti;
  for (size_t i = 0; i < 3; ++i) info.xy[i] = {part.v[i]->x, part.v[i]->y};
  triangles_.push_back(info);
  ++f_.st.drawn;
  f_.fb.markDrawn(std::min({sv[0].x, sv[1].x, sv[2].x}), std::min({sv[0].y, sv[1].y, sv[2].y}),
                  std::max({sv[0].x, sv[1].x, sv[2].x}), std::max({sv[0].y, sv[1].y, sv[2].y}));
  part.unit->draw(SpanTriangle{part.v, part.method, s, rc, tag});
}

}  // namespace


int64_t SpecEngine::zeroCode(uint32_t shin) {
  constexpr int64_t kUnknown = -2;
  const SpecUnitModel* m = model();
  if (m == nullptr) {
    if (!table_model_) {
      const PromTable& t = table();
      table_model_ = std::make_unique<SpecUnitModel>(t.unit, t.words, t.seg_words);
    }
    m = table_model_.get();
  }
  if (shin >= zero_.size()) zero_.resize(std::max<size_t>(shin + 1, m->prom().size()), kUnknown);
  if (zero_[shin] == kUnknown) zero_[shin] = m->zeroCode(shin);
  return zero_[shin];
}

uint64_t ModelSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.resize(in.size());
  for (size_t i = 0; i < in.size(); ++i) {
    unit_.checkCosine(in[i].shin, in[i].cos);
    out[i] = in[i].cos <= zeroCode(in[i].shin) ? std::array<uint32_t, 3>{} : unit_.evaluate(in[i].shin, in[i].cos, in[i].light).rgb;
  }
  return batchCycles(in.size(), unit_.params().latency());
}

std::vector<Lobe> deviceLobesUsed(const Scene& scene, const RenderOptions& opt) {
  std::vector<Lobe> used;
  if (traits(opt.method).exact) return used;  // the reference uses the exact lobes
  for (const SceneObject& o : scene.objects) {
    const Lobe l = parseLobe(opt.brdf.empty() ? scene.materials.at(static_cast<size_t>(o.material)).brdf : opt.brdf);
    if (isDeviceLobe(l) && std::find(used.begin(), used.end(), l) == used.end()) used.push_back(l);
  }
  return used;
}

Image frameImage(const Framebuffer& fb) {
  Image img(fb.width, fb.height);
  img.rgb = fb.rgb;
  return img;
}

PixelMask coveredPixels(const Framebuffer& fb) {
  PixelMask m(fb.width, fb.height);
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.covered(x, y)) m.set(x, y);
  return m;
}

ImageF exactImage(const Framebuffer& reference) {
  ImageF img(reference.width, reference.height);
  img.rgb = reference.lsb;
  for (double& v : img.rgb) v = std::clamp(v, 0.0, 255.0);
  return img;
}

RenderResult render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines) {
  RenderResult res;
  render(scene, opt, span, engines, res);
  return res;
}

void render(const Scene& scene, const RenderOptions& opt, SpanEngine& span, const SpecEngines& engines, RenderResult& res) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opt.phong_widths) {
    if (opt.method != Method::PhongFixed)
      throw std::invalid_argument(
          fmt::format("render: datapath widths apply to phong-fixed only, not to {}", toString(opt.method)));
    opt.phong_widths->validate();
  }
  res.stats = RenderStats{};
  res.triangles.clear();
  clearFramebuffer(res.fb, scene.camera.width, scene.camera.height, traits(opt.method).exact);
  Frame frame(scene, opt, span, res.fb, res.stats);
  SceneDrawer drawer(frame, scene, engines, res.triangles);
  span.beginFrame();
  for (size_t oi = 0; oi < scene.objects.size(); ++oi) drawer.drawObject(oi);
  span.endFrame();
  res.stats.ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

}  // namespace shd
