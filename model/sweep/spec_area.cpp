#include "sweep/spec_area.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#include "device/prom_io.h"
#include "io/files.h"
#include "io/json_strict.h"
#include "sweep/grid.h"

extern char** environ;

namespace shd {

namespace fs = std::filesystem;

namespace {

std::string readText(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Runs argv with stdout and stderr into `log`; its exit status, or -1 if it could not start.
int runLogged(const std::vector<std::string>& argv, const std::string& log) {
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&fa, 1, 2);
  std::vector<char*> args;
  for (const std::string& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, args[0], &fa, nullptr, args.data(), environ);
  posix_spawn_file_actions_destroy(&fa);
  if (rc != 0) return -1;
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
}

// The figures of one target from synth.py's summary (no timings: a cached result is the same on
// every machine with the same yosys).
nlohmann::json targetFigures(const nlohmann::json& t) {
  return {{"luts", t.at("luts")},   {"ffs", t.at("ffs")},   {"carries", t.at("carries")}, {"dsps", t.at("dsps")},
          {"brams", t.at("brams")}, {"bram_kbits", t.at("bram_kbits")}, {"cells", t.at("cells_total")}};
}

}  // namespace

std::string synthToolVersion(const std::string& script) {
  char tmpl[] = "/tmp/shadesim-yosys-XXXXXX";
  const int fd = mkstemp(tmpl);
  if (fd < 0) throw std::runtime_error(fmt::format("cannot make a temporary file: {}", std::strerror(errno)));
  close(fd);
  const int rc = runLogged({"yosys", "-V"}, tmpl);
  std::string v = readText(tmpl);
  unlink(tmpl);
  if (rc != 0) throw std::runtime_error(fmt::format("--area: yosys -V failed (exit {}): {}", rc, v));
  while (!v.empty() && (v.back() == '\n' || v.back() == '\r')) v.pop_back();
  // The flow and the RTL it synthesises (rtl/ beside scripts/).
  std::string sources = readText(script);
  const fs::path rtl = fs::path(script).parent_path().parent_path() / "rtl";
  std::vector<fs::path> files;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(rtl, ec))
    if (e.path().extension() == ".v") files.push_back(e.path());
  std::sort(files.begin(), files.end());
  for (const fs::path& f : files) sources += f.filename().string() + "\n" + readText(f);
  return v + " flow " + textHash(sources);
}

std::string findSynthScript() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const fs::path installed = exe.parent_path().parent_path() / "share" / "shadesim" / "scripts" / "synth.py";
    if (fs::is_regular_file(installed, ec)) return installed.string();
  }
#ifdef SHD_SOURCE_ROOT
  const fs::path source = fs::path(SHD_SOURCE_ROOT) / "scripts" / "synth.py";
  if (fs::is_regular_file(source, ec)) return source.string();
#endif
  return "";
}

nlohmann::json specPointArea(const PromTable& table, const SynthTool& tool) {
  const std::string hex = renderProm(table, PromFormat::Hex);
  const nlohmann::json rtl = table.unit.toJson();
  const std::string key = textHash(fmt::format("spec {} {} {} {}", rtl.dump(), tool.targets, tool.version, hex));
  const fs::path cached = fs::path(tool.cache_dir) / fmt::format("spec-{}.json", key);
  std::error_code ec;
  if (fs::is_regular_file(cached, ec)) {
    try {
      return parseJsonStrict(readText(cached)).at("area");
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: not a cached area ({}); remove it", cached.string(), e.what()));
    }
  }
  // A private directory in the cache for the inputs and yosys's output.
  std::string tmpl = (fs::path(tool.cache_dir) / fmt::format("spec-{}.XXXXXX", key)).string();
  if (mkdtemp(tmpl.data()) == nullptr)
    throw std::runtime_error(fmt::format("{}: cannot make a directory in it: {}", tool.cache_dir, std::strerror(errno)));
  const fs::path tmp(tmpl);
  struct Cleanup {
    fs::path p;
    ~Cleanup() {
      std::error_code e;
      fs::remove_all(p, e);
    }
  } cleanup{tmp};
  const nlohmann::json cfg = {{"name", "sweep"},
                              {"description", "a point of a shadesim sweep"},
                              {"rtl", rtl},
                              {"prom",
                               {{"fit", toString(table.request.fit)},
                                {"level", table.request.level},
                                {"n", table.request.n.text}}}};
  writeFileAtomic((tmp / "spec_sweep.json").string(), cfg.dump(2) + "\n");
  writeFileAtomic((tmp / "spec_sweep.hex").string(), hex);
  const std::string log = (tmp / "synth.log").string();
  const int rc = runLogged({"python3", tool.script, (tmp / "spec_sweep.json").string(), "--unit", "spec", "--prom",
                            (tmp / "spec_sweep.hex").string(), "--out", (tmp / "out").string(), "--target",
                            tool.targets},
                           log);
  if (rc != 0) {
    // The log goes with the temporary directory: keep its end in the message.
    std::string tail = readText(log);
    if (tail.size() > 600) tail = "..." + tail.substr(tail.size() - 600);
    throw std::runtime_error(fmt::format("synthesis of point {} failed ({}: exit {}):\n{}", key, tool.script, rc, tail));
  }
  const nlohmann::json summary = parseJsonStrict(readText(tmp / "out" / "summary.json"));
  nlohmann::json area = nlohmann::json::object();
  for (const auto& item : summary.at("targets").items()) area[item.key()] = targetFigures(item.value());
  writeFileAtomic(cached.string(),
                  nlohmann::json{{"key", key}, {"tools", tool.version}, {"rtl", rtl}, {"area", area}}.dump(1) + "\n");
  return area;
}

}  // namespace shd
