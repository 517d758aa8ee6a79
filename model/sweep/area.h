// Area of a sweep's point by yosys: scripts/synth.py on the point's configuration (and, for the
// specular unit, its PROM), for iCE40 and Xilinx 7-series, cached by a hash of the unit, the
// parameters, the PROM's contents and the tools, so that a repeated sweep (in any directory)
// does not synthesise again.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "device/prom.h"
#include "device/prom_io.h"

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
// PROM files ($readmemh texts by suffix, renderPromFiles: the piecewise kind's segment ROM too)
// and `prom_desc`, the configuration's "prom" member. From the cache when
// it holds the key; otherwise synthesised (in a temporary directory inside the cache, removed
// after) and cached. std::runtime_error naming the point's hash, with the end of synth.py's
// output, when it fails.
nlohmann::json unitPointArea(const std::string& unit, const nlohmann::json& rtl, const PromFiles& prom,
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

// The devices a configuration is placed on, each with its flow: the UP5K with its DSPs
// (synth_ice40 -dsp; fmax an upper bound, scripts/pnr.py "DSP timing"), the HX8K without (it has
// none: every multiplier in logic cells, fmax exact).
struct PnrDevice {
  std::string name;   // pnr.py's --device
  std::string title;  // "iCE40UP5K"
  bool dsps;          // synthesised with -dsp
};
const std::vector<PnrDevice>& pnrDevices();

// Place and route on iCE40 by scripts/pnr.py (nextpnr-ice40), cached beside the areas.
struct PnrTool {
  std::string script;     // scripts/pnr.py
  std::string cache_dir;  // an existing directory: <unit>-pnr-<key>.json per configuration
  std::string version;    // pnrToolVersion()
  std::vector<PnrDevice> devices = pnrDevices();  // those placed on, in pnrDevices() order
};

// synthToolVersion() of the synth.py beside `script`, nextpnr-ice40's version and a hash of
// `script`: part of every cache key. std::runtime_error if yosys or nextpnr-ice40 does not run.
std::string pnrToolVersion(const std::string& script);

// {"<device>": {"flow", "fits", "fmax_mhz", "fmax_kind", "luts", "luts_total", "dsps",
// "dsps_total", "brams", "brams_total", "util_percent", "seed", "why_not"}} per tool.devices
// entry (pnr.py's summary, docs/place-and-route.md; fmax_mhz and fmax_kind null and why_not set
// when it does not fit). Arguments and cache as unitPointArea; std::runtime_error when pnr.py
// fails (not fitting is a result, not a failure).
nlohmann::json unitPointPnr(const std::string& unit, const nlohmann::json& rtl, const PromFiles& prom,
                            const nlohmann::json& prom_desc, const PnrTool& tool);
nlohmann::json specPointPnr(const PromTable& table, const PnrTool& tool);

}  // namespace shd
