// The SystemC testbench of the span unit: a driver, a module wrapping the cycle-accurate golden
// model (SpanUnitModel) that predicts every output and the time it must be on the ports, and a
// scoreboard. Clock and sampling convention: sc_common.h.
//
//   SpanDriver ──desc_valid_i, out_ready_i, descriptor pins (SpanPinsIf)──> SpanRtl (verilated)
//      │  └─sc_fifo<DescToken>: each descriptor as it is offered──┐          │ desc_ready_o,
//      │                                                          v          │ out_valid_o, fragments
//      │   desc_valid_i, out_ready_i (the same signals) ──> SpanGolden       v
//      └── model_idle <───────────────────────────────────────┘ └─sc_fifo<SpanExpect>─> SpanScoreboard
//
// The driver offers descriptors with random gaps (valid/ready: an offered descriptor stays until
// the RTL's desc_ready accepts it) and drives out_ready randomly (back-pressure). SpanGolden
// gets each descriptor as a transaction (not by reading the pins back, so a packing error in the
// pin adapter shows as a mismatch), reads desc_valid_i and out_ready_i at each rising edge t
// and ticks the model, whose outputs before the edge are the sample at t. The scoreboard
// compares every output on every active cycle (desc_ready, out_valid, the tag while out_valid,
// each lane's valid bit, each valid lane's pixel and attributes), and pairs the fragments handed
// over (valid lane, out_valid and out_ready at the same edge) in order, checking each one's
// value and time.
#pragma once

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <random>
#include <string>

#include <systemc>

#include "raster/span_unit.h"
#include "sc_common.h"
#include "span_rtl.h"
#include "vectors/vector_file.h"

namespace shd {

struct DescToken {
  std::shared_ptr<const SpanDesc> desc;
};
std::ostream& operator<<(std::ostream& os, const DescToken& t);

struct SpanExpect {
  sc_core::sc_time time;  // the rising edge at which the scoreboard samples it
  SpanOut out;
  bool out_ready = false;  // the out_ready the model took at that edge
  int64_t cycle = -1;      // vector-file expectations: the file's cycle index (0-based; messages
                           // count from 1, as shadesim replay and the Icarus testbenches do)
};
std::ostream& operator<<(std::ostream& os, const SpanExpect& e);

struct SpanDriverOptions {
  uint64_t seed = 1;
  double ready_prob = 0.8;     // out_ready high on a cycle with this probability
  double desc_gap_prob = 0.1;  // a descriptor waits 1..3 cycles before being offered
  // After this many descriptors accepted, none is offered until the golden model is idle (0:
  // never): the full-rate unit, which takes the next descriptor while it works, is otherwise
  // never idle in a stream, and the failing case starts at its last idle cycle.
  uint64_t drain_every = 0;
};

class SpanDriver : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"}, desc_ready_o{"desc_ready_o"}, model_idle{"model_idle"};
  sc_core::sc_out<bool> desc_valid_i{"desc_valid_i"}, out_ready_i{"out_ready_i"};
  sc_core::sc_port<SpanPinsIf> pins{"pins"};
  sc_core::sc_fifo_out<DescToken> offered{"offered"};

  // next(d) fills the next descriptor, false at the end. The first step runs when rst_n rises
  // (the first active rising edge samples it), then one per rising edge. The run ends two cycles
  // after the last descriptor was accepted and the golden model is idle again.
  SpanDriver(const sc_core::sc_module_name& name, std::function<bool(SpanDesc&)> next, const SpanDriverOptions& opt,
             ScRunControl& ctl);
  SC_HAS_PROCESS(SpanDriver);
  uint64_t offeredCount() const { return offered_; }
  uint64_t acceptedByRtl() const { return accepted_; }

 private:
  void onEdge();
  bool fetch();
  std::function<bool(SpanDesc&)> next_;
  std::mt19937_64 rng_;
  std::bernoulli_distribution ready_, gap_;
  ScRunControl& ctl_;
  std::shared_ptr<SpanDesc> pending_;
  bool have_pending_ = false, offering_ = false;
  int wait_ = 0, idle_edges_ = 0;
  uint64_t offered_ = 0, accepted_ = 0, drain_every_ = 0;
  bool draining_ = false;
};

// Replays a vector file's cycles (sim/vectors/vector_file.h): desc_valid, out_ready and the
// descriptor on the ports as the file gives them (not following desc_ready: the file's own
// expectations say when a descriptor is taken), and the file's expected outputs to the
// scoreboard. Each descriptor goes to the golden model as a transaction when the file starts
// offering it. The run ends two cycles after the file's last cycle.
class SpanFileDriver : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"};
  sc_core::sc_out<bool> desc_valid_i{"desc_valid_i"}, out_ready_i{"out_ready_i"};
  sc_core::sc_port<SpanPinsIf> pins{"pins"};
  sc_core::sc_fifo_out<DescToken> offered{"offered"};
  sc_core::sc_fifo_out<SpanExpect> file_expect{"file_expect"};

  SpanFileDriver(const sc_core::sc_module_name& name, const SpanVectors& v, ScRunControl& ctl);
  SC_HAS_PROCESS(SpanFileDriver);
  uint64_t cyclesDriven() const { return next_; }
  uint64_t offeredCount() const { return offered_; }

 private:
  void onEdge();
  const SpanVectors& v_;
  std::vector<std::shared_ptr<const SpanDesc>> descs_;
  ScRunControl& ctl_;
  size_t next_ = 0;
  int on_pins_ = -1;
  bool offering_ = false;
  int tail_ = 0;
  uint64_t offered_ = 0;
};

enum class SpanFault { None, Latency, Value };

// What SpanGolden computes, free of SystemC, so that the failing case's expected outputs come
// from the same code: the model behind the faults. Latency puts one register in front of the
// model's inputs (its predictions come a cycle late); Value gives the model every descriptor
// with attribute 0's reference value one code higher.
class SpanGoldenCore {
 public:
  SpanGoldenCore(SpanParams p, SpanFault fault) : model_(p), fault_(fault) {}
  // A descriptor offered on the ports (as a transaction), queued for the model.
  void offer(std::shared_ptr<const SpanDesc> d);
  void reset();  // the model and the Latency register (the queue of offers stays)
  // One rising edge with desc_valid and out_ready as on the ports: the model's outputs before
  // it (the sample at that edge). readyTaken() is the out_ready the model took.
  const SpanOut& tick(bool desc_valid, bool out_ready);
  bool readyTaken() const { return ready_taken_; }
  bool idle() const { return model_.idle() && queue_.empty(); }
  uint64_t accepted() const { return accepted_; }
  const SpanUnitModel& model() const { return model_; }

 private:
  SpanUnitModel model_;
  SpanFault fault_;
  std::deque<std::shared_ptr<const SpanDesc>> queue_;  // offered, not yet taken by the model
  bool delayed_valid_ = false, delayed_ready_ = false;  // the Latency fault's register
  bool ready_taken_ = false;
  SpanOut out_;
  uint64_t accepted_ = 0;
};

// The golden model's predictions for a vector file's cycles, from reset, the way SpanGolden
// computes them when SpanFileDriver replays the file: each descriptor offered to the model when
// an offer starts (desc_valid after none pending), the expected outputs filled in.
void spanGoldenReplay(SpanVectors& v, SpanParams model_params, SpanFault fault);

class SpanGolden : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"}, desc_valid_i{"desc_valid_i"}, out_ready_i{"out_ready_i"};
  sc_core::sc_fifo_in<DescToken> offered{"offered"};
  sc_core::sc_fifo_out<SpanExpect> expect{"expect"};
  sc_core::sc_out<bool> model_idle{"model_idle"};

  // Fault injection, to prove the scoreboard can fail (SpanGoldenCore).
  // record: keep every active cycle's inputs (as on the ports) and the model's outputs, and the
  // descriptors, as a vector file's cycles (--save-vectors).
  // capture: keep what the failing case is saved from: the inputs on the ports (desc_valid,
  // out_ready, the descriptor) of every active cycle since the last one the model was idle
  // before (from reset before the first), as sim/cosim/span_cosim.cpp does: from an idle unit
  // the inputs reproduce its state. The paper's unit is idle in the cycle that accepts each
  // triangle; the full-rate unit where the driver lets it drain (SpanDriverOptions::drain_every).
  SpanGolden(const sc_core::sc_module_name& name, SpanParams p, SpanFault fault, bool record, bool capture = false);
  SC_HAS_PROCESS(SpanGolden);
  uint64_t accepted() const { return core_.accepted(); }
  const SpanUnitModel& model() const { return core_.model(); }
  // The recorded cycles as a vector file's content (config, params and source left to the caller).
  SpanVectors recorded() const;
  // The captured cycles up to the one sampled at last_edge, as a vector file's cycles without
  // expected outputs (params, descs, cycles; spanGoldenReplay fills them in). first_cycle gets
  // the run's cycle (1-based from reset) of the first one, from_idle whether it is the last cycle
  // the golden model was idle before (for the paper's unit, the one that accepted the current
  // triangle; else the run's first).
  SpanVectors capturedCase(const sc_core::sc_time& last_edge, uint64_t& first_cycle, bool& from_idle) const;

 private:
  void onEdge();
  SpanGoldenCore core_;
  bool record_;
  std::vector<SpanDesc> rec_descs_;  // as offered (before the Value fault)
  std::vector<SpanVectorCycle> rec_cycles_;
  bool capture_;
  struct Captured {
    sc_core::sc_time edge;
    uint64_t cycle;  // 1-based from reset
    bool desc_valid, out_ready;
    std::shared_ptr<const SpanDesc> on_ports;  // as offered (before the Value fault); null: none yet
  };
  std::deque<Captured> cap_;
  bool cap_from_idle_ = false;
  int64_t idle_at_ = -1;  // index in cap_ of an idle cycle not yet applied (the window moves at the
                          // next edge, so a mismatch in the idle cycle keeps the cycles before it)
  std::shared_ptr<const SpanDesc> on_ports_;
  uint64_t active_edges_ = 0;
};

class SpanScoreboard : public sc_core::sc_module {
 public:
  sc_core::sc_in<bool> clk{"clk"}, rst_n{"rst_n"}, out_ready_i{"out_ready_i"};
  sc_core::sc_port<SpanPinsIf> rtl{"rtl"};
  sc_core::sc_fifo_in<SpanExpect> expect{"expect"}, file_expect{"file_expect"};

  SpanScoreboard(const sc_core::sc_module_name& name, ScRunControl& ctl);
  SC_HAS_PROCESS(SpanScoreboard);
  // Called once, at the first sample whose outputs differ from an expectation: the sample's
  // rising edge, the expectation it failed and whether it came from the vector file (else the
  // golden model). The runner saves the failing case from it.
  std::function<void(const sc_core::sc_time& sample, const SpanOut& expected, bool from_file)> on_first_mismatch;
  void finish();  // fragments only one side produced count as mismatches
  const ScScore& score() const { return s_; }
  uint64_t fileChecks() const { return file_checks_; }

 private:
  struct Sample {
    sc_core::sc_time time;
    SpanOut out;
    bool out_ready = false;
  };
  struct Fragment {
    sc_core::sc_time time;
    uint32_t tag;
    size_t lane;
    SpanLaneOut px;
  };
  void sample();
  void compare();
  void check(const Sample& got, const SpanExpect& exp, const char* who);
  void pairFragments();
  static void handedOver(const sc_core::sc_time& t, const SpanOut& o, bool ready, std::deque<Fragment>& q, uint64_t& n);
  static std::string show(const Fragment& f);

  ScRunControl& ctl_;
  ScScore s_;
  std::deque<Sample> samples_;
  std::deque<SpanExpect> expected_, file_expected_;
  std::deque<Fragment> exp_frags_, got_frags_;
  uint64_t file_checks_ = 0;
};

}  // namespace shd
