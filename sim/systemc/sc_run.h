// One shadesim_systemc run: the options of the command line (sc_main.cpp), what a run of either
// unit reports (sc_run_spec.cpp, sc_run_span.cpp), and what both runners share (sc_run.cpp).
// Kept free of CLI11, JSON and Verilator headers so that the runners, the heavy SystemC
// translation units, compile in parallel with sc_main.cpp.
#pragma once

#include <cstdint>
#include <functional>
#include <stdexcept>
#include <string>
#include <utility>
#include <variant>
#include <vector>

#include <systemc>

#include "cli/options.h"
#include "sc_common.h"

class VerilatedFstC;
class VerilatedFstSc;

namespace shd {

// Bad input (an argument, a file, a configuration): a message naming it, exit status 2.
using cli::ArgError;

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

// --- Shared by the runners (sc_run.cpp) ---

// ArgError unless this program holds a SystemC model of configuration o.config of `unit`
// ("specular unit", "span unit"); built: the configurations it holds.
void requireBuilt(const ScOptions& o, const std::vector<std::string>& built, const char* unit);

// ArgError for a --vector-file made for other parameters than the unit's (each as text).
void requireFileParams(const ScOptions& o, const std::string& file_config, const std::string& file_params,
                       const std::string& unit_params);

// The output files named by --save-vectors and --fst, checked by the output policy (io/files.h)
// after the inputs are read and before the run, so that a path that cannot be written fails
// before the run (ArgError), not after it; the program's directories are never created.
void prepareOutputs(const ScOptions& o);

// The stimulus as the command line gave it: "--vector-file F", "--scene S", "--seed N --vectors M"
// (spec) or "--seed N --triangles M" (span). The source lines of the files a run writes name it.
std::string stimulusArgs(const ScOptions& o);
// The source line of the --save-vectors file.
std::string savedVectorsSource(const ScOptions& o);

// The --fst waveform: every signal of the verilated unit.
class ScWaveform {
 public:
  // Before the unit's model is built (Verilated::traceEverOn, or it traces nothing); path empty:
  // no waveform.
  explicit ScWaveform(std::string path);
  // After elaboration (VerilatedFstSc::open requires it): trace adds the unit's signals.
  void open(const std::function<void(VerilatedFstC&)>& trace);
  void close();

 private:
  std::string path_;
  // The kernel keeps the trace file in its list until the process ends, so it is not deleted.
  VerilatedFstSc* tfp_ = nullptr;
};

// The simulated cycles of a run and the wall time they took.
struct ScRunTime {
  uint64_t cycles = 0;
  double secs = 0;
  // "<cycles> cycles simulated in <secs> s wall (<rate> cycles/s)", for the summaries.
  std::string describe() const;
};

// sc_start() in slices of 20000 cycles until ctl.done, progress on stderr (unless o.quiet) as
// done() of total `unit`s, under "systemc <unit>/<config>".
ScRunTime scSimulate(ScRunControl& ctl, const ScOptions& o, const char* unit, double total,
                     const std::function<double()>& done);

// The run's first mismatching sample, as the runners capture it for the failing case.
template <class Out>
struct ScFirstMismatch {
  sc_core::sc_time sample;  // its rising edge
  Out expected;             // the expectation it failed
  bool from_file = false;   // ... the vector file's (else the golden model's)
};

// The paths of a failing case: <fail-dir>/<unit>_<config>_fail.<ext>.
std::string failPath(const ScOptions& o, const char* ext);

// Saves a failing case of `cycles` cycles (ScFailCase), the first of them the run's cycle
// run_first; what: the run's first mismatch. With no cycle, nothing is saved and why_none says
// why. Else creates --fail-dir and has write() write the vector file at the path it is given;
// an exception it throws becomes the reason the case was not saved.
ScFailCase saveFailCase(const ScOptions& o, const std::string& what, uint64_t cycles, uint64_t run_first,
                        const char* why_none, const std::function<void(const std::string& vec)>& write);
// The failing case's source line ...
std::string failCaseSource(const ScOptions& o, uint64_t run_first, uint64_t cycles);
// ... and its note on where its expected outputs come from.
std::string failCaseExpectedNote(const ScOptions& o, bool from_file);

}  // namespace shd
