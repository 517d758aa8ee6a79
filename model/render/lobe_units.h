// The specular units behind the device lobes (quadratic, cubic) of a render: which
// configuration each lobe uses, and the model's engines for the lobes a scene uses. The
// quadratic lobe is "(N.H)^n by the specular unit": the paper's degree-2 device by default, or a
// unit of another kind (table, schlick) standing in for it.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "config/registry.h"
#include "render/render.h"

namespace shd {

// A registry name or a JSON file per lobe; the quadratic lobe needs a degree-2 poly unit or a
// unit of another kind, the cubic a degree-3 poly one. The defaults are the registry's reference configurations of each degree.
struct LobeConfigs {
  std::string quadratic = "default";
  std::string cubic = "cubic";
  const std::string& forLobe(Lobe l) const { return l == Lobe::Cubic ? cubic : quadratic; }
  // The configuration of a device lobe, checked against its degree (std::invalid_argument).
  SpecUnitConfig load(Lobe l) const;
};

// The model's engine of a configuration: its PROM table and, with cos_code_min, the cosines it
// refuses (std::invalid_argument naming the configuration when the list does not have one code
// per PROM entry).
std::unique_ptr<ModelSpecEngine> modelSpecEngine(const SpecUnitConfig& cfg);
// The same with the configuration's PROM table already built (buildPromTable of its "prom" and
// "rtl"): for a caller that keeps the table of a configuration it makes engines of again.
std::unique_ptr<ModelSpecEngine> modelSpecEngine(const SpecUnitConfig& cfg, PromTable table);

// The model's engines (bit-exact specular units with their PROM tables) for the device lobes
// the scene uses with these options; `view` points into `owned`.
struct LobeEngines {
  std::vector<std::unique_ptr<SpecEngine>> owned;
  SpecEngines view;
};
LobeEngines modelLobeEngines(const Scene& scene, const RenderOptions& opt, const LobeConfigs& configs);

}  // namespace shd
