// The span unit's SystemC run: sc_clock and reset from sc_main, the verilated configuration
// (SpanRtl), a driver (SpanDriver for generator triangles or a scene's descriptors,
// SpanFileDriver for a vector file), SpanGolden and SpanScoreboard (span_tb.h).
//
// runSpanSc, in order: the verilated unit, checked against its configuration; SpanStimulus, the
// descriptors or the vector file; SpanBench, the testbench around the unit; the run; then the
// --save-vectors file, the failing case and the report.
#include <algorithm>
#include <functional>
#include <memory>
#include <optional>
#include <utility>

#include <fmt/format.h>

#include "config/registry.h"
#include "raster/desc_stream.h"
#include "sc_run.h"
#include "scene_descs.h"
#include "span_rtl.h"
#include "span_tb.h"
#include "vectors/vector_file.h"

namespace shd {

namespace {

std::string describe(const SpanParams& p) {
  return fmt::format("NumTri={} LanesPerTri={} AlignLanes={} NumAttr={} AttrBits={} CoordBits={} RemBits={} PixBits={} "
                     "TagBits={}",
                     p.NumTri, p.LanesPerTri, p.AlignLanes, p.NumAttr, p.AttrBits, p.CoordBits, p.RemBits, p.PixBits,
                     p.TagBits);
}

// The verilated configuration, checked against the configuration file, which may have changed
// since the build.
std::unique_ptr<SpanRtl> makeRtl(const ScOptions& o) {
  std::unique_ptr<SpanRtl> rtl = makeSpanRtl(o.config, "span_rtl");
  const SpanParams& p = rtl->params();
  const SpanUnitConfig cfg = spanConfig(o.config);
  if (describe(cfg.rtl) != describe(p))
    throw ArgError(fmt::format("--config {}: {} holds {}, the SystemC model was verilated with {}: rebuild", o.config,
                               cfg.path, describe(cfg.rtl), describe(p)));
  return rtl;
}

// --vector-file, made for the unit's parameters p.
std::unique_ptr<SpanVectors> loadSpanFile(const ScOptions& o, const SpanParams& p) {
  std::unique_ptr<SpanVectors> file;
  try {
    file = std::make_unique<SpanVectors>(loadSpanVectors(o.vector_file));
  } catch (const std::exception& e) {
    throw ArgError(fmt::format("--vector-file: {}", e.what()));
  }
  requireFileParams(o, file->config, describe(file->params), describe(p));
  return file;
}

// The stimulus: a vector file, the scene's descriptors, or seeded generator triangles. next()
// hands the descriptors of the latter two to SpanDriver.
struct SpanStimulus {
  std::unique_ptr<SpanVectors> file;
  std::optional<SceneDescriptors> scene;
  size_t scene_next = 0;
  std::unique_ptr<DescriptorStream> stream;
  uint64_t total = 0;  // descriptors (scene, generator triangles) or cycles (file)
  std::function<bool(SpanDesc&)> next;

  SpanStimulus(const ScOptions& o, const SpanParams& p) {
    if (!o.vector_file.empty()) {
      file = loadSpanFile(o, p);
      total = file->cycles.size();
    } else if (!o.scene.empty()) {
      try {
        scene = recordSceneDescriptors(o.scene, p);
      } catch (const std::exception& e) {
        throw ArgError(fmt::format("--scene {}: {}", o.scene, e.what()));
      }
      total = scene->descs.size();
      if (o.triangles_given) total = std::min<uint64_t>(total, o.triangles);
      next = [this](SpanDesc& d) {
        if (scene_next >= total) return false;
        d = scene->descs[scene_next++];
        return true;
      };
    } else {
      RasterConfig rc;
      rc.unit = p;
      stream = std::make_unique<DescriptorStream>(o.seed, o.triangles, rc);
      total = o.triangles;  // generator triangles; setup drops some
      next = [this](SpanDesc& d) { return stream->next(d); };
    }
  }
  SpanStimulus(const SpanStimulus&) = delete;  // next refers to this object
  SpanStimulus& operator=(const SpanStimulus&) = delete;
};

SpanFault spanFault(const ScOptions& o) {
  return o.fault == "latency" ? SpanFault::Latency : o.fault == "value" ? SpanFault::Value : SpanFault::None;
}

SpanDriverOptions driverOptions(const ScOptions& o, const SpanParams& p) {
  SpanDriverOptions dopt;
  dopt.seed = o.seed;
  dopt.ready_prob = o.ready;
  dopt.desc_gap_prob = o.desc_gap;
  dopt.drain_every = p.RowAhead ? 32 : 0;  // as shadesim cosim's default
  return dopt;
}

// What the failing case is saved from, captured at the run's first mismatching sample.
struct SpanFailCapture {
  std::optional<ScFirstMismatch<SpanOut>> first;
  SpanVectors cycles;        // the captured cycles up to the failing one (SpanGolden::capturedCase)
  uint64_t run_first = 0;    // the run's cycle of the first of them
  bool from_idle = false;  // ... the last cycle the golden model was idle before (else the run's first)
};

// The testbench around the verilated unit (the diagram in span_tb.h): the driver (the vector
// file's or the random one), the golden-model module and the scoreboard, and the signals and
// FIFOs that connect them, bound in the constructor.
struct SpanBench {
  ScRunControl ctl;
  sc_core::sc_signal<bool> desc_valid_i{"desc_valid_i"}, desc_ready_o{"desc_ready_o"}, out_valid_o{"out_valid_o"},
      out_ready_i{"out_ready_i"}, model_idle{"model_idle"};
  sc_core::sc_fifo<DescToken> desc_fifo{"desc_fifo", 16};
  sc_core::sc_fifo<SpanExpect> expect_fifo{"expect_fifo", 16}, file_fifo{"file_fifo", 16};
  std::unique_ptr<SpanFileDriver> file_driver;  // with a vector file
  std::unique_ptr<SpanDriver> driver;           // else
  SpanGolden golden;
  SpanScoreboard board;
  SpanFailCapture fail;  // filled unless --no-fail-save

  SpanBench(const ScOptions& o, SpanRtl& rtl, const SpanStimulus& stim, sc_core::sc_clock& clk,
            sc_core::sc_signal<bool>& rst_n)
      : file_driver(stim.file ? std::make_unique<SpanFileDriver>("driver", *stim.file, ctl) : nullptr),
        driver(stim.file ? nullptr : std::make_unique<SpanDriver>("driver", stim.next, driverOptions(o, rtl.params()), ctl)),
        golden("golden", rtl.params(), spanFault(o), !o.save_vectors.empty(), o.save_fail),
        board("scoreboard", ctl) {
    ctl.max_mismatches = o.max_mismatches;
    rtl.clk_i(clk);
    rtl.rst_ni(rst_n);
    rtl.desc_valid_i(desc_valid_i);
    rtl.desc_ready_o(desc_ready_o);
    rtl.out_valid_o(out_valid_o);
    rtl.out_ready_i(out_ready_i);

    if (file_driver) {
      file_driver->clk(clk);
      file_driver->rst_n(rst_n);
      file_driver->desc_valid_i(desc_valid_i);
      file_driver->out_ready_i(out_ready_i);
      file_driver->pins(rtl);
      file_driver->offered(desc_fifo);
      file_driver->file_expect(file_fifo);
    } else {
      driver->clk(clk);
      driver->rst_n(rst_n);
      driver->desc_ready_o(desc_ready_o);
      driver->model_idle(model_idle);
      driver->desc_valid_i(desc_valid_i);
      driver->out_ready_i(out_ready_i);
      driver->pins(rtl);
      driver->offered(desc_fifo);
    }

    golden.clk(clk);
    golden.rst_n(rst_n);
    golden.desc_valid_i(desc_valid_i);
    golden.out_ready_i(out_ready_i);
    golden.offered(desc_fifo);
    golden.expect(expect_fifo);
    golden.model_idle(model_idle);

    board.clk(clk);
    board.rst_n(rst_n);
    board.out_ready_i(out_ready_i);
    board.rtl(rtl);
    board.expect(expect_fifo);
    board.file_expect(file_fifo);
    if (o.save_fail)
      board.on_first_mismatch = [this](const sc_core::sc_time& t, const SpanOut& e, bool from_file) {
        fail.first = ScFirstMismatch<SpanOut>{t, e, from_file};  // the outputs during the cycle sampled at t
        fail.cycles = golden.capturedCase(t, fail.run_first, fail.from_idle);
      };
  }

  // The run's progress: the file's cycles driven, or the triangles the RTL accepted.
  ScRunTime simulate(const ScOptions& o, const SpanStimulus& stim) {
    if (file_driver)
      return scSimulate(ctl, o, "cycles", static_cast<double>(stim.total),
                        [&] { return static_cast<double>(file_driver->cyclesDriven()); });
    return scSimulate(ctl, o, "triangles", static_cast<double>(stim.total),
                      [&] { return static_cast<double>(driver->acceptedByRtl()); });
  }
};

// --save-vectors: the inputs on the ports every cycle and the golden model's outputs.
void saveSpanVectors(const ScOptions& o, const SpanGolden& golden) {
  SpanVectors v = golden.recorded();
  v.config = o.config;
  v.source = savedVectorsSource(o);
  writeSpanVectors(o.save_vectors, v);
}

// The failing case (sc_run.h, ScFailCase): the captured cycles (the current triangle from the
// cycle that accepted it, and what the ports carried up to the failing cycle), from reset, with
// the golden module's predictions replayed on them (the fault included); the last cycle carries
// the expectation the run failed when that was the vector file's.
ScFailCase saveSpanFail(const ScOptions& o, SpanFailCapture cap, const std::string& what) {
  const ScFirstMismatch<SpanOut>& first = *cap.first;
  SpanVectors& v = cap.cycles;
  const auto write = [&](const std::string& vec) {
    v.config = o.config;
    spanGoldenReplay(v, v.params, spanFault(o));
    if (first.from_file) v.cycles.back().expected = first.expected;
    v.source = failCaseSource(o, cap.run_first, v.cycles.size());
    v.notes = {cap.from_idle ? "from the last cycle the unit was idle (the paper's unit: the one that accepted the failing "
                               "triangle) to the failing cycle"
                               : "from the run's first cycle (no triangle accepted before) to the failing cycle",
               failCaseExpectedNote(o, first.from_file),
               fmt::format("the run's first mismatch (the outputs during the last cycle): {}", what)};
    writeSpanVectors(vec, v);
  };
  return saveFailCase(o, what, v.cycles.size(), cap.run_first, "no captured cycle up to the failing sample", write);
}

// The descriptors the run was to put through: the file's offered ones, the scene's (at most
// --triangles), or the generator triangles setup did not drop.
uint64_t spanDescriptors(const SpanStimulus& stim, const SpanBench& tb) {
  if (stim.file) return tb.file_driver->offeredCount();
  return stim.scene ? stim.total : stim.stream->generated() - stim.stream->dropped();
}

// Whether every cycle of the file or every descriptor went through (r.complete; why not:
// r.incomplete).
void checkSpanComplete(const ScOptions& o, const SpanStimulus& stim, const SpanBench& tb, uint64_t descs,
                       ScReport& r) {
  if (stim.file) {
    const uint64_t cycles = stim.file->cycles.size(), driven = tb.file_driver->cyclesDriven();
    if (driven != cycles || tb.board.fileChecks() != cycles) {
      r.complete = false;
      r.incomplete = fmt::format("{} of the file's {} cycles driven, {} compared with its expected outputs", driven,
                                 cycles, tb.board.fileChecks());
    }
    return;
  }
  if (tb.driver->acceptedByRtl() != descs || tb.golden.accepted() != descs) {
    r.complete = false;
    r.incomplete = fmt::format("of {} descriptors the RTL accepted {}, the model {}", descs, tb.driver->acceptedByRtl(),
                               tb.golden.accepted());
  }
  if (stim.scene && stim.total == stim.scene->descs.size() && r.complete &&
      r.score.matched_items != stim.scene->frame_fragments) {
    // The whole frame went through: the unit must have handed over exactly the fragments the
    // render counted for it.
    r.complete = false;
    r.incomplete = fmt::format("the render of {} counted {} fragments, the co-simulation handed over {}", o.scene,
                               stim.scene->frame_fragments, r.score.matched_items);
  }
}

// The stimulus, for the summary.
std::string describeSpanStimulus(const ScOptions& o, const SpanStimulus& stim, uint64_t descs) {
  if (stim.file)
    return fmt::format("vector file {} ({} cycles, {} descriptors offered)", o.vector_file, stim.file->cycles.size(),
                       descs);
  if (stim.scene) {
    const SceneDescriptors& scene = *stim.scene;
    return fmt::format("scene {} ({} scene triangles, {} culled, {} drawn, {} fragments in the frame{})", o.scene,
                       scene.scene_triangles, scene.culled, scene.descs.size(), scene.frame_fragments,
                       stim.total < scene.descs.size() ? fmt::format(", the first {} simulated", stim.total)
                                                       : std::string());
  }
  return fmt::format("seed {}: {} generator triangles ({} dropped by setup)", o.seed, stim.stream->generated(),
                     stim.stream->dropped());
}

// The report's fields (--json), in print order.
void addSpanFields(const ScOptions& o, const SpanStimulus& stim, const SpanBench& tb, uint64_t descs,
                   const ScRunTime& time, ScReport& r) {
  const ScScore& s = r.score;
  r.add("stimulus", std::string(stim.file ? "vector-file" : stim.scene ? "scene" : "random"));
  if (stim.file) {
    r.add("vector_file", o.vector_file);
    r.add("file_cycles", static_cast<uint64_t>(stim.file->cycles.size()));
    r.add("file_checks", tb.board.fileChecks());
  } else {
    r.add("seed", o.seed);
    r.add("ready_prob", o.ready);
    r.add("desc_gap_prob", o.desc_gap);
  }
  if (stim.scene) {
    r.add("scene", o.scene);
    r.add("scene_triangles", stim.scene->scene_triangles);
    r.add("drawn", static_cast<uint64_t>(stim.scene->descs.size()));
    r.add("frame_fragments", stim.scene->frame_fragments);
    r.add("frame_cycles_always_ready", stim.scene->frame_cycles);
  }
  if (stim.stream) {
    r.add("generated", stim.stream->generated());
    r.add("dropped_at_setup", stim.stream->dropped());
  }
  r.add("descriptors", descs);
  if (tb.driver) r.add("accepted_rtl", tb.driver->acceptedByRtl());
  r.add("accepted_model", tb.golden.accepted());
  r.add("fragments_expected", s.expected_items);
  r.add("fragments_observed", s.observed_items);
  r.add("fragments_matched", s.matched_items);
  r.add("cycles", time.cycles);
  r.add("seconds", time.secs);
  if (!o.save_vectors.empty()) r.add("saved_vectors", o.save_vectors);
}

// The report's fields, completeness and summary (r.score and r.fail already in).
void reportSpan(const ScOptions& o, const SpanStimulus& stim, const SpanBench& tb, const ScRunTime& time,
                ScReport& r) {
  const ScScore& s = r.score;
  if (stim.file) {
    // Where the first mismatching sample falls in the file (1-based; cycle i's outputs are sampled
    // kResetCycles + 1 + i edges from time 0), and the first that differs from the file's own
    // expectation: a replayed failing case must fail at its last cycle.
    r.add("mismatch_file_cycle", s.first.empty() ? uint64_t{0} : scCycle(s.first_time) - kResetCycles);
    r.add("file_mismatch_cycle", static_cast<uint64_t>(s.first_file_cycle + 1));
  }
  const uint64_t descs = spanDescriptors(stim, tb);
  checkSpanComplete(o, stim, tb, descs, r);
  r.summary = fmt::format(
      "systemc span/{} {}: descriptors accepted by {}the model {}, {} fragments (model {}, rtl {}, {} equal in value "
      "and cycle), {} samples compared{}, {} mismatches; {}",
      o.config, describeSpanStimulus(o, stim, descs),
      tb.driver ? fmt::format("the RTL {}, ", tb.driver->acceptedByRtl()) : std::string(), tb.golden.accepted(),
      s.matched_items, s.expected_items, s.observed_items, s.matched_items, s.samples,
      stim.file ? fmt::format(" ({} also against the file's expected outputs)", tb.board.fileChecks()) : std::string(),
      s.mismatches(), time.describe());
  addSpanFields(o, stim, tb, descs, time, r);
}

}  // namespace

ScReport runSpanSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n) {
  requireBuilt(o, scSpanRtlConfigs(), "span unit");
  ScWaveform wave(o.fst);  // before the model
  const std::unique_ptr<SpanRtl> rtl = makeRtl(o);
  SpanStimulus stim(o, rtl->params());
  prepareOutputs(o);  // after the inputs are read: an output may not be one of them
  SpanBench tb(o, *rtl, stim, clk, rst_n);

  sc_core::sc_start(sc_core::SC_ZERO_TIME);  // elaborate: the waveform opens after it
  wave.open([&](VerilatedFstC& tfp) { rtl->traceFst(tfp, 99); });
  const ScRunTime time = tb.simulate(o, stim);
  rtl->finalize();
  wave.close();
  tb.board.finish();

  if (!o.save_vectors.empty()) saveSpanVectors(o, tb.golden);
  ScReport r;
  r.score = tb.board.score();
  if (tb.fail.first) r.fail = saveSpanFail(o, std::move(tb.fail), r.score.first);
  reportSpan(o, stim, tb, time, r);
  return r;
}

}  // namespace shd
