#include "cli/table_options.h"

#include <fmt/format.h>

#include "cli/command.h"
#include "cli/options.h"

namespace shd::cli {

void TableOptions::add(CLI::App& app) {
  app.add_option("--config", config, "configuration: " + configChoices("spec"))->default_val("default");
  app.add_option("--fit", fit,
                 "inflection | level | shortcut | minimax for the poly kind, exact for the other kinds "
                 "(default: the configuration's)")
      ->check(CLI::IsMember({"inflection", "level", "shortcut", "minimax", "exact"}));
  app.add_option("--level", level, "level q (degree 2) or Q (degree 3) of the level fit, in (0, 1)")
      ->check(realIn(0, 1, Ends::Open));
  app.add_option("--degree", degree, "2 (quadratic) or 3 (cubic)")->check(countIn(2, 3));
  auto* n_opt = app.add_option("--n", n, "shininess range lo:hi[:step], each in [1, 1000]");
  auto* list_opt = app.add_option("--n-list", n_list, "explicit shininess list, e.g. 8,32,200");
  n_opt->excludes(list_opt);
  app.add_option("--coef-format", coef_format, "coefficient format, e.g. uQ10.14 (degree 3: sQm.f)");
}

PromTable TableOptions::build(SpecUnitConfig& cfg_out, bool size_to_n) const {
  SpecUnitConfig cfg = specConfigArg("--config", config);
  PromContent content = cfg.prom;
  if (!fit.empty()) content.fit = fit;
  if (level) content.level = *level;
  if (n) content = PromContent{content.fit, content.level, *n, false};
  if (n_list) content = PromContent{content.fit, content.level, *n_list, true};
  PromRequest req;
  try {
    req = PromRequest::fromContent(content);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("{}: {}", n_list ? "--n-list" : (n ? "--n" : "--fit"), e.what()));
  }
  SpecUnitParams& p = cfg.rtl;
  if (degree != 0) p.Degree = degree;
  if (!coef_format.empty()) {
    FixedFormat f;
    try {
      f = FixedFormat::parse(coef_format);
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--coef-format: {}", e.what()));
    }
    if (f.is_signed != p.coefFormat().is_signed)
      throw ArgError(fmt::format("--coef-format {}: degree {} coefficients are {}; use {}Qm.f", coef_format, p.Degree,
                                 p.Degree == 3 ? "signed" : "unsigned (a >= 0)", p.Degree == 3 ? 's' : 'u'));
    p.CoefIntBits = f.int_bits;
    p.CoefFracBits = f.frac_bits;
  }
  // A table made without a configuration is as deep as its n list needs.
  if (size_to_n) p.ShinBits = addressBitsFor(req.n.values.size());
  try {
    p.validate();
  } catch (const std::invalid_argument& e) {
    throw ArgError(
        fmt::format("{}: {}", !coef_format.empty() ? "--coef-format " + coef_format : "--config " + config, e.what()));
  }
  try {
    PromTable t = buildPromTable(req, p);
    cfg_out = cfg;
    cfg_out.rtl = p;
    cfg_out.prom = content;
    return t;
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("{}: {}",
                               !coef_format.empty()
                                   ? "--coef-format " + coef_format
                                   : fmt::format("coefficient format {} of --config {} (choose one with --coef-format)",
                                                 p.coefFormat().str(), config),
                               e.what()));
  }
}

}  // namespace shd::cli
