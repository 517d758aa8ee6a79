// shadesim sweep: a unit over a grid of its parameters, each point evaluated by the model, then
// the area of the points that can still reach a front, then optionally the least point within a
// target error (cli/sweep_target.h); shadesim sweep-merge: shard directories joined (and their
// area phase). The directory layout, the resume rule and which points are synthesised:
// model/sweep/sweep_run.h.
#include <cctype>
#include <cstdio>
#include <optional>
#include <thread>

#include <fmt/format.h>

#include "cli/command.h"
#include "cli/progress.h"
#include "cli/sweep_target.h"
#include "cli/table_options.h"
#include "sweep/phong_sweep.h"
#include "sweep/span_sweep.h"
#include "sweep/spec_sweep.h"
#include "sweep/sweep_run.h"
#include "sweep/sweep_unit.h"

namespace shd::cli {

namespace {

// f(args...), its std::invalid_argument an ArgError.
template <class F, class... A>
auto argOr(F f, A&&... args) {
  try {
    return f(std::forward<A>(args)...);
  } catch (const std::invalid_argument& e) {
    throw ArgError(e.what());
  }
}

// A configuration name that is also a file name: [A-Za-z][A-Za-z0-9_]*, at most 64 characters.
bool isConfigName(const std::string& s) {
  if (s.empty() || s.size() > 64 || !std::isalpha(static_cast<unsigned char>(s[0]))) return false;
  for (char c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') return false;
  return true;
}

unsigned jobsOr(unsigned jobs) { return jobs > 0 ? jobs : std::max(1u, std::thread::hardware_concurrency()); }

// The synthesis tools of --area TARGETS --synth-cache DIR.
SynthTool synthTool(const std::string& targets, const std::string& cache) {
  if (cache.empty()) throw ArgError("--area needs --synth-cache DIR (an existing directory)");
  requireDirectoryArg("--synth-cache", cache);
  SynthTool synth{findShareFile("scripts/synth.py"), cache, targets, ""};
  if (synth.script.empty())
    throw ArgError("--area: scripts/synth.py is neither in this installation nor in the source tree it was built from");
  synth.version = synthToolVersion(synth.script);
  return synth;
}

// A progress callback whose rate leaves out what was recorded before this run.
std::function<void(uint64_t, uint64_t)> progressOf(Progress& progress, const char* unit) {
  return [&progress, unit, base = std::optional<uint64_t>()](uint64_t d, uint64_t n) mutable {
    if (!base) base = d;
    progress.update(static_cast<double>(d - *base), static_cast<double>(n - *base), unit);
  };
}

// The second phase of a complete sweep, then its results: the area of every point that can
// still reach a front (areaDominators), each kept in DIR/area-<index>.json, then sweep.csv,
// sweep.json and pareto.csv. Returns the results (sweepResults).
nlohmann::json finishSweep(const std::string& dir, const SweepPlan& plan, const SweepRecords& records,
                         const SynthTool* synth, unsigned jobs, bool quiet) {
  SweepRecords areas;
  std::vector<int64_t> dominator;
  if (plan.json.at("area") != "none") {
    if (synth == nullptr) throw ArgError("this sweep asks for area: give --synth-cache DIR");
    const SweepUnit unit = makeSweepUnit(plan.json.at("base"));
    const Grid grid = planGrid(plan);
    std::vector<nlohmann::json> rtl;
    for (uint64_t k = 0; k < grid.size(); ++k) rtl.push_back(unit.rtl(grid.point(k)));
    dominator = areaDominators(plan, records, dspClasses(unit.name, rtl, *synth));
    std::vector<uint64_t> todo;
    for (uint64_t k = 0; k < dominator.size(); ++k)
      if (dominator[k] < 0) todo.push_back(k);
    areas = readSweepAreas(dir, plan);
    if (!quiet)
      std::fprintf(stderr, "sweep %s: area of %zu of %zu points (the others cannot reach a front), %zu recorded\n",
                   plan.hash.c_str(), todo.size(), dominator.size(), areas.size());
    Progress progress(fmt::format("sweep {} area", plan.hash), !quiet);
    runSweepJobs(
        dir, plan, "area", todo, jobs,
        [&](uint64_t k) { return nlohmann::json{{"index", k}, {"area", unit.area(grid.point(k), *synth)}}; }, areas,
        progressOf(progress, "points"));
  }
  nlohmann::json results = sweepResults(plan, records, areas, dominator);
  writeSweepResults(dir, plan, results);
  return results;
}

class SweepCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--unit", unit_, "the unit swept: " + sweepUnitHelp())
        ->check(CLI::IsMember(sweepUnitNames()))
        ->default_val("spec");
    table_.add(app);
    app.get_option("--config")
        ->description(fmt::format("the base configuration: spec {}; span {} (default serial)", configChoices("spec"),
                                  configChoices("span")));
    app.add_option("--triangles", triangles_, "span: the triangles of the error's set (seeded, raster/trigen.h)")
        ->check(countIn(1, static_cast<int64_t>(kMaxSpanSweepTriangles)))
        ->default_val(kSpanSweepTriangles);
    app.add_option("--seed", seed_, "span: the seed of the triangle set")->default_val(kSpanSweepSeed);
    app.add_option("--scene", scenes_, "span, phong: the bundled scenes (vectors/scenes) to count cycles or error on")
        ->delimiter(',')
        ->default_str("sphere,still_life");
    app.add_option("--param", params_,
                   "a parameter and its values, Name=lo:hi[:step] or Name=v1,v2,...; repeat for more axes "
                   "(the others keep the --config's values)")
        ->required();
    app.add_option("--shard", shard_, "run the i-th of N deterministic parts (i/N); join with sweep-merge");
    app.add_option("--jobs", jobs_, "threads (default: the machine's cores)")->check(countIn(1, 256));
    app.add_option("--area", area_,
                   "also the area by yosys (scripts/synth.py) of every point that can still reach a front: ice40, xc7 "
                   "or both")
        ->check(CLI::IsMember({"ice40", "xc7", "both"}));
    app.add_flag("--area-all", area_all_, "with --area: synthesise every point (to check the pruning)");
    app.add_option("--synth-cache", synth_cache_,
                   "an existing directory where synthesised areas are kept by the point's parameters and PROM "
                   "(required with --area; shared by sweeps)");
    app.add_option("--target-lsb", target_.lsb,
                   "then pick the least point whose datapath error is at most this many output LSBs, write it as a "
                   "configuration, replay it under Icarus and show it minimal (specular unit)")
        ->check(realIn(0, 1e6, Ends::Open));
    app.add_option("--objective", target_.objective, "what --target-lsb minimises: area (LUTs; needs --area) or latency")
        ->check(CLI::IsMember({"area", "latency"}));
    app.add_option("--target-name", target_.name, "the configuration --target-lsb writes: DIR/<unit>_<name>.json")
        ->default_val("target");
    app.add_option("--verify-cycles", target_.verify_cycles, "cycles of the vector file --target-lsb replays under Icarus")
        ->check(countIn(1, 10'000'000))
        ->default_val(20000);
    app.add_option("-o,--output", dir_, "the sweep's directory (must exist; a killed sweep resumes in it)")->required();
    app.add_flag("--quiet", quiet_, "no progress on stderr");
  }

  int run(const CLI::App& app) override {
    const bool target = app.count("--target-lsb") > 0;
    checkTargetOptions(app, target);
    const SweepUnit unit = argOr(makeSweepUnit, unitBase(app));
    if (target && !unit.config) throw ArgError(fmt::format("--target-lsb: the {} sweep has no configuration to write", unit.name));
    std::vector<GridAxis> axes;
    for (const std::string& p : params_) axes.push_back(argOr(parseGridAxis, p, unit.params));
    const Grid grid = argOr([](std::vector<GridAxis> a) { return Grid(std::move(a)); }, axes);
    const Shard shard = shard_.empty() ? Shard{} : argOr(Shard::parse, shard_);
    argOr(unit.validate, grid);
    std::optional<SynthTool> synth;
    if (!area_.empty()) {
      if (!unit.area) throw ArgError(fmt::format("--area: the {} sweep has no RTL to synthesise", unit.name));
      synth = synthTool(area_, synth_cache_);
    } else if (!synth_cache_.empty() || area_all_) {
      throw ArgError(fmt::format("{} applies only with --area", area_all_ ? "--area-all" : "--synth-cache"));
    }

    const SweepPlan plan = SweepPlan::make(planJson(unit, grid, synth ? synth->version : ""));
    claimSweepDir(dir_, plan);
    SweepRecords done = readSweepRecords(dir_, plan);
    if (!done.empty() && !quiet_)
      std::fprintf(stderr, "sweep %s: resuming, %zu of %llu points already recorded in %s\n", plan.hash.c_str(),
                   done.size(), static_cast<unsigned long long>(grid.size()), dir_.c_str());
    const unsigned jobs = jobsOr(jobs_);
    {
      Progress progress(fmt::format("sweep {} ({} points{})", plan.hash, grid.size(),
                                    shard.count > 1 ? fmt::format(", shard {}/{}", shard.index, shard.count) : ""),
                        !quiet_);
      runSweepJobs(
          dir_, plan, "point", shardPoints(plan, shard), jobs,
          [&](uint64_t k) { return unit.evaluate(k, grid.point(k)); }, done, progressOf(progress, "points"));
    }
    if (!missingPoints(plan, done).empty()) {
      std::printf("sweep %s: shard %llu/%llu recorded in %s; join the shards with shadesim sweep-merge\n",
                  plan.hash.c_str(), static_cast<unsigned long long>(shard.index),
                  static_cast<unsigned long long>(shard.count), dir_.c_str());
      return kExitOk;
    }
    const nlohmann::json results = finishSweep(dir_, plan, done, synth ? &*synth : nullptr, jobs, quiet_);
    std::printf("sweep %s: %llu points; %s/sweep.csv, sweep.json, pareto.csv\n", plan.hash.c_str(),
                static_cast<unsigned long long>(grid.size()), dir_.c_str());
    if (!target) return kExitOk;
    std::fflush(stdout);
    return runTarget(dir_, plan, unit, results, synth ? &*synth : nullptr, target_);
  }

 private:
  // The --target-lsb options: checked before any work. Not part of the plan: --target-lsb on a
  // finished sweep's directory (or a merged one) picks again without evaluating anything.
  void checkTargetOptions(const CLI::App& app, bool target) {
    if (!target) {
      for (const char* o : {"--objective", "--target-name", "--verify-cycles"})
        if (app.count(o) > 0) throw ArgError(fmt::format("{} applies only with --target-lsb", o));
      return;
    }
    if (!shard_.empty()) throw ArgError("--target-lsb: not with --shard (pick in the merged directory)");
    if (target_.objective.empty()) target_.objective = area_.empty() ? "latency" : "area";
    if (target_.objective == "area" && area_.empty()) throw ArgError("--objective area needs --area");
    if (!isConfigName(target_.name))
      throw ArgError(fmt::format("--target-name {}: letters, digits and '_' only, starting with a letter", target_.name));
  }

  // The base of --unit, from its options; an option of another unit is an error.
  nlohmann::json unitBase(const CLI::App& app) const {
    auto only = [&](const std::vector<const char*>& options, std::initializer_list<const char*> units) {
      if (std::find(units.begin(), units.end(), unit_) != units.end()) return;
      for (const char* o : options)
        if (app.count(o) > 0) throw ArgError(fmt::format("{} does not apply to --unit {}", o, unit_));
    };
    only({"--fit", "--level", "--degree", "--n", "--n-list", "--coef-format"}, {"spec"});
    only({"--triangles", "--seed"}, {"span"});
    only({"--scene"}, {"span", "phong"});
    only({"--config"}, {"spec", "span"});
    const std::vector<std::string> scenes = scenes_.empty() ? std::vector<std::string>{"sphere", "still_life"} : scenes_;
    if (unit_ == "span")
      return argOr(spanSweepBase, spanConfigArg("--config", app.count("--config") ? table_.config : "serial"),
                   triangles_, seed_, scenes);
    if (unit_ == "phong") return argOr(phongSweepBase, scenes);
    SpecUnitConfig cfg;
    table_.build(cfg, false);
    return specSweepBase(cfg.ref(), cfg.rtl, cfg.prom);
  }

  // The plan; with --area it names the synthesis tools (synthToolVersion), so that a sweep does
  // not resume (nor a merge synthesise) with another yosys or flow.
  nlohmann::json planJson(const SweepUnit& unit, const Grid& grid, const std::string& synth_tools) const {
    nlohmann::json axes = nlohmann::json::array();
    std::string command = fmt::format("shadesim sweep --unit {} {}", unit.name, unit.base_options);
    if (!area_.empty()) command += " --area " + area_ + (area_all_ ? " --area-all" : "");
    for (const GridAxis& a : grid.axes()) {
      axes.push_back({{"name", a.name}, {"text", a.text}, {"values", a.values}});
      command += fmt::format(" --param {}={}", a.name, a.text);
    }
    return {{"format", "shadesim sweep 2"},
            {"tool", std::string("shadesim ") + SHD_VERSION},
            {"command", command},
            {"base", unit.base},
            {"params", unit.params_member},
            {"front", {{"error", unit.front_error}, {"costs", unit.front_costs}}},
            {"area", area_.empty() ? "none" : area_ + " (" + synth_tools + ")"},
            {"area_all", area_all_},
            {"axes", axes},
            {"points", grid.size()}};
  }

  TableOptions table_;
  TargetRequest target_;
  std::string unit_ = "spec", shard_, dir_, area_, synth_cache_;
  std::vector<std::string> params_, scenes_;
  uint64_t triangles_ = kSpanSweepTriangles, seed_ = kSpanSweepSeed;
  unsigned jobs_ = 0;
  bool area_all_ = false, quiet_ = false;
};

class SweepMergeCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("dirs", dirs_, "the shards' directories")->required();
    app.add_option("-o,--output", out_, "the merged sweep's directory (must exist)")->required();
    app.add_option("--synth-cache", synth_cache_,
                   "for a sweep with --area: the existing directory of synthesised areas (the area phase runs here)");
    app.add_option("--jobs", jobs_, "threads of the area phase (default: the machine's cores)")->check(countIn(1, 256));
    app.add_flag("--quiet", quiet_, "no progress on stderr");
  }

  int run(const CLI::App&) override {
    const auto [plan, records] = mergeSweeps(dirs_, out_);
    std::optional<SynthTool> synth;
    const std::string area = plan.json.at("area").get<std::string>();
    if (area != "none") {
      synth = synthTool(area.substr(0, area.find(' ')), synth_cache_);
      if (area != synth->targets + " (" + synth->version + ")")
        throw ArgError(fmt::format("the sweep's areas are asked of {}; this machine has {}", area, synth->version));
    } else if (!synth_cache_.empty()) {
      throw ArgError("--synth-cache: this sweep asks for no area");
    }
    finishSweep(out_, plan, records, synth ? &*synth : nullptr, jobsOr(jobs_), quiet_);
    std::printf("merged %zu directories into %s: sweep.csv, sweep.json, pareto.csv\n", dirs_.size(), out_.c_str());
    return kExitOk;
  }

 private:
  std::vector<std::string> dirs_;
  std::string out_, synth_cache_;
  unsigned jobs_ = 0;
  bool quiet_ = false;
};

}  // namespace

std::unique_ptr<Command> makeSweepCmd() { return std::make_unique<SweepCmd>(); }
std::unique_ptr<Command> makeSweepMergeCmd() { return std::make_unique<SweepMergeCmd>(); }

}  // namespace shd::cli
