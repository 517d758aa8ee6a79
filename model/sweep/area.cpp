#include "sweep/area.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <functional>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "device/prom_io.h"
#include "io/files.h"
#include "io/json_strict.h"
#include "io/process.h"
#include "sweep/grid.h"

namespace shd {

namespace fs = std::filesystem;

namespace {

constexpr uint64_t kMaxAreaFileBytes = 16 << 20;  // a cached area, synth.py's summary

// Runs argv; std::runtime_error naming `what`, with the end of what it said, unless it exits 0.
std::string run(const std::vector<std::string>& argv, const std::string& what) {
  std::string out, err, error;
  const int rc = runProcess(argv, out, err, error);
  if (rc == 0) return out;
  std::string said = out + err;
  if (said.size() > 600) said = "..." + said.substr(said.size() - 600);
  while (!said.empty() && (said.back() == '\n' || said.back() == '\r')) said.pop_back();
  throw std::runtime_error(fmt::format("{} failed ({}){}{}", what, rc < 0 ? error : fmt::format("exit {}", rc),
                                       said.empty() ? "" : ":\n", said));
}

// The figures of one target from synth.py's summary (no timings: a cached result is the same on
// every machine with the same yosys).
nlohmann::json targetFigures(const nlohmann::json& t) {
  return {{"luts", t.at("luts")},   {"ffs", t.at("ffs")},   {"carries", t.at("carries")}, {"dsps", t.at("dsps")},
          {"brams", t.at("brams")}, {"bram_kbits", t.at("bram_kbits")}, {"cells", t.at("cells_total")}};
}

// A private directory in `parent`, named from `stem`, removed with everything in it when the
// object goes.
class PrivateDir {
 public:
  PrivateDir(const std::string& parent, const std::string& stem) {
    std::string tmpl = (fs::path(parent) / (stem + ".XXXXXX")).string();
    if (mkdtemp(tmpl.data()) == nullptr)
      throw std::runtime_error(fmt::format("{}: cannot make a directory in it: {}", parent, std::strerror(errno)));
    path_ = tmpl;
  }
  ~PrivateDir() {
    std::error_code e;
    fs::remove_all(path_, e);
  }
  PrivateDir(const PrivateDir&) = delete;
  PrivateDir& operator=(const PrivateDir&) = delete;
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

}  // namespace

std::string synthToolVersion(const std::string& script) {
  std::string v = run({"yosys", "-V"}, "yosys -V");
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  // The flow and the RTL it synthesises (rtl/ beside scripts/).
  std::string sources = readInputFile(script, kMaxAreaFileBytes);
  const fs::path rtl = fs::path(script).parent_path().parent_path() / "rtl";
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(rtl, ec))
    if (e.path().extension() == ".v") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) sources += f.filename().string() + "\n" + readInputFile(f.string(), kMaxAreaFileBytes);
  return v + " flow " + textHash(sources);
}

std::string findShareFile(const std::string& relative) {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "shadesim" / relative;
    if (fs::is_regular_file(installed, ec)) return installed.string();
  }
#ifdef SHD_SOURCE_ROOT
  const fs::path source = fs::path(SHD_SOURCE_ROOT) / relative;
  if (fs::is_regular_file(source, ec)) return source.string();
#endif
  return "";
}

namespace {

// A unit configuration's figures by one of the scripts (synth.py, pnr.py), cached in cache_dir as
// <stem>-<key>.json {"key", "tools", "rtl", member: figures}, key a hash of the unit, its
// parameters, the PROM, `tools` and `what`. Otherwise `produce(argv, tmp)` computes them, argv
// being "python3 <script> <configuration file> --unit <unit> [--prom <file>]" in a private
// directory `tmp` of the cache (removed after).
nlohmann::json cachedUnitRun(const std::string& stem, const std::string& member, const std::string& unit,
                             const nlohmann::json& rtl, const PromFiles& prom, const nlohmann::json& prom_desc,
                             const std::string& script, const std::string& cache_dir, const std::string& tools,
                             const std::string& what,
                             const std::function<nlohmann::json(std::vector<std::string>, const fs::path&)>& produce) {
  std::string prom_text;  // every file's text (one file: the key the caches had before the segment ROM)
  for (const auto& f : prom) prom_text += f.second;
  const std::string key = textHash(fmt::format("{} {} {} {} {}", unit, rtl.dump(), what, tools, prom_text));
  const fs::path cached = fs::path(cache_dir) / fmt::format("{}-{}.json", stem, key);
  std::error_code ec;
  if (fs::is_regular_file(cached, ec)) {
    try {
      return parseJsonStrict(readInputFile(cached.string(), kMaxAreaFileBytes)).at(member);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: not a cached {} ({}); remove it", cached.string(), member, e.what()));
    }
  }
  const PrivateDir dir(cache_dir, fmt::format("{}-{}", stem, key));
  const fs::path& tmp = dir.path();
  nlohmann::json cfg = {{"name", "sweep"}, {"description", "a point of a shadesim sweep"}, {"rtl", rtl}};
  const std::string cfg_file = (tmp / (unit + "_sweep.json")).string();
  std::vector<std::string> argv = {"python3", script, cfg_file, "--unit", unit};
  if (unit == "spec") {
    cfg["prom"] = prom_desc;
    const std::string hex = (tmp / "spec_sweep.hex").string();
    for (const auto& [suffix, text] : prom) writeFileAtomic(hex + suffix, text);
    argv.insert(argv.end(), {"--prom", hex});
  }
  writeFileAtomic(cfg_file, cfg.dump(2) + "\n");
  nlohmann::json figures;
  try {
    figures = produce(std::move(argv), tmp);
  } catch (const std::runtime_error& e) {
    throw std::runtime_error(fmt::format("configuration {}: {}", key, e.what()));
  }
  writeFileAtomic(cached.string(),
                  nlohmann::json{{"key", key}, {"tools", tools}, {"rtl", rtl}, {member, figures}}.dump(1) + "\n");
  return figures;
}

// The figures of one device from pnr.py's summary (no timings, as targetFigures).
nlohmann::json deviceFigures(const nlohmann::json& d, const std::string& flow) {
  nlohmann::json r = {{"flow", flow},           {"fits", d.at("fits")},     {"fmax_mhz", d.at("fmax_mhz")},
                      {"luts", d.at("luts")},   {"luts_total", d.at("luts_total")}, {"dsps", d.at("dsps")},
                      {"dsps_total", d.at("dsps_total")}, {"brams", d.at("brams")},
                      {"brams_total", d.at("brams_total")}, {"util_percent", d.at("util_percent")},
                      {"seed", d.at("seed")}};
  r["fmax_kind"] = d.value("fmax_kind", nlohmann::json());
  r["why_not"] = d.value("why_not", nlohmann::json());
  return r;
}

}  // namespace

nlohmann::json unitPointArea(const std::string& unit, const nlohmann::json& rtl, const PromFiles& prom,
                             const nlohmann::json& prom_desc, const SynthTool& tool) {
  // The stem and key as before the place and route was added: existing caches stay valid.
  return cachedUnitRun(unit, "area", unit, rtl, prom, prom_desc, tool.script, tool.cache_dir, tool.version,
                       tool.targets, [&](std::vector<std::string> argv, const fs::path& tmp) {
                         argv.insert(argv.end(), {"--out", (tmp / "out").string(), "--target", tool.targets});
                         run(argv, fmt::format("synthesis of {} ({})", unit, tool.script));
                         const nlohmann::json summary = parseJsonStrict(
                             readInputFile((tmp / "out" / "summary.json").string(), kMaxAreaFileBytes));
                         nlohmann::json area = nlohmann::json::object();
                         for (const auto& item : summary.at("targets").items())
                           area[item.key()] = targetFigures(item.value());
                         return area;
                       });
}

std::string pnrToolVersion(const std::string& script) {
  std::string out, err, error;
  if (runProcess({"nextpnr-ice40", "--version"}, out, err, error) != 0)
    throw std::runtime_error(fmt::format("nextpnr-ice40 --version failed{}{} (apt-get install nextpnr-ice40)",
                                         error.empty() ? "" : ": ", error));
  std::string v = out + err;
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  const std::string synth = (fs::path(script).parent_path() / "synth.py").string();
  return synthToolVersion(synth) + " " + v + " pnr " + textHash(readInputFile(script, kMaxAreaFileBytes));
}

nlohmann::json unitPointPnr(const std::string& unit, const nlohmann::json& rtl, const PromFiles& prom,
                            const nlohmann::json& prom_desc, const PnrTool& tool) {
  // The devices and flows, as the key of the caches made before the devices could be chosen
  // ("up5k hx8k-nodsp" for both).
  std::string what;
  for (const PnrDevice& d : tool.devices) what += fmt::format("{}{}{}", what.empty() ? "" : " ", d.name, d.dsps ? "" : "-nodsp");
  return cachedUnitRun(
      unit + "-pnr", "pnr", unit, rtl, prom, prom_desc, tool.script, tool.cache_dir, tool.version, what,
      [&](const std::vector<std::string>& argv, const fs::path& tmp) {
        nlohmann::json devices = nlohmann::json::object();
        for (const PnrDevice& d : tool.devices) {
          std::vector<std::string> a = argv;
          a.insert(a.end(), {"--device", d.name, "--out", (tmp / d.name).string()});
          if (!d.dsps) a.push_back("--no-dsp");
          run(a, fmt::format("place and route of {} on the {} ({})", unit, d.name, tool.script));
          const nlohmann::json summary =
              parseJsonStrict(readInputFile((tmp / d.name / "summary.json").string(), kMaxAreaFileBytes));
          devices[d.name] = deviceFigures(summary.at("devices").at(d.name), summary.at("flow").get<std::string>());
        }
        return devices;
      });
}

const std::vector<PnrDevice>& pnrDevices() {
  static const std::vector<PnrDevice> devices = {{"up5k", "iCE40UP5K", true}, {"hx8k", "iCE40HX8K", false}};
  return devices;
}

std::vector<std::string> dspClasses(const std::string& unit, const std::vector<nlohmann::json>& rtl,
                                    const SynthTool& tool) {
  const PrivateDir dir(tool.cache_dir, unit + "-dsps");
  const std::string in = (dir.path() / "rtl.json").string();
  writeFileAtomic(in, nlohmann::json(rtl).dump() + "\n");
  const std::string out =
      run({"python3", tool.script, "--dsps-of", in, "--unit", unit, "--target", tool.targets}, "synth.py --dsps-of");
  const nlohmann::json counts = parseJsonStrict(out);
  if (!counts.is_array() || counts.size() != rtl.size())
    throw std::runtime_error(fmt::format("synth.py --dsps-of: {} counts for {} points", counts.size(), rtl.size()));
  std::vector<std::string> classes;
  for (const nlohmann::json& c : counts) {
    std::string text;
    for (const auto& item : c.items()) text += fmt::format("{}{} {}", text.empty() ? "" : " ", item.key(), item.value().dump());
    classes.push_back(text);
  }
  return classes;
}

namespace {
nlohmann::json promDesc(const PromTable& table) {
  return {{"fit", toString(table.request.fit)}, {"level", table.request.level}, {"n", table.request.n.text}};
}
}  // namespace

nlohmann::json specPointArea(const PromTable& table, const SynthTool& tool) {
  return unitPointArea("spec", table.unit.toJson(), renderPromFiles(table, PromFormat::Hex), promDesc(table), tool);
}

nlohmann::json specPointPnr(const PromTable& table, const PnrTool& tool) {
  return unitPointPnr("spec", table.unit.toJson(), renderPromFiles(table, PromFormat::Hex), promDesc(table), tool);
}

}  // namespace shd
