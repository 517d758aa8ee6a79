// What the runners of both units share (sc_run.h).
#include "sc_run.h"

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <verilated.h>
#include <verilated_fst_sc.h>

#include "cli/progress.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd {

namespace {

// An output file named by `option`, checked by the output policy (io/files.h) before the run:
// a regular file or a new one in an existing directory, not one of the run's inputs.
void prepareOutput(const std::string& path, const char* option) {
  try {
    outputTarget(path);
  } catch (const std::exception& e) {
    throw ArgError(fmt::format("{}: {}", option, e.what()));
  }
}

}  // namespace

void requireBuilt(const ScOptions& o, const std::vector<std::string>& built, const char* unit) {
  if (std::find(built.begin(), built.end(), o.config) == built.end())
    throw ArgError(fmt::format("--config {}: no SystemC model of the {} by that name (built: {})", o.config, unit,
                               fmt::join(built, ", ")));
}

void requireFileParams(const ScOptions& o, const std::string& file_config, const std::string& file_params,
                       const std::string& unit_params) {
  if (file_params != unit_params)
    throw ArgError(fmt::format("--vector-file {}: made for configuration {} ({}), not for {} ({})", o.vector_file,
                               file_config, file_params, o.config, unit_params));
}

void prepareOutputs(const ScOptions& o) {
  if (!o.save_vectors.empty()) prepareOutput(o.save_vectors, "--save-vectors");
  if (!o.fst.empty()) prepareOutput(o.fst, "--fst");
}

std::string stimulusArgs(const ScOptions& o) {
  if (!o.vector_file.empty()) return "--vector-file " + o.vector_file;
  if (!o.scene.empty()) return "--scene " + o.scene;
  if (o.unit == "spec") return fmt::format("--seed {} --vectors {}", o.seed, o.vectors);
  return fmt::format("--seed {} --triangles {}", o.seed, o.triangles);
}

std::string savedVectorsSource(const ScOptions& o) {
  return fmt::format("shadesim_systemc --unit {} --config {} {} (the golden-model module's predictions{})", o.unit,
                     o.config, stimulusArgs(o), o.fault == "none" ? "" : ", fault " + o.fault);
}

ScWaveform::ScWaveform(std::string path) : path_(std::move(path)) {
  if (!path_.empty()) Verilated::traceEverOn(true);
}

void ScWaveform::open(const std::function<void(VerilatedFstC&)>& trace) {
  if (path_.empty()) return;
  tfp_ = new VerilatedFstSc;
  trace(*tfp_);
  tfp_->open(path_.c_str());
}

void ScWaveform::close() {
  if (tfp_) tfp_->close();
}

std::string ScRunTime::describe() const {
  return fmt::format("{} cycles simulated in {:.2f} s wall ({:.0f} cycles/s)", cycles, secs,
                     secs > 0 ? cycles / secs : 0.0);
}

ScRunTime scSimulate(ScRunControl& ctl, const ScOptions& o, const char* unit, double total,
                     const std::function<double()>& done) {
  const auto t0 = std::chrono::steady_clock::now();
  {
    Progress progress(fmt::format("systemc {}/{}", o.unit, o.config), !o.quiet);
    while (!ctl.done) {
      sc_core::sc_start(20000 * scPeriod());
      progress.update(done(), total, unit);
    }
  }
  ScRunTime t;
  t.secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  t.cycles = scCycle(sc_core::sc_time_stamp());
  return t;
}

std::string failPath(const ScOptions& o, const char* ext) {
  const std::string name = fmt::format("{}_{}_fail.{}", o.unit, o.config, ext);
  if (o.fail_dir.empty() || o.fail_dir == ".") return name;
  return (fs::path(o.fail_dir) / name).string();
}

ScFailCase saveFailCase(const ScOptions& o, const std::string& what, uint64_t cycles, uint64_t run_first,
                        const char* why_none, const std::function<void(const std::string& vec)>& write) {
  ScFailCase f;
  f.attempted = true;
  f.what = what;
  if (cycles == 0) {
    f.not_saved = why_none;
    return f;
  }
  try {
    if (!o.fail_dir.empty()) fs::create_directories(o.fail_dir);
    const std::string vec = failPath(o, "vec");
    write(vec);
    f.vec = vec;
    f.fst = failPath(o, "fst");
    f.cycles = cycles;
    f.run_first = run_first;
  } catch (const std::exception& e) {
    f.not_saved = e.what();
  }
  return f;
}

std::string failCaseSource(const ScOptions& o, uint64_t run_first, uint64_t cycles) {
  return fmt::format("shadesim_systemc --unit {} --config {} {}{}: the failing case, the run's cycles {}..{} after "
                     "reset replayed from reset",
                     o.unit, o.config, stimulusArgs(o), o.fault == "none" ? "" : " --fault " + o.fault, run_first,
                     run_first + cycles - 1);
}

std::string failCaseExpectedNote(const ScOptions& o, bool from_file) {
  return fmt::format("expected outputs: the golden-model module{} replayed on these inputs from reset{}",
                     o.fault == "none" ? "" : " (fault " + o.fault + ")",
                     from_file ? "; the last cycle: the run's vector file's expectation, which it failed" : "");
}

}  // namespace shd
