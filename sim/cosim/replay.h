// Replay of a vector file (sim/vectors/vector_file.h) on the verilated configuration it names: reset,
// then per cycle the file's inputs, and every output compared with the file's expectation on
// every cycle. The same files run under Icarus (testbench/icarus/); `shadesim replay FILE`.
//
// Before the run: the configuration must be verilated into this binary and its parameters must
// equal the file's (a stale or foreign file is an error, not a mismatch); for the specular unit
// the PROM file is parsed strictly and the words the simulator loaded are compared with it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace shd {

struct ReplayOptions {
  std::string fst_path;   // "": no waveform
  std::string prom_path;  // spec: overrides the file's "# prom:" (resolved against the file's directory)
  uint64_t max_listed = 10;  // mismatching values kept in ReplayResult::listed
};

struct ReplayMismatch {
  uint64_t cycle = 0;   // 1-based cycle after reset (the file's n-th cycle line)
  std::string signal;   // port name, with the lane and attribute where it has them
  uint64_t expected = 0, got = 0;  // the port's bits
  std::string describe() const;    // "cycle 7: spec_o: expected 0x38f, rtl 0x390"
};

struct ReplayResult {
  std::string unit, config;
  uint64_t cycles = 0;
  uint64_t compared = 0;             // output values compared
  uint64_t mismatching_cycles = 0;   // cycles with at least one differing output
  uint64_t mismatches = 0;           // differing output values
  uint64_t results = 0;  // spec: valid results; span: expected-valid lanes, summed over cycles
                         // (a fragment stalled by out_ready counts on every cycle it is shown)
  std::optional<ReplayMismatch> first;
  std::vector<ReplayMismatch> listed;  // the first max_listed mismatches, in order
  std::string fst_path;
};

// std::runtime_error / std::invalid_argument for an unreadable or malformed file, an unknown
// configuration, parameters that differ from the verilated ones, or a bad PROM.
ReplayResult replayVectorFile(const std::string& path, const ReplayOptions& opts = {});

}  // namespace shd
