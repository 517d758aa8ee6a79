// shadesim cosim: a verilated unit against its golden model, every output on every cycle
// (cosim/spec_cosim.h, cosim/span_cosim.h).
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli/command.h"
#include "cli/options.h"
#include "cli/progress.h"
#include "cli/table_options.h"
#include "cosim/span_cosim.h"
#include "cosim/spec_cosim.h"
#include "device/prom_io.h"
#include "raster/desc_stream.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd::cli {

namespace {

class CosimCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--unit", unit_, "unit under test: spec (specular unit) or span (span unit)")
        ->check(CLI::IsMember({"spec", "span"}))
        ->default_val("spec");
    app.add_option("--mode", mode_, "span unit: its configuration (lane mode), " + configChoices("span"));
    app.add_option("--triangles", triangles_, "span unit: seeded random triangles (raster/trigen.h classes)")
        ->check(countIn(1, kMaxStreamTriangles));
    app.add_option("--ready", ready_prob_, "span unit: probability that the consumer is ready on a cycle")
        ->check(realIn(kMinReady, 1.0));
    app.add_option("--drain-every", drain_every_,
                   "span unit: after this many descriptors, offer none until the unit is idle, so that a failing "
                   "case replays from a short window (the full-rate unit is otherwise never idle); 0: never")
        ->check(countIn(0, kMaxStreamTriangles));
    app.add_option("--threads", threads_,
                   "span unit: 2 runs the stimulus and the model on a second thread, ahead of the verilated unit "
                   "(the same result); default 2 where the machine has two hardware threads, else 1")
        ->check(countIn(1, 2));
    table_.add(app);
    app.add_option("--prom", prom_, "PROM hex file the RTL loads (default: the table written to a temporary file); "
                                    "it must hold the table the options describe");
    app.add_flag("--exhaustive", exhaustive_, "every (shininess code, cos code) pair, valid on every cycle");
    app.add_option("--vectors", vectors_, "random vectors (without --exhaustive)")->check(countIn(1, kMaxVectors));
    app.add_option("--seed", seed_, "random seed")->check(countIn(0, UINT64_MAX));
    app.add_option("--gap", gap_, "probability of dropping valid_i for 1..3 cycles (random mode)")
        ->check(realIn(0.0, kMaxGap));
    app.add_option("--fail-dir", fail_dir_, "where a failing case's FST waveform and vector file go");
    app.add_flag("--json", json_, "print the result as one JSON object on stdout");
    app.add_flag("--quiet", quiet_, "no progress on stderr");
  }

  int run(const CLI::App& app) override {
    requireDirectoryArg("--fail-dir", fail_dir_);
    if (unit_ == "span") {
      requireAbsent(app, {"--config", "--fit", "--level", "--degree", "--n", "--n-list", "--coef-format", "--prom",
                          "--exhaustive", "--vectors", "--gap"},
                    "applies to --unit spec only");
      return runSpan();
    }
    requireAbsent(app, {"--mode", "--triangles", "--ready", "--drain-every", "--threads"}, "applies to --unit span only");
    if (exhaustive_) requireAbsent(app, {"--vectors", "--gap"}, "and --exhaustive exclude each other");
    return runSpec();
  }

 private:
  TableOptions table_;
  std::string unit_ = "spec", prom_, fail_dir_ = ".", mode_ = "serial";
  uint64_t triangles_ = 100000, drain_every_ = SpanCosimOptions{}.drain_every;
  int threads_ = std::thread::hardware_concurrency() >= 2 ? 2 : 1;
  double ready_prob_ = 0.8;
  bool exhaustive_ = false, json_ = false, quiet_ = false;
  uint64_t vectors_ = 1'000'000, seed_ = 1;
  double gap_ = 0.2;

  int runSpan();
  int runSpec();
  void printSpec(const SpecCosimResult& r, const PromTable& t, const std::string& prom_path) const;
};

int CosimCmd::runSpan() {
  const SpanUnitConfig cfg = spanConfigArg("--mode", mode_);
  try {
    requireVerilated(cfg);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--mode {}: {}", mode_, e.what()));
  }
  RasterConfig rc;
  rc.unit = cfg.rtl;
  DescriptorStream descs(seed_, triangles_, rc);
  auto next = [&](SpanDesc& d) { return descs.next(d); };
  Progress progress(fmt::format("cosim span/{}", cfg.name), !quiet_);
  SpanCosimOptions o;
  o.seed = seed_;
  o.ready_prob = ready_prob_;
  o.drain_every = drain_every_;
  o.threads = threads_;
  o.fail_dir = fs::absolute(fail_dir_).string();
  o.progress = [&](uint64_t) {
    progress.update(static_cast<double>(descs.generated()), static_cast<double>(triangles_), "triangles");
  };
  const SpanCosimResult r = runSpanCosim(cfg.name, next, o);
  if (json_) {
    nlohmann::json j = {{"unit", "span"},
                        {"mode", cfg.name},
                        {"seed", seed_},
                        {"threads", threads_},
                        {"triangles", r.triangles},
                        {"generated", descs.generated()},
                        {"dropped_at_setup", descs.dropped()},
                        {"fragments", r.fragments},
                        {"cycles", r.cycles},
                        {"mismatches", r.mismatches},
                        {"seconds", r.seconds},
                        {"fragments_per_second", r.seconds > 0 ? r.fragments / r.seconds : 0.0}};
    if (r.first)
      j["first_mismatch"] = {{"cycle", r.first->cycle}, {"triangle", r.first->tag}, {"what", r.first->what},
                             {"fst", r.fst_path},       {"case", r.case_path},    {"vectors", r.vector_path}};
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("cosim span/%s seed %llu: %llu triangles drawn (%llu generated, %llu dropped by setup), %llu fragments, "
                "%llu cycles, %llu mismatches, %.2f s on %d thread%s (%.1f M fragments/s)\n",
                cfg.name.c_str(), static_cast<unsigned long long>(seed_), static_cast<unsigned long long>(r.triangles),
                static_cast<unsigned long long>(descs.generated()), static_cast<unsigned long long>(descs.dropped()),
                static_cast<unsigned long long>(r.fragments), static_cast<unsigned long long>(r.cycles),
                static_cast<unsigned long long>(r.mismatches), r.seconds, threads_, threads_ == 1 ? "" : "s",
                r.seconds > 0 ? r.fragments / r.seconds / 1e6 : 0.0);
  }
  if (r.first) {
    std::fprintf(stderr, "MISMATCH (first of %llu) cycle %llu, triangle %u: %s\n",
                 static_cast<unsigned long long>(r.mismatches), static_cast<unsigned long long>(r.first->cycle),
                 r.first->tag, r.first->what.c_str());
    if (r.case_note.empty())
      std::fprintf(stderr, "waveform: %s\nvectors:  %s\ncase:     %s\n", r.fst_path.c_str(), r.vector_path.c_str(),
                   r.case_path.c_str());
    else
      std::fprintf(stderr, "%s\n", r.case_note.c_str());
    return 1;
  }
  return 0;
}

int CosimCmd::runSpec() {
  SpecUnitConfig cfg;
  const PromTable t = table_.build(cfg, false);
  // The RTL side is the configuration verilated into this binary: its parameters must be the
  // ones the model is built with (after --degree / --coef-format).
  cfg.rtl = t.unit;
  try {
    requireVerilated(cfg);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--config {} (after --degree/--coef-format): {}", table_.config, e.what()));
  }
  std::string prom_path = prom_;
  if (!prom_path.empty()) noteInput(prom_path);
  fs::path tmp_dir;
  if (prom_path.empty()) {
    tmp_dir = fs::temp_directory_path() / fmt::format("shadesim-{}", getpid());
    fs::create_directories(tmp_dir);
    prom_path = (tmp_dir / fmt::format("spec_{}.hex", cfg.name)).string();
    writePromHexFiles(prom_path, t);
  }
  prom_path = fs::absolute(prom_path).string();
  SpecUnitModel model(t.unit, t.words, t.seg_words);
  std::unique_ptr<SpecStimulus> stim;
  if (exhaustive_) stim = std::make_unique<ExhaustiveSpecStimulus>(t.unit, seed_);
  else stim = std::make_unique<RandomSpecStimulus>(t.unit, seed_, vectors_, gap_);
  Progress progress(fmt::format("cosim spec/{}", cfg.name), !quiet_);
  SpecCosimOptions o;
  o.prom_path = prom_path;
  o.fail_dir = fs::absolute(fail_dir_).string();
  o.progress = [&](uint64_t done, uint64_t total) { progress.update(done, total, "vectors"); };
  SpecCosimResult r;
  try {
    r = runSpecCosim(cfg.name, model, *stim, o);
  } catch (...) {
    if (!tmp_dir.empty()) fs::remove_all(tmp_dir);
    throw;
  }
  if (!tmp_dir.empty()) fs::remove_all(tmp_dir);
  printSpec(r, t, prom_path);
  if (r.first) {
    std::fprintf(stderr, "MISMATCH (first of %llu) %s\nwaveform: %s\nvectors:  %s\n",
                 static_cast<unsigned long long>(r.mismatches), r.first->describe(t.unit).c_str(), r.fst_path.c_str(),
                 r.vector_path.c_str());
    return 1;
  }
  return 0;
}

void CosimCmd::printSpec(const SpecCosimResult& r, const PromTable& t, const std::string& prom_path) const {
  const double rate = r.seconds > 0 ? r.vectors / r.seconds : 0;
  if (json_) {
    nlohmann::json j = {{"unit", "spec"},
                        {"config", r.config},
                        {"mode", exhaustive_ ? "exhaustive" : "random"},
                        {"seed", seed_},
                        {"prom", prom_.empty() ? std::string("(temporary)") : prom_path},
                        {"table", t.request.describe()},
                        {"vectors", r.vectors},
                        {"cycles", r.cycles},
                        {"mismatches", r.mismatches},
                        {"seconds", r.seconds},
                        {"vectors_per_second", rate}};
    if (r.first) {
      j["first_mismatch"] = {{"cycle", r.first->cycle},
                             {"description", r.first->describe(t.unit)},
                             {"fst", r.fst_path},
                             {"vectors", r.vector_path}};
    }
    std::cout << j.dump(2) << "\n";
  } else {
    std::printf("cosim spec/%s %s seed %llu: %llu vectors, %llu cycles, %llu mismatches, %.2f s (%.1f M vectors/s)\n",
                r.config.c_str(), exhaustive_ ? "exhaustive" : "random", static_cast<unsigned long long>(seed_),
                static_cast<unsigned long long>(r.vectors), static_cast<unsigned long long>(r.cycles),
                static_cast<unsigned long long>(r.mismatches), r.seconds, rate / 1e6);
  }
}

}  // namespace

std::unique_ptr<Command> makeCosimCmd() { return std::make_unique<CosimCmd>(); }

}  // namespace shd::cli
