// shadesim replay: a vector file replayed on the verilated RTL, every output compared on every
// cycle (cosim/replay.h).
#include <cstdio>
#include <iostream>

#include <nlohmann/json.hpp>

#include "cli/command.h"
#include "cosim/replay.h"

namespace shd::cli {

namespace {

class ReplayCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("file", file_, "the vector file (vectors/cycles/*.vec, or a failing case saved by cosim)")
        ->required();
    app.add_option("--fst", fst_, "write an FST waveform of the replay (open it with gtkwave)");
    app.add_option("--prom", prom_, "spec: the PROM file to load instead of the file's '# prom'");
    app.add_flag("--json", json_, "print the result as one JSON object on stdout");
  }

  int run(const CLI::App&) override {
    // replayVectorFile checks the waveform's target by the output policy (io/files.h) once it
    // has read the file and its PROM: the FST writer is not atomic.
    ReplayOptions o;
    o.fst_path = fst_;
    o.prom_path = prom_;
    const ReplayResult r = replayVectorFile(file_, o);
    if (json_) {
      nlohmann::json j = {{"file", file_},          {"unit", r.unit},           {"config", r.config},
                          {"cycles", r.cycles},     {"results", r.results},     {"compared", r.compared},
                          {"mismatches", r.mismatches}, {"mismatching_cycles", r.mismatching_cycles}};
      if (!fst_.empty()) j["fst"] = fst_;
      if (r.first)
        j["first_mismatch"] = {{"cycle", r.first->cycle}, {"signal", r.first->signal},
                               {"expected", r.first->expected}, {"rtl", r.first->got}};
      std::cout << j.dump(2) << "\n";
    } else {
      std::printf("replay %s: %s/%s, %llu cycles, %llu %s, %llu output values compared, %llu mismatches\n",
                  file_.c_str(), r.unit.c_str(), r.config.c_str(), static_cast<unsigned long long>(r.cycles),
                  static_cast<unsigned long long>(r.results), r.unit == "spec" ? "valid results" : "valid lane outputs",
                  static_cast<unsigned long long>(r.compared), static_cast<unsigned long long>(r.mismatches));
    }
    if (!r.first) return 0;
    std::fprintf(stderr, "MISMATCH (first of %llu, in %llu cycles) %s\n", static_cast<unsigned long long>(r.mismatches),
                 static_cast<unsigned long long>(r.mismatching_cycles), r.first->describe().c_str());
    for (size_t i = 1; i < r.listed.size(); ++i) std::fprintf(stderr, "  then %s\n", r.listed[i].describe().c_str());
    if (!fst_.empty()) std::fprintf(stderr, "waveform: %s\n", fst_.c_str());
    return 1;
  }

 private:
  std::string file_, fst_, prom_;
  bool json_ = false;
};

}  // namespace

std::unique_ptr<Command> makeReplayCmd() { return std::make_unique<ReplayCmd>(); }

}  // namespace shd::cli
