#include "cosim/render_rtl.h"

#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "cosim/replay.h"
#include "cosim/span_cosim.h"
#include "cosim/spec_cosim.h"
#include "raster/span_walk.h"
#include "vectors/vector_file.h"
#include "io/files.h"

namespace shd {

namespace fs = std::filesystem;

namespace {

// Replays a saved failing case on the RTL into an FST beside it: the verdict for the message.
std::string replayAlone(const std::string& vec, const std::string& fst) {
  ReplayOptions ro;
  ro.fst_path = fst;
  const ReplayResult rr = replayVectorFile(vec, ro);
  return rr.first ? "replays alone: " + rr.first->describe() : std::string("does NOT fail when replayed alone");
}

}  // namespace

RtlSpanEngine::RtlSpanEngine(const SpanUnitConfig& config, std::string fail_dir, std::optional<SpanParams> model_params)
    : mode_(config.name),
      fail_dir_(std::move(fail_dir)),
      dut_(makeSpanDut(config, "")),
      model_(model_params ? *model_params : dut_->params()),
      stream_model_(model_.params()) {
  dut_->reset();
  model_.reset();
  if (dut_->params().RowAhead) stream_dut_ = makeSpanDut(config, "");
}

void RtlSpanEngine::beginFrame() {
  SpanEngine::beginFrame();
  if (!stream_dut_) return;
  stream_dut_->reset();
  stream_model_.reset();
  stream_offered_.reset();
  stream_descs_ = 0;
}

void RtlSpanEngine::streamTick() {
  SpanIn in;
  in.desc_valid = stream_offered_.has_value();
  in.desc = in.desc_valid ? &*stream_offered_ : nullptr;
  in.out_ready = true;
  stream_model_.tick(in, stream_expected_);
  stream_dut_->tick(in, stream_out_);
  if (const std::string diff = compareSpanOutputs(stream_expected_, stream_out_); !diff.empty())
    throw std::runtime_error(fmt::format(
        "span unit ({}): the RTL differs from the model at cycle {} of the frame's stream, after {} descriptors "
        "accepted: {}",
        mode_, stream_model_.cycle() - 1, stream_descs_, diff));
  if (in.desc_valid && stream_expected_.desc_ready) {
    stream_offered_.reset();
    ++stream_descs_;
  }
}

void RtlSpanEngine::endFrame() {
  if (!stream_dut_) return;
  while (stream_offered_ || !stream_model_.idle()) streamTick();
  const uint64_t want = streamOrNull()->end();
  if (stream_model_.cycle() != want)
    throw std::runtime_error(fmt::format("span unit ({}): the frame's {} descriptors took {} cycles back to back on the "
                                         "RTL, the model's stream counts {}",
                                         mode_, stream_descs_, stream_model_.cycle(), want));
}

SpanWalk RtlSpanEngine::run(const SpanDesc& d, std::vector<SpanFragment>& out) {
  SpanWalk run;
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  in.out_ready = true;
  for (bool accepted = false;;) {
    model_.tick(in, expected_);
    dut_->tick(in, out_);
    ++run.cycles;
    if (const std::string diff = compareSpanOutputs(expected_, out_); !diff.empty()) {
      // The triangle alone from reset: the accepting cycle, then out_ready high to this cycle.
      fs::create_directories(fail_dir_);
      const std::string vec = fmt::format("{}/render_span_{}_fail.vec", fail_dir_, mode_);
      const std::string fst = fmt::format("{}/render_span_{}_fail.fst", fail_dir_, mode_);
      SpanVectors v;
      v.config = mode_;
      v.params = dut_->params();
      v.source = fmt::format("shadesim render --rtl: triangle {} alone, from reset; the RTL differed from the model at "
                             "its cycle {}",
                             d.tag, run.cycles);
      v.descs.push_back(d);
      SpanUnitModel replay(model_.params());
      replay.reset();
      for (uint64_t c = 0; c < run.cycles; ++c) {
        SpanVectorCycle vc;
        vc.desc_valid = c == 0;
        vc.out_ready = true;
        vc.desc = 0;
        SpanIn rin;
        rin.desc_valid = vc.desc_valid;
        rin.desc = &v.descs[0];
        replay.tick(rin, vc.expected);
        v.cycles.push_back(std::move(vc));
      }
      writeSpanVectors(vec, v);
      throw std::runtime_error(fmt::format(
          "span unit ({}): the RTL differs from the model on triangle {} at its cycle {}: {}; the triangle alone: {} "
          "({}), waveform {}",
          mode_, d.tag, run.cycles, diff, vec, replayAlone(vec, fst), fst));
    }
    if (!accepted) {
      if (!out_.desc_ready) throw std::logic_error("RtlSpanEngine: the span unit is not idle");
      accepted = true;
      in.desc_valid = false;
      continue;
    }
    for (const SpanLaneOut& l : out_.lane)
      if (l.valid) {
        out.push_back({out_.tag, l.x, l.y, l.attr});
        ++run.fragments;
      }
    if (model_.idle()) break;  // the RTL equal so far, so idle too (the full-rate unit's desc_ready is 1 throughout)
  }
  if (stream_dut_) {
    // The descriptor's share of the frame's stream, and the stream instance up to its acceptance.
    run.cycles = walkSpanUnit(params(), d, [](int32_t, int32_t, const int64_t*) {}, span_detail::NoRuns{},
                              streamOrNull()).cycles;
    stream_offered_ = d;
    while (stream_offered_) streamTick();
  }
  return run;
}

RtlSpecEngine::RtlSpecEngine(const SpecUnitConfig& config, PromTable table, const std::string& prom_path,
                             std::string fail_dir, std::optional<std::vector<PromWord>> model_words)
    : config_(config.name),
      fail_dir_(std::move(fail_dir)),
      t_(std::move(table)),
      model_(t_.unit, model_words ? *model_words : t_.words, t_.seg_words) {
  if (t_.unit.toJson() != config.rtl.toJson())
    throw std::invalid_argument(fmt::format("RtlSpecEngine: the table's unit {} is not configuration {}'s {}",
                                            t_.unit.toJson().dump(), config.name, config.rtl.toJson().dump()));
  writePromHexFiles(prom_path, t_);
  dut_ = makeSpecDut(config, SpecDutOptions{prom_path, ""});
  verifyLoadedProm(*dut_, RomImage::of(t_), prom_path, t_.unit);
  dut_->reset();
}

uint64_t RtlSpecEngine::evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) {
  out.clear();
  out.reserve(in.size());
  uint64_t cycles = 0;
  size_t next = 0;
  const uint64_t limit = in.size() + static_cast<uint64_t>(t_.unit.latency()) + 2;
  while (out.size() < in.size()) {
    SpecIn v;
    if (next < in.size()) {
      v.valid = true;
      v.shin = in[next].shin;
      v.cos = in[next].cos;
      v.light = in[next].light;
      ++next;
    }
    const SpecOut o = dut_->tick(v);
    ++cycles;
    if (o.valid) {
      const SpecRequest& r = in[out.size()];
      const SpecOut m = model_.evaluate(r.shin, r.cos, r.light);
      if (m.spec != o.spec || m.rgb != o.rgb) {
        // The request alone from reset: one valid cycle, then the pipeline's latency.
        fs::create_directories(fail_dir_);
        const std::string vec = fmt::format("{}/render_spec_{}_fail.vec", fail_dir_, config_);
        const std::string fst = fmt::format("{}/render_spec_{}_fail.fst", fail_dir_, config_);
        const std::string hex = fmt::format("{}/render_spec_{}_fail.hex", fail_dir_, config_);
        writePromHexFiles(hex, t_);
        SpecVectors sv;
        sv.config = config_;
        sv.params = t_.unit;
        sv.prom = fs::path(hex).filename().string();
        sv.source = "shadesim render --rtl: the specular request the RTL and the model disagree on, alone, from reset";
        SpecUnitModel replay(t_.unit, model_.prom(), model_.segRom());
        for (int c = 0; c < t_.unit.latency(); ++c) {
          SpecIn si;
          if (c == 0) si = {true, r.shin, r.cos, r.light};
          sv.in.push_back(si);
          sv.expected.push_back(replay.tick(si));
        }
        writeSpecVectors(vec, sv);
        throw std::runtime_error(fmt::format(
            "specular unit ({}): the RTL differs from the model for shininess code {}, cos {:#x}, light ({}, {}, {}): "
            "model spec {:#x} rgb ({}, {}, {}), rtl spec {:#x} rgb ({}, {}, {}); the request alone: {} ({}), waveform {}",
            config_, r.shin, r.cos, r.light[0], r.light[1], r.light[2], m.spec, m.rgb[0], m.rgb[1], m.rgb[2], o.spec,
            o.rgb[0], o.rgb[1], o.rgb[2], vec, replayAlone(vec, fst), fst));
      }
      out.push_back(o.rgb);
    }
    if (cycles > limit) throw std::logic_error("RtlSpecEngine: results missing from the specular unit");
  }
  return cycles;
}

}  // namespace shd
