// The verilated model of a configuration given as a whole (a registry name or a user's file).
#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>

#include "harness/span_dut.h"
#include "harness/spec_dut.h"

namespace shd {

namespace {

// The model of cfg's name exists and was verilated with cfg's parameters, or a message saying
// how to add one.
template <class Config>
void requireBuilt(const Config& cfg, const char* unit, const std::vector<std::string>& built,
                      const nlohmann::json& built_params) {
  const bool named = std::find(built.begin(), built.end(), cfg.name) != built.end();
  if (named && built_params == cfg.rtl.toJson()) return;
  const std::string why =
      named ? fmt::format("its parameters {} differ from the verilated '{}' unit's {}", cfg.rtl.toJson().dump(),
                          cfg.name, built_params.dump())
            : fmt::format("this build has no verilated {} unit of that name (built: {})", unit, fmt::join(built, ", "));
  throw std::invalid_argument(fmt::format(
      "configuration '{}' ({}): {}. To simulate its RTL, add the file to the registry as "
      "vectors/config/{}_<name>.json (or give its directory to cmake -DSHD_CONFIG_DIRS), rebuild and run "
      "scripts/regen_vectors.sh; everything that needs no RTL (prom, spec-error, vectors, render without --rtl) "
      "takes the file as it is",
      cfg.name, cfg.path, why, unit));
}

nlohmann::json builtParams(const std::vector<std::string>& built, const std::string& name, bool spec) {
  if (std::find(built.begin(), built.end(), name) == built.end()) return nullptr;
  return spec ? specConfig(name).rtl.toJson() : spanConfig(name).rtl.toJson();
}

}  // namespace

void requireVerilated(const SpecUnitConfig& cfg) {
  const std::vector<std::string> built = rtlSpecConfigs();
  requireBuilt(cfg, "spec", built, builtParams(built, cfg.name, true));
}

void requireVerilated(const SpanUnitConfig& cfg) {
  const std::vector<std::string> built = rtlSpanConfigs();
  requireBuilt(cfg, "span", built, builtParams(built, cfg.name, false));
}

std::unique_ptr<SpecDut> makeSpecDut(const SpecUnitConfig& cfg, const SpecDutOptions& opts) {
  requireVerilated(cfg);
  return makeSpecDut(cfg.name, opts);
}

std::unique_ptr<SpanDut> makeSpanDut(const SpanUnitConfig& cfg, const std::string& fst_path) {
  requireVerilated(cfg);
  return makeSpanDut(cfg.name, fst_path);
}

}  // namespace shd
