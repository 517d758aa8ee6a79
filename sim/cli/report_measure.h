// shadesim report, the measurement: every shading method with every lobe that applies, in every
// lane mode asked, by the golden model (and with --rtl by the verilated units), each image
// against the double-precision reference. The rows of report.json (docs/report.md).
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/registry.h"
#include "image/image.h"
#include "render/lobe_units.h"
#include "render/render.h"
#include "scene/scene.h"

namespace shd::cli {

// A lobe of the report: a brdf every material is rendered with, or "material": each material's
// own (RenderOptions::brdf ""); or the quadratic lobe evaluated by another specular unit (a
// table or schlick configuration standing in for the paper's device).
struct LobeGroup {
  std::string name;  // "material", the brdf, or "<unit>-unit"
  std::string brdf;  // "" for "material"
  std::string unit;  // the specular configuration of the quadratic lobe ("": ReportSetup::lobes')
};

struct ReportSetup {
  const Scene* scene = nullptr;
  std::vector<SpanUnitConfig> modes;  // the lane modes, the first the one whose image is kept
  LobeConfigs lobes;                  // the specular unit of each device lobe
  std::vector<std::string> alt_units;  // more specular units (registry names or files), each a lobe group
  size_t frames = 5;                  // the model's frames per row (the median is reported)
  bool rtl = false;                   // also with the verilated units (verilated: checked before)
  bool quiet = false;
  double highlight_lsb = 32, heat_scale = 8;  // as render's --highlight, --heat-scale
  std::filesystem::path tmp;          // the RTL engines' PROM files (removed after)
  std::string fail_dir = ".";         // where an RTL disagreement is saved
};

// One method and lobe: its two PNG files (encoded) and the thumbnail of the contact sheet (the
// image above its heat map, reduced).
struct CellImages {
  std::string image_file, heat_file;  // relative to the report's directory
  std::string image_png, heat_png;
  Image thumb;
};

struct Measured {
  std::vector<LobeGroup> groups;   // every lobe considered, in the report's order
  std::vector<Method> methods;     // every method, in the table's order
  nlohmann::json rows = nlohmann::json::array();     // one per method x lobe x mode rendered
  nlohmann::json skipped = nlohmann::json::array();  // {"method", "lobe", "why"}
  std::map<std::pair<size_t, size_t>, CellImages> images;  // by (group, method) index
  std::vector<std::string> spec_configs;  // the specular configurations some row uses
  std::vector<std::string> failures;      // a check that failed: images across modes, RTL
  std::vector<std::string> warnings;      // legal but probably not what was meant (no lights, ...)
  size_t mode_comparisons = 0;            // images compared with the first mode's
  size_t renders_total = 0, renders_done = 0;  // rows to render, rendered or refused (progress)
};

// The lobe group of an alternative unit: "<configuration name>-unit".
inline std::string unitLobeGroup(const std::string& config_name) { return config_name + "-unit"; }

// The lobes considered for the scene: "material" and every brdf name, in Lobe's order, then one
// per alternative unit (unitLobeGroup).
std::vector<LobeGroup> reportLobeGroups(const std::vector<std::string>& alt_units);

// Renders everything (stderr progress unless quiet). std::invalid_argument when no method and
// lobe of the scene can be rendered; the RTL engines' std::runtime_error on a disagreement.
Measured measureReport(const ReportSetup& s);

// The scene as rendered (camera, ambient, lights, materials, objects with their meshes and
// transforms), hashed (textHash): the same value for the same scene wherever it was read from.
std::string sceneContentHash(const Scene& sc);

}  // namespace shd::cli
