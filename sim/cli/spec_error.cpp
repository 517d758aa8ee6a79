// shadesim spec-error: the specular unit's approximation, datapath and total error
// (report/spec_error.h), the configuration's fit beside a second one.
#include <iostream>
#include <optional>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "cli/progress.h"
#include "cli/table_options.h"
#include "device/prom_io.h"
#include "report/spec_error.h"
#include "io/files.h"

namespace shd::cli {

namespace {

class SpecErrorCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    table_.add(app);
    app.add_option("--compare", compare_, "second fit shown beside the first: auto (minimax, or inflection when the "
                                          "first is minimax), none, or a fit name")
        ->check(CLI::IsMember({"auto", "none", "inflection", "level", "shortcut", "minimax"}));
    app.add_flag("--json", json_, "print one JSON object on stdout instead of the table");
    app.add_option("--json-out", json_out_, "also write the JSON object to this file");
    app.add_flag("--quiet", quiet_, "no progress on stderr");
  }

  int run(const CLI::App&) override {
    SpecUnitConfig cfg;
    const PromTable t = table_.build(cfg, false);
    if (!json_out_.empty()) outputTarget(json_out_);  // refused before the work, not after it
    Progress progress(fmt::format("spec-error {}", toString(t.request.fit)), !quiet_);
    auto prog = [&](size_t done, size_t total) {
      progress.update(static_cast<double>(done), static_cast<double>(total), "n");
    };
    const SpecErrorReport primary = computeSpecError(cfg.name, t, prog);
    std::optional<SpecErrorReport> second;
    std::string cmp = compare_;
    if (cmp == "auto")  // the other kinds have one content only
      cmp = t.unit.kind() != SpecKind::Poly ? "none" : t.request.fit == FitKind::Minimax ? "inflection" : "minimax";
    if (cmp != "none" && cmp != toString(t.request.fit)) {
      PromRequest req2 = t.request;
      req2.fit = parseFitKind(cmp);
      Progress p2(fmt::format("spec-error {}", cmp), !quiet_);
      try {
        second = computeSpecError(cfg.name, buildPromTable(req2, t.unit), [&](size_t d, size_t n) {
          p2.update(static_cast<double>(d), static_cast<double>(n), "n");
        });
      } catch (const std::invalid_argument& e) {
        throw ArgError(fmt::format("--compare {}: {}", cmp, e.what()));
      }
    }
    nlohmann::json j = toJson(primary);
    if (second) j["compare"] = toJson(*second);
    if (!json_out_.empty()) writeFileAtomic(json_out_, j.dump(2) + "\n");
    if (json_) std::cout << j.dump(2) << "\n";
    else std::cout << renderSpecErrorTable(primary, second ? &*second : nullptr, representativeN(t));
    return 0;
  }

 private:
  TableOptions table_;
  std::string compare_ = "auto", json_out_;
  bool json_ = false, quiet_ = false;
};

}  // namespace

std::unique_ptr<Command> makeSpecErrorCmd() { return std::make_unique<SpecErrorCmd>(); }

}  // namespace shd::cli
