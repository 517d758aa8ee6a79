// The options that choose a PROM's contents, shared by prom, cosim and spec-error: a
// configuration and the overrides of its fit, shininess list and coefficient format.
#pragma once

#include <optional>
#include <string>

#include <CLI/CLI.hpp>

#include "config/registry.h"
#include "device/prom.h"

namespace shd::cli {

struct TableOptions {
  std::string config = "default";
  std::string fit, coef_format;
  std::optional<std::string> n, n_list;  // given (even empty: an error) or not
  std::optional<double> level;
  int degree = 0;  // 0: the configuration's

  void add(CLI::App& app);

  // The unit parameters and the table request after applying the overrides. With size_to_n the
  // PROM is as deep as the n list needs (a table made without naming a configuration);
  // otherwise it keeps the configuration's ShinBits. Errors are ArgError naming the option.
  PromTable build(SpecUnitConfig& cfg_out, bool size_to_n) const;
};

}  // namespace shd::cli
