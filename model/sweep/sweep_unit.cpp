#include "sweep/sweep_unit.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

#include "sweep/phong_sweep.h"
#include "sweep/span_sweep.h"
#include "sweep/spec_sweep.h"

namespace shd {

namespace {

struct UnitEntry {
  const char* name;
  const char* what;  // for --help
  SweepUnit (*make)(const nlohmann::json& base);
};

// The units a sweep can vary: the one list.
const UnitEntry kUnits[] = {
    {"spec", "the specular unit (error over every input, latency, PROM bits, area)", specSweepUnit},
    {"span", "the span unit and triangle setup's widths (error against the exact plane, cycles, lanes, area)",
     spanSweepUnit},
    {"phong", "the widths of phong-fixed's datapath (error on the scenes, table and multiplier bits)", phongSweepUnit},
};

}  // namespace

std::vector<std::string> sweepUnitNames() {
  std::vector<std::string> names;
  for (const UnitEntry& u : kUnits) names.push_back(u.name);
  return names;
}

std::string sweepUnitHelp() {
  std::string help;
  for (const UnitEntry& u : kUnits) help += fmt::format("{}{}: {}", help.empty() ? "" : "; ", u.name, u.what);
  return help;
}

bool isSceneName(const std::string& name) {
  return !name.empty() && std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_';
  });
}

std::string sweepSceneFile(const std::string& name) {
  if (!isSceneName(name)) throw std::invalid_argument(fmt::format("scene \"{}\": a bundled scene's name (lower-case letters, digits, '_')", name));
  const std::string file = findShareFile("vectors/scenes/" + name + ".json");
  if (file.empty())
    throw std::invalid_argument(fmt::format("scene {}: no such file in vectors/scenes of this installation or the source tree", name));
  return file;
}

SweepUnit makeSweepUnit(const nlohmann::json& base) {
  const std::string name = base.at("unit").get<std::string>();
  for (const UnitEntry& u : kUnits)
    if (name == u.name) return u.make(base);
  throw std::invalid_argument(fmt::format("no sweep unit \"{}\"", name));
}

}  // namespace shd
