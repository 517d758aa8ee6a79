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

SpecUnitParams specPointParams(const SpecUnitParams& base, const PointValues& values) {
  nlohmann::json rtl = base.toJson();
  for (const auto& [name, value] : values) rtl[name] = value;
  return SpecUnitParams::fromJson(rtl, "point " + describePoint(values));
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

nlohmann::json evaluateSpecPoint(uint64_t index, const SpecUnitParams& p, const PromRequest& req) {
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
  j["prom_bits"] = p.promBits();
  j["rom_bits"] = p.promBits() + p.fixedRomBits();  // with the explog kind's tables
  j["inputs"] = static_cast<int64_t>(table.entries.size()) * (codes.empty() ? p.cosOne() + 1 : static_cast<int64_t>(codes.size()));
  j["exhaustive"] = codes.empty() ? 1 : 0;
  return j;
}

nlohmann::json specSweepBase(const std::string& config, const SpecUnitParams& rtl, const PromContent& prom) {
  return {{"unit", "spec"},
          {"config", config},
          {"rtl", rtl.toJson()},
          {"prom", {{"fit", prom.fit}, {"level", prom.level}, {prom.is_list ? "n_list" : "n", prom.n}}}};
}

SweepUnit specSweepUnit(const nlohmann::json& base_json) {
  const SpecUnitParams base = SpecUnitParams::fromJson(base_json.at("rtl"), "the sweep's base");
  const nlohmann::json& pj = base_json.at("prom");
  const bool is_list = pj.contains("n_list");
  const PromRequest req = PromRequest::fromContent(
      {pj.at("fit").get<std::string>(), pj.at("level").get<double>(), pj.at(is_list ? "n_list" : "n").get<std::string>(),
       is_list});
  SweepUnit u;
  u.name = "spec";
  u.base = base_json;
  u.base_options = fmt::format("--config {} --fit {} --level {} --{} {}", base_json.at("config").get<std::string>(),
                               pj.at("fit").get<std::string>(), pj.at("level").dump(), is_list ? "n-list" : "n",
                               pj.at(is_list ? "n_list" : "n").get<std::string>());
  u.params = specParamNames();
  u.params_member = "rtl";
  u.front_error = "datapath_max_lsb";
  u.front_costs = {"latency", "rom_bits"};
  u.validate = [base, req](const Grid& grid) {
    std::set<std::string> tables;  // the parameter sets whose PROM was built
    for (uint64_t k = 0; k < grid.size(); ++k) {
      const PointValues values = grid.point(k);
      const SpecUnitParams p = specPointParams(base, values);
      if (!tables.insert(p.toJson().dump()).second) continue;
      try {
        buildPromTable(req, p);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(fmt::format("point {} ({}): {}", k, describePoint(values), e.what()));
      }
    }
  };
  u.evaluate = [base, req](uint64_t index, const PointValues& values) {
    return evaluateSpecPoint(index, specPointParams(base, values), req);
  };
  u.area = [base, req](const PointValues& values, const SynthTool& tool) {
    return specPointArea(buildPromTable(req, specPointParams(base, values)), tool);
  };
  u.rtl = [base](const PointValues& values) { return specPointParams(base, values).toJson(); };
  u.config = [base, pj](const PointValues& values, const std::string& name, const std::string& description) {
    return nlohmann::json{{"name", name},
                          {"description", description},
                          {"rtl", specPointParams(base, values).toJson()},
                          {"prom", pj}};
  };
  // The datapath's own widths; CosFracBits, ShinBits and LightBits are its interface (the
  // inputs' formats and the PROM's depth), PipeStages and Degree no widths. Each kind has its
  // own: HornerFracBits only at degree 3 (the quadratic unit has no Horner step); the other kinds
  // use neither DiffFracBits nor HornerFracBits, and TableBits is the resolution of the table's
  // and explog's tables (Segments, like Degree, shapes the piecewise unit rather than a width).
  switch (base.kind()) {
    case SpecKind::Poly:
      u.widths = {"CoefIntBits", "CoefFracBits", "DiffFracBits", "SpecFracBits"};
      if (base.Degree == 3) u.widths.push_back("HornerFracBits");
      break;
    case SpecKind::Table: u.widths = {"SpecFracBits", "TableBits"}; break;
    case SpecKind::Schlick: u.widths = {"CoefIntBits", "CoefFracBits", "SpecFracBits"}; break;
    case SpecKind::ExpLog: u.widths = {"CoefIntBits", "CoefFracBits", "SpecFracBits", "TableBits"}; break;
    case SpecKind::Piecewise: u.widths = {"CoefIntBits", "CoefFracBits", "SpecFracBits"}; break;
  }
  return u;
}

}  // namespace shd
