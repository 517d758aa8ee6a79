// What the SystemC testbenches of both units share: the clock convention, the reset generator,
// the run control and the mismatch bookkeeping of the scoreboards.
//
// Clock and sampling convention (both units):
//   One sc_clock of period scPeriod() = 10 ns whose rising edges fall at k * 10 ns, k >= 1: the
//   rising edge at time t is clock cycle t / 10 ns. rst_n is low from time 0 and rises after the
//   ScResetGen's last reset edge (kResetCycles edges), in the delta after edge kResetCycles.
//   The drivers take their first step when rst_n rises, so the first active rising edge (edge
//   kResetCycles + 1) samples the first stimulus cycle: cycle i of a vector file is sampled at
//   edge kResetCycles + 1 + i, as the files count from reset.
//   Every testbench process is an SC_METHOD triggered by an edge (no SC_THREAD: no coroutine
//   stacks, which AddressSanitizer cannot follow, and cheaper). At a rising edge every process
//   reads the signals' values from before the edge (a signal written in this evaluation phase
//   changes only in the next delta), which are exactly the values the verilated model samples
//   at that edge; what a process writes there is seen by the model from the next edge on.
//   A "sample at time t" is the value of an output during the clock cycle that ends at the
//   rising edge at t: the scoreboard reads it at that edge, before the edge takes effect.
#pragma once

#include <cstdint>
#include <string>
#include <utility>

#include <systemc>

#include <fmt/format.h>

namespace shd {

inline sc_core::sc_time scPeriod() { return sc_core::sc_time(10, sc_core::SC_NS); }
inline uint64_t scCycle(const sc_core::sc_time& t) { return static_cast<uint64_t>(t / scPeriod()); }
inline uint64_t scNs(const sc_core::sc_time& t) { return static_cast<uint64_t>(t / sc_core::sc_time(1, sc_core::SC_NS)); }
// "230 ns (cycle 23)"
inline std::string scWhen(const sc_core::sc_time& t) { return fmt::format("{} ns (cycle {})", scNs(t), scCycle(t)); }

constexpr int kResetCycles = 2;  // rising edges with rst_n low

// Shared by the modules of one run: the driver or the scoreboard sets done and pauses the
// simulation (sc_pause: sc_main's sc_start() returns, no "stopped by user" report).
struct ScRunControl {
  bool done = false;
  uint64_t max_mismatches = 16;
  void finish() {
    if (done) return;
    done = true;
    sc_core::sc_pause();
  }
};

// rst_n low for kResetCycles rising edges from time 0, then high.
class ScResetGen : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"};
  sc_core::sc_out<bool> rst_n{"rst_n"};

  explicit ScResetGen(const sc_core::sc_module_name& name) : sc_module(name) {
    SC_METHOD(onEdge);
    sensitive << clk.pos();
    dont_initialize();
  }
  SC_HAS_PROCESS(ScResetGen);

 private:
  void onEdge() {
    if (++edges_ == kResetCycles) rst_n.write(true);
  }
  int edges_ = 0;
};

// The scoreboards' counts and first failures.
struct ScScore {
  uint64_t samples = 0;            // output samples compared (every active cycle)
  uint64_t sample_mismatches = 0;  // samples with at least one differing signal
  uint64_t expected_items = 0;     // results (spec) or fragments (span) the model predicted
  uint64_t observed_items = 0;     // ... the RTL delivered
  uint64_t matched_items = 0;      // pairs equal in value and in time
  uint64_t item_mismatches = 0;    // pairs differing in value or time, plus unpaired items
  std::string first;               // first differing sample: time, signal, both values
  sc_core::sc_time first_time;     // ... the rising edge it was sampled at
  int64_t first_file_cycle = -1;   // the first sample differing from a vector file's expectation:
                                   // the file's cycle (0-based), -1 none
  std::string first_item;          // first differing item
  // Records the first differing sample (later ones only count: the caller counts them).
  bool firstSample(const sc_core::sc_time& t, std::string what) {
    if (!first.empty()) return false;
    first = std::move(what);
    first_time = t;
    return true;
  }
  uint64_t mismatches() const { return sample_mismatches + item_mismatches; }
  bool passed() const { return mismatches() == 0 && expected_items == observed_items && matched_items == expected_items; }
};

}  // namespace shd
