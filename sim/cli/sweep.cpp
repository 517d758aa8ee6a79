// shadesim sweep: the specular unit over a grid of its parameters, each point evaluated by the
// model (exhaustive error, latency, PROM size); shadesim sweep-merge: shard directories joined.
// The directory layout and the resume rule: model/sweep/sweep_run.h.
#include <cstdio>
#include <optional>
#include <set>
#include <thread>
#include <tuple>

#include <fmt/format.h>

#include "cli/command.h"
#include "cli/progress.h"
#include "cli/table_options.h"
#include "sweep/spec_sweep.h"
#include "sweep/sweep_run.h"

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

class SweepCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--unit", unit_, "the unit swept: spec")->check(CLI::IsMember({"spec"}))->default_val("spec");
    table_.add(app);
    app.add_option("--param", params_,
                   "a parameter and its values, Name=lo:hi[:step] or Name=v1,v2,...; repeat for more axes "
                   "(the others keep the --config's values)")
        ->required();
    app.add_option("--shard", shard_, "run the i-th of N deterministic parts (i/N); join with sweep-merge");
    app.add_option("--jobs", jobs_, "threads (default: the machine's cores)")->check(countIn(1, 256));
    app.add_option("--area", area_, "also the area by yosys (scripts/synth.py): ice40, xc7 or both")
        ->check(CLI::IsMember({"ice40", "xc7", "both"}));
    app.add_option("--synth-cache", synth_cache_,
                   "an existing directory where synthesised areas are kept by the point's parameters and PROM "
                   "(required with --area; shared by sweeps)");
    app.add_option("-o,--output", dir_, "the sweep's directory (must exist; a killed sweep resumes in it)")->required();
    app.add_flag("--quiet", quiet_, "no progress on stderr");
  }

  int run(const CLI::App&) override {
    SpecUnitConfig cfg;
    const PromTable base_table = table_.build(cfg, false);
    std::vector<GridAxis> axes;
    for (const std::string& p : params_) axes.push_back(argOr(parseGridAxis, p, specParamNames()));
    const Grid grid = argOr([](std::vector<GridAxis> a) { return Grid(std::move(a)); }, axes);
    const Shard shard = shard_.empty() ? Shard{} : argOr(Shard::parse, shard_);
    validatePoints(grid, cfg.rtl, base_table.request);
    SynthTool synth;
    if (!area_.empty()) {
      if (synth_cache_.empty()) throw ArgError("--area needs --synth-cache DIR (an existing directory)");
      requireDirectoryArg("--synth-cache", synth_cache_);
      synth = {findSynthScript(), synth_cache_, area_, ""};
      if (synth.script.empty())
        throw ArgError("--area: scripts/synth.py is neither in this installation nor in the source tree it was built from");
      synth.version = synthToolVersion(synth.script);
    } else if (!synth_cache_.empty()) {
      throw ArgError("--synth-cache applies only with --area");
    }

    const SweepPlan plan = SweepPlan::make(planJson(cfg, base_table.request, grid, synth.version));
    claimSweepDir(dir_, plan);
    SweepRecords done = readSweepRecords(dir_, plan);
    if (!done.empty() && !quiet_)
      std::fprintf(stderr, "sweep %s: resuming, %zu of %llu points already recorded in %s\n", plan.hash.c_str(),
                   done.size(), static_cast<unsigned long long>(grid.size()), dir_.c_str());
    const unsigned jobs = jobs_ > 0 ? jobs_ : std::max(1u, std::thread::hardware_concurrency());
    {
      Progress progress(fmt::format("sweep {} ({} points{})", plan.hash, grid.size(),
                                    shard.count > 1 ? fmt::format(", shard {}/{}", shard.index, shard.count) : ""),
                        !quiet_);
      const PromRequest req = base_table.request;
      runSweepPoints(
          dir_, plan, shard, jobs,
          [&](uint64_t k) {
            return evaluateSpecPoint(k, specPointParams(cfg.rtl, grid.point(k)), req, area_.empty() ? nullptr : &synth);
          },
          done,
          [&, base = std::optional<uint64_t>()](uint64_t d, uint64_t n) mutable {
            if (!base) base = d;  // the points recorded before this run: not counted in its rate
            progress.update(static_cast<double>(d - *base), static_cast<double>(n - *base), "points");
          });
    }
    if (!missingPoints(plan, done).empty()) {
      std::printf("sweep %s: shard %llu/%llu recorded in %s; join the shards with shadesim sweep-merge\n",
                  plan.hash.c_str(), static_cast<unsigned long long>(shard.index),
                  static_cast<unsigned long long>(shard.count), dir_.c_str());
      return kExitOk;
    }
    writeSweepResults(dir_, plan, done);
    std::printf("sweep %s: %llu points; %s/sweep.csv, sweep.json, pareto.csv\n", plan.hash.c_str(),
                static_cast<unsigned long long>(grid.size()), dir_.c_str());
    return kExitOk;
  }

 private:
  // Every point's parameters, and every distinct coefficient format's PROM, before any work: a
  // point that breaks a derivation or whose coefficients do not fit stops the sweep here.
  static void validatePoints(const Grid& grid, const SpecUnitParams& base, const PromRequest& req) {
    std::set<std::tuple<int, int, int, int, int>> tables;  // the coefficient formats built
    for (uint64_t k = 0; k < grid.size(); ++k) {
      const auto values = grid.point(k);
      const SpecUnitParams p = argOr(specPointParams, base, values);
      const auto key = std::make_tuple(p.Degree, p.CosFracBits, p.ShinBits, p.CoefIntBits, p.CoefFracBits);
      if (!tables.insert(key).second) continue;
      try {
        buildPromTable(req, p);
      } catch (const std::invalid_argument& e) {
        std::string where;
        for (const auto& [name, value] : values) where += fmt::format("{}{}={}", where.empty() ? "" : " ", name, value);
        throw ArgError(fmt::format("point {} ({}): {}", k, where, e.what()));
      }
    }
  }

  // The plan; with --area it names the synthesis tools (synthToolVersion), so that a sweep does
  // not resume with another yosys or flow.
  nlohmann::json planJson(const SpecUnitConfig& cfg, const PromRequest& req, const Grid& grid,
                          const std::string& synth_tools) const {
    nlohmann::json axes = nlohmann::json::array();
    std::string command = fmt::format("shadesim sweep --unit {} --config {} --fit {} --level {} --{} {}{}", unit_,
                                      cfg.ref(), toString(req.fit), req.level, req.n.is_list ? "n-list" : "n",
                                      req.n.text, area_.empty() ? "" : " --area " + area_);
    for (const GridAxis& a : grid.axes()) {
      axes.push_back({{"name", a.name}, {"text", a.text}, {"values", a.values}});
      command += fmt::format(" --param {}={}", a.name, a.text);
    }
    return {{"format", "shadesim sweep 1"},
            {"tool", std::string("shadesim ") + SHD_VERSION},
            {"command", command},
            {"unit", unit_},
            {"base", {{"config", cfg.ref()}, {"rtl", cfg.rtl.toJson()}}},
            {"prom", req.describe()},
            {"area", area_.empty() ? "none" : area_ + " (" + synth_tools + ")"},
            {"axes", axes},
            {"points", grid.size()}};
  }

  TableOptions table_;
  std::string unit_ = "spec", shard_, dir_, area_, synth_cache_;
  std::vector<std::string> params_;
  unsigned jobs_ = 0;
  bool quiet_ = false;
};

class SweepMergeCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("dirs", dirs_, "the shards' directories")->required();
    app.add_option("-o,--output", out_, "the merged sweep's directory (must exist)")->required();
  }

  int run(const CLI::App&) override {
    mergeSweeps(dirs_, out_);
    std::printf("merged %zu directories into %s: sweep.csv, sweep.json, pareto.csv\n", dirs_.size(), out_.c_str());
    return kExitOk;
  }

 private:
  std::vector<std::string> dirs_;
  std::string out_;
};

}  // namespace

std::unique_ptr<Command> makeSweepCmd() { return std::make_unique<SweepCmd>(); }
std::unique_ptr<Command> makeSweepMergeCmd() { return std::make_unique<SweepMergeCmd>(); }

}  // namespace shd::cli
