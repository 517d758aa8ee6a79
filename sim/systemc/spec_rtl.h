// SpecRtl: one verilated SystemC configuration of rtl/shd_spec_unit.v (verilate(... SYSTEMC ...)),
// with the ports of the Verilog (1-bit ports bool, 2..32-bit ports uint32_t in every
// configuration), chosen by name at run time (makeSpecRtl).
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <systemc>

#include <verilated_fst_c.h>

#include "device/spec_unit.h"

namespace shd {

class SpecRtl : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk_i{"clk_i"}, rst_ni{"rst_ni"}, valid_i{"valid_i"};
  sc_core::sc_in<uint32_t> shin_i{"shin_i"}, cos_i{"cos_i"};
  sc_core::sc_in<uint32_t> light_r_i{"light_r_i"}, light_g_i{"light_g_i"}, light_b_i{"light_b_i"};
  sc_core::sc_out<bool> valid_o{"valid_o"};
  sc_core::sc_out<uint32_t> spec_o{"spec_o"}, spec_r_o{"spec_r_o"}, spec_g_o{"spec_g_o"}, spec_b_o{"spec_b_o"};

  virtual const std::string& configName() const = 0;
  // The parameters the model was verilated with (the configuration JSON at configure time).
  virtual const SpecUnitParams& params() const = 0;
  // The words the simulator loaded into the PROM (a public signal); valid once the model has
  // evaluated (after sc_start(SC_ZERO_TIME)).
  virtual std::vector<PromWord> romWords() const = 0;
  // The piecewise kind's segment ROM as loaded (empty for the other kinds).
  virtual std::vector<PromWord> segRomWords() const = 0;
  // All signals of the model into an FST file (opened after elaboration by the caller).
  virtual void traceFst(VerilatedFstC& tfp, int levels) = 0;
  virtual void finalize() = 0;  // final blocks

 protected:
  explicit SpecRtl(const sc_core::sc_module_name& name) : sc_module(name) {}
};

std::vector<std::string> scSpecRtlConfigs();
// std::invalid_argument naming the configuration and the ones built when it is unknown.
std::unique_ptr<SpecRtl> makeSpecRtl(const std::string& config, const char* name);

}  // namespace shd
