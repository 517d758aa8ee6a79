// The verilated span and specular units as render engines (model/render/render.h), so that a
// scene rendered with the RTL in the loop can be compared pixel for pixel with the model's.
#pragma once

#include <memory>
#include <string>

#include "render/render.h"
#include "span_dut.h"
#include "spec_dut.h"

namespace shd {

// Each descriptor runs from IDLE to IDLE with the consumer always ready. The ports show the
// cycles and the fragments; the ROW/SPAN split of the cycles is internal (left 0).
class RtlSpanEngine final : public SpanEngine {
 public:
  explicit RtlSpanEngine(SpanMode mode);
  const SpanParams& params() const override { return dut_->params(); }
  SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override;

 private:
  std::unique_ptr<SpanDut> dut_;
  SpanOut out_;
};

// A batch streams through the pipeline with valid_i high on every cycle; the results are
// collected in order as valid_o rises. The PROM is written to `prom_path` (hex) and the words
// the simulator loaded are checked against the table.
class RtlSpecEngine final : public SpecEngine {
 public:
  RtlSpecEngine(const std::string& config, PromTable table, const std::string& prom_path);
  const PromTable& table() const override { return t_; }
  uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override;

 private:
  PromTable t_;
  std::unique_ptr<SpecDut> dut_;
};

}  // namespace shd
