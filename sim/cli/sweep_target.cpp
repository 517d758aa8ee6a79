#include "cli/sweep_target.h"

#include <cstdio>
#include <filesystem>
#include <optional>
#include <tuple>

#include <fmt/format.h>

#include "cli/command.h"
#include "io/files.h"
#include "io/process.h"
#include "vectors/vector_gen.h"

namespace shd::cli {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kVerifySeed = 20261125;

// LUTs of the first synthesised target (iCE40 before xc7), or -1 without area.
int64_t luts(const nlohmann::json& r) {
  if (!r.contains("area")) return -1;
  for (const char* t : {"ice40", "xc7"})
    if (r.at("area").contains(t)) return r.at("area").at(t).at("luts").get<int64_t>();
  return -1;
}

// The values of every parameter of a record (each named, so the base's own values do not matter).
PointValues valuesOf(const nlohmann::json& r, const std::string& member) {
  PointValues v;
  for (const auto& item : r.at(member).items()) v.emplace_back(item.key(), item.value().get<int>());
  return v;
}

// The chosen record's index, or -1.
int64_t choose(const nlohmann::json& results, const std::string& error, const std::string& member,
               const TargetRequest& req) {
  using Key = std::tuple<int64_t, int64_t, int64_t, uint64_t>;
  std::optional<Key> best;
  int64_t chosen = -1;
  for (const nlohmann::json& r : results) {
    if (r.at("error").at(error).get<double>() > req.lsb) continue;
    if (req.objective == "area" && !r.contains("area")) continue;  // pruned: a narrower point matches it
    const int64_t lat = r.at("latency").get<int64_t>(), l = luts(r);
    const Key k = req.objective == "area" ? Key{l, lat, paramBits(r, member), r.at("index").get<uint64_t>()}
                                          : Key{lat, l, paramBits(r, member), r.at("index").get<uint64_t>()};
    if (!best || k < *best) best = k, chosen = r.at("index").get<int64_t>();
  }
  return chosen;
}

std::string areaText(const nlohmann::json& area) {
  std::string s;
  for (const auto& t : area.items())
    s += fmt::format("{}{}: {} LUT {} FF {} carry {} DSP {} BRAM", s.empty() ? "" : "; ", t.key(),
                     t.value().at("luts").get<int64_t>(), t.value().at("ffs").get<int64_t>(),
                     t.value().at("carries").get<int64_t>(), t.value().at("dsps").get<int64_t>(),
                     t.value().at("brams").get<int64_t>());
  return s;
}

// Each internal width of the chosen point one bit narrower: its error and, where it breaks E,
// the input; where it still meets E, its area (minimality is by area).
nlohmann::json narrowerPoints(const SweepUnit& unit, const nlohmann::json& chosen, const SynthTool* synth,
                              const TargetRequest& req) {
  const std::string& error = unit.front_error;
  const PointValues values = valuesOf(chosen, unit.params_member);
  nlohmann::json narrower = nlohmann::json::array();
  for (const std::string& w : unit.widths) {
    PointValues v = values;
    for (auto& [name, value] : v)
      if (name == w) --value;
    nlohmann::json n = {{"width", w}, {"value", chosen.at(unit.params_member).at(w).get<int>() - 1}};
    try {
      const nlohmann::json r = unit.evaluate(0, v);
      const double e = r.at("error").at(error).get<double>();
      n["error"] = e;
      n["breaks_target"] = e > req.lsb;
      for (const char* f : {"datapath_worst_n", "datapath_worst_c"})
        if (r.at("error").contains(f)) n[f] = r.at("error").at(f);
      if (e <= req.lsb && synth != nullptr) {
        n["area"] = unit.area(v, *synth);
        n["smaller"] = luts(n) < luts(chosen);
      }
    } catch (const std::invalid_argument& e) {
      n["invalid"] = e.what();
    }
    narrower.push_back(std::move(n));
  }
  return narrower;
}

void printNarrower(const nlohmann::json& narrower) {
  std::printf("  one bit narrower:\n");
  for (const nlohmann::json& n : narrower) {
    std::string what;
    if (n.contains("invalid")) {
      what = "not a valid configuration: " + n.at("invalid").get<std::string>();
    } else if (n.at("breaks_target").get<bool>()) {
      what = fmt::format("breaks the target: {:.6g} LSB at n = {}, c = {}", n.at("error").get<double>(),
                         n.at("datapath_worst_n").dump(), n.at("datapath_worst_c").dump());
    } else if (!n.contains("area")) {
      what = fmt::format("still within it ({:.6g} LSB): not minimal in this width", n.at("error").get<double>());
    } else {
      what = fmt::format("still within it ({:.6g} LSB), {}; {}", n.at("error").get<double>(), areaText(n.at("area")),
                         n.at("smaller").get<bool>() ? "fewer LUTs: NOT minimal (a value the grid misses, or a point "
                                                       "the pruning dropped: docs/sweeps.md)"
                                                     : "no fewer LUTs");
    }
    std::printf("    %s %d: %s\n", n.at("width").get<std::string>().c_str(), n.at("value").get<int>(), what.c_str());
  }
}

}  // namespace

void replayUnderIcarus(const std::string& vec) {
  const std::string script = findShareFile("testbench/icarus/run_icarus.sh");
  if (script.empty())
    throw std::runtime_error("testbench/icarus/run_icarus.sh is neither in this installation nor in the source tree");
  std::string out, err, error;
  const int rc = runProcess({script, vec}, out, err, error);
  if (rc != 0) {
    std::string said = out + err;
    if (said.size() > 1200) said = "..." + said.substr(said.size() - 1200);
    throw std::runtime_error(fmt::format("{} {}: {}\n{}", script, vec, rc < 0 ? error : fmt::format("exit {}", rc), said));
  }
}

std::string verifyUnderIcarus(const std::string& config_file, uint64_t cycles) {
  const SpecUnitConfig cfg = specConfig(config_file);
  const std::string vec = fs::path(config_file).replace_extension(".vec").string();
  VectorGenSummary s;
  writeSpecVectorsWithProm(cfg, cycles, kVerifySeed, vec, &s);
  replayUnderIcarus(vec);
  return fmt::format("Icarus replayed {} ({} cycles, {} valid inputs, seed {}): every output matches the model",
                     vec, s.cycles, s.valid_inputs, kVerifySeed);
}

int runTarget(const std::string& dir, const SweepPlan& plan, const SweepUnit& unit, const nlohmann::json& results,
              const SynthTool* synth, const TargetRequest& req) {
  const std::string error = unit.front_error, member = unit.params_member;
  const int64_t k = choose(results, error, member, req);
  if (k < 0) {
    const nlohmann::json* best = nullptr;
    for (const nlohmann::json& r : results)
      if (best == nullptr || r.at("error").at(error).get<double>() < best->at("error").at(error).get<double>()) best = &r;
    std::printf("target %g LSB: no point of sweep %s meets it; the least %s is %.6g LSB (point %lld: %s)\n", req.lsb,
                plan.hash.c_str(), error.c_str(), best->at("error").at(error).get<double>(),
                static_cast<long long>(best->at("index").get<int64_t>()),
                describePoint(valuesOf(*best, member)).c_str());
    return kExitFailed;
  }
  nlohmann::json chosen = results.at(static_cast<size_t>(k));
  // By area: the grid's pick, then one-bit steps down while a narrower width still meets E with
  // fewer LUTs (a value the grid misses, or a point its pruning dropped), so that every width of
  // the written configuration is shown minimal.
  nlohmann::json narrower = narrowerPoints(unit, chosen, synth, req);
  int steps = 0;
  for (;;) {
    const nlohmann::json* step = nullptr;
    for (const nlohmann::json& n : narrower)
      if (n.value("smaller", false) && (step == nullptr || luts(n) < luts(*step))) step = &n;
    if (step == nullptr || req.objective != "area") break;
    PointValues v = valuesOf(chosen, member);
    for (auto& [name, value] : v)
      if (name == step->at("width")) value = step->at("value").get<int>();
    nlohmann::json next = unit.evaluate(0, v);
    next["index"] = nullptr;  // not a point of the grid
    next["area"] = step->at("area");
    chosen = std::move(next);
    ++steps;
    narrower = narrowerPoints(unit, chosen, synth, req);
  }
  const PointValues values = valuesOf(chosen, member);
  // The configuration file, then the RTL against the model on it.
  const std::string config_file = (fs::path(dir) / fmt::format("{}_{}.json", unit.name, req.name)).string();
  const std::string description =
      fmt::format("The least-{} point of sweep {} with at most {} LSB {} (shadesim sweep --target-lsb {}).",
                  req.objective, plan.hash, req.lsb, error, req.lsb);
  writeFileAtomic(config_file, unit.config(values, req.name, description).dump(2) + "\n");
  const std::string verdict = verifyUnderIcarus(config_file, req.verify_cycles);

  // The base configuration beside it, and each width one bit narrower.
  const nlohmann::json base = unit.evaluate(0, {});
  nlohmann::json base_area;
  if (synth != nullptr) base_area = unit.area({}, *synth);
  const nlohmann::json report = {{"target_lsb", req.lsb}, {"objective", req.objective}, {"sweep", plan.hash},
                                 {"chosen", chosen},      {"config", config_file},      {"rtl_check", verdict},
                                 {"grid_point", k},       {"steps_down", steps},
                                 {"base", base},          {"base_area", base_area},     {"one_bit_narrower", narrower}};
  writeFileAtomic((fs::path(dir) / "target.json").string(), report.dump(1) + "\n");

  const std::string from = steps == 0 ? fmt::format("point {}", k)
                                      : fmt::format("point {} and {} one-bit step{} down", k, steps, steps > 1 ? "s" : "");
  std::printf("target %g LSB (%s), least %s: %s, %s\n", req.lsb, error.c_str(), req.objective.c_str(), from.c_str(),
              describePoint(values).c_str());
  std::printf("  written as %s\n  %s\n", config_file.c_str(), verdict.c_str());
  std::printf("  %-10s %-16s %-8s %s\n", "", error.c_str(), "latency", "area");
  std::printf("  %-10s %-16.6g %-8lld %s\n", "chosen", chosen.at("error").at(error).get<double>(),
              static_cast<long long>(chosen.at("latency").get<int64_t>()),
              chosen.contains("area") ? areaText(chosen.at("area")).c_str() : "-");
  std::printf("  %-10s %-16.6g %-8lld %s\n", "base", base.at("error").at(error).get<double>(),
              static_cast<long long>(base.at("latency").get<int64_t>()),
              base_area.is_null() ? "-" : areaText(base_area).c_str());
  printNarrower(narrower);
  return kExitOk;
}

}  // namespace shd::cli
