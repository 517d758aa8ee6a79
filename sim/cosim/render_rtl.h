// The verilated span and specular units as render engines (model/render/render.h), so that a
// scene rendered with the RTL in the loop can be compared pixel for pixel with the model's.
#pragma once

#include <memory>
#include <optional>
#include <string>

#include "render/render.h"
#include "harness/span_dut.h"
#include "harness/spec_dut.h"

namespace shd {

// Each descriptor runs alone, from idle to idle, with the consumer always ready: the ports show the
// fragments, and the paper's unit's cycles; the ROW/SPAN split of the cycles is internal (left 0).
// The full-rate unit's cycles are the descriptor's share of the frame's stream (SpanEngine), as
// the model's walk counts them. A second verilated instance then takes the frame's descriptors back
// to back, each offered from the cycle after the one before was accepted, its outputs compared
// with a second cycle-by-cycle model on every cycle; endFrame() checks that it took the stream's
// cycles. A difference there throws std::runtime_error naming the cycle and the descriptor.
// The cycle-accurate model ticks beside the RTL and every output is compared on every cycle. On
// the first difference the triangle is saved alone, from reset, as a vector file
// <fail_dir>/render_span_<config>_fail.vec with the model's expected outputs, replayed into an FST
// beside it, and run() throws std::runtime_error naming the triangle, the cycle, both values
// and the files. (model_params: fault injection for the tests, a model of another layout.)
class RtlSpanEngine final : public SpanEngine {
 public:
  // config: a span configuration (lane mode) verilated into this build.
  explicit RtlSpanEngine(const SpanUnitConfig& config, std::string fail_dir = ".",
                         std::optional<SpanParams> model_params = {});
  const SpanParams& params() const override { return dut_->params(); }
  SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override;
  void beginFrame() override;
  void endFrame() override;

 private:
  // The full-rate unit's stream instance: one cycle, offering the descriptor not yet taken.
  void streamTick();

  std::string mode_, fail_dir_;
  std::unique_ptr<SpanDut> dut_;
  SpanUnitModel model_;
  SpanOut out_, expected_;
  std::unique_ptr<SpanDut> stream_dut_;  // the full-rate unit only
  SpanUnitModel stream_model_;
  SpanOut stream_out_, stream_expected_;
  std::optional<SpanDesc> stream_offered_;  // run() offers each descriptor until it is taken
  uint64_t stream_descs_ = 0;  // descriptors of the frame accepted by the stream instance
};

// A batch streams through the pipeline with valid_i high on every cycle; the results are
// collected in order as valid_o rises. The PROM is written to `prom_path` (hex) and the words
// the simulator loaded are checked against the table. Every result is compared with the
// model's; on the first difference the request is saved alone, from reset, as
// <fail_dir>/render_spec_<config>_fail.vec (with a copy of the PROM beside it), replayed into an
// FST, and evaluate() throws std::runtime_error naming the request, both values and the files.
// (model_words: fault injection for the tests, the model's PROM words.)
class RtlSpecEngine final : public SpecEngine {
 public:
  // config: verilated into this build; table: its PROM (table.unit must be config.rtl).
  RtlSpecEngine(const SpecUnitConfig& config, PromTable table, const std::string& prom_path, std::string fail_dir = ".",
                std::optional<std::vector<PromWord>> model_words = {});
  const PromTable& table() const override { return t_; }
  uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override;

 private:
  std::string config_, fail_dir_;
  PromTable t_;
  std::unique_ptr<SpecDut> dut_;
  SpecUnitModel model_;
};

}  // namespace shd
