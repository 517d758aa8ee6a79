// shadesim_systemc: SystemC co-simulation of the verilated specular unit or span unit against
// the golden model. One run per process (a SystemC simulation elaborates once):
//
//   shadesim_systemc --unit spec --config default --vectors 100000 --seed 1
//   shadesim_systemc --unit spec --config wide --vector-file vectors/cycles/spec_wide.vec
//   shadesim_systemc --unit span --config sierpinski --triangles 2000 --seed 3
//   shadesim_systemc --unit span --config serial --scene builtin:sphere [--fst span.fst] [--json]
//
// sc_main builds the sc_clock (10 ns) and the reset generator; the unit's runner
// (sc_run_spec.cpp, sc_run_span.cpp) adds the verilated unit (chosen by --config), the driver,
// the golden-model module and the scoreboard (spec_tb.h, span_tb.h), runs until the driver has
// drained the stimulus (or the scoreboard has seen --max-mismatches), and reports the counts,
// the simulated cycles and the wall time. Exit status: 0 every sample and every result/fragment
// equal in value and cycle; 1 a mismatch (the first one printed with its time, signal and both
// values); 2 bad input.
//
// On the first mismatching sample the runner saves the failing case alone, from reset, as a
// vector file <fail-dir>/<unit>_<config>_fail.vec (sc_run.h, ScFailCase); sc_main then replays
// it in a child process of this program, which writes its FST waveform and must fail at the
// file's last cycle (sc_fail_case.h), and reports both paths.
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <new>
#include <string>

#include <systemc>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "io/files.h"
#include "sc_fail_case.h"
#include "sc_run.h"

using namespace shd;

namespace {

struct OptionRefs {
  CLI::Option *vectors = nullptr, *triangles = nullptr, *gap = nullptr, *ready = nullptr, *desc_gap = nullptr;
};

// The command line: the run's options and what sc_main itself does with the result.
struct CommandLine {
  ScOptions o;
  OptionRefs given;  // the options whose presence matters, not only their value
  bool json = false;
  bool no_fail_save = false;
};

void addOptions(CLI::App& app, CommandLine& c) {
  ScOptions& o = c.o;
  OptionRefs& given = c.given;
  app.add_option("--unit", o.unit, "spec (specular unit) or span (span unit)")
      ->required()
      ->check(CLI::IsMember({"spec", "span"}));
  app.add_option("--config", o.config,
                 "configuration (vectors/config/<unit>_<name>.json); default: default (spec), serial (span)");
  given.vectors = app.add_option("--vectors", o.vectors, "spec: seeded random vectors (default 20000)")
                      ->check(cli::countIn(1, cli::kMaxVectors));
  app.add_option("--vector-file", o.vector_file,
                 "replay a vector file (sim/vectors/vector_file.h, e.g. vectors/cycles/<unit>_<config>.vec): its "
                 "inputs, and its expected outputs checked as well")
      ->check(CLI::ExistingFile);
  app.add_option("--save-vectors", o.save_vectors,
                 "write the run as a vector file: the inputs on the ports every cycle and the golden model's outputs");
  given.gap = app.add_option("--gap", o.gap, "spec: probability of dropping valid_i for 1..3 cycles (default 0.2)")
                  ->check(cli::realIn(0.0, cli::kMaxGap));
  app.add_option("--prom", o.prom,
                 "spec: PROM hex file (default: the vector file's, else vectors/prom/spec_<config>.hex); it must hold "
                 "the configuration's table");
  given.triangles = app.add_option("--triangles", o.triangles,
                                   "span: seeded generator triangles (default 1000); with --scene: at most this many of "
                                   "the scene's descriptors")
                        ->check(cli::countIn(1, cli::kMaxStreamTriangles));
  app.add_option("--scene", o.scene, "span: the descriptors of a scene's frame, e.g. builtin:sphere");
  given.ready = app.add_option("--ready", o.ready, "span: probability that out_ready is high on a cycle (default 0.8)")
                    ->check(cli::realIn(cli::kMinReady, 1.0));
  given.desc_gap = app.add_option("--desc-gap", o.desc_gap,
                                  "span: probability that a descriptor waits 1..3 cycles before it is offered "
                                  "(default 0.1)")
                       ->check(cli::realIn(0.0, cli::kMaxGap));
  app.add_option("--seed", o.seed, "random seed (stimulus and back-pressure)")->check(cli::countIn(0, UINT64_MAX));
  app.add_option("--fst", o.fst, "write an FST waveform of the unit (every signal) to this file");
  app.add_option("--fault", o.fault,
                 "fault injection in the golden-model module, to see the scoreboard fail: latency (predictions one "
                 "cycle late) or value (spec: one bit less of c^2 - c; span: attribute 0 one code off)")
      ->check(CLI::IsMember({"none", "latency", "value"}));
  app.add_option("--max-mismatches", o.max_mismatches, "stop after this many mismatches (default 16)")
      ->check(cli::countIn(1, 1'000'000));
  app.add_option("--fail-dir", o.fail_dir,
                 "on a mismatch, save the failing case alone here: <unit>_<config>_fail.vec (from reset, the failing "
                 "cycle last; spec: and the PROM copy .hex) and the FST waveform of its replay, "
                 "<unit>_<config>_fail.fst (default: the current directory)");
  app.add_flag("--no-fail-save", c.no_fail_save, "do not save the failing case (the replay of a saved case runs so)");
  app.add_flag("--json", c.json, "print the result as one JSON object on stdout");
  app.add_flag("--quiet", o.quiet, "no progress on stderr");
}

// Cross-option checks CLI11 cannot express.
void checkOptions(const ScOptions& o, const OptionRefs& given) {
  auto only = [&](bool is_given, const char* opt, const char* unit) {
    if (is_given) throw ArgError(fmt::format("{} applies to --unit {} only", opt, unit));
  };
  const bool spec = o.unit == "spec";
  only(!spec && given.vectors->count() > 0, "--vectors", "spec");
  only(!spec && !o.prom.empty(), "--prom", "spec");
  only(!spec && given.gap->count() > 0, "--gap", "spec");
  only(spec && given.triangles->count() > 0, "--triangles", "span");
  only(spec && !o.scene.empty(), "--scene", "span");
  only(spec && given.ready->count() > 0, "--ready", "span");
  only(spec && given.desc_gap->count() > 0, "--desc-gap", "span");
  if (!o.vector_file.empty()) {
    for (auto [opt, name] : {std::pair{given.vectors, "--vectors"}, {given.gap, "--gap"}, {given.triangles, "--triangles"},
                             {given.ready, "--ready"}, {given.desc_gap, "--desc-gap"}})
      if (opt->count() > 0) throw ArgError(fmt::format("{} and --vector-file exclude each other (the file is the stimulus)", name));
    if (!o.scene.empty()) throw ArgError("--scene and --vector-file exclude each other");
  }
}

// The unit's run between sc_main's clock and reset generator.
ScReport runUnit(const ScOptions& o) {
  // 10 ns clock, rising edges at 10, 20, ... ns (sc_common.h); rst_n low from time 0.
  sc_core::sc_clock clk("clk", scPeriod(), 0.5, scPeriod(), true);
  sc_core::sc_signal<bool> rst_n("rst_n", false);
  ScResetGen reset("reset");
  reset.clk(clk);
  reset.rst_n(rst_n);
  return o.unit == "spec" ? runSpecSc(o, clk, rst_n) : runSpanSc(o, clk, rst_n);
}

// The failing case the run saved, replayed alone in a child process (sc_fail_case.h).
struct FailReplay {
  ScFailReplay replay;
  bool reproduced = false;  // it fails at its last cycle, as the run did
};

nlohmann::json toJson(const ScReport::Value& v) {
  return std::visit([](const auto& x) { return nlohmann::json(x); }, v);
}

nlohmann::json failCaseJson(const ScFailCase& fc, const FailReplay& fr) {
  nlohmann::json f = {{"saved", !fc.vec.empty()}};
  if (fc.vec.empty()) {
    f["not_saved"] = fc.not_saved;
    return f;
  }
  const ScFailReplay& replay = fr.replay;
  f["vectors"] = fc.vec;
  if (!fc.prom.empty()) f["prom"] = fc.prom;
  f["fst"] = fc.fst;
  f["cycles"] = fc.cycles;
  f["run_cycles"] = {fc.run_first, fc.run_first + fc.cycles - 1};
  f["replay"] = {{"command", replay.command()},
                 {"status", replay.status},
                 {"mismatch_file_cycle", replay.mismatch_cycle},
                 {"file_mismatch_cycle", replay.file_mismatch_cycle},
                 {"first_mismatch", replay.first},
                 {"fst_written", replay.fst_written},
                 {"fails_at_last_cycle", fr.reproduced}};
  if (!replay.error.empty()) f["replay"]["error"] = replay.error;
  return f;
}

// --json: the report as one object.
nlohmann::json reportJson(const ScOptions& o, const ScReport& r, const FailReplay& fr) {
  const ScScore& s = r.score;
  nlohmann::json j = {{"unit", o.unit}, {"config", o.config}, {"fault", o.fault}};
  for (const auto& [key, value] : r.fields) j[key] = toJson(value);
  j["samples"] = s.samples;
  j["sample_mismatches"] = s.sample_mismatches;
  j["item_mismatches"] = s.item_mismatches;
  j["passed"] = s.passed() && r.complete;
  if (!s.first.empty()) j["first_mismatch"] = s.first;
  if (!s.first_item.empty()) j["first_item_mismatch"] = s.first_item;
  if (!r.complete) j["incomplete"] = r.incomplete;
  if (!o.fst.empty()) j["fst"] = o.fst;
  if (r.fail.attempted) j["fail_case"] = failCaseJson(r.fail, fr);
  return j;
}

// A failed run on stderr: the first mismatches, what is incomplete, the files written.
void printFailure(const ScOptions& o, const ScReport& r) {
  const ScScore& s = r.score;
  const char* items = o.unit == "spec" ? "results" : "fragments";
  if (!s.first.empty())
    std::fprintf(stderr, "MISMATCH (first of %llu samples) %s\n", static_cast<unsigned long long>(s.sample_mismatches),
                 s.first.c_str());
  if (!s.first_item.empty())
    std::fprintf(stderr, "MISMATCH (first of %llu %s) %s\n", static_cast<unsigned long long>(s.item_mismatches), items,
                 s.first_item.c_str());
  if (s.mismatches() == 0 && s.expected_items != s.observed_items)
    std::fprintf(stderr, "MISMATCH the model predicts %llu %s, the RTL delivered %llu\n",
                 static_cast<unsigned long long>(s.expected_items), items,
                 static_cast<unsigned long long>(s.observed_items));
  if (!r.complete) std::fprintf(stderr, "INCOMPLETE %s\n", r.incomplete.c_str());
  if (!o.fst.empty()) std::fprintf(stderr, "waveform: %s\n", o.fst.c_str());
  if (!o.save_vectors.empty()) std::fprintf(stderr, "vectors:  %s\n", o.save_vectors.c_str());
}

// The failing case on stderr: where it was saved and whether its replay reproduced the failure,
// or why it was not saved and how to keep the case.
void printFailCase(const ScOptions& o, const ScFailCase& fc, const FailReplay& fr) {
  const ScFailReplay& replay = fr.replay;
  if (fc.vec.empty()) {
    if (fc.attempted) std::fprintf(stderr, "failing case not saved: %s\n", fc.not_saved.c_str());
    if (o.save_vectors.empty())
      std::fprintf(stderr, "to keep this case: the same command with --save-vectors <file.vec> --fst <file.fst> (the "
                           "run is deterministic); the file replays alone (--vector-file, shadesim replay, Icarus)\n");
    return;
  }
  std::string saved = fmt::format("failing case: {} ({} cycles from reset, the run's cycles {}..{} after reset, the "
                                  "failing one last{})",
                                  fc.vec, fc.cycles, fc.run_first, fc.run_first + fc.cycles - 1,
                                  fc.prom.empty() ? std::string() : "; PROM " + fc.prom);
  std::fprintf(stderr, "%s\n", saved.c_str());
  if (replay.fst_written)
    std::fprintf(stderr, "failing case waveform: %s (gtkwave %s)\n", fc.fst.c_str(), fc.fst.c_str());
  else
    std::fprintf(stderr, "failing case waveform: NOT WRITTEN (%s)\n", fc.fst.c_str());
  if (fr.reproduced) {
    std::fprintf(stderr, "replayed alone (%s): fails at its last cycle %llu, as the run did: %s\n",
                 replay.command().c_str(), static_cast<unsigned long long>(fc.cycles), replay.first.c_str());
    return;
  }
  // Both sides, so that the difference can be judged.
  std::string why = !replay.error.empty() ? replay.error
                    : replay.status == 0  ? std::string("it passes")
                                          : fmt::format("exit status {}, first mismatch at file cycle {} (against "
                                                        "the file: cycle {}): {}",
                                                        replay.status, replay.mismatch_cycle,
                                                        replay.file_mismatch_cycle, replay.first);
  std::fprintf(stderr, "REPLAY DOES NOT REPRODUCE the failure at the file's last cycle %llu (%s): %s; the run: %s\n",
               static_cast<unsigned long long>(fc.cycles), replay.command().c_str(), why.c_str(), fc.what.c_str());
}

}  // namespace

int sc_main(int argc, char* argv[]) {
  CommandLine c;
  ScOptions& o = c.o;
  CLI::App app{"shadesim_systemc: the verilated specular or span unit in a SystemC testbench (clock, reset, driver, "
               "golden-model module, scoreboard), checked value by value and cycle by cycle"};
  addOptions(app, c);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return cli::parseErrorExit(app, e, "shadesim_systemc");
  }
  if (o.config.empty()) o.config = o.unit == "spec" ? "default" : "serial";
  o.argv0 = argv[0];
  o.save_fail = !c.no_fail_save;
  o.triangles_given = c.given.triangles->count() > 0;

  ScReport r;
  try {
    const RunInputs inputs;  // the files the run reads may not be its outputs (io/files.h)
    checkOptions(o, c.given);
    cli::requireDirectoryArg("--fail-dir", o.fail_dir);
    r = runUnit(o);
  } catch (const std::bad_alloc&) {
    std::fprintf(stderr, "shadesim_systemc: error: out of memory\n");
    return cli::kExitBadInput;
  } catch (const std::exception& e) {  // ArgError, files, configurations, SystemC elaboration errors
    std::fprintf(stderr, "shadesim_systemc: error: %s\n", e.what());
    return cli::kExitBadInput;
  }

  const ScFailCase& fc = r.fail;
  FailReplay fr;
  if (!fc.vec.empty()) {
    fr.replay = replayFailCase(o, fc);
    fr.reproduced = fr.replay.failsAtLastCycle(fc.cycles);
  }
  if (c.json) std::cout << reportJson(o, r, fr).dump(2) << std::endl;
  else std::cout << r.summary << std::endl;
  if (r.score.passed() && r.complete) return cli::kExitOk;
  printFailure(o, r);
  printFailCase(o, fc, fr);
  return cli::kExitFailed;
}

// Our own main (IEEE 1666 lets an application call sc_elab_and_sim itself), only to keep the
// SystemC banner off the console: stdout carries the result (--json), stderr the progress and
// failures. libsystemc prints the banner before sc_main runs unless this variable is set.
int main(int argc, char* argv[]) {
  setenv("SYSTEMC_DISABLE_COPYRIGHT_MESSAGE", "1", 0);
  return sc_core::sc_elab_and_sim(argc, argv);
}
