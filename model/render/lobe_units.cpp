#include "render/lobe_units.h"

#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "device/prom.h"

namespace shd {

SpecUnitConfig LobeConfigs::load(Lobe l) const {
  SpecUnitConfig c = specConfig(forLobe(l));
  const bool poly = c.rtl.kind() == SpecKind::Poly;
  if (l == Lobe::Cubic && !(poly && c.rtl.Degree == 3))
    throw std::invalid_argument(fmt::format("the cubic lobe needs a degree-3 poly specular unit; configuration {} {}",
                                            forLobe(l), poly ? fmt::format("has Degree {}", c.rtl.Degree)
                                                             : fmt::format("is of kind {}", specKindInfo(c.rtl.kind()).name)));
  if (l != Lobe::Cubic && poly && c.rtl.Degree != 2)
    throw std::invalid_argument(fmt::format(
        "the quadratic lobe needs a degree-2 poly unit or one of another kind; configuration {} has Degree {}",
        forLobe(l), c.rtl.Degree));
  return c;
}

std::unique_ptr<ModelSpecEngine> modelSpecEngine(const SpecUnitConfig& cfg) {
  return modelSpecEngine(cfg, buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl));
}

std::unique_ptr<ModelSpecEngine> modelSpecEngine(const SpecUnitConfig& cfg, PromTable table) {
  auto e = std::make_unique<ModelSpecEngine>(std::move(table));
  if (!cfg.cos_code_min.empty()) {
    if (cfg.cos_code_min.size() != e->table().entries.size())
      throw std::invalid_argument(fmt::format("configuration {}: inputs.cos_code_min has {} codes, its PROM {} entries",
                                              cfg.ref(), cfg.cos_code_min.size(), e->table().entries.size()));
    e->limitCosines(cfg.cos_code_min, "configuration " + cfg.ref());
  }
  return e;
}

LobeEngines modelLobeEngines(const Scene& scene, const RenderOptions& opt, const LobeConfigs& configs) {
  LobeEngines e;
  for (Lobe l : deviceLobesUsed(scene, opt)) {
    const SpecUnitConfig cfg = configs.load(l);
    e.owned.push_back(modelSpecEngine(cfg));
    e.view.set(l, e.owned.back().get());
  }
  return e;
}

}  // namespace shd
