#include "render/lobe_units.h"

#include <stdexcept>

#include <fmt/format.h>

#include "device/prom.h"

namespace shd {

SpecUnitConfig LobeConfigs::load(Lobe l) const {
  SpecUnitConfig c = specConfig(forLobe(l));
  const int degree = l == Lobe::Cubic ? 3 : 2;
  if (c.rtl.Degree != degree)
    throw std::invalid_argument(fmt::format("the {} lobe needs a degree-{} specular unit; configuration {} has Degree {}",
                                            toString(l), degree, forLobe(l), c.rtl.Degree));
  return c;
}

LobeEngines modelLobeEngines(const Scene& scene, const RenderOptions& opt, const LobeConfigs& configs) {
  LobeEngines e;
  for (Lobe l : deviceLobesUsed(scene, opt)) {
    const SpecUnitConfig cfg = configs.load(l);
    e.owned.push_back(std::make_unique<ModelSpecEngine>(buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl)));
    (l == Lobe::Cubic ? e.view.cubic : e.view.quadratic) = e.owned.back().get();
  }
  return e;
}

}  // namespace shd
