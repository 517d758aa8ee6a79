// The scoreboard of the specular unit: a verilated configuration and its golden model run the
// same input stream, and every output port is compared on every cycle (the outputs hold their
// last valid result, so data is compared even on cycles without valid_o).
//
// Before the run the PROM the simulator loaded is read back and compared with the table the
// model was built from: $readmemh only warns on a missing, short or corrupt file, so this is
// where such a file fails loudly.
//
// On a mismatch the run records the first failing cycle with the input that produced it and
// both outputs, keeps counting up to max_mismatches, then replays the last few cycles from reset
// into a traced instance to write an FST waveform and a vector file (sim/vectors/vector_file.h) of the
// failing window: the model's expected outputs for the verilated configuration, with a copy of
// the PROM beside it, so that `shadesim replay` and the Icarus testbench reproduce the mismatch
// from the file alone.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include "device/prom.h"
#include "device/prom_io.h"
#include "device/spec_stimulus.h"
#include "device/spec_unit.h"
#include "harness/spec_dut.h"
#include "vectors/vector_file.h"

namespace shd {

struct SpecMismatch {
  uint64_t cycle = 0;  // cycle after reset whose outputs differ
  SpecIn input;        // the input applied latency - 1 cycles earlier (invalid if none)
  SpecOut expected, got;
  std::string describe(const SpecUnitParams& p) const;
};

struct SpecCosimOptions {
  std::string prom_path;        // the $readmemh file the simulator loads
  std::string fail_dir = ".";   // where the failing window's FST and vector file go
  uint64_t max_mismatches = 16;
  std::function<void(uint64_t done, uint64_t total)> progress;  // called about every 2^20 vectors
};

struct SpecCosimResult {
  std::string config;
  uint64_t vectors = 0;  // valid inputs driven
  uint64_t cycles = 0;
  uint64_t mismatches = 0;
  double seconds = 0;
  std::optional<SpecMismatch> first;
  std::string fst_path, vector_path;  // written when mismatches > 0
  std::string prom_copy_path;         // the PROM beside the vector file (its "# prom")
};

// Compares the words the simulator loaded with `expected`; throws std::runtime_error naming the
// first differing address, both words and the file.
void verifyLoadedProm(SpecDut& dut, const RomImage& expected, const std::string& prom_path, const SpecUnitParams& p);

SpecCosimResult runSpecCosim(const std::string& config, SpecUnitModel& model, SpecStimulus& stim,
                             const SpecCosimOptions& opts);

}  // namespace shd
