// One shadesim_systemc run: the options of the command line (sc_main.cpp) and what a run of
// either unit reports (sc_run_spec.cpp, sc_run_span.cpp). Kept free of CLI11 and JSON headers so
// that the runners, the heavy SystemC translation units, compile in parallel with sc_main.cpp.
#pragma once

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <systemc>

#include <fmt/format.h>

#include "cli/progress.h"
#include "sc_common.h"

namespace shd {

// Bad input (an argument, a file, a configuration): a message naming it, exit status 2.
struct ArgError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

struct ScOptions {
  std::string unit, config, vector_file, save_vectors, scene, prom, fst, fault = "none";
  uint64_t vectors = 20000, triangles = 1000, seed = 1, max_mismatches = 16;
  bool triangles_given = false;
  double gap = 0.2, ready = 0.8, desc_gap = 0.1;
  bool quiet = false;
  std::string fail_dir = ".";  // where the failing case is saved (sc_fail_case.h)
  bool save_fail = true;       // --no-fail-save: not (the replay of a saved case runs so)
  std::string argv0;           // to run this program again if /proc/self/exe is unavailable
};

// The failing case a run saved at its first mismatch: a vector file that holds it alone, from
// reset, its failing cycle last (bounded: the specular unit's last latency + 8 cycles, the span
// unit's current triangle from the cycle that accepted it). sc_main then replays it in a child
// process that writes the FST (sc_fail_case.h).
struct ScFailCase {
  bool attempted = false;       // the run had a first mismatching sample
  std::string vec;              // the vector file; empty: not saved (why: not_saved)
  std::string prom;             // spec: the PROM copy the file names
  std::string fst;              // the waveform the replay writes
  uint64_t cycles = 0;          // cycles in the file, the failing one last
  uint64_t run_first = 0;       // the run's cycle (1-based from reset) of the file's first one
  std::string what;             // the run's first mismatch (the scoreboard's line)
  std::string not_saved;
};

struct ScReport {
  using Value = std::variant<uint64_t, double, bool, std::string>;
  std::vector<std::pair<std::string, Value>> fields;  // unit-specific counts, in print order
  std::string summary;                                // one line
  ScScore score;
  bool complete = true;    // every stimulus item went through
  std::string incomplete;  // why not
  ScFailCase fail;
  void add(std::string key, Value v) { fields.emplace_back(std::move(key), std::move(v)); }
};

// Each builds the unit's testbench around clk and rst_n (already bound to the reset generator),
// runs it to the end and returns the report. ArgError for bad input.
ScReport runSpecSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n);
ScReport runSpanSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n);

// An output file named by `option`: its directory is created and the file opened for writing
// now, so that a path that cannot be written fails before the run (ArgError), not after it.
inline void prepareOutput(const std::string& path, const char* option) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::absolute(path).parent_path();
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw ArgError(fmt::format("{} {}: cannot create {}: {}", option, path, dir.string(), ec.message()));
  std::ofstream probe(path, std::ios::app);
  if (!probe) throw ArgError(fmt::format("{} {}: cannot write it", option, path));
}

// The paths of a failing case: <fail-dir>/<unit>_<config>_fail.<ext>.
inline std::string failPath(const ScOptions& o, const char* ext) {
  const std::string name = fmt::format("{}_{}_fail.{}", o.unit, o.config, ext);
  if (o.fail_dir.empty() || o.fail_dir == ".") return name;
  return (std::filesystem::path(o.fail_dir) / name).string();
}

// The run's first mismatching sample, as the runners capture it for the failing case.
template <class Out>
struct ScFirstMismatch {
  sc_core::sc_time sample;  // its rising edge
  Out expected;             // the expectation it failed
  bool from_file = false;   // ... the vector file's (else the golden model's)
};

// sc_start() in slices of 20000 cycles until ctl.done, progress on stderr (unless quiet) as
// done() of total.
inline void scSimulate(ScRunControl& ctl, bool quiet, const std::string& what, const char* unit, double total,
                       const std::function<double()>& done) {
  Progress progress(what, !quiet);
  while (!ctl.done) {
    sc_core::sc_start(20000 * scPeriod());
    progress.update(done(), total, unit);
  }
}

}  // namespace shd
