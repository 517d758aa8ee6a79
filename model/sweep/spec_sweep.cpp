#include "sweep/spec_sweep.h"

#include <fmt/format.h>

#include "report/spec_error.h"
#include "sweep/grid.h"

namespace shd {

std::vector<std::string> specParamNames() {
  const nlohmann::json rtl = SpecUnitParams{}.toJson();
  std::vector<std::string> names;
  for (auto it = rtl.begin(); it != rtl.end(); ++it) names.push_back(it.key());
  return names;
}

SpecUnitParams specPointParams(const SpecUnitParams& base, const std::vector<std::pair<std::string, int>>& values) {
  nlohmann::json rtl = base.toJson();
  std::string where;
  for (const auto& [name, value] : values) {
    rtl[name] = value;
    where += fmt::format("{}{}={}", where.empty() ? "" : " ", name, value);
  }
  return SpecUnitParams::fromJson(rtl, "point " + where);
}

std::string specPointHash(const SpecUnitParams& p) { return textHash(p.toJson().dump()); }

nlohmann::json evaluateSpecPoint(uint64_t index, const SpecUnitParams& p, const PromRequest& req,
                                 const SynthTool* synth) {
  const PromTable table = buildPromTable(req, p);
  const SpecErrorReport r = computeSpecError("sweep", table);
  const SpecErrorSummary& s = r.summary;
  // The cosine at which the worst n reaches its worst error.
  auto worstC = [&](double n, double SpecErrorRow::*c) {
    for (const SpecErrorRow& row : r.rows)
      if (row.n == n) return row.*c;
    return 0.0;
  };
  nlohmann::json j;
  j["index"] = index;
  j["hash"] = specPointHash(p);
  j["rtl"] = p.toJson();
  j["error"] = {
      {"approx_lobe_max_abs", s.approx_lobe_max_abs.value},
      {"approx_lobe_worst_n", s.approx_lobe_max_abs.n},
      {"datapath_max_lsb", s.datapath_max_lsb.value},
      {"datapath_worst_n", s.datapath_max_lsb.n},
      {"datapath_worst_c", worstC(s.datapath_max_lsb.n, &SpecErrorRow::datapath_worst_c)},
      {"datapath_max_f_lsb", s.datapath_max_f_lsb.value},
      {"total_max_lsb", s.total_max_lsb.value},
      {"total_worst_n", s.total_max_lsb.n},
      {"total_worst_c", worstC(s.total_max_lsb.n, &SpecErrorRow::total_worst_c)},
      {"total_peak_max_lsb", s.total_peak_max_lsb.value},
  };
  j["latency"] = p.latency();
  j["prom_bits"] = static_cast<int64_t>(p.promDepth()) * p.promWordBits();
  j["inputs"] = static_cast<int64_t>(table.entries.size()) * (p.cosOne() + 1);
  if (synth != nullptr) j["area"] = specPointArea(table, *synth);
  return j;
}

}  // namespace shd
