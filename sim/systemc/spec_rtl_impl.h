// SpecRtlImpl<V>: the verilated SystemC model V of one configuration inside SpecRtl, its ports
// bound straight to SpecRtl's. Included only by the generated adapters (sc_spec_<cfg>.cpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <verilated.h>

#include "spec_rtl.h"
#include "harness/verilated_ports.h"

namespace shd {

// SegRom reads the segment ROM of a piecewise model (a generated function: the signal exists in
// those models only).
template <class V>
class SpecRtlImpl final : public SpecRtl {
 public:
  using SegRom = std::vector<PromWord> (*)(const V&);
  // name by value: the sc_module_name must live until the model below is constructed, so that
  // it becomes a child of this module.
  SpecRtlImpl(sc_core::sc_module_name name, std::string config, const SpecUnitParams& p, SegRom seg_rom)
      : SpecRtl(name), config_(std::move(config)), p_(p), seg_rom_(seg_rom), dut_("dut") {
    dut_.clk_i(clk_i);
    dut_.rst_ni(rst_ni);
    dut_.valid_i(valid_i);
    dut_.shin_i(shin_i);
    dut_.cos_i(cos_i);
    dut_.light_r_i(light_r_i);
    dut_.light_g_i(light_g_i);
    dut_.light_b_i(light_b_i);
    dut_.valid_o(valid_o);
    dut_.spec_o(spec_o);
    dut_.spec_r_o(spec_r_o);
    dut_.spec_g_o(spec_g_o);
    dut_.spec_b_o(spec_b_o);
  }

  const std::string& configName() const override { return config_; }
  const SpecUnitParams& params() const override { return p_; }
  std::vector<PromWord> romWords() const override {
    return ports::romWords(dut_.rootp->shd_spec_unit__DOT__u_rom__DOT__rom);
  }
  std::vector<PromWord> segRomWords() const override { return seg_rom_(dut_); }
  void traceFst(VerilatedFstC& tfp, int levels) override { dut_.trace(&tfp, levels); }
  void finalize() override { dut_.final(); }

 private:
  std::string config_;
  SpecUnitParams p_;
  SegRom seg_rom_;
  V dut_;
};

}  // namespace shd
