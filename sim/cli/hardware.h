// The hardware figures of a unit configuration for the commands that give them (report, prune):
// where the tools are (scripts/synth.py with yosys, scripts/pnr.py with nextpnr), the cache they
// share, why a figure is absent, and the jobs that compute them in parallel.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "sweep/area.h"

namespace shd::cli {

// The tools of the hardware figures (area by yosys, fmax by nextpnr) and why a figure is absent.
struct Hardware {
  std::optional<SynthTool> synth;
  std::optional<PnrTool> pnr;
  std::string cache;
  nlohmann::json absent = nlohmann::json::array();  // [{"figures", "why"}]: a tool missing or a run failed
  bool failed = false;  // a figure is absent for a reason other than --no-hardware
  void absentBecause(const std::string& figures, const std::string& why, bool failure) {
    absent.push_back({{"figures", figures}, {"why", why}});
    failed = failed || failure;
  }
};

// The options of the hardware figures: --hardware-cache, --pnr-devices, --no-hardware.
struct HardwareOptions {
  std::string cache;                 // --hardware-cache ("": the default)
  std::vector<std::string> devices;  // --pnr-devices ({}: every one of pnrDevices())
  bool none = false;                 // --no-hardware
  void add(CLI::App& app, const std::string& no_hardware_help);
  // Before any work: the cache an existing directory or a new one whose parent exists, no device
  // named twice (ArgError).
  void check() const;
  std::vector<PnrDevice> chosenDevices() const;  // in pnrDevices() order
  // The tools, or none with --no-hardware (absent, not a failure); the cache ("": $XDG_CACHE_HOME/
  // shadesim, else ~/.cache/shadesim) made if missing. A tool that is missing or does not run
  // leaves its figures absent, a failure.
  Hardware tools() const;
};

// One hardware figure of one unit configuration: `member` ("area" or "pnr") of units[unit][name].
struct HardwareJob {
  std::string unit, name, member, what;
  std::function<nlohmann::json()> run;
};

// The jobs on as many threads as the machine has cores (each job runs yosys or nextpnr in
// processes of its own); their figures into `units`, in job order, and a failed job's reason into
// hw.absent, in job order too, so the report does not depend on which job ended first.
void runHardwareJobs(const std::vector<HardwareJob>& jobs, nlohmann::json& units, Hardware& hw,
                     const std::function<void(const std::string&)>& say);

}  // namespace shd::cli
