// SpecRtlImpl<V>: the verilated SystemC model V of one configuration inside SpecRtl, its ports
// bound straight to SpecRtl's. Included only by the generated adapters (sc_spec_<cfg>.cpp).
#pragma once

#include <string>
#include <utility>
#include <vector>

#include <verilated.h>

#include "spec_rtl.h"

namespace shd {

namespace detail {
inline PromWord promWordOf(uint64_t v) { return v; }
template <std::size_t N>
PromWord promWordOf(const VlWide<N>& w) {
  static_assert(N <= 4, "PROM words are at most 128 bits");
  PromWord r = 0;
  for (std::size_t i = 0; i < N; ++i) r |= static_cast<PromWord>(w[i]) << (32 * i);
  return r;
}
template <class T, std::size_t Depth>
std::vector<PromWord> romWordsOf(const VlUnpacked<T, Depth>& rom) {
  std::vector<PromWord> words;
  words.reserve(Depth);
  for (std::size_t i = 0; i < Depth; ++i) words.push_back(promWordOf(rom[i]));
  return words;
}
}  // namespace detail

template <class V>
class SpecRtlImpl final : public SpecRtl {
 public:
  // name by value: the sc_module_name must live until the model below is constructed, so that
  // it becomes a child of this module.
  SpecRtlImpl(sc_core::sc_module_name name, std::string config, const SpecUnitParams& p)
      : SpecRtl(name), config_(std::move(config)), p_(p), dut_("dut") {
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
    return detail::romWordsOf(dut_.rootp->shd_spec_unit__DOT__u_rom__DOT__rom);
  }
  void traceFst(VerilatedFstC& tfp, int levels) override { dut_.trace(&tfp, levels); }
  void finalize() override { dut_.final(); }

 private:
  std::string config_;
  SpecUnitParams p_;
  V dut_;
};

}  // namespace shd
