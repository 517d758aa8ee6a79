#include "sweep/area.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
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
  throw std::runtime_error(fmt::format("{} failed ({}):\n{}", what, rc < 0 ? error : fmt::format("exit {}", rc), said));
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
  std::string v = run({"yosys", "-V"}, "--area: yosys -V");
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

nlohmann::json unitPointArea(const std::string& unit, const nlohmann::json& rtl, const std::string& prom,
                             const nlohmann::json& prom_desc, const SynthTool& tool) {
  const std::string key = textHash(fmt::format("{} {} {} {} {}", unit, rtl.dump(), tool.targets, tool.version, prom));
  const fs::path cached = fs::path(tool.cache_dir) / fmt::format("{}-{}.json", unit, key);
  std::error_code ec;
  if (fs::is_regular_file(cached, ec)) {
    try {
      return parseJsonStrict(readInputFile(cached.string(), kMaxAreaFileBytes)).at("area");
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: not a cached area ({}); remove it", cached.string(), e.what()));
    }
  }
  // A private directory in the cache for the inputs and yosys's output.
  const PrivateDir dir(tool.cache_dir, fmt::format("{}-{}", unit, key));
  const fs::path& tmp = dir.path();
  nlohmann::json cfg = {{"name", "sweep"}, {"description", "a point of a shadesim sweep"}, {"rtl", rtl}};
  const std::string cfg_file = (tmp / (unit + "_sweep.json")).string();
  std::vector<std::string> argv = {"python3", tool.script, cfg_file, "--unit", unit};
  if (unit == "spec") {
    cfg["prom"] = prom_desc;
    const std::string hex = (tmp / "spec_sweep.hex").string();
    writeFileAtomic(hex, prom);
    argv.insert(argv.end(), {"--prom", hex});
  }
  writeFileAtomic(cfg_file, cfg.dump(2) + "\n");
  argv.insert(argv.end(), {"--out", (tmp / "out").string(), "--target", tool.targets});
  run(argv, fmt::format("synthesis of point {} ({})", key, tool.script));
  const nlohmann::json summary =
      parseJsonStrict(readInputFile((tmp / "out" / "summary.json").string(), kMaxAreaFileBytes));
  nlohmann::json area = nlohmann::json::object();
  for (const auto& item : summary.at("targets").items()) area[item.key()] = targetFigures(item.value());
  writeFileAtomic(cached.string(),
                  nlohmann::json{{"key", key}, {"tools", tool.version}, {"rtl", rtl}, {"area", area}}.dump(1) + "\n");
  return area;
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

nlohmann::json specPointArea(const PromTable& table, const SynthTool& tool) {
  return unitPointArea("spec", table.unit.toJson(), renderProm(table, PromFormat::Hex),
                       {{"fit", toString(table.request.fit)}, {"level", table.request.level}, {"n", table.request.n.text}},
                       tool);
}

}  // namespace shd
