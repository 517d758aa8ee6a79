// The specular unit's SystemC run: sc_clock and reset from sc_main, the verilated configuration
// (SpecRtl), SpecDriver, SpecGolden and SpecScoreboard (spec_tb.h), bound by signals and FIFOs.
//
// runSpecSc, in order: the configuration and the files the run is checked against (vector file,
// PROM), checked before anything is built; the verilated unit and the golden model; SpecBench,
// the testbench around them; the run; then the --save-vectors file, the failing case and the
// report.
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <optional>

#include <unistd.h>

#include <fmt/format.h>
#include <verilated.h>

#include "config/registry.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "sc_run.h"
#include "spec_rtl.h"
#include "spec_tb.h"
#include "vectors/vector_file.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd {

namespace {

// The parameters as text (compared and shown; SpecUnitParams::toJson would need the JSON headers).
std::string describe(const SpecUnitParams& p) {
  return fmt::format("Degree={} CosFracBits={} ShinBits={} CoefIntBits={} CoefFracBits={} DiffFracBits={} "
                     "HornerFracBits={} SpecFracBits={} LightBits={} PipeStages={} Kind={} TableBits={}",
                     p.Degree, p.CosFracBits, p.ShinBits, p.CoefIntBits, p.CoefFracBits, p.DiffFracBits,
                     p.HornerFracBits, p.SpecFracBits, p.LightBits, p.PipeStages, p.Kind, p.TableBits);
}

// --vector-file (null without one), made for the unit's parameters p.
std::unique_ptr<SpecVectors> loadSpecFile(const ScOptions& o, const SpecUnitParams& p) {
  if (o.vector_file.empty()) return nullptr;
  std::unique_ptr<SpecVectors> file;
  try {
    file = std::make_unique<SpecVectors>(loadSpecVectors(o.vector_file));
  } catch (const std::exception& e) {
    throw ArgError(fmt::format("--vector-file: {}", e.what()));
  }
  requireFileParams(o, file->config, describe(file->params), describe(p));
  return file;
}

// A temporary PROM file and, for the piecewise kind, its segment ROM (path + kSegRomSuffix),
// removed with this object.
struct TempProm {
  std::string path;
  ~TempProm() {
    if (!path.empty()) {
      std::error_code ec;
      fs::remove(path, ec);
      fs::remove(path + kSegRomSuffix, ec);
    }
  }
};

// The PROM file the simulator loads: --prom, else the vector file's own (relative to the file),
// else the configuration's table written to a temporary file (temp).
std::string promFile(const ScOptions& o, const SpecVectors* file, const PromTable& table, TempProm& temp) {
  if (!o.prom.empty()) return fs::absolute(o.prom).string();
  if (file && !file->prom.empty()) {
    const fs::path p(file->prom);
    return (p.is_absolute() ? p : fs::absolute(o.vector_file).parent_path() / p).lexically_normal().string();
  }
  temp.path = (fs::temp_directory_path() / fmt::format("shadesim_systemc-{}-spec_{}.hex", getpid(), o.config)).string();
  writePromHexFiles(temp.path, table);
  return temp.path;
}

// The PROM must hold the configuration's table: the file first, strictly (the simulators only
// warn about a missing or short file) ...
void checkPromFile(const ScOptions& o, const std::string& prom, const SpecUnitConfig& cfg, const PromTable& table) {
  RomImage file_words;
  try {
    file_words = readPromHexFiles(prom, cfg.rtl);
  } catch (const std::exception& e) {
    throw ArgError(fmt::format("PROM: {}", e.what()));
  }
  const std::string d = romImageDiff(file_words, RomImage::of(table), cfg.rtl);
  if (!d.empty())
    throw ArgError(fmt::format("PROM {}: {} (the table of configuration {}, {})", prom, d, o.config,
                               table.request.describe()));
}

// ... then what the simulator loaded from it (once the model has evaluated).
void checkLoadedProm(const SpecRtl& rtl, const std::string& prom, const SpecUnitParams& p, const PromTable& table) {
  const std::string d = romImageDiff({rtl.romWords(), rtl.segRomWords()}, RomImage::of(table), p);
  if (!d.empty()) throw ArgError(fmt::format("the simulator loaded from {}: {} (the table's)", prom, d));
}

// The verilated configuration, which loads the PROM file prom; checked against the
// configuration file, which may have changed since the build.
std::unique_ptr<SpecRtl> makeRtl(const ScOptions& o, const SpecUnitConfig& cfg, const std::string& prom) {
  // Plusargs reach $value$plusargs through the default context: set before the model exists.
  const std::string prom_arg = "+prom=" + prom;
  const char* vargv[] = {"shadesim_systemc", prom_arg.c_str()};
  Verilated::commandArgs(2, vargv);
  std::unique_ptr<SpecRtl> rtl = makeSpecRtl(o.config, "spec_rtl");
  if (describe(rtl->params()) != describe(cfg.rtl))
    throw ArgError(fmt::format("--config {}: {} now holds {}, the SystemC model was verilated with {}: rebuild",
                               o.config, cfg.path, describe(cfg.rtl), describe(rtl->params())));
  return rtl;
}

SpecFault specFault(const ScOptions& o) {
  return o.fault == "latency" ? SpecFault::Latency : o.fault == "value" ? SpecFault::Value : SpecFault::None;
}

// The golden model's parameters: the unit's p, but with --fault value one bit less of c^2 - c in
// the model than in the RTL (the datapath fault of testbench/test_spec_cosim.cpp).
SpecUnitParams modelParams(const ScOptions& o, SpecUnitParams p) {
  if (o.fault == "value") {
    p.DiffFracBits -= 1;
    p.validate();
  }
  return p;
}

// What the failing case is saved from, captured at the run's first mismatching sample.
struct SpecFailCapture {
  std::optional<ScFirstMismatch<SpecOut>> first;
  std::vector<SpecIn> window;  // the inputs of the active cycles up to the failing one
  uint64_t run_first = 0;      // the run's cycle of the window's first
};

// The testbench around the verilated unit (the diagram in spec_tb.h): the driver, the
// golden-model module and the scoreboard, and the signals and FIFOs that connect them, bound in
// the constructor.
struct SpecBench {
  ScRunControl ctl;
  sc_core::sc_signal<bool> valid_i{"valid_i"}, valid_o{"valid_o"};
  sc_core::sc_signal<uint32_t> shin_i{"shin_i"}, cos_i{"cos_i"}, light_r_i{"light_r_i"}, light_g_i{"light_g_i"},
      light_b_i{"light_b_i"};
  sc_core::sc_signal<uint32_t> spec_o{"spec_o"}, spec_r_o{"spec_r_o"}, spec_g_o{"spec_g_o"}, spec_b_o{"spec_b_o"};
  sc_core::sc_fifo<SpecExpect> expect_fifo{"expect_fifo", 16}, file_fifo{"file_fifo", 16};
  SpecDriver driver;
  SpecGolden golden;
  SpecScoreboard board;
  SpecFailCapture fail;  // filled unless --no-fail-save

  SpecBench(const ScOptions& o, const SpecUnitParams& p, SpecRtl& rtl, SpecSource& src, SpecUnitModel& model,
            sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n)
      : driver("driver", src, p.latency() + 2, ctl),
        // The failing case's window: the C++ co-simulation's (sim/cosim/spec_cosim.cpp), latency + 8 cycles.
        golden("golden", model, specFault(o), !o.save_vectors.empty(),
               o.save_fail ? static_cast<size_t>(p.latency()) + 8 : 0),
        board("scoreboard", p, ctl) {
    ctl.max_mismatches = o.max_mismatches;
    rtl.clk_i(clk);
    rtl.rst_ni(rst_n);
    rtl.valid_i(valid_i);
    rtl.shin_i(shin_i);
    rtl.cos_i(cos_i);
    rtl.light_r_i(light_r_i);
    rtl.light_g_i(light_g_i);
    rtl.light_b_i(light_b_i);
    rtl.valid_o(valid_o);
    rtl.spec_o(spec_o);
    rtl.spec_r_o(spec_r_o);
    rtl.spec_g_o(spec_g_o);
    rtl.spec_b_o(spec_b_o);

    driver.clk(clk);
    driver.rst_n(rst_n);
    driver.valid_i(valid_i);
    driver.shin_i(shin_i);
    driver.cos_i(cos_i);
    driver.light_r_i(light_r_i);
    driver.light_g_i(light_g_i);
    driver.light_b_i(light_b_i);
    driver.file_expect(file_fifo);

    golden.clk(clk);
    golden.rst_n(rst_n);
    golden.valid_i(valid_i);
    golden.shin_i(shin_i);
    golden.cos_i(cos_i);
    golden.light_r_i(light_r_i);
    golden.light_g_i(light_g_i);
    golden.light_b_i(light_b_i);
    golden.expect(expect_fifo);

    board.clk(clk);
    board.rst_n(rst_n);
    board.valid_o(valid_o);
    board.spec_o(spec_o);
    board.spec_r_o(spec_r_o);
    board.spec_g_o(spec_g_o);
    board.spec_b_o(spec_b_o);
    board.expect(expect_fifo);
    board.file_expect(file_fifo);
    if (o.save_fail)
      board.on_first_mismatch = [this](const sc_core::sc_time& t, const SpecOut& e, bool from_file) {
        // The sample at t is the outputs after the edge before it: that edge's cycle fails last.
        fail.first = ScFirstMismatch<SpecOut>{t, e, from_file};
        fail.window = golden.capturedWindow(t - scPeriod(), fail.run_first);
      };
  }
};

// --save-vectors: the inputs on the ports every cycle and the golden model's outputs, naming the
// PROM file the run loaded (temp_prom: the configuration's table, then kept beside the file).
void saveSpecVectors(const ScOptions& o, const SpecUnitParams& p, const PromTable& table, const std::string& prom,
                     bool temp_prom, const SpecGolden& golden) {
  SpecVectors v;
  v.config = o.config;
  v.params = p;  // the unit's: the file replays on it (a fault shows in the source line)
  v.prom = prom;
  OutputFiles out;  // the file and the PROM kept beside it: both or neither
  if (temp_prom) {
    const std::string kept = o.save_vectors + ".hex";
    for (const auto& [suffix, text] : renderPromFiles(table, PromFormat::Hex)) out.add(kept + suffix, text);
    v.prom = fs::path(kept).filename().string();
  }
  v.source = savedVectorsSource(o);
  v.in = golden.recordedInputs();
  v.expected = golden.recordedOutputs();
  out.add(o.save_vectors, renderSpecVectors(v));
  out.commit();
}

// The failing case (sc_run.h, ScFailCase): the captured window of inputs, from reset, with the
// golden module's predictions replayed on it (the fault included: that is what differs from the
// RTL), beside a copy of the PROM; the last cycle, the failing one, carries the expectation the
// run failed when that was the vector file's (the model agrees with the RTL there).
ScFailCase saveSpecFail(const ScOptions& o, const SpecFailCapture& cap, const SpecUnitParams& unit,
                        const SpecUnitModel& model, const std::string& prom, const std::string& what) {
  const ScFirstMismatch<SpecOut>& first = *cap.first;
  const auto write = [&](const std::string& vec) {
    const std::string hex = failPath(o, "hex");
    SpecVectors v;
    v.config = o.config;
    v.params = unit;  // the unit's: the file replays on it
    v.prom = fs::path(hex).filename().string();
    v.in = cap.window;
    v.expected = specGoldenReplay(model, specFault(o), cap.window);
    if (first.from_file) v.expected.back() = first.expected;
    v.source = failCaseSource(o, cap.run_first, cap.window.size());
    v.notes = {failCaseExpectedNote(o, first.from_file),
               fmt::format("the run's first mismatch (the outputs after the last cycle's edge): {}", what)};
    // The PROM the simulator loaded, beside the file (the file names it relative to itself).
    std::ifstream in(prom, std::ios::binary);
    if (!in) throw std::runtime_error(fmt::format("cannot read back PROM file {}", prom));
    writeFileAtomic(hex, std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>()));
    writeSpecVectors(vec, v);
  };
  ScFailCase f = saveFailCase(o, what, cap.window.size(), cap.run_first,
                              "the first mismatch is the sample at the first active edge (the state reset left), "
                              "which no cycle of a vector file holds",
                              write);
  if (!f.vec.empty()) f.prom = failPath(o, "hex");
  return f;
}

// Whether every vector went through (r.complete; why not: r.incomplete).
void checkSpecComplete(const SpecVectors* file, const SpecSource& src, const SpecBench& tb, ScReport& r) {
  const uint64_t driven = tb.driver.driven();
  if (driven != src.total()) {
    r.complete = false;
    r.incomplete = fmt::format("the run stopped after {} of {} valid vectors", driven, src.total());
  }
  if (r.complete && r.score.expected_items != driven) {
    // One result per valid input (the unit never stalls): fewer means the stimulus did not
    // reach the ports the model and the RTL read.
    r.complete = false;
    r.incomplete = fmt::format("{} valid vectors driven, the model predicts {} results", driven, r.score.expected_items);
  }
  if (file && tb.board.fileChecks() != file->in.size()) {
    r.complete = false;
    r.incomplete = fmt::format("{} of the file's {} expected outputs were compared", tb.board.fileChecks(), file->in.size());
  }
}

// The report's fields, completeness and summary (r.score and r.fail already in).
void reportSpec(const ScOptions& o, const SpecVectors* file, const SpecSource& src, const SpecBench& tb,
                const std::string& prom, const ScRunTime& time, ScReport& r) {
  const ScScore& s = r.score;
  if (file) {
    // Where the first mismatching sample falls in the file (1-based; the outputs after cycle i's
    // edge are sampled kResetCycles + 2 + i edges from time 0), and the first that differs from the
    // file's own expectation: a replayed failing case must fail at its last cycle.
    r.add("mismatch_file_cycle", s.first.empty() ? uint64_t{0} : scCycle(s.first_time) - kResetCycles - 1);
    r.add("file_mismatch_cycle", static_cast<uint64_t>(s.first_file_cycle + 1));
  }
  checkSpecComplete(file, src, tb, r);
  const std::string what = file ? fmt::format("vector file {} ({} cycles)", o.vector_file, file->in.size())
                                : fmt::format("seed {}", o.seed);
  r.summary = fmt::format(
      "systemc spec/{} {}: {} vectors driven, {} results (model {}, rtl {}, {} equal in value and cycle), {} samples "
      "compared{}, {} mismatches; {}",
      o.config, what, tb.driver.driven(), s.matched_items, s.expected_items, s.observed_items, s.matched_items,
      s.samples, file ? fmt::format(" ({} also against the file's expected outputs)", tb.board.fileChecks()) : std::string(),
      s.mismatches(), time.describe());
  r.add("prom", prom);
  r.add("stimulus", std::string(file ? "vector-file" : "random"));
  if (file) r.add("vector_file", o.vector_file);
  else r.add("seed", o.seed);
  r.add("vectors", tb.driver.driven());
  r.add("results_expected", s.expected_items);
  r.add("results_observed", s.observed_items);
  r.add("results_matched", s.matched_items);
  r.add("file_checks", tb.board.fileChecks());
  r.add("cycles", time.cycles);
  r.add("seconds", time.secs);
  if (!o.save_vectors.empty()) r.add("saved_vectors", o.save_vectors);
}

}  // namespace

ScReport runSpecSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n) {
  requireBuilt(o, scSpecRtlConfigs(), "specular unit");
  const SpecUnitConfig cfg = specConfig(o.config);
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
  const std::unique_ptr<SpecVectors> file = loadSpecFile(o, cfg.rtl);
  TempProm temp_prom;
  const std::string prom = promFile(o, file.get(), table, temp_prom);
  checkPromFile(o, prom, cfg, table);
  prepareOutputs(o);

  ScWaveform wave(o.fst);  // before the model
  const std::unique_ptr<SpecRtl> rtl = makeRtl(o, cfg, prom);
  SpecUnitModel model(modelParams(o, cfg.rtl), table.words, table.seg_words);
  std::unique_ptr<SpecSource> src;
  if (file) src = std::make_unique<FileSpecSource>(*file);
  else src = std::make_unique<RandomSpecSource>(cfg.rtl, o.seed, o.vectors, o.gap);
  SpecBench tb(o, cfg.rtl, *rtl, *src, model, clk, rst_n);

  // Elaborate and evaluate once (initial blocks: the PROM loads), then check what it loaded.
  sc_core::sc_start(sc_core::SC_ZERO_TIME);
  checkLoadedProm(*rtl, prom, cfg.rtl, table);
  wave.open([&](VerilatedFstC& tfp) { rtl->traceFst(tfp, 99); });
  const ScRunTime time = scSimulate(tb.ctl, o, "vectors", static_cast<double>(src->total()),
                                    [&] { return static_cast<double>(tb.driver.driven()); });
  rtl->finalize();
  wave.close();
  tb.board.finish();

  if (!o.save_vectors.empty()) saveSpecVectors(o, cfg.rtl, table, prom, !temp_prom.path.empty(), tb.golden);
  ScReport r;
  r.score = tb.board.score();
  if (tb.fail.first) r.fail = saveSpecFail(o, tb.fail, cfg.rtl, model, prom, r.score.first);
  reportSpec(o, file.get(), *src, tb, prom, time, r);
  return r;
}

}  // namespace shd
