// shadesim sweep --target-lsb E: the least point of a finished sweep that meets E, written as a
// configuration, verified against the RTL, and shown minimal.
#pragma once

#include <string>

#include "sweep/sweep_run.h"
#include "sweep/sweep_unit.h"

namespace shd::cli {

struct TargetRequest {
  double lsb = 0;               // E: the most datapath error allowed (the unit's front error), output LSBs
  std::string objective;        // "area" (LUTs of the first target synthesised) or "latency"
  std::string name = "target";  // the configuration's name: DIR/<unit>_<name>.json
  uint64_t verify_cycles = 0;   // cycles of the vector file Icarus replays
};

// Of the sweep's points within E, the least by the objective (area: LUTs, then latency; latency:
// latency, then LUTs if synthesised; then the fewest parameter bits, then the least index).
// Writes DIR/<unit>_<name>.json, a vector file of it from the model with its PROM
// (DIR/<unit>_<name>.vec, .vec.hex) and replays that under Icarus (testbench/icarus/
// run_icarus.sh); evaluates the base configuration (and synthesises it with `synth`); and for
// each of unit.widths one bit narrower evaluates the point, naming the input at which it breaks
// E. Prints the comparison, writes DIR/target.json. Returns kExitOk, or kExitFailed when no
// point meets E (saying the best error reached) or the RTL disagrees with the model.
int runTarget(const std::string& dir, const SweepPlan& plan, const SweepUnit& unit, const nlohmann::json& results,
              const SynthTool* synth, const TargetRequest& req);

// Writes the specular configuration's vector file (<config>.vec, its PROM <config>.vec.hex) from
// the model (`cycles` cycles, a fixed seed) and replays it under Icarus (testbench/icarus/
// run_icarus.sh, the configuration's parameters: nothing to build). Returns the verdict line;
// std::runtime_error when Icarus reports a mismatch or cannot run.
std::string verifyUnderIcarus(const std::string& config_file, uint64_t cycles);
// Replays a vector file under Icarus (its '# config' line gives the parameters); std::runtime_error
// when Icarus reports a mismatch or cannot run.
void replayUnderIcarus(const std::string& vec);

}  // namespace shd::cli
