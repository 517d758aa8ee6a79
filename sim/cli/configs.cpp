// shadesim configs: the unit configurations built into this program (the registry,
// config/registry.h), with which of them have a verilated model.
#include <algorithm>
#include <cstdio>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "harness/span_dut.h"
#include "harness/spec_dut.h"

namespace shd::cli {

namespace {

class ConfigsCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--unit", unit_, "only this unit: spec or span")->check(CLI::IsMember({"spec", "span"}));
    app.add_flag("--json", json_, "print one JSON array: unit, name, file, verilated, rtl parameters, description");
  }

  int run(const CLI::App&) override {
    const std::vector<std::string> spec_built = rtlSpecConfigs(), span_built = rtlSpanConfigs();
    nlohmann::json all = nlohmann::json::array();
    for (const BuiltinConfig& b : builtinConfigs()) {
      if (!unit_.empty() && unit_ != b.unit) continue;
      const bool spec = std::string(b.unit) == "spec";
      const std::vector<std::string>& built = spec ? spec_built : span_built;
      const bool verilated = std::find(built.begin(), built.end(), b.name) != built.end();
      const nlohmann::json rtl = spec ? specConfig(b.name).rtl.toJson() : spanConfig(b.name).rtl.toJson();
      const std::string description = spec ? specConfig(b.name).description : spanConfig(b.name).description;
      if (json_) {
        all.push_back({{"unit", b.unit}, {"name", b.name}, {"file", b.file}, {"verilated", verilated},
                       {"rtl", rtl}, {"description", description}});
      } else {
        std::printf("%s %-12s %s%s\n", b.unit, b.name, b.file, verilated ? "" : "  (no verilated model)");
      }
    }
    if (json_) std::cout << all.dump(2) << "\n";
    return 0;
  }

 private:
  std::string unit_;
  bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> makeConfigsCmd() { return std::make_unique<ConfigsCmd>(); }

}  // namespace shd::cli
