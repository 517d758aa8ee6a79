// SpanRtlImpl<V>: the verilated SystemC model V of one span-unit configuration inside SpanRtl.
// Its handshake ports are bound to SpanRtl's; its data ports to signals of the types Verilator
// chose for this configuration, packed and unpacked field by field (a flattened Verilog vector
// [n*W +: W] is the field at bit n*W of width W, whatever the C++ type). Included only by the
// generated adapters (sc_span_<cfg>.cpp).
#pragma once

#include <string>
#include <type_traits>
#include <utility>

#include <verilated.h>

#include "span_rtl.h"
#include "harness/verilated_ports.h"

namespace shd {

namespace scpins {
// A bit field of a port value: integral types (bool, uint32_t, uint64_t) as in the C++ harness.
template <class T>
std::enable_if_t<std::is_integral_v<T>> put(T& v, int lsb, int width, uint64_t x) {
  ports::put(v, lsb, width, x);
}
template <class T>
std::enable_if_t<std::is_integral_v<T>, uint64_t> get(const T& v, int lsb, int width) {
  return ports::get(v, lsb, width);
}
// ... and sc_bv<N> for ports wider than 64 bits (fields are at most 64 bits wide).
template <int N>
void put(sc_dt::sc_bv<N>& v, int lsb, int width, uint64_t x) {
  v.range(lsb + width - 1, lsb) = static_cast<sc_dt::uint64>(x);
}
template <int N>
uint64_t get(const sc_dt::sc_bv<N>& v, int lsb, int width) {
  return v.range(lsb + width - 1, lsb).to_uint64();
}
}  // namespace scpins

template <class V>
class SpanRtlImpl final : public SpanRtl {
  template <class Port>
  using SignalFor = sc_core::sc_signal<typename std::remove_reference_t<Port>::data_type>;
#define SHD_SPAN_SIGNAL(port) SignalFor<decltype(std::declval<V&>().port)> port{#port};

 public:
  // name by value: it must live until dut_ is constructed, so that dut_ becomes our child.
  SpanRtlImpl(sc_core::sc_module_name name, std::string config, const SpanParams& p)
      : SpanRtl(name), config_(std::move(config)), p_(p), dut_("dut") {
    p_.validate();
    dut_.clk_i(clk_i);
    dut_.rst_ni(rst_ni);
    dut_.desc_valid_i(desc_valid_i);
    dut_.desc_ready_o(desc_ready_o);
    dut_.out_valid_o(out_valid_o);
    dut_.out_ready_i(out_ready_i);
    dut_.desc_tag_i(desc_tag_i);
    dut_.desc_row_first_i(desc_row_first_i);
    dut_.desc_row_last_i(desc_row_last_i);
    dut_.desc_xref_i(desc_xref_i);
    dut_.desc_iref_i(desc_iref_i);
    dut_.desc_didx_i(desc_didx_i);
    dut_.desc_didy_i(desc_didy_i);
    dut_.desc_interleave_i(desc_interleave_i);
    dut_.lt_row_first_i(lt_row_first_i);
    dut_.lt_row_last_i(lt_row_last_i);
    dut_.lt_clip_x0_i(lt_clip_x0_i);
    dut_.lt_clip_x1_i(lt_clip_x1_i);
    dut_.lt_ox_i(lt_ox_i);
    dut_.lt_oy_i(lt_oy_i);
    dut_.lt_flip_i(lt_flip_i);
    dut_.lt_aoff_i(lt_aoff_i);
    dut_.e_right_i(e_right_i);
    dut_.e_row_first_i(e_row_first_i);
    dut_.e_row_last_i(e_row_last_i);
    dut_.e_q_i(e_q_i);
    dut_.e_k_i(e_k_i);
    dut_.e_r_i(e_r_i);
    dut_.e_div_i(e_div_i);
    dut_.e_m_i(e_m_i);
    dut_.out_tag_o(out_tag_o);
    dut_.out_lane_valid_o(out_lane_valid_o);
    dut_.out_x_o(out_x_o);
    dut_.out_y_o(out_y_o);
    dut_.out_attr_o(out_attr_o);
  }

  const std::string& configName() const override { return config_; }
  const SpanParams& params() const override { return p_; }
  void traceFst(VerilatedFstC& tfp, int levels) override { dut_.trace(&tfp, levels); }
  void finalize() override { dut_.final(); }

  void driveDesc(const SpanDesc& d) override {
    using scpins::put;
    const int CB = p_.CoordBits, AB = p_.AttrBits, RB = p_.RemBits, K = p_.NumAttr;
    auto u = [](int64_t v) { return static_cast<uint64_t>(v); };
    write(desc_tag_i, [&](auto& v) { put(v, 0, p_.TagBits, d.tag); });
    write(desc_row_first_i, [&](auto& v) { put(v, 0, CB, u(d.row_first)); });
    write(desc_row_last_i, [&](auto& v) { put(v, 0, CB, u(d.row_last)); });
    write(desc_xref_i, [&](auto& v) { put(v, 0, CB, u(d.xref)); });
    auto attrs = [&](auto& sig, const auto& a) {
      write(sig, [&](auto& v) {
        for (int k = 0; k < K; ++k) put(v, k * AB, AB, u(a.at(static_cast<size_t>(k))));
      });
    };
    attrs(desc_iref_i, d.iref);
    attrs(desc_didx_i, d.didx);
    attrs(desc_didy_i, d.didy);
    write(desc_interleave_i, [&](auto& v) { put(v, 0, 1, d.interleave ? 1 : 0); });
    // One field per lane-triangle j (width CB, or 1 for flip; K*AB for aoff).
    auto perTri = [&](auto& sig, int width, auto field) {
      write(sig, [&](auto& v) {
        for (int j = 0; j < p_.NumTri; ++j) put(v, j * width, width, u(field(d.tri.at(static_cast<size_t>(j)))));
      });
    };
    perTri(lt_row_first_i, CB, [](const SpanLaneTri& t) { return t.row_first; });
    perTri(lt_row_last_i, CB, [](const SpanLaneTri& t) { return t.row_last; });
    perTri(lt_clip_x0_i, CB, [](const SpanLaneTri& t) { return t.clip_x0; });
    perTri(lt_clip_x1_i, CB, [](const SpanLaneTri& t) { return t.clip_x1; });
    perTri(lt_ox_i, CB, [](const SpanLaneTri& t) { return t.ox; });
    perTri(lt_oy_i, CB, [](const SpanLaneTri& t) { return t.oy; });
    perTri(lt_flip_i, 1, [](const SpanLaneTri& t) { return t.flip ? 1 : 0; });
    write(lt_aoff_i, [&](auto& v) {
      for (int j = 0; j < p_.NumTri; ++j)
        for (int k = 0; k < K; ++k)
          put(v, (j * K + k) * AB, AB, u(d.tri.at(static_cast<size_t>(j)).aoff.at(static_cast<size_t>(k))));
    });
    // One field per edge slot n = 3 j + s.
    auto perEdge = [&](auto& sig, int width, auto field) {
      write(sig, [&](auto& v) {
        for (int j = 0; j < p_.NumTri; ++j)
          for (int s = 0; s < 3; ++s) put(v, (3 * j + s) * width, width, u(field(d.tri.at(static_cast<size_t>(j)).edge[s])));
      });
    };
    perEdge(e_right_i, 1, [](const SpanEdge& e) { return e.right ? 1 : 0; });
    perEdge(e_row_first_i, CB, [](const SpanEdge& e) { return e.row_first; });
    perEdge(e_row_last_i, CB, [](const SpanEdge& e) { return e.row_last; });
    perEdge(e_q_i, CB, [](const SpanEdge& e) { return e.q; });
    perEdge(e_k_i, CB, [](const SpanEdge& e) { return e.k; });
    perEdge(e_r_i, RB, [](const SpanEdge& e) { return e.r; });
    perEdge(e_div_i, RB, [](const SpanEdge& e) { return e.div; });
    perEdge(e_m_i, RB, [](const SpanEdge& e) { return e.m; });
  }

  void sampleOutputs(SpanOut& o) const override {
    using scpins::get;
    o.desc_ready = desc_ready_o.read();
    o.out_valid = out_valid_o.read();
    o.tag = static_cast<uint32_t>(get(out_tag_o.read(), 0, p_.TagBits));
    const int L = p_.lanes(), PB = p_.PixBits, AB = p_.AttrBits, K = p_.NumAttr;
    o.lane.resize(static_cast<size_t>(L));
    const auto& lane_valid = out_lane_valid_o.read();
    const auto& xs = out_x_o.read();
    const auto& ys = out_y_o.read();
    const auto& attrs = out_attr_o.read();
    for (int l = 0; l < L; ++l) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(l)];
      lane.valid = get(lane_valid, l, 1) != 0;
      if (!lane.valid) continue;
      lane.x = static_cast<int32_t>(get(xs, l * PB, PB));
      lane.y = static_cast<int32_t>(get(ys, l * PB, PB));
      lane.attr.resize(static_cast<size_t>(K));
      for (int k = 0; k < K; ++k)
        lane.attr[static_cast<size_t>(k)] = ports::signExtend(get(attrs, (l * K + k) * AB, AB), AB);
    }
  }

 private:
  template <class Sig, class Fill>
  static void write(Sig& sig, Fill&& fill) {
    std::decay_t<decltype(sig.read())> v{};
    fill(v);
    sig.write(v);
  }

  std::string config_;
  SpanParams p_;
  V dut_;
  SHD_SPAN_SIGNAL(desc_tag_i)
  SHD_SPAN_SIGNAL(desc_row_first_i)
  SHD_SPAN_SIGNAL(desc_row_last_i)
  SHD_SPAN_SIGNAL(desc_xref_i)
  SHD_SPAN_SIGNAL(desc_iref_i)
  SHD_SPAN_SIGNAL(desc_didx_i)
  SHD_SPAN_SIGNAL(desc_didy_i)
  SHD_SPAN_SIGNAL(desc_interleave_i)
  SHD_SPAN_SIGNAL(lt_row_first_i)
  SHD_SPAN_SIGNAL(lt_row_last_i)
  SHD_SPAN_SIGNAL(lt_clip_x0_i)
  SHD_SPAN_SIGNAL(lt_clip_x1_i)
  SHD_SPAN_SIGNAL(lt_ox_i)
  SHD_SPAN_SIGNAL(lt_oy_i)
  SHD_SPAN_SIGNAL(lt_flip_i)
  SHD_SPAN_SIGNAL(lt_aoff_i)
  SHD_SPAN_SIGNAL(e_right_i)
  SHD_SPAN_SIGNAL(e_row_first_i)
  SHD_SPAN_SIGNAL(e_row_last_i)
  SHD_SPAN_SIGNAL(e_q_i)
  SHD_SPAN_SIGNAL(e_k_i)
  SHD_SPAN_SIGNAL(e_r_i)
  SHD_SPAN_SIGNAL(e_div_i)
  SHD_SPAN_SIGNAL(e_m_i)
  SHD_SPAN_SIGNAL(out_tag_o)
  SHD_SPAN_SIGNAL(out_lane_valid_o)
  SHD_SPAN_SIGNAL(out_x_o)
  SHD_SPAN_SIGNAL(out_y_o)
  SHD_SPAN_SIGNAL(out_attr_o)
#undef SHD_SPAN_SIGNAL
};

}  // namespace shd
