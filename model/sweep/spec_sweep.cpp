#include "sweep/spec_sweep.h"

#include <algorithm>
#include <set>

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

std::vector<int64_t> specSampleCodes(const SpecUnitParams& p, size_t entries, uint64_t seed) {
  const int64_t all = p.cosOne() + 1;
  if (static_cast<uint64_t>(all) * entries <= kSpecExhaustiveInputs) return {};
  const int64_t per_n = std::max<int64_t>(64, static_cast<int64_t>(kSpecExhaustiveInputs / entries));
  std::set<int64_t> codes = {0, 1, 2, p.cosOne() / 2, p.cosOne() - 2, p.cosOne() - 1, p.cosOne()};
  // The corners above, then codes drawn uniformly by SplitMix64 (the same on every machine).
  uint64_t x = seed;
  while (static_cast<int64_t>(codes.size()) < per_n) {
    uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    codes.insert(static_cast<int64_t>((z ^ (z >> 31)) % static_cast<uint64_t>(all)));
  }
  return {codes.begin(), codes.end()};
}

nlohmann::json evaluateSpecPoint(uint64_t index, const SpecUnitParams& p, const PromRequest& req,
                                 const SynthTool* synth) {
  const PromTable table = buildPromTable(req, p);
  const std::vector<int64_t> codes = specSampleCodes(p, table.entries.size(), kSpecSampleSeed);
  const SpecErrorReport r = computeSpecError("sweep", table, {}, codes);
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
  j["inputs"] = static_cast<int64_t>(table.entries.size()) * (codes.empty() ? p.cosOne() + 1 : static_cast<int64_t>(codes.size()));
  j["exhaustive"] = codes.empty() ? 1 : 0;
  if (synth != nullptr) j["area"] = specPointArea(table, *synth);
  return j;
}

}  // namespace shd
