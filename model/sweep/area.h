// Area of a sweep's point by yosys: scripts/synth.py on the point's configuration (and, for the
// specular unit, its PROM), for iCE40 and Xilinx 7-series, cached by a hash of the unit, the
// parameters, the PROM's contents and the tools, so that a repeated sweep (in any directory)
// does not synthesise again.
#pragma once

#include <string>
#include <vector>

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

// A file of the project's share directory beside this program ("scripts/synth.py",
// "testbench/icarus/run_icarus.sh"): <exe dir>/../share/shadesim/<relative> (an installation),
// or the source tree this program was built from. "" if neither exists.
std::string findShareFile(const std::string& relative);

// {"<target>": {"luts", "ffs", "carries", "dsps", "brams", "bram_kbits", "cells"}} of the
// configuration {"rtl": rtl} of `unit` ("spec" or "span"); a specular unit's also `prom`, its
// PROM ($readmemh text) and `prom_desc`, the configuration's "prom" member. From the cache when
// it holds the key; otherwise synthesised (in a temporary directory inside the cache, removed
// after) and cached. std::runtime_error naming the point's hash, with the end of synth.py's
// output, when it fails.
nlohmann::json unitPointArea(const std::string& unit, const nlohmann::json& rtl, const std::string& prom,
                             const nlohmann::json& prom_desc, const SynthTool& tool);

// Per point (`rtl`, the parameters of each), the DSP count each of the tool's targets maps its
// multipliers to, as text ("ice40 7 xc7 6"): scripts/synth.py --dsps-of, which runs no yosys
// (the same counts its --check compares with the synthesised netlists). Points of different
// classes may differ in area either way (a narrower product can fall out of a DSP into LUTs),
// so areaDominators() (sweep_run.h) compares points within a class only.
std::vector<std::string> dspClasses(const std::string& unit, const std::vector<nlohmann::json>& rtl,
                                    const SynthTool& tool);

// The area of the specular-unit point whose PROM `table` is (its parameters are table.unit).
nlohmann::json specPointArea(const PromTable& table, const SynthTool& tool);

}  // namespace shd
