// The span unit's SystemC run: sc_clock and reset from sc_main, the verilated configuration
// (SpanRtl), a driver (SpanDriver for generator triangles or a scene's descriptors,
// SpanFileDriver for a vector file), SpanGolden and SpanScoreboard (span_tb.h).
#include <algorithm>
#include <memory>
#include <optional>

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

// The failing case (sc_run.h, ScFailCase): the captured cycles (the current triangle from the
// cycle that accepted it, and what the ports carried up to the failing cycle), from reset, with
// the golden module's predictions replayed on them (the fault included); the last cycle carries
// the expectation the run failed when that was the vector file's.
ScFailCase saveSpanFail(const ScOptions& o, const ScFirstMismatch<SpanOut>& first, SpanVectors v, uint64_t run_first,
                        bool from_accept, SpanFault fault, const std::string& what) {
  const auto write = [&](const std::string& vec) {
    v.config = o.config;
    spanGoldenReplay(v, v.params, fault);
    if (first.from_file) v.cycles.back().expected = first.expected;
    v.source = failCaseSource(o, run_first, v.cycles.size());
    v.notes = {from_accept ? "the failing triangle alone: from the cycle that accepted it to the failing cycle"
                           : "from the run's first cycle (no triangle accepted before) to the failing cycle",
               failCaseExpectedNote(o, first.from_file),
               fmt::format("the run's first mismatch (the outputs during the last cycle): {}", what)};
    writeSpanVectors(vec, v);
  };
  return saveFailCase(o, what, v.cycles.size(), run_first, "no captured cycle up to the failing sample", write);
}

}  // namespace

ScReport runSpanSc(const ScOptions& o, sc_core::sc_clock& clk, sc_core::sc_signal<bool>& rst_n) {
  requireBuilt(o, scSpanRtlConfigs(), "span unit");
  ScWaveform wave(o.fst);
  std::unique_ptr<SpanRtl> rtl = makeSpanRtl(o.config, "span_rtl");
  const SpanParams p = rtl->params();
  const SpanUnitConfig cfg = spanConfig(o.config);
  if (describe(cfg.rtl) != describe(p))
    throw ArgError(fmt::format("--config {}: {} holds {}, the SystemC model was verilated with {}: rebuild", o.config,
                               cfg.path, describe(cfg.rtl), describe(p)));
  prepareOutputs(o);

  // The stimulus: a vector file, the scene's descriptors, or seeded generator triangles.
  std::unique_ptr<SpanVectors> file;
  std::unique_ptr<DescriptorStream> stream;
  std::optional<SceneDescriptors> scene;
  size_t scene_next = 0;
  uint64_t total = 0;  // descriptors (scene, generator triangles) or cycles (file)
  std::function<bool(SpanDesc&)> next;
  if (!o.vector_file.empty()) {
    try {
      file = std::make_unique<SpanVectors>(loadSpanVectors(o.vector_file));
    } catch (const std::exception& e) {
      throw ArgError(fmt::format("--vector-file: {}", e.what()));
    }
    requireFileParams(o, file->config, describe(file->params), describe(p));
    total = file->cycles.size();
  } else if (!o.scene.empty()) {
    try {
      scene = recordSceneDescriptors(o.scene, p);
    } catch (const std::exception& e) {
      throw ArgError(fmt::format("--scene {}: {}", o.scene, e.what()));
    }
    total = scene->descs.size();
    if (o.triangles_given) total = std::min<uint64_t>(total, o.triangles);
    next = [&](SpanDesc& d) {
      if (scene_next >= total) return false;
      d = scene->descs[scene_next++];
      return true;
    };
  } else {
    RasterConfig rc;
    rc.unit = p;
    stream = std::make_unique<DescriptorStream>(o.seed, o.triangles, rc);
    total = o.triangles;  // generator triangles; setup drops some
    next = [&](SpanDesc& d) { return stream->next(d); };
  }

  ScRunControl ctl;
  ctl.max_mismatches = o.max_mismatches;
  sc_core::sc_signal<bool> desc_valid_i{"desc_valid_i"}, desc_ready_o{"desc_ready_o"}, out_valid_o{"out_valid_o"},
      out_ready_i{"out_ready_i"}, model_idle{"model_idle"};
  sc_core::sc_fifo<DescToken> desc_fifo{"desc_fifo", 16};
  sc_core::sc_fifo<SpanExpect> expect_fifo{"expect_fifo", 16}, file_fifo{"file_fifo", 16};

  rtl->clk_i(clk);
  rtl->rst_ni(rst_n);
  rtl->desc_valid_i(desc_valid_i);
  rtl->desc_ready_o(desc_ready_o);
  rtl->out_valid_o(out_valid_o);
  rtl->out_ready_i(out_ready_i);

  std::unique_ptr<SpanDriver> driver;
  std::unique_ptr<SpanFileDriver> file_driver;
  if (file) {
    file_driver = std::make_unique<SpanFileDriver>("driver", *file, ctl);
    file_driver->clk(clk);
    file_driver->rst_n(rst_n);
    file_driver->desc_valid_i(desc_valid_i);
    file_driver->out_ready_i(out_ready_i);
    file_driver->pins(*rtl);
    file_driver->offered(desc_fifo);
    file_driver->file_expect(file_fifo);
  } else {
    SpanDriverOptions dopt;
    dopt.seed = o.seed;
    dopt.ready_prob = o.ready;
    dopt.desc_gap_prob = o.desc_gap;
    driver = std::make_unique<SpanDriver>("driver", next, dopt, ctl);
    driver->clk(clk);
    driver->rst_n(rst_n);
    driver->desc_ready_o(desc_ready_o);
    driver->model_idle(model_idle);
    driver->desc_valid_i(desc_valid_i);
    driver->out_ready_i(out_ready_i);
    driver->pins(*rtl);
    driver->offered(desc_fifo);
  }

  const SpanFault fault = o.fault == "latency" ? SpanFault::Latency : o.fault == "value" ? SpanFault::Value : SpanFault::None;
  SpanGolden golden("golden", p, fault, !o.save_vectors.empty(), o.save_fail);
  golden.clk(clk);
  golden.rst_n(rst_n);
  golden.desc_valid_i(desc_valid_i);
  golden.out_ready_i(out_ready_i);
  golden.offered(desc_fifo);
  golden.expect(expect_fifo);
  golden.model_idle(model_idle);

  SpanScoreboard board("scoreboard", ctl);
  board.clk(clk);
  board.rst_n(rst_n);
  board.out_ready_i(out_ready_i);
  board.rtl(*rtl);
  board.expect(expect_fifo);
  board.file_expect(file_fifo);
  std::optional<ScFirstMismatch<SpanOut>> first;
  SpanVectors fail_case;
  uint64_t fail_first = 0;
  bool fail_from_accept = false;
  if (o.save_fail)
    board.on_first_mismatch = [&](const sc_core::sc_time& t, const SpanOut& e, bool from_file) {
      first = ScFirstMismatch<SpanOut>{t, e, from_file};  // the outputs during the cycle sampled at t
      fail_case = golden.capturedCase(t, fail_first, fail_from_accept);
    };

  sc_core::sc_start(sc_core::SC_ZERO_TIME);
  wave.open([&](VerilatedFstC& tfp) { rtl->traceFst(tfp, 99); });
  const ScRunTime time =
      file ? scSimulate(ctl, o, "cycles", static_cast<double>(total),
                        [&] { return static_cast<double>(file_driver->cyclesDriven()); })
           : scSimulate(ctl, o, "triangles", static_cast<double>(total),
                        [&] { return static_cast<double>(driver->acceptedByRtl()); });
  rtl->finalize();
  wave.close();
  board.finish();

  if (!o.save_vectors.empty()) {
    SpanVectors v = golden.recorded();
    v.config = o.config;
    v.source = savedVectorsSource(o);
    writeSpanVectors(o.save_vectors, v);
  }

  ScReport r;
  r.score = board.score();
  const ScScore& s = r.score;
  if (first) r.fail = saveSpanFail(o, *first, std::move(fail_case), fail_first, fail_from_accept, fault, s.first);
  if (file) {
    // Where the first mismatching sample falls in the file (1-based; cycle i's outputs are sampled
    // kResetCycles + 1 + i edges from time 0), and the first that differs from the file's own
    // expectation: a replayed failing case must fail at its last cycle.
    r.add("mismatch_file_cycle", s.first.empty() ? uint64_t{0} : scCycle(s.first_time) - kResetCycles);
    r.add("file_mismatch_cycle", static_cast<uint64_t>(s.first_file_cycle + 1));
  }
  std::string what;
  uint64_t descs = 0;
  if (file) {
    descs = file_driver->offeredCount();
    if (file_driver->cyclesDriven() != file->cycles.size() || board.fileChecks() != file->cycles.size()) {
      r.complete = false;
      r.incomplete = fmt::format("{} of the file's {} cycles driven, {} compared with its expected outputs",
                                 file_driver->cyclesDriven(), file->cycles.size(), board.fileChecks());
    }
    what = fmt::format("vector file {} ({} cycles, {} descriptors offered)", o.vector_file, file->cycles.size(), descs);
  } else {
    descs = scene ? total : stream->generated() - stream->dropped();
    if (driver->acceptedByRtl() != descs || golden.accepted() != descs) {
      r.complete = false;
      r.incomplete = fmt::format("of {} descriptors the RTL accepted {}, the model {}", descs, driver->acceptedByRtl(),
                                 golden.accepted());
    }
    if (scene && total == scene->descs.size() && r.complete && s.matched_items != scene->frame_fragments) {
      // The whole frame went through: the unit must have handed over exactly the fragments the
      // render counted for it.
      r.complete = false;
      r.incomplete = fmt::format("the render of {} counted {} fragments, the co-simulation handed over {}", o.scene,
                                 scene->frame_fragments, s.matched_items);
    }
    what = scene ? fmt::format("scene {} ({} scene triangles, {} culled, {} drawn, {} fragments in the frame{})", o.scene,
                               scene->scene_triangles, scene->culled, scene->descs.size(), scene->frame_fragments,
                               total < scene->descs.size() ? fmt::format(", the first {} simulated", total) : std::string())
                 : fmt::format("seed {}: {} generator triangles ({} dropped by setup)", o.seed, stream->generated(),
                               stream->dropped());
  }
  r.summary = fmt::format(
      "systemc span/{} {}: descriptors accepted by {}the model {}, {} fragments (model {}, rtl {}, {} equal in value "
      "and cycle), {} samples compared{}, {} mismatches; {}",
      o.config, what, driver ? fmt::format("the RTL {}, ", driver->acceptedByRtl()) : std::string(), golden.accepted(),
      s.matched_items, s.expected_items,
      s.observed_items, s.matched_items, s.samples,
      file ? fmt::format(" ({} also against the file's expected outputs)", board.fileChecks()) : std::string(),
      s.mismatches(), time.describe());
  r.add("stimulus", std::string(file ? "vector-file" : scene ? "scene" : "random"));
  if (file) {
    r.add("vector_file", o.vector_file);
    r.add("file_cycles", static_cast<uint64_t>(file->cycles.size()));
    r.add("file_checks", board.fileChecks());
  } else {
    r.add("seed", o.seed);
    r.add("ready_prob", o.ready);
    r.add("desc_gap_prob", o.desc_gap);
  }
  if (scene) {
    r.add("scene", o.scene);
    r.add("scene_triangles", scene->scene_triangles);
    r.add("drawn", static_cast<uint64_t>(scene->descs.size()));
    r.add("frame_fragments", scene->frame_fragments);
    r.add("frame_cycles_always_ready", scene->frame_cycles);
  }
  if (stream) {
    r.add("generated", stream->generated());
    r.add("dropped_at_setup", stream->dropped());
  }
  r.add("descriptors", descs);
  if (driver) r.add("accepted_rtl", driver->acceptedByRtl());
  r.add("accepted_model", golden.accepted());
  r.add("fragments_expected", s.expected_items);
  r.add("fragments_observed", s.observed_items);
  r.add("fragments_matched", s.matched_items);
  r.add("cycles", time.cycles);
  r.add("seconds", time.secs);
  if (!o.save_vectors.empty()) r.add("saved_vectors", o.save_vectors);
  return r;
}

}  // namespace shd
