#include "cli/hardware.h"

#include <algorithm>
#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <thread>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "cli/command.h"

namespace fs = std::filesystem;
using nlohmann::json;

namespace shd::cli {

void HardwareOptions::add(CLI::App& app, const std::string& no_hardware_help) {
  app.add_option("--hardware-cache", cache,
                 "the directory (made if missing; its parent must exist) where each unit configuration's yosys area "
                 "and nextpnr place and route are kept, computed once (shared with sweep --synth-cache); default "
                 "$XDG_CACHE_HOME/shadesim or ~/.cache/shadesim");
  std::vector<std::string> names;
  for (const PnrDevice& d : pnrDevices()) names.push_back(d.name);
  app.add_option("--pnr-devices", devices,
                 fmt::format("the iCE40 devices each unit is placed and routed on, comma-separated (default: {}): the "
                             "UP5K with its DSPs, the HX8K without (every multiplier in logic cells: the longer run)",
                             fmt::join(names, ",")))
      ->delimiter(',')
      ->check(CLI::IsMember(names));
  app.add_flag("--no-hardware", none, no_hardware_help)->excludes("--hardware-cache")->excludes("--pnr-devices");
}

void HardwareOptions::check() const {
  if (!cache.empty()) existingOrNewDir("--hardware-cache", cache, cache, "");
  for (const std::string& n : devices) refuseRepeat("--pnr-devices", devices, n);
}

std::vector<PnrDevice> HardwareOptions::chosenDevices() const {
  std::vector<PnrDevice> out;
  for (const PnrDevice& d : pnrDevices())
    if (devices.empty() || std::count(devices.begin(), devices.end(), d.name) > 0) out.push_back(d);
  return out;
}

Hardware HardwareOptions::tools() const {
  Hardware hw;
  if (none) {
    hw.absentBecause("area, fmax, time", "not measured: --no-hardware", false);
    return hw;
  }
  std::error_code ec;
  if (!cache.empty()) {
    hw.cache = cache;
  } else {
    const char* xdg = std::getenv("XDG_CACHE_HOME");
    const char* home = std::getenv("HOME");
    if (xdg && *xdg)
      hw.cache = (fs::path(xdg) / "shadesim").string();
    else if (home && *home)
      hw.cache = (fs::path(home) / ".cache" / "shadesim").string();
  }
  if (hw.cache.empty()) {
    hw.absentBecause("area, fmax, time", "no cache directory: give --hardware-cache DIR (neither XDG_CACHE_HOME nor HOME is set)", true);
    return hw;
  }
  if (!fs::is_directory(hw.cache, ec)) fs::create_directories(hw.cache, ec);
  if (!fs::is_directory(hw.cache, ec)) {
    hw.absentBecause("area, fmax, time", fmt::format("cannot make the cache directory {}: {}", hw.cache, ec.message()), true);
    return hw;
  }
  const std::string synth = findShareFile("scripts/synth.py"), pnr = findShareFile("scripts/pnr.py");
  try {
    if (synth.empty()) throw std::runtime_error("scripts/synth.py is neither in this installation nor in the source tree");
    hw.synth = SynthTool{synth, hw.cache, "both", synthToolVersion(synth)};
  } catch (const std::exception& e) {
    hw.absentBecause("area", fmt::format("yosys: {}", e.what()), true);
  }
  try {
    if (pnr.empty()) throw std::runtime_error("scripts/pnr.py is neither in this installation nor in the source tree");
    hw.pnr = PnrTool{pnr, hw.cache, pnrToolVersion(pnr), chosenDevices()};
  } catch (const std::exception& e) {
    hw.absentBecause("fmax, time", fmt::format("place and route: {}", e.what()), true);
  }
  return hw;
}

void runHardwareJobs(const std::vector<HardwareJob>& jobs, json& units, Hardware& hw,
                     const std::function<void(const std::string&)>& say) {
  std::vector<json> figures(jobs.size());
  std::vector<std::string> errors(jobs.size());
  std::atomic<size_t> next{0};
  auto worker = [&] {
    for (size_t i; (i = next++) < jobs.size();) {
      say(fmt::format("{} (or the cache)", jobs[i].what));
      try {
        figures[i] = jobs[i].run();
      } catch (const std::exception& e) {
        errors[i] = e.what();
      }
    }
  };
  std::vector<std::thread> threads(std::min<size_t>(jobs.size(), std::max(1u, std::thread::hardware_concurrency())));
  for (std::thread& t : threads) t = std::thread(worker);
  for (std::thread& t : threads) t.join();
  for (size_t i = 0; i < jobs.size(); ++i) {
    if (errors[i].empty())
      units[jobs[i].unit][jobs[i].name][jobs[i].member] = figures[i];
    else
      hw.absentBecause(jobs[i].member, fmt::format("{}: {}", jobs[i].what, errors[i]), true);
  }
}

}  // namespace shd::cli
