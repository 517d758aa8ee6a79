#include "render_rtl.h"

#include <stdexcept>

#include <fmt/format.h>

#include "device/prom_io.h"
#include "spec_cosim.h"

namespace shd {

RtlSpanEngine::RtlSpanEngine(SpanMode mode) : dut_(makeSpanDut(toString(mode), "")) { dut_->reset(); }

SpanWalk RtlSpanEngine::run(const SpanDesc& d, std::vector<SpanFragment>& out) {
  SpanWalk run;
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  in.out_ready = true;
  for (bool accepted = false;;) {
    dut_->tick(in, out_);
    ++run.cycles;
    if (!accepted) {
      if (!out_.desc_ready) throw std::logic_error("RtlSpanEngine: the span unit is not idle");
      accepted = true;
      in.desc_valid = false;
      continue;
    }
    for (const SpanLaneOut& l : out_.lane)
      if (l.valid) {
        out.push_back({out_.tag, l.x, l.y, l.attr});
        ++run.fragments;
      }
    if (out_.desc_ready) {  // back in IDLE: this cycle belongs to the next descriptor
      --run.cycles;
      break;
    }
  }
  return run;
}

RtlSpecEngine::RtlSpecEngine(const std::string& config, PromTable table, const std::string& prom_path)
    : t_(std::move(table)) {
  writeFileAtomic(prom_path, renderProm(t_, PromFormat::Hex));
  dut_ = makeSpecDut(config, SpecDutOptions{prom_path, ""});
  verifyLoadedProm(*dut_, t_.words, prom_path, t_.unit);
  dut_->reset();
}

uint64_t RtlSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.clear();
  out.reserve(in.size());
  uint64_t cycles = 0;
  size_t next = 0;
  const uint64_t limit = in.size() + static_cast<uint64_t>(t_.unit.latency()) + 2;
  while (out.size() < in.size()) {
    SpecIn v;
    if (next < in.size()) {
      v.valid = true;
      v.shin = in[next].shin;
      v.cos = in[next].cos;
      v.light = in[next].light;
      ++next;
    }
    const SpecOut o = dut_->tick(v);
    ++cycles;
    if (o.valid) out.push_back(o.rgb);
    if (cycles > limit) throw std::logic_error("RtlSpecEngine: results missing from the specular unit");
  }
  return cycles;
}

}  // namespace shd
