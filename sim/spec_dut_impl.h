// SpecDutImpl<V>: the Verilator harness of one configuration. Included only by the generated
// per-configuration adapters (spec_dut_<name>.cpp), which include V<prefix>.h and its root
// header first.
#pragma once

#include <memory>
#include <string>

#include <verilated.h>
#include <verilated_fst_c.h>

#include "spec_dut.h"

namespace shd {

// A PROM word as Verilator stores it: CData/SData/IData/QData, or VlWide for > 64 bits.
inline PromWord toPromWord(uint64_t v) { return v; }
template <std::size_t N>
PromWord toPromWord(const VlWide<N>& w) {
  static_assert(N <= 4, "PROM words are at most 128 bits");
  PromWord r = 0;
  for (std::size_t i = 0; i < N; ++i) r |= static_cast<PromWord>(w[i]) << (32 * i);
  return r;
}

template <class T, std::size_t Depth>
std::vector<PromWord> romWordsOf(const VlUnpacked<T, Depth>& rom) {
  std::vector<PromWord> words;
  words.reserve(Depth);
  for (std::size_t i = 0; i < Depth; ++i) words.push_back(toPromWord(rom[i]));
  return words;
}

template <class V>
class SpecDutImpl final : public SpecDut {
 public:
  SpecDutImpl(std::string name, const SpecDutOptions& opts) : name_(std::move(name)) {
    // Several models with their own contexts live in one process (a traced replay beside the
    // main run): Verilator 5.006 resolves plusargs, $fatal and even ~VerilatedScope through the
    // thread's current context, so each harness makes its own context current before it
    // evaluates or destroys its model (verilator issue #8265).
    ctx_ = std::make_unique<VerilatedContext>();
    Verilated::threadContextp(ctx_.get());
    const std::string plusarg = "+prom=" + opts.prom_path;
    const char* argv[] = {"shadesim", plusarg.c_str()};
    ctx_->commandArgs(2, argv);
    if (!opts.fst_path.empty()) ctx_->traceEverOn(true);  // before the model (TOOLCHAIN 4)
    dut_ = std::make_unique<V>(ctx_.get(), "dut");
    if (!opts.fst_path.empty()) {
      fst_ = std::make_unique<VerilatedFstC>();
      dut_->trace(fst_.get(), 99);
      fst_->open(opts.fst_path.c_str());
    }
    dut_->clk_i = 0;
    dut_->rst_ni = 1;
    dut_->valid_i = 0;
    dut_->eval();
    dump();
  }
  ~SpecDutImpl() override {
    finish();
    Verilated::threadContextp(ctx_.get());
    fst_.reset();
    dut_.reset();
  }

  const std::string& configName() const override { return name_; }

  void reset() override {
    dut_->rst_ni = 0;
    SpecIn idle;
    tick(idle);
    tick(idle);
    dut_->rst_ni = 1;
  }

  SpecOut tick(const SpecIn& in) override {
    Verilated::threadContextp(ctx_.get());
    dut_->valid_i = in.valid;
    dut_->shin_i = in.shin;
    dut_->cos_i = in.cos;
    dut_->light_r_i = in.light[0];
    dut_->light_g_i = in.light[1];
    dut_->light_b_i = in.light[2];
    dut_->clk_i = 0;
    dut_->eval();
    ctx_->timeInc(5);
    dump();
    dut_->clk_i = 1;
    dut_->eval();
    ctx_->timeInc(5);
    dump();
    ++cycle_;
    SpecOut out;
    out.valid = dut_->valid_o;
    out.spec = dut_->spec_o;
    out.rgb = {dut_->spec_r_o, dut_->spec_g_o, dut_->spec_b_o};
    return out;
  }

  std::vector<PromWord> romWords() override { return romWordsOf(dut_->rootp->shd_spec_unit__DOT__u_rom__DOT__rom); }

  uint64_t cycle() const override { return cycle_; }

  void finish() override {
    if (finished_) return;
    finished_ = true;
    Verilated::threadContextp(ctx_.get());
    dut_->final();
    if (fst_) fst_->close();
  }

 private:
  void dump() {
    if (fst_) fst_->dump(ctx_->time());
  }

  std::string name_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> dut_;
  std::unique_ptr<VerilatedFstC> fst_;
  uint64_t cycle_ = 0;
  bool finished_ = false;
};

}  // namespace shd
