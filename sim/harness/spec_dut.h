// SpecDut: one verilated configuration of rtl/shd_spec_unit.v behind a small interface, so the
// scoreboard, the tests and the CLI pick a configuration by name at run time.
// Clocking: tick() drives the inputs, then a falling and a rising clock edge, and returns the
// registered outputs after the rising edge: the same contract as SpecUnitModel::tick().
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "config/registry.h"
#include "device/spec_unit.h"

namespace shd {

struct SpecDutOptions {
  std::string prom_path;  // absolute path of the $readmemh file, passed as +prom=<path>
  std::string fst_path;   // empty: no waveform
};

class SpecDut {
 public:
  virtual ~SpecDut() = default;
  virtual const std::string& configName() const = 0;
  // rst_ni low for two cycles with valid_i = 0, then high.
  virtual void reset() = 0;
  virtual SpecOut tick(const SpecIn& in) = 0;
  // The words the simulator loaded into the PROM (read through a public signal).
  virtual std::vector<PromWord> romWords() = 0;
  // The piecewise kind's segment ROM as loaded (empty for the other kinds).
  virtual std::vector<PromWord> segRomWords() = 0;
  virtual uint64_t cycle() const = 0;
  // Runs final blocks and closes the waveform. Called by the destructor too.
  virtual void finish() = 0;
};

// Configurations built into this binary (one verilate() per registry file, config/registry.h).
std::vector<std::string> rtlSpecConfigs();
// std::invalid_argument naming the configuration and the ones available when it is unknown.
std::unique_ptr<SpecDut> makeSpecDut(const std::string& config, const SpecDutOptions& opts);
// The verilated model of `cfg` is the one of its name, whose parameters must be cfg.rtl:
// std::invalid_argument saying how to add a model when the build has none (a user's file).
void requireVerilated(const SpecUnitConfig& cfg);
std::unique_ptr<SpecDut> makeSpecDut(const SpecUnitConfig& cfg, const SpecDutOptions& opts);

}  // namespace shd
