// The specular unit's SystemC run: sc_clock and reset from sc_main, the verilated configuration
// (SpecRtl), SpecDriver, SpecGolden and SpecScoreboard (spec_tb.h), bound by signals and FIFOs.
#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>

#include <unistd.h>

#include <fmt/format.h>
#include <verilated.h>
#include <verilated_fst_sc.h>

#include "device/prom.h"
#include "device/prom_io.h"
#include "config/registry.h"
#include "sc_run.h"
#include "spec_rtl.h"
#include "spec_tb.h"
#include "vectors/vector_file.h"

namespace fs = std::filesystem;

namespace shd {

namespace {

// The parameters as text (compared and shown; SpecUnitParams::toJson would need the JSON headers).
std::string describe(const SpecUnitParams& p) {
  return fmt::format("Degree={} CosFracBits={} ShinBits={} CoefIntBits={} CoefFracBits={} DiffFracBits={} "
                     "HornerFracBits={} SpecFracBits={} LightBits={} PipeStages={}",
                     p.Degree, p.CosFracBits, p.ShinBits, p.CoefIntBits, p.CoefFracBits, p.DiffFracBits,
                     p.HornerFracBits, p.SpecFracBits, p.LightBits, p.PipeStages);
}

// The PROM file: --prom, else the vector file's own (relative to the file), else "" (the
// configuration's table, written to a temporary file).
std::string promPath(const ScOptions& o, const SpecVectors* file) {
  if (!o.prom.empty()) return fs::absolute(o.prom).string();
  if (file && !file->prom.empty()) {
    const fs::path p(file->prom);
    return (p.is_absolute() ? p : fs::absolute(o.vector_file).parent_path() / p).lexically_normal().string();
  }
  return "";
}

// A temporary PROM file, removed with this object.
struct TempProm {
  std::string path;
  ~TempProm() {
    if (!path.empty()) {
      std::error_code ec;
      fs::remove(path, ec);
    }
  }
};

// The failing case (sc_run.h, ScFailCase): the captured window of inputs, from reset, with the
// golden module's predictions replayed on it (the fault included: that is what differs from the
// RTL), beside a copy of the PROM; the last cycle, the failing one, carries the expectation the
// run failed when that was the vector file's (the model agrees with the RTL there).
ScFailCase saveSpecFail(const ScOptions& o, const ScFirstMismatch<SpecOut>& first, const std::vector<SpecIn>& window,
                        uint64_t run_first, const SpecUnitParams& unit, const SpecUnitModel& model, SpecFault fault,
                        const std::string& prom, const std::string& what) {
  ScFailCase f;
  f.attempted = true;
  f.what = what;
  if (window.empty()) {
    f.not_saved = "the first mismatch is the sample at the first active edge (the state reset left), which no cycle "
                  "of a vector file holds";
    return f;
  }
  try {
    if (!o.fail_dir.empty()) fs::create_directories(o.fail_dir);
    const std::string vec = failPath(o, "vec"), hex = failPath(o, "hex");
    SpecVectors v;
    v.config = o.config;
    v.params = unit;  // the unit's: the file replays on it
    v.prom = fs::path(hex).filename().string();
    v.in = window;
    v.expected = specGoldenReplay(model, fault, window);
    if (first.from_file) v.expected.back() = first.expected;
    const uint64_t run_last = run_first + window.size() - 1;
    v.source = fmt::format(
        "shadesim_systemc --unit spec --config {} {}{}: the failing case, the run's cycles {}..{} after reset replayed "
        "from reset",
        o.config,
        o.vector_file.empty() ? fmt::format("--seed {} --vectors {}", o.seed, o.vectors) : "--vector-file " + o.vector_file,
        o.fault == "none" ? "" : " --fault " + o.fault, run_first, run_last);
    v.notes = {fmt::format("expected outputs: the golden-model module{} replayed on these inputs from reset{}",
                           o.fault == "none" ? "" : " (fault " + o.fault + ")",
                           first.from_file ? "; the last cycle: the run's vector file's expectation, which it failed" : ""),
               fmt::format("the run's first mismatch (the outputs after the last cycle's edge): {}", what)};
    // The PROM the simulator loaded, beside the file (the file names it relative to itself).
    std::ifstream in(prom, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("cannot read back PROM file {}", prom));
    writeFileAtomic(hex, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
    writeSpecVectors(vec, v);
    f.vec = vec;
    f.prom = hex;
    f.fst = failPath(o, "fst");
    f.cycles = window.size();
    f.run_first = run_first;
  } catch (const std::exception& e) {
    f.not_saved = e.what();
  }
  return f;
}

}  // namespace

ScReport runSpecSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n) {
  const std::vector<std::string> built = scSpecRtlConfigs();
  if (std::find(built.begin(), built.end(), o.config) == built.end())
    throw ArgError(fmt::format("--config {}: no SystemC model of the specular unit by that name (built: {})", o.config,
                               fmt::join(built, ", ")));
  const SpecUnitConfig cfg = specConfig(o.config);
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);

  std::unique_ptr<SpecVectors> file;
  if (!o.vector_file.empty()) {
    try {
      file = std::make_unique<SpecVectors>(loadSpecVectors(o.vector_file));
    } catch (const std::exception& e) {
      throw ArgError(fmt::format("--vector-file: {}", e.what()));
    }
    if (describe(file->params) != describe(cfg.rtl))
      throw ArgError(fmt::format("--vector-file {}: made for configuration {} ({}), not for {} ({})", o.vector_file,
                                 file->config, describe(file->params), o.config, describe(cfg.rtl)));
  }
  std::string prom = promPath(o, file.get());
  TempProm temp_prom;
  if (prom.empty()) {
    temp_prom.path = prom = (fs::temp_directory_path() / fmt::format("shadesim_systemc-{}-spec_{}.hex", getpid(), o.config)).string();
    writeFileAtomic(prom, renderProm(table, PromFormat::Hex));
  }
  // The file first, strictly (the simulators only warn about a missing or short file) ...
  std::vector<PromWord> file_words;
  try {
    file_words = readPromHex(prom, cfg.rtl.promWordBits(), cfg.rtl.promDepth());
  } catch (const std::exception& e) {
    throw ArgError(fmt::format("PROM: {}", e.what()));
  }
  for (size_t i = 0; i < file_words.size(); ++i)
    if (file_words[i] != table.words[i])
      throw ArgError(fmt::format("PROM {}: word {} is 0x{}, the table of configuration {} ({}) holds 0x{}", prom, i,
                                 hexWord(file_words[i], cfg.rtl.promWordBits()), o.config, table.request.describe(),
                                 hexWord(table.words[i], cfg.rtl.promWordBits())));
  if (!o.save_vectors.empty()) prepareOutput(o.save_vectors, "--save-vectors");
  if (!o.fst.empty()) prepareOutput(o.fst, "--fst");

  // Plusargs reach $value$plusargs through the default context: set before the model exists.
  const std::string prom_arg = "+prom=" + prom;
  const char* vargv[] = {"shadesim_systemc", prom_arg.c_str()};
  Verilated::commandArgs(2, vargv);
  if (!o.fst.empty()) Verilated::traceEverOn(true);  // before the model, or it traces nothing

  std::unique_ptr<SpecRtl> rtl = makeSpecRtl(o.config, "spec_rtl");
  if (describe(rtl->params()) != describe(cfg.rtl))
    throw ArgError(fmt::format("--config {}: {} now holds {}, the SystemC model was verilated with {}: rebuild",
                               o.config, cfg.path, describe(cfg.rtl), describe(rtl->params())));
  SpecUnitParams model_params = cfg.rtl;
  if (o.fault == "value") {
    // One bit less of c^2 - c in the model than in the RTL (the datapath fault of test_spec_cosim).
    model_params.DiffFracBits -= 1;
    model_params.validate();
  }
  SpecUnitModel model(model_params, table.words);

  std::unique_ptr<SpecSource> src;
  if (file) src = std::make_unique<FileSpecSource>(*file);
  else src = std::make_unique<RandomSpecSource>(cfg.rtl, o.seed, o.vectors, o.gap);

  ScRunControl ctl;
  ctl.max_mismatches = o.max_mismatches;
  sc_core::sc_signal<bool> valid_i{"valid_i"}, valid_o{"valid_o"};
  sc_core::sc_signal<uint32_t> shin_i{"shin_i"}, cos_i{"cos_i"}, light_r_i{"light_r_i"}, light_g_i{"light_g_i"},
      light_b_i{"light_b_i"};
  sc_core::sc_signal<uint32_t> spec_o{"spec_o"}, spec_r_o{"spec_r_o"}, spec_g_o{"spec_g_o"}, spec_b_o{"spec_b_o"};
  sc_core::sc_fifo<SpecExpect> expect_fifo{"expect_fifo", 16}, file_fifo{"file_fifo", 16};

  rtl->clk_i(clk);
  rtl->rst_ni(rst_n);
  rtl->valid_i(valid_i);
  rtl->shin_i(shin_i);
  rtl->cos_i(cos_i);
  rtl->light_r_i(light_r_i);
  rtl->light_g_i(light_g_i);
  rtl->light_b_i(light_b_i);
  rtl->valid_o(valid_o);
  rtl->spec_o(spec_o);
  rtl->spec_r_o(spec_r_o);
  rtl->spec_g_o(spec_g_o);
  rtl->spec_b_o(spec_b_o);

  SpecDriver driver("driver", *src, cfg.rtl.latency() + 2, ctl);
  driver.clk(clk);
  driver.rst_n(rst_n);
  driver.valid_i(valid_i);
  driver.shin_i(shin_i);
  driver.cos_i(cos_i);
  driver.light_r_i(light_r_i);
  driver.light_g_i(light_g_i);
  driver.light_b_i(light_b_i);
  driver.file_expect(file_fifo);

  const SpecFault fault = o.fault == "latency" ? SpecFault::Latency : o.fault == "value" ? SpecFault::Value : SpecFault::None;
  // The failing case's window: the C++ co-simulation's (sim/spec_cosim.cpp), latency + 8 cycles.
  SpecGolden golden("golden", model, fault, !o.save_vectors.empty(),
                    o.save_fail ? static_cast<size_t>(cfg.rtl.latency()) + 8 : 0);
  golden.clk(clk);
  golden.rst_n(rst_n);
  golden.valid_i(valid_i);
  golden.shin_i(shin_i);
  golden.cos_i(cos_i);
  golden.light_r_i(light_r_i);
  golden.light_g_i(light_g_i);
  golden.light_b_i(light_b_i);
  golden.expect(expect_fifo);

  SpecScoreboard board("scoreboard", cfg.rtl, ctl);
  board.clk(clk);
  board.rst_n(rst_n);
  board.valid_o(valid_o);
  board.spec_o(spec_o);
  board.spec_r_o(spec_r_o);
  board.spec_g_o(spec_g_o);
  board.spec_b_o(spec_b_o);
  board.expect(expect_fifo);
  board.file_expect(file_fifo);
  std::optional<ScFirstMismatch<SpecOut>> first;
  std::vector<SpecIn> fail_window;
  uint64_t fail_first = 0;
  if (o.save_fail)
    board.on_first_mismatch = [&](const sc_core::sc_time& t, const SpecOut& e, bool from_file) {
      // The sample at t is the outputs after the edge before it: that edge's cycle fails last.
      first = ScFirstMismatch<SpecOut>{t, e, from_file};
      fail_window = golden.capturedWindow(t - scPeriod(), fail_first);
    };

  // Elaborate and evaluate once (initial blocks: the PROM loads), then check what it loaded.
  sc_core::sc_start(sc_core::SC_ZERO_TIME);
  const std::vector<PromWord> loaded = rtl->romWords();
  for (size_t i = 0; i < loaded.size(); ++i)
    if (loaded[i] != table.words[i])
      throw ArgError(fmt::format("the simulator loaded PROM word {} = 0x{} from {}, the table holds 0x{}", i,
                                 hexWord(loaded[i], cfg.rtl.promWordBits()), prom,
                                 hexWord(table.words[i], cfg.rtl.promWordBits())));
  // Tracing starts after elaboration (VerilatedFstSc::open requires it). The kernel keeps the
  // trace file in its list until the process ends, so it is not deleted here.
  VerilatedFstSc* tfp = nullptr;
  if (!o.fst.empty()) {
    tfp = new VerilatedFstSc;
    rtl->traceFst(*tfp, 99);
    tfp->open(o.fst.c_str());
  }

  const auto t0 = std::chrono::steady_clock::now();
  scSimulate(ctl, o.quiet, fmt::format("systemc spec/{}", o.config), "vectors", static_cast<double>(src->total()),
             [&] { return static_cast<double>(driver.driven()); });
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const uint64_t cycles = scCycle(sc_core::sc_time_stamp());
  rtl->finalize();
  if (tfp) tfp->close();
  board.finish();

  if (!o.save_vectors.empty()) {
    SpecVectors v;
    v.config = o.config;
    v.params = cfg.rtl;  // the unit's: the file replays on it (a fault shows in the source line)
    v.prom = prom;
    if (!temp_prom.path.empty()) {  // the configuration's table, kept beside the file
      const std::string kept = o.save_vectors + ".hex";
      writeFileAtomic(kept, renderProm(table, PromFormat::Hex));
      v.prom = fs::path(kept).filename().string();
    }
    v.source = fmt::format("shadesim_systemc --unit spec --config {} {} (the golden-model module's predictions{})",
                           o.config, file ? "--vector-file " + o.vector_file : fmt::format("--seed {} --vectors {}", o.seed, o.vectors),
                           o.fault == "none" ? "" : ", fault " + o.fault);
    v.in = golden.recordedInputs();
    v.expected = golden.recordedOutputs();
    writeSpecVectors(o.save_vectors, v);
  }

  ScReport r;
  r.score = board.score();
  const ScScore& s = r.score;
  if (first) r.fail = saveSpecFail(o, *first, fail_window, fail_first, cfg.rtl, model, fault, prom, s.first);
  if (file) {
    // Where the first mismatching sample falls in the file (1-based; the outputs after cycle i's
    // edge are sampled kResetCycles + 2 + i edges from time 0), and the first that differs from the
    // file's own expectation: a replayed failing case must fail at its last cycle.
    r.add("mismatch_file_cycle", s.first.empty() ? uint64_t{0} : scCycle(s.first_time) - kResetCycles - 1);
    r.add("file_mismatch_cycle", static_cast<uint64_t>(s.first_file_cycle + 1));
  }
  if (driver.driven() != src->total()) {
    r.complete = false;
    r.incomplete = fmt::format("the run stopped after {} of {} valid vectors", driver.driven(), src->total());
  }
  if (r.complete && s.expected_items != driver.driven()) {
    // One result per valid input (the unit never stalls): fewer means the stimulus did not
    // reach the ports the model and the RTL read.
    r.complete = false;
    r.incomplete = fmt::format("{} valid vectors driven, the model predicts {} results", driver.driven(), s.expected_items);
  }
  if (file && board.fileChecks() != file->in.size()) {
    r.complete = false;
    r.incomplete = fmt::format("{} of the file's {} expected outputs were compared", board.fileChecks(), file->in.size());
  }
  const std::string what = file ? fmt::format("vector file {} ({} cycles)", o.vector_file, file->in.size())
                                : fmt::format("seed {}", o.seed);
  r.summary = fmt::format(
      "systemc spec/{} {}: {} vectors driven, {} results (model {}, rtl {}, {} equal in value and cycle), {} samples "
      "compared{}, {} mismatches; {} cycles simulated in {:.2f} s wall ({:.0f} cycles/s)",
      o.config, what, driver.driven(), s.matched_items, s.expected_items, s.observed_items, s.matched_items, s.samples,
      file ? fmt::format(" ({} also against the file's expected outputs)", board.fileChecks()) : std::string(),
      s.mismatches(), cycles, secs, secs > 0 ? cycles / secs : 0.0);
  r.add("prom", prom);
  r.add("stimulus", std::string(file ? "vector-file" : "random"));
  if (file) r.add("vector_file", o.vector_file);
  else r.add("seed", o.seed);
  r.add("vectors", driver.driven());
  r.add("results_expected", s.expected_items);
  r.add("results_observed", s.observed_items);
  r.add("results_matched", s.matched_items);
  r.add("file_checks", board.fileChecks());
  r.add("cycles", cycles);
  r.add("seconds", secs);
  if (!o.save_vectors.empty()) r.add("saved_vectors", o.save_vectors);
  return r;
}

}  // namespace shd
