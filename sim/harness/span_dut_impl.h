// SpanDutImpl<V>: the Verilator harness of one span-unit configuration. Included only by the
// generated per-configuration adapters (span_dut_<mode>.cpp), which include V<prefix>.h and its
// root class.
#pragma once

#include <memory>
#include <string>

#include "raster/span_walk.h"
#include "harness/span_dut.h"
#include "harness/verilated_harness.h"
#include "harness/verilated_ports.h"

namespace shd {

// P::get(): the configuration's parameters, a constant expression, so that the positions of
// the fields in the ports are constants.
template <class V, class P>
class SpanDutImpl final : public SpanDut {
  static constexpr SpanParams kP = P::get();
  static constexpr int kLanes = kP.NumTri * kP.LanesPerTri;

 public:
  SpanDutImpl(std::string name, const std::string& fst_path) : name_(std::move(name)), h_({}, fst_path) {
    h_.dut().desc_valid_i = 0;
    h_.dut().out_ready_i = 0;
    h_.settle();
  }

  const std::string& configName() const override { return name_; }
  const SpanParams& params() const override { return kP; }
  uint64_t cycle() const override { return h_.cycle(); }

  void reset() override {
    h_.dut().rst_ni = 0;
    setInputs(SpanIn{});
    for (int i = 0; i < 2; ++i) {
      h_.fallingEdge();
      h_.risingEdge();
    }
    h_.dut().rst_ni = 1;
  }

  // The outputs are functions of the registers: read before the cycle's edges, they are this
  // cycle's values (VerilatedHarness::cycle()).
  using SpanDut::tick;
  void tick(const SpanIn& in, SpanOut& out) override {
    setInputs(in);
    sample(out);
    endCycle(in);
  }

  bool tickCheck(const SpanIn& in, const SpanOut& expected, SpanOut& out) override {
    setInputs(in);
    const bool same = matches(expected);
    if (!same) sample(out);
    endCycle(in);
    return same;
  }

  void finish() override { h_.finish(); }

 private:
  void setInputs(const SpanIn& in) {
    h_.dut().desc_valid_i = in.desc_valid;
    h_.dut().out_ready_i = in.out_ready;
    // valid/ready: an offered descriptor stays unchanged until it is accepted, so the ports are
    // packed once per offer, not on every cycle it waits.
    if (!in.desc_valid) driven_ = false;
    else if (!driven_ && in.desc != nullptr) {
      drive(*in.desc);
      driven_ = true;
    }
  }

  void endCycle(const SpanIn& in) {
    if (in.desc_valid && h_.dut().desc_ready_o) driven_ = false;  // accepted at this edge
    h_.cycle();
  }

  void drive(const SpanDesc& d) {
    using ports::put;
    span_detail::checkDescriptor(kP, d);  // the ports below read NumAttr codes and NumTri lane-triangles
    constexpr int CB = kP.CoordBits, AB = kP.AttrBits, RB = kP.RemBits, K = kP.NumAttr;
    put(h_.dut().desc_tag_i, 0, kP.TagBits, d.tag);
    put(h_.dut().desc_row_first_i, 0, CB, static_cast<uint64_t>(d.row_first));
    put(h_.dut().desc_row_last_i, 0, CB, static_cast<uint64_t>(d.row_last));
    put(h_.dut().desc_xref_i, 0, CB, static_cast<uint64_t>(d.xref));
    for (int a = 0; a < K; ++a) {
      const size_t ai = static_cast<size_t>(a);
      put(h_.dut().desc_iref_i, a * AB, AB, static_cast<uint64_t>(d.iref[ai]));
      put(h_.dut().desc_didx_i, a * AB, AB, static_cast<uint64_t>(d.didx[ai]));
      put(h_.dut().desc_didy_i, a * AB, AB, static_cast<uint64_t>(d.didy[ai]));
    }
    h_.dut().desc_interleave_i = d.interleave ? 1 : 0;
    for (int j = 0; j < kP.NumTri; ++j) {
      const SpanLaneTri& t = d.tri[static_cast<size_t>(j)];
      put(h_.dut().lt_row_first_i, j * CB, CB, static_cast<uint64_t>(t.row_first));
      put(h_.dut().lt_row_last_i, j * CB, CB, static_cast<uint64_t>(t.row_last));
      put(h_.dut().lt_clip_x0_i, j * CB, CB, static_cast<uint64_t>(t.clip_x0));
      put(h_.dut().lt_clip_x1_i, j * CB, CB, static_cast<uint64_t>(t.clip_x1));
      put(h_.dut().lt_ox_i, j * CB, CB, static_cast<uint64_t>(t.ox));
      put(h_.dut().lt_oy_i, j * CB, CB, static_cast<uint64_t>(t.oy));
      put(h_.dut().lt_flip_i, j, 1, t.flip ? 1 : 0);
      for (int a = 0; a < K; ++a)
        put(h_.dut().lt_aoff_i, (j * K + a) * AB, AB, static_cast<uint64_t>(t.aoff[static_cast<size_t>(a)]));
      for (int s = 0; s < 3; ++s) {
        const SpanEdge& e = t.edge[s];
        const int n = j * 3 + s;
        put(h_.dut().e_right_i, n, 1, e.right ? 1 : 0);
        put(h_.dut().e_row_first_i, n * CB, CB, static_cast<uint64_t>(e.row_first));
        put(h_.dut().e_row_last_i, n * CB, CB, static_cast<uint64_t>(e.row_last));
        put(h_.dut().e_q_i, n * CB, CB, static_cast<uint64_t>(e.q));
        put(h_.dut().e_k_i, n * CB, CB, static_cast<uint64_t>(e.k));
        put(h_.dut().e_r_i, n * RB, RB, static_cast<uint64_t>(e.r));
        put(h_.dut().e_div_i, n * RB, RB, static_cast<uint64_t>(e.div));
        put(h_.dut().e_m_i, n * RB, RB, static_cast<uint64_t>(e.m));
      }
    }
  }

  // This cycle's outputs against `e`, field for field as compareSpanOutputs compares them, read
  // straight from the ports (no SpanOut is filled).
  bool matches(const SpanOut& e) const {
    using ports::get;
    const V& d = h_.dut();
    if (static_cast<bool>(d.desc_ready_o) != e.desc_ready || static_cast<bool>(d.out_valid_o) != e.out_valid)
      return false;
    if (e.out_valid && static_cast<uint32_t>(get(d.out_tag_o, 0, kP.TagBits)) != e.tag) return false;
    constexpr int L = kLanes, PB = kP.PixBits, AB = kP.AttrBits, K = kP.NumAttr;
    if (e.lane.size() != static_cast<size_t>(L)) return false;
    const uint64_t valid = get(d.out_lane_valid_o, 0, L);
    for (int l = 0; l < L; ++l) {
      const SpanLaneOut& el = e.lane[static_cast<size_t>(l)];
      if (((valid >> l) & 1) != uint64_t{el.valid}) return false;
      if (!el.valid) continue;
      if (static_cast<int32_t>(get(d.out_x_o, l * PB, PB)) != el.x ||
          static_cast<int32_t>(get(d.out_y_o, l * PB, PB)) != el.y || el.attr.size() != static_cast<size_t>(K))
        return false;
      for (int a = 0; a < K; ++a)
        if (ports::signExtend(get(d.out_attr_o, (l * K + a) * AB, AB), AB) != el.attr[static_cast<size_t>(a)])
          return false;
    }
    return true;
  }

  void sample(SpanOut& o) const {
    using ports::get;
    o.desc_ready = h_.dut().desc_ready_o;
    o.out_valid = h_.dut().out_valid_o;
    o.tag = static_cast<uint32_t>(get(h_.dut().out_tag_o, 0, kP.TagBits));
    constexpr int L = kLanes, PB = kP.PixBits, AB = kP.AttrBits, K = kP.NumAttr;
    o.lane.resize(static_cast<size_t>(L));
    for (int l = 0; l < L; ++l) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(l)];
      lane.valid = get(h_.dut().out_lane_valid_o, l, 1) != 0;
      if (!lane.valid) continue;
      lane.x = static_cast<int32_t>(get(h_.dut().out_x_o, l * PB, PB));
      lane.y = static_cast<int32_t>(get(h_.dut().out_y_o, l * PB, PB));
      lane.attr.resize(static_cast<size_t>(K));
      for (int a = 0; a < K; ++a)
        lane.attr[static_cast<size_t>(a)] = ports::signExtend(get(h_.dut().out_attr_o, (l * K + a) * AB, AB), AB);
    }
  }

  std::string name_;
  VerilatedHarness<V> h_;
  bool driven_ = false;  // the offered descriptor is on the ports
};

}  // namespace shd
