// SpanDutImpl<V>: the Verilator harness of one span-unit configuration. Included only by the
// generated per-configuration adapters (span_dut_<mode>.cpp).
#pragma once

#include <memory>
#include <string>

#include <verilated.h>
#include <verilated_fst_c.h>

#include "span_dut.h"
#include "verilated_ports.h"

namespace shd {

template <class V>
class SpanDutImpl final : public SpanDut {
 public:
  SpanDutImpl(std::string name, SpanParams p, const std::string& fst_path) : name_(std::move(name)), p_(p) {
    ctx_ = std::make_unique<VerilatedContext>();
    Verilated::threadContextp(ctx_.get());  // see spec_dut_impl.h (verilator issue #8265)
    if (!fst_path.empty()) ctx_->traceEverOn(true);
    dut_ = std::make_unique<V>(ctx_.get(), "dut");
    if (!fst_path.empty()) {
      fst_ = std::make_unique<VerilatedFstC>();
      dut_->trace(fst_.get(), 99);
      fst_->open(fst_path.c_str());
    }
    dut_->clk_i = 0;
    dut_->rst_ni = 1;
    dut_->desc_valid_i = 0;
    dut_->out_ready_i = 0;
    dut_->eval();
  }
  ~SpanDutImpl() override {
    finish();
    Verilated::threadContextp(ctx_.get());
    fst_.reset();
    dut_.reset();
  }

  const std::string& configName() const override { return name_; }
  const SpanParams& params() const override { return p_; }
  uint64_t cycle() const override { return cycle_; }

  void reset() override {
    dut_->rst_ni = 0;
    tick(SpanIn{});
    tick(SpanIn{});
    dut_->rst_ni = 1;
  }

  using SpanDut::tick;
  void tick(const SpanIn& in, SpanOut& out) override {
    Verilated::threadContextp(ctx_.get());
    dut_->desc_valid_i = in.desc_valid;
    dut_->out_ready_i = in.out_ready;
    // valid/ready: an offered descriptor stays unchanged until it is accepted, so the ports are
    // packed once per offer, not on every cycle it waits.
    if (!in.desc_valid) driven_ = false;
    else if (!driven_ && in.desc != nullptr) {
      drive(*in.desc);
      driven_ = true;
    }
    dut_->clk_i = 0;
    dut_->eval();
    ctx_->timeInc(5);
    if (fst_) fst_->dump(ctx_->time());
    sample(out);
    if (in.desc_valid && out.desc_ready) driven_ = false;  // accepted at this edge
    dut_->clk_i = 1;
    dut_->eval();
    ctx_->timeInc(5);
    if (fst_) fst_->dump(ctx_->time());
    ++cycle_;
  }

  void finish() override {
    if (finished_) return;
    finished_ = true;
    Verilated::threadContextp(ctx_.get());
    dut_->final();
    if (fst_) fst_->close();
  }

 private:
  void drive(const SpanDesc& d) {
    using ports::put;
    const int CB = p_.CoordBits, AB = p_.AttrBits, RB = p_.RemBits, K = p_.NumAttr;
    put(dut_->desc_tag_i, 0, p_.TagBits, d.tag);
    put(dut_->desc_row_first_i, 0, CB, static_cast<uint64_t>(d.row_first));
    put(dut_->desc_row_last_i, 0, CB, static_cast<uint64_t>(d.row_last));
    put(dut_->desc_xref_i, 0, CB, static_cast<uint64_t>(d.xref));
    for (int a = 0; a < K; ++a) {
      const size_t ai = static_cast<size_t>(a);
      put(dut_->desc_iref_i, a * AB, AB, static_cast<uint64_t>(d.iref[ai]));
      put(dut_->desc_didx_i, a * AB, AB, static_cast<uint64_t>(d.didx[ai]));
      put(dut_->desc_didy_i, a * AB, AB, static_cast<uint64_t>(d.didy[ai]));
    }
    for (int j = 0; j < p_.NumTri; ++j) {
      const SpanLaneTri& t = d.tri[static_cast<size_t>(j)];
      put(dut_->lt_row_first_i, j * CB, CB, static_cast<uint64_t>(t.row_first));
      put(dut_->lt_row_last_i, j * CB, CB, static_cast<uint64_t>(t.row_last));
      put(dut_->lt_clip_x0_i, j * CB, CB, static_cast<uint64_t>(t.clip_x0));
      put(dut_->lt_clip_x1_i, j * CB, CB, static_cast<uint64_t>(t.clip_x1));
      put(dut_->lt_ox_i, j * CB, CB, static_cast<uint64_t>(t.ox));
      put(dut_->lt_oy_i, j * CB, CB, static_cast<uint64_t>(t.oy));
      put(dut_->lt_flip_i, j, 1, t.flip ? 1 : 0);
      for (int a = 0; a < K; ++a)
        put(dut_->lt_aoff_i, (j * K + a) * AB, AB, static_cast<uint64_t>(t.aoff[static_cast<size_t>(a)]));
      for (int s = 0; s < 3; ++s) {
        const SpanEdge& e = t.edge[s];
        const int n = j * 3 + s;
        put(dut_->e_right_i, n, 1, e.right ? 1 : 0);
        put(dut_->e_row_first_i, n * CB, CB, static_cast<uint64_t>(e.row_first));
        put(dut_->e_row_last_i, n * CB, CB, static_cast<uint64_t>(e.row_last));
        put(dut_->e_q_i, n * CB, CB, static_cast<uint64_t>(e.q));
        put(dut_->e_k_i, n * CB, CB, static_cast<uint64_t>(e.k));
        put(dut_->e_r_i, n * RB, RB, static_cast<uint64_t>(e.r));
        put(dut_->e_div_i, n * RB, RB, static_cast<uint64_t>(e.div));
        put(dut_->e_m_i, n * RB, RB, static_cast<uint64_t>(e.m));
      }
    }
  }

  void sample(SpanOut& o) const {
    using ports::get;
    o.desc_ready = dut_->desc_ready_o;
    o.out_valid = dut_->out_valid_o;
    o.tag = static_cast<uint32_t>(get(dut_->out_tag_o, 0, p_.TagBits));
    const int L = p_.lanes(), PB = p_.PixBits, AB = p_.AttrBits, K = p_.NumAttr;
    o.lane.resize(static_cast<size_t>(L));
    for (int l = 0; l < L; ++l) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(l)];
      lane.valid = get(dut_->out_lane_valid_o, l, 1) != 0;
      if (!lane.valid) continue;
      lane.x = static_cast<int32_t>(get(dut_->out_x_o, l * PB, PB));
      lane.y = static_cast<int32_t>(get(dut_->out_y_o, l * PB, PB));
      lane.attr.resize(static_cast<size_t>(K));
      for (int a = 0; a < K; ++a)
        lane.attr[static_cast<size_t>(a)] = ports::signExtend(get(dut_->out_attr_o, (l * K + a) * AB, AB), AB);
    }
  }

  std::string name_;
  SpanParams p_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<V> dut_;
  std::unique_ptr<VerilatedFstC> fst_;
  uint64_t cycle_ = 0;
  bool finished_ = false;
  bool driven_ = false;  // the offered descriptor is on the ports
};

}  // namespace shd
