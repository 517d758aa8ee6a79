// The SystemC testbench of the specular unit: a driver, a module wrapping the golden model
// (SpecUnitModel) that predicts every output and the time it must be on the ports, and a
// scoreboard. Clock and sampling convention: sc_common.h.
//
//   SpecDriver ──valid_i, shin_i, cos_i, light_*_i──> SpecRtl (verilated)
//        │              │ (the same signals)                │ valid_o, spec_o, spec_*_o
//        │              v                                   v
//        │         SpecGolden ──sc_fifo<SpecExpect>──> SpecScoreboard
//        └─(vector file's own expected outputs)─sc_fifo──────^
//
// SpecGolden monitors the input signals: at each active rising edge t it reads what the RTL
// samples there, ticks the model, and predicts the outputs after the edge, i.e. the sample at
// t + 10 ns, tagged with that time and with the input whose result it is (sampled latency - 1
// edges before t). The scoreboard compares every sample of valid_o, spec_o and spec_*_o at the
// predicted time (the outputs hold their last result, so data are compared on idle cycles too),
// and pairs the results (valid_o high) in order, checking value and time of each.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <systemc>

#include "device/spec_stimulus.h"
#include "device/spec_unit.h"
#include "sc_common.h"
#include "vectors/vector_file.h"

namespace shd {

// A predicted (or, from a vector file, given) output sample.
struct SpecExpect {
  sc_core::sc_time time;    // the rising edge at which the scoreboard samples it
  SpecOut out;
  std::optional<SpecIn> src;  // the input this result comes from (valid results)
  sc_core::sc_time src_time;  // when it was sampled
  int64_t cycle = -1;         // vector-file expectations: the file's cycle index (0-based; messages
                              // count from 1, as shadesim replay and the Icarus testbenches do)
};
std::ostream& operator<<(std::ostream& os, const SpecExpect& e);  // sc_fifo needs it

// The stimulus: one SpecIn per active cycle, until next() returns false.
class SpecSource {
 public:
  virtual ~SpecSource() = default;
  virtual bool next(SpecIn& in) = 0;
  // The output the source expects after the edge that samples the input just returned (vector
  // files with expected columns), or nothing.
  virtual std::optional<SpecOut> expected() const { return std::nullopt; }
  virtual uint64_t total() const = 0;  // valid inputs it will produce
};

// Seeded random vectors: RandomSpecStimulus (device/spec_stimulus.h), the C++ co-simulation's
// stream: shininess over the PROM, cos biased toward 1.0 and above it, valid_i dropped with
// probability gap for 1..3 cycles at a time; the inputs change on idle cycles too.
class RandomSpecSource final : public SpecSource {
 public:
  RandomSpecSource(const SpecUnitParams& p, uint64_t seed, uint64_t vectors, double gap)
      : stim_(p, seed, vectors, gap) {}
  bool next(SpecIn& in) override { return stim_.next(in); }
  uint64_t total() const override { return stim_.total(); }

 private:
  RandomSpecStimulus stim_;
};

// The cycles of a vector file (sim/vectors/vector_file.h), one per active cycle, with their
// expected outputs.
class FileSpecSource final : public SpecSource {
 public:
  explicit FileSpecSource(const SpecVectors& v);
  bool next(SpecIn& in) override;
  std::optional<SpecOut> expected() const override;
  uint64_t total() const override { return valid_; }
  size_t cycle() const { return next_ - 1; }  // of the input next() returned last
  size_t cycles() const { return v_.in.size(); }

 private:
  const SpecVectors& v_;
  size_t next_ = 0;
  uint64_t valid_ = 0;
};

class SpecDriver : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"};
  sc_core::sc_out<bool> valid_i{"valid_i"};
  sc_core::sc_out<uint32_t> shin_i{"shin_i"}, cos_i{"cos_i"};
  sc_core::sc_out<uint32_t> light_r_i{"light_r_i"}, light_g_i{"light_g_i"}, light_b_i{"light_b_i"};
  sc_core::sc_fifo_out<SpecExpect> file_expect{"file_expect"};

  // Drives the source's first input when rst_n rises, so that the first active rising edge
  // samples it (vector files count their cycles from there), then one input per rising edge.
  // After the source ends, drives idle inputs for drain_cycles cycles, then ends the run.
  SpecDriver(const sc_core::sc_module_name& name, SpecSource& src, int drain_cycles, ScRunControl& ctl);
  SC_HAS_PROCESS(SpecDriver);
  uint64_t driven() const { return driven_; }  // valid inputs driven

 private:
  void onEdge();
  void drive(const SpecIn& in);
  SpecSource& src_;
  FileSpecSource* file_;  // src_ when it is a vector file
  int drain_left_;
  ScRunControl& ctl_;
  bool src_done_ = false;
  uint64_t driven_ = 0;
};

enum class SpecFault { None, Latency, Value };

class SpecGolden : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"}, valid_i{"valid_i"};
  sc_core::sc_in<uint32_t> shin_i{"shin_i"}, cos_i{"cos_i"};
  sc_core::sc_in<uint32_t> light_r_i{"light_r_i"}, light_g_i{"light_g_i"}, light_b_i{"light_b_i"};
  sc_core::sc_fifo_out<SpecExpect> expect{"expect"};

  // Fault injection, to prove the scoreboard can fail: Latency puts one register in front of
  // the model (every prediction one cycle late); Value is applied by the caller (a model built
  // with other parameters). record: keep every active cycle's input (as on the ports) and the
  // model's prediction after that edge, a vector file's cycles (--save-vectors).
  // capture: keep the inputs (as on the ports) of the last `capture` active cycles, the window
  // a failing case is saved from (0: none). Bounded whatever the run length.
  SpecGolden(const sc_core::sc_module_name& name, SpecUnitModel& model, SpecFault fault, bool record,
             size_t capture = 0);
  SC_HAS_PROCESS(SpecGolden);
  const std::vector<SpecIn>& recordedInputs() const { return rec_in_; }
  const std::vector<SpecOut>& recordedOutputs() const { return rec_out_; }
  // The captured inputs of the active edges up to last_edge, at most `capture` of them, oldest
  // first; first_cycle gets the run's cycle (1-based from reset) of the oldest one. Empty if
  // last_edge precedes the first active edge.
  std::vector<SpecIn> capturedWindow(const sc_core::sc_time& last_edge, uint64_t& first_cycle) const;

 private:
  void onEdge();
  void put(const SpecExpect& e);
  SpecUnitModel& model_;
  SpecFault fault_;
  bool record_;
  bool started_ = false;
  SpecIn delayed_;                                             // the Latency fault's register
  sc_core::sc_time delayed_time_;                              // ... and when it was sampled
  std::deque<std::pair<sc_core::sc_time, SpecIn>> history_;  // the last `latency` inputs
  std::vector<SpecIn> rec_in_;
  std::vector<SpecOut> rec_out_;
  size_t capture_;
  uint64_t active_edges_ = 0;
  struct Captured {
    sc_core::sc_time edge;
    uint64_t cycle;  // 1-based from reset
    SpecIn in;
  };
  std::deque<Captured> cap_;  // the last capture_ + 1 active edges
};

// What SpecGolden predicts for a vector file's cycles: from reset, `in` (as on the ports) through
// the Latency fault's register (if any) into a fresh copy of `model` (its parameters and table,
// so a Value fault too); one output per cycle, after its rising edge. Used for the failing case.
std::vector<SpecOut> specGoldenReplay(const SpecUnitModel& model, SpecFault fault, const std::vector<SpecIn>& in);

class SpecScoreboard : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"};
  sc_core::sc_in<bool> valid_o{"valid_o"};
  sc_core::sc_in<uint32_t> spec_o{"spec_o"}, spec_r_o{"spec_r_o"}, spec_g_o{"spec_g_o"}, spec_b_o{"spec_b_o"};
  sc_core::sc_fifo_in<SpecExpect> expect{"expect"}, file_expect{"file_expect"};

  SpecScoreboard(const sc_core::sc_module_name& name, const SpecUnitParams& p, ScRunControl& ctl);
  SC_HAS_PROCESS(SpecScoreboard);
  // Called once, at the first sample whose outputs differ from an expectation: the sample's
  // rising edge, the expectation it failed and whether it came from the vector file (else the
  // golden model). The runner saves the failing case from it.
  std::function<void(const sc_core::sc_time& sample, const SpecOut& expected, bool from_file)> on_first_mismatch;
  // After the run: pairs left over (a result only one side produced) count as mismatches.
  void finish();
  const ScScore& score() const { return s_; }
  uint64_t fileChecks() const { return file_checks_; }

 private:
  struct Sample {
    sc_core::sc_time time;
    SpecOut out;
  };
  void sample();
  void compare();
  void check(const Sample& got, const SpecExpect& exp, const char* who);
  void pairResults();
  std::string describe(const SpecExpect& e) const;

  SpecUnitParams p_;
  ScRunControl& ctl_;
  ScScore s_;
  std::deque<Sample> samples_;
  std::deque<SpecExpect> expected_, file_expected_;
  std::deque<SpecExpect> exp_results_;
  std::deque<Sample> got_results_;
  uint64_t file_checks_ = 0;
};

}  // namespace shd
