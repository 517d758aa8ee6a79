// SpanDut: one verilated configuration (mode) of rtl/shd_span_unit.v behind a small interface.
// tick() drives the inputs, reads the outputs (functions of the registers, so they are the
// values of this cycle) and then clocks a rising edge: the contract of SpanUnitModel::tick().
// Valid/ready rule: a descriptor offered with desc_valid must not change until it is accepted.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "config/registry.h"
#include "raster/span_unit.h"

namespace shd {

class SpanDut {
 public:
  virtual ~SpanDut() = default;
  virtual const std::string& configName() const = 0;
  virtual const SpanParams& params() const = 0;
  virtual void reset() = 0;  // rst_ni low for two cycles, inputs idle
  virtual void tick(const SpanIn& in, SpanOut& out) = 0;  // reuses out's storage
  SpanOut tick(const SpanIn& in) {
    SpanOut out;
    tick(in, out);
    return out;
  }
  // tick() with the checker's comparison done on the ports (the co-simulation's hot path):
  // true when this cycle's outputs equal `expected` as compareSpanOutputs (span_cosim.h)
  // compares them: desc_ready, out_valid, the tag while out_valid, each lane's valid bit and,
  // on each lane valid in `expected`, the pixel and every attribute (also false when the lane
  // or attribute counts differ). When false, `out` holds this cycle's outputs as tick() gives
  // them, for compareSpanOutputs' message; when true, `out` is left as it was.
  virtual bool tickCheck(const SpanIn& in, const SpanOut& expected, SpanOut& out) = 0;
  virtual uint64_t cycle() const = 0;
  virtual void finish() = 0;
};

// Configurations built into this binary (one verilate() per registry file, config/registry.h).
std::vector<std::string> rtlSpanConfigs();
// config: a span configuration (lane mode) of the registry. fst_path "": no trace.
std::unique_ptr<SpanDut> makeSpanDut(const std::string& config, const std::string& fst_path);
// As for the specular unit (spec_dut.h): the model of cfg's name with cfg.rtl's parameters.
void requireVerilated(const SpanUnitConfig& cfg);
std::unique_ptr<SpanDut> makeSpanDut(const SpanUnitConfig& cfg, const std::string& fst_path);

}  // namespace shd
