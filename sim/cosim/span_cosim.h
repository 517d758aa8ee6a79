// The scoreboard of the span unit: the verilated configuration and SpanUnitModel take the same
// descriptor stream with the same random back-pressure (out_ready) and descriptor gaps, and
// every output is compared on every cycle: desc_ready, out_valid, the tag, each lane's valid
// bit, and each valid lane's pixel and attributes.
//
// On the first mismatch the failing case is replayed from reset: the run's inputs from the last
// cycle that began with the unit idle (for the paper's unit, the one that accepted the failing
// triangle) to the failing one, with the descriptors accepted since, into a traced instance (an
// FST waveform), and saved as a vector file (sim/vectors/vector_file.h: the descriptors, the
// inputs and the model's expected outputs, cycle by cycle) that `shadesim replay` and the Icarus
// testbench replay alone; the last descriptor and the out_ready pattern are also written as JSON.
// On two threads (SpanCosimOptions::threads) the stimulus and the model run ahead of the
// verilated unit on a thread of their own, with the same result.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>

#include <nlohmann/json_fwd.hpp>

#include "raster/span_unit.h"
#include "harness/span_dut.h"
#include "vectors/vector_file.h"

namespace shd {

struct SpanCosimOptions {
  uint64_t seed = 1;             // the back-pressure and gap pattern
  double ready_prob = 0.8;       // out_ready high on a cycle with this probability
  double desc_gap_prob = 0.1;    // a descriptor waits 1..3 cycles before being offered
  std::string fail_dir = ".";
  uint64_t max_mismatches = 16;
  // After this many descriptors accepted, desc_valid stays low until the unit is idle (0: never).
  // The paper's unit is idle after each descriptor anyway; the full-rate unit, which takes the
  // next descriptor while it works, is otherwise never idle in a stream, and the failing case
  // (below) is replayed from the last idle cycle.
  uint64_t drain_every = 32;
  std::function<void(uint64_t done)> progress;  // called every 4096 triangles
  // 2: the stimulus and the model (`next` and `progress` with them) on a thread of their own,
  // up to 256 cycles ahead of the verilated unit, which stays on the calling thread. The result
  // is the same as on one thread; only where the run stops early (max_mismatches) may `next`
  // have been called for descriptors the run did not reach.
  int threads = 1;
  // Fault injection for the checker's own tests: run the model with other parameters than
  // the verilated unit (e.g. another lane layout) so that the comparison must fail.
  std::optional<SpanParams> model_params;
};

struct SpanMismatch {
  uint64_t cycle = 0;
  uint32_t tag = 0;  // the triangle being processed
  std::string what;  // which output differs, with both values
};

struct SpanCosimResult {
  std::string mode;
  uint64_t triangles = 0;  // descriptors accepted
  uint64_t fragments = 0;  // lane fragments handed over (valid lane, out_valid and out_ready)
  uint64_t cycles = 0;
  uint64_t mismatches = 0;
  double seconds = 0;
  std::optional<SpanMismatch> first;
  std::string fst_path, case_path, vector_path;
  std::string case_note;  // why no case was saved for the first mismatch, if none was
};

// The co-simulation's out_ready draw: bit for bit std::bernoulli_distribution(p) on the same
// generator (one rng() per draw), with an integer comparison instead of the conversion to
// double. The distribution answers generate_canonical(x) < p for x = rng(), which is monotone in
// x: it is x < threshold for the least x where it is false, found once by bisection on the
// distribution itself.
class ReadyDraw {
 public:
  explicit ReadyDraw(double p);
  bool operator()(std::mt19937_64& rng) const {
    const uint64_t x = rng();
    return always_ || x < threshold_;
  }

 private:
  bool always_ = false;  // true for every x (p >= 1)
  uint64_t threshold_ = 0;
};

// next(d) fills the next descriptor and returns false at the end of the stream.
SpanCosimResult runSpanCosim(const std::string& mode, const std::function<bool(SpanDesc&)>& next,
                             const SpanCosimOptions& opts);

nlohmann::json toJson(const SpanDesc& d);

// The first difference between the outputs of one cycle (model, rtl) as a message, or "".
std::string compareSpanOutputs(const SpanOut& model, const SpanOut& rtl);

}  // namespace shd
