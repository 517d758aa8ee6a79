// SpecDutImpl<V>: the Verilator harness of one configuration. Included only by the generated
// per-configuration adapters (spec_dut_<name>.cpp), which include V<prefix>.h and its root
// header first.
#pragma once

#include <memory>
#include <string>

#include <verilated.h>

#include "harness/spec_dut.h"
#include "harness/verilated_harness.h"
#include "harness/verilated_ports.h"

namespace shd {

// SegRom reads the segment ROM of a piecewise model (a generated function: the signal exists in
// those models only).
template <class V>
class SpecDutImpl final : public SpecDut {
 public:
  using SegRom = std::vector<PromWord> (*)(const V&);
  SpecDutImpl(std::string name, const SpecDutOptions& opts, SegRom seg_rom)
      : name_(std::move(name)), h_({"+prom=" + opts.prom_path}, opts.fst_path), seg_rom_(seg_rom) {
    h_.dut().valid_i = 0;
    h_.settle();
  }

  const std::string& configName() const override { return name_; }

  void reset() override {
    h_.dut().rst_ni = 0;
    SpecIn idle;
    tick(idle);
    tick(idle);
    h_.dut().rst_ni = 1;
  }

  SpecOut tick(const SpecIn& in) override {
    V& d = h_.dut();
    d.valid_i = in.valid;
    d.shin_i = in.shin;
    d.cos_i = in.cos;
    d.light_r_i = in.light[0];
    d.light_g_i = in.light[1];
    d.light_b_i = in.light[2];
    h_.fallingEdge();
    h_.risingEdge();
    SpecOut out;
    out.valid = d.valid_o;
    out.spec = d.spec_o;
    out.rgb = {d.spec_r_o, d.spec_g_o, d.spec_b_o};
    return out;
  }

  std::vector<PromWord> romWords() override { return ports::romWords(h_.dut().rootp->shd_spec_unit__DOT__u_rom__DOT__rom); }
  std::vector<PromWord> segRomWords() override { return seg_rom_(h_.dut()); }

  uint64_t cycle() const override { return h_.cycle(); }
  void finish() override { h_.finish(); }

 private:
  std::string name_;
  VerilatedHarness<V> h_;
  SegRom seg_rom_;
};

}  // namespace shd
