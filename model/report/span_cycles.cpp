#include "report/span_cycles.h"

#include <algorithm>
#include <chrono>
#include <map>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "raster/soft_raster.h"
#include "raster/span_walk.h"

namespace shd {

namespace {

double medianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

std::vector<SpanUnitConfig> spanCyclesConfigs() {
  std::vector<SpanUnitConfig> all;
  for (const std::string& n : builtinConfigNames("span")) all.push_back(spanConfig(n));
  const auto serial = std::find_if(all.begin(), all.end(),
                                   [](const SpanUnitConfig& c) { return c.rtl.lanes() == 1 && c.rtl.RowAhead == 0; });
  if (serial == all.end())
    throw std::invalid_argument("span-cycles: the speed-ups are relative to the paper's serial unit (one lane, "
                                "RowAhead 0); the registry has no such span configuration");
  std::rotate(all.begin(), serial, serial + 1);
  // Each full-rate unit right after the paper's unit of the same parameters.
  std::vector<SpanUnitConfig> out;
  std::vector<bool> placed(all.size(), false);
  for (size_t i = 0; i < all.size(); ++i) {
    if (placed[i] || all[i].rtl.RowAhead != 0) continue;
    out.push_back(all[i]);
    placed[i] = true;
    SpanParams full = all[i].rtl;
    full.RowAhead = 1;
    for (size_t k = 0; k < all.size(); ++k)
      if (!placed[k] && all[k].rtl.toJson() == full.toJson()) {
        out.push_back(all[k]);
        placed[k] = true;
      }
  }
  for (size_t k = 0; k < all.size(); ++k)
    if (!placed[k]) out.push_back(all[k]);
  return out;
}

TriangleSetCycles measureSpanCycles(const std::string& name, const TriangleList& tris, const RasterConfig& base,
                                    const std::vector<SpanUnitConfig>& modes, const std::vector<int>& divider_latency,
                                    int soft_repeats) {
  if (modes.empty() || modes.front().rtl.lanes() != 1 || modes.front().rtl.RowAhead != 0)
    throw std::invalid_argument(
        "span-cycles: the first configuration measured must be the paper's serial unit (one lane, RowAhead 0)");
  TriangleSetCycles out;
  out.name = name;
  out.input_triangles = tris.size();
  out.divider_latency = divider_latency;
  for (const SpanUnitConfig& m : modes) {
    RasterConfig c = base;
    c.unit = m.rtl;
    SpanUnitModel unit(c.unit);
    SpanStream stream;
    ModeCycles mc;
    mc.mode = m.name;
    mc.row_ahead = c.unit.RowAhead != 0;
    mc.lanes = c.unit.lanes();
    uint32_t tag = 0;
    for (const auto& v : tris) {
      const SetupResult s = setupTriangle(v, tag++, c);
      if (!s.desc) continue;
      ++mc.triangles;
      if (mc.row_ahead) {  // the stream's timing (the cycle model's, SpanUnitModel.FullRateStreamKeepsItsTiming)
        const SpanWalk wk =
            walkSpanUnit(c.unit, *s.desc, [](int32_t, int32_t, const int64_t*) {}, span_detail::NoRuns{}, &stream);
        mc.fragments += wk.fragments;
        mc.row_cycles += wk.row_cycles;
        mc.span_cycles += wk.span_cycles;
        continue;
      }
      const SpanRun run = runSpanUnit(unit, *s.desc);
      mc.fragments += run.fragments.size();
      mc.cycles += run.cycles;
      mc.row_cycles += run.row_cycles;
      mc.span_cycles += run.span_cycles;
      if (out.modes.empty()) {  // the serial unit's rows
        std::map<int32_t, int> per_row;
        for (const SpanFragment& f : run.fragments) ++per_row[f.y];
        for (const auto& [y, n] : per_row) out.divisions += n >= 2 ? 1 : 0;
      }
    }
    if (mc.row_ahead) mc.cycles = stream.end();
    out.modes.push_back(mc);
  }
  // Software: the same triangles, attribute 0, float scanline loops.
  std::vector<std::array<SoftVertex, 3>> soft;
  for (const auto& v : tris) {
    std::array<SoftVertex, 3> s;
    for (size_t i = 0; i < 3; ++i)
      s[i] = {static_cast<float>(v[i].x), static_cast<float>(v[i].y), static_cast<float>(v[i].attr.at(0))};
    soft.push_back(s);
  }
  std::vector<double> t_classical, t_constant;
  for (int r = 0; r < soft_repeats; ++r) {
    for (int which = 0; which < 2; ++which) {
      SoftFramebuffer fb(base.width, base.height);
      SoftStats st;
      const auto t0 = std::chrono::steady_clock::now();
      for (const auto& s : soft) {
        if (which == 0) rasterClassical(s, fb, st);
        else rasterConstantIncrement(s, fb, st);
      }
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
      (which == 0 ? t_classical : t_constant).push_back(ms);
      if (which == 0) out.soft_divisions = st.divisions;
    }
  }
  out.soft_ms_classical = medianMs(t_classical);
  out.soft_ms_constant = medianMs(t_constant);
  return out;
}

nlohmann::json toJson(const TriangleSetCycles& s) {
  nlohmann::json modes = nlohmann::json::array();
  const double serial = static_cast<double>(s.modes.front().cycles);
  for (const ModeCycles& m : s.modes)
    modes.push_back({{"mode", m.mode},
                     {"row_ahead", m.row_ahead ? 1 : 0},
                     {"lanes", m.lanes},
                     {"triangles", m.triangles},
                     {"fragments", m.fragments},
                     {"cycles", m.cycles},
                     {"row_cycles", m.row_cycles},
                     {"span_cycles", m.span_cycles},
                     {"no_overhead_bound", m.span_cycles},
                     {"cycles_over_bound", m.overBound()},
                     {"fragments_per_cycle", m.fragmentsPerCycle()},
                     {"speedup_vs_serial", m.cycles ? serial / static_cast<double>(m.cycles) : 0.0},
                     {"lane_utilisation", m.utilisation()}});
  nlohmann::json classical = nlohmann::json::array();
  for (int d : s.divider_latency) {
    const double c = serial + static_cast<double>(d) * static_cast<double>(s.divisions);
    classical.push_back({{"divider_latency", d}, {"cycles", c}, {"speedup_constant_increment", c / serial}});
  }
  return {{"set", s.name},
          {"input_triangles", s.input_triangles},
          {"modes", modes},
          {"divisions", s.divisions},
          {"classical", classical},
          {"software",
           {{"classical_ms", s.soft_ms_classical},
            {"constant_increment_ms", s.soft_ms_constant},
            {"speedup", s.soft_ms_constant > 0 ? s.soft_ms_classical / s.soft_ms_constant : 0.0},
            {"divisions", s.soft_divisions}}}};
}

std::string renderSpanCyclesTable(const std::vector<TriangleSetCycles>& sets) {
  std::string out =
      "Span unit cycles per triangle set (cycle-accurate model; triangles back to back, the consumer always ready).\n"
      "The paper claims 2x over serial for even/odd and 4x for the 4-way split. <mode>full: the full-rate unit.\n"
      "bound: the lane layout's no-overhead bound, its lane groups alone (every row and triangle transition free).\n";
  for (const TriangleSetCycles& s : sets) {
    const ModeCycles& serial = s.modes.front();
    out += fmt::format("\n{}: {} triangles, {} fragments, {:.1f} px/triangle\n", s.name, serial.triangles,
                       serial.fragments,
                       serial.triangles ? static_cast<double>(serial.fragments) / serial.triangles : 0.0);
    out += fmt::format("{:<16} {:>12} {:>10} {:>12} {:>12} {:>9} {:>9}\n", "mode", "cycles", "frag/cyc", "bound",
                       "cyc/bound", "x serial", "lane use");
    for (const ModeCycles& m : s.modes)
      out += fmt::format("{:<16} {:>12} {:>10.3f} {:>12} {:>12.3f} {:>8.2f}x {:>8.1f}%\n", m.mode, m.cycles,
                         m.fragmentsPerCycle(), m.span_cycles, m.overBound(),
                         m.cycles ? static_cast<double>(serial.cycles) / m.cycles : 0.0, 100 * m.utilisation());
  }
  out += "(lane use: fragments per lane in the lane groups shown)\n\n";
  out += "Constant increment vs a division per raster line (the paper claims 1.7x): cycles(classical) / cycles(constant)\n";
  out += fmt::format("{:<16} {:>10} {:>10} |", "set", "serial cyc", "divisions");
  for (int d : sets.front().divider_latency) out += fmt::format(" {:>7}", fmt::format("D={}", d));
  out += fmt::format(" | {:>10} {:>10} {:>7}\n", "sw classic", "sw const", "sw x");
  for (const TriangleSetCycles& s : sets) {
    const double serial = static_cast<double>(s.modes.front().cycles);
    out += fmt::format("{:<16} {:>10} {:>10} |", s.name, s.modes.front().cycles, s.divisions);
    for (int d : s.divider_latency) out += fmt::format(" {:>6.2f}x", (serial + d * static_cast<double>(s.divisions)) / serial);
    out += fmt::format(" | {:>8.2f}ms {:>8.2f}ms {:>6.2f}x\n", s.soft_ms_classical, s.soft_ms_constant,
                       s.soft_ms_constant > 0 ? s.soft_ms_classical / s.soft_ms_constant : 0.0);
  }
  out += "(D: divider latency in cycles; sw: software time of the float scanline loops, median)\n";
  return out;
}

}  // namespace shd
