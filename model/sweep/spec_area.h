// Area of a specular-unit point by yosys: scripts/synth.py on the point's configuration and
// PROM, for iCE40 and Xilinx 7-series, cached by a hash of the parameters and the PROM's
// contents so that a repeated sweep (in any directory) does not synthesise again.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "device/prom.h"

namespace shd {

struct SynthTool {
  std::string script;     // scripts/synth.py
  std::string cache_dir;  // an existing directory: <key>.json per point and targets
  std::string targets = "both";  // ice40 | xc7 | both
  std::string version;    // what else decides the netlist: synthToolVersion()
};

// The yosys version (`yosys -V`) and a hash of `script` and the RTL it reads, part of every cache
// key: another yosys or an edited flow or RTL synthesises again. std::runtime_error if yosys
// does not run.
std::string synthToolVersion(const std::string& script);

// scripts/synth.py beside this program: <exe dir>/../share/shadesim/scripts (an installation), or
// the source tree this program was built from. "" if neither exists.
std::string findSynthScript();

// {"<target>": {"luts", "ffs", "carries", "dsps", "brams", "bram_kbits", "cells"}} for the
// point whose PROM `table` is (its unit parameters are table.unit). From the cache when it holds
// the key; otherwise synthesised (in a temporary directory inside the cache, removed after) and
// cached. std::runtime_error naming the point's hash, with the end of synth.py's output, when it
// fails.
nlohmann::json specPointArea(const PromTable& table, const SynthTool& tool);

}  // namespace shd
