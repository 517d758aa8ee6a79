#include "scene_descs.h"

#include <memory>

#include "render/lobe_units.h"
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
  // Device lobes (quadratic, cubic) need a specular unit: the model's, as `shadesim render` builds
  // it by default.
  const LobeEngines lobes = modelLobeEngines(sc, ro, LobeConfigs{});
  RecordingSpanEngine rec(p);
  const RenderResult r = render(sc, ro, rec, lobes.view);
  SceneDescriptors out;
  out.descs = std::move(rec.descs());
  out.scene_triangles = r.stats.triangles;
  out.culled = r.stats.culled();
  out.frame_fragments = r.stats.fragments;
  out.frame_cycles = r.stats.span_cycles;
  return out;
}

}  // namespace shd
