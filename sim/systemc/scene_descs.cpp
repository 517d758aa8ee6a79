#include "scene_descs.h"

#include <memory>

#include "device/prom.h"
#include "render/render.h"
#include "scene/scene.h"

namespace shd {

namespace {

class RecordingSpanEngine final : public SpanEngine {
 public:
  explicit RecordingSpanEngine(SpanParams p) : model_(p) {}
  const SpanParams& params() const override { return model_.params(); }
  SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override {
    descs_.push_back(d);
    return model_.run(d, out);
  }
  std::vector<SpanDesc>& descs() { return descs_; }

 private:
  ModelSpanEngine model_;
  std::vector<SpanDesc> descs_;
};

}  // namespace

SceneDescriptors recordSceneDescriptors(const std::string& scene, const SpanParams& p) {
  const Scene sc = loadScene(scene);
  RenderOptions ro;
  ro.method = Method::Gouraud;
  ro.span_mode = p.mode();
  // Device lobes (quadratic, cubic) need a specular unit: the model's, as `shadesim render` builds it.
  std::vector<std::unique_ptr<SpecEngine>> owned;
  SpecEngines engines;
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    const SpecUnitConfig cfg = SpecUnitConfig::load(configPath(specConfigForLobe(l)));
    owned.push_back(std::make_unique<ModelSpecEngine>(buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl)));
    (l == Lobe::Cubic ? engines.cubic : engines.quadratic) = owned.back().get();
  }
  RecordingSpanEngine rec(p);
  const RenderResult r = render(sc, ro, rec, engines);
  SceneDescriptors out;
  out.descs = std::move(rec.descs());
  out.scene_triangles = r.stats.triangles;
  out.culled = r.stats.culled;
  out.frame_fragments = r.stats.fragments;
  out.frame_cycles = r.stats.span_cycles;
  return out;
}

}  // namespace shd
