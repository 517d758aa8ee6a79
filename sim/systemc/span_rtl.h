// SpanRtl: one verilated SystemC configuration (mode) of rtl/shd_span_unit.v, chosen by name at
// run time (makeSpanRtl).
//
// The handshake ports are SystemC ports of fixed types. The descriptor and fragment ports change
// type with the configuration (Verilator maps 2..32 bits to uint32_t, 33..64 to uint64_t, wider
// to sc_bv<N>), so SpanRtl owns the signals bound to them and offers them through SpanPinsIf:
// driveDesc() writes a descriptor onto the input signals (visible from the next delta, like any
// signal write) and sampleOutputs() reads the output signals as they are now.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include <systemc>

#include <verilated_fst_c.h>

#include "raster/span_unit.h"

namespace shd {

class SpanPinsIf : public virtual sc_core::sc_interface {
 public:
  virtual const SpanParams& params() const = 0;
  // Packs d onto desc_*, lt_*, e_* (the valid/ready rule: it must stay until accepted).
  virtual void driveDesc(const SpanDesc& d) = 0;
  // desc_ready, out_valid, tag and every lane (pixel and attributes only on valid lanes), as
  // the output signals hold them now; reuses o's storage.
  virtual void sampleOutputs(SpanOut& o) const = 0;
};

class SpanRtl : public sc_core::sc_module, public SpanPinsIf {
 public:
  sc_core::sc_in<bool> clk_i{"clk_i"}, rst_ni{"rst_ni"};
  sc_core::sc_in<bool> desc_valid_i{"desc_valid_i"}, out_ready_i{"out_ready_i"};
  sc_core::sc_out<bool> desc_ready_o{"desc_ready_o"}, out_valid_o{"out_valid_o"};

  virtual const std::string& configName() const = 0;
  virtual void traceFst(VerilatedFstC& tfp, int levels) = 0;
  virtual void finalize() = 0;

 protected:
  explicit SpanRtl(const sc_core::sc_module_name& name) : sc_module(name) {}
};

std::vector<std::string> scSpanRtlConfigs();
std::unique_ptr<SpanRtl> makeSpanRtl(const std::string& config, const char* name);

}  // namespace shd
