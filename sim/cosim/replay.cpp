#include "cosim/replay.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "io/files.h"
#include "harness/span_dut.h"
#include "cosim/spec_cosim.h"
#include "harness/spec_dut.h"
#include "vectors/vector_file.h"

namespace fs = std::filesystem;

namespace shd {

std::string ReplayMismatch::describe() const {
  return fmt::format("cycle {}: {}: expected {:#x}, rtl {:#x}", cycle, signal, expected, got);
}

namespace {

class Checker {
 public:
  Checker(ReplayResult& r, const ReplayOptions& o) : r_(r), o_(o) {}
  void beginCycle(uint64_t cycle) {
    cycle_ = cycle;
    cycle_bad_ = false;
  }
  void check(const std::string& signal, uint64_t expected, uint64_t got) {
    ++r_.compared;
    if (expected == got) return;
    ++r_.mismatches;
    if (!cycle_bad_) ++r_.mismatching_cycles;
    cycle_bad_ = true;
    const ReplayMismatch m{cycle_, signal, expected, got};
    if (!r_.first) r_.first = m;
    if (r_.listed.size() < o_.max_listed) r_.listed.push_back(m);
  }

 private:
  ReplayResult& r_;
  const ReplayOptions& o_;
  uint64_t cycle_ = 0;
  bool cycle_bad_ = false;
};

uint64_t bits(int64_t v, int width) {
  const uint64_t u = static_cast<uint64_t>(v);
  return width >= 64 ? u : u & ((uint64_t{1} << width) - 1);
}

ReplayResult replaySpec(const std::string& path, const ReplayOptions& opts) {
  const SpecVectors v = loadSpecVectors(path);
  ReplayResult r;
  r.unit = "spec";
  r.config = v.config;
  const SpecUnitParams& p = v.params;
  // The verilated configuration is made from the registry's file of that name: its parameters
  // must be the vector file's.
  const std::vector<std::string> built = rtlSpecConfigs();
  if (std::find(built.begin(), built.end(), v.config) == built.end())
    throw std::invalid_argument(fmt::format("{}: configuration '{}' is not verilated into this build (built: {})", path,
                                            v.config, fmt::join(built, ", ")));
  const SpecUnitParams built_p = specConfig(v.config).rtl;
  if (built_p.toJson() != p.toJson())
    throw std::invalid_argument(fmt::format("{}: made for parameters {}, the verilated '{}' has {}: regenerate the file",
                                            path, p.toJson().dump(), v.config, built_p.toJson().dump()));
  std::string prom = opts.prom_path.empty() ? v.prom : opts.prom_path;
  if (opts.prom_path.empty() && fs::path(prom).is_relative()) prom = (fs::absolute(path).parent_path() / prom).string();
  prom = fs::absolute(prom).lexically_normal().string();
  const RomImage words = readPromHexFiles(prom, p);
  // Every input is read: the waveform (written as it runs, not atomically) may replace none.
  if (!opts.fst_path.empty()) outputTarget(opts.fst_path);
  auto dut = makeSpecDut(v.config, SpecDutOptions{prom, opts.fst_path});
  verifyLoadedProm(*dut, words, prom, p);
  dut->reset();
  Checker chk(r, opts);
  for (size_t i = 0; i < v.in.size(); ++i) {
    const SpecOut got = dut->tick(v.in[i]);
    const SpecOut& e = v.expected[i];
    chk.beginCycle(i + 1);
    chk.check("valid_o", e.valid, got.valid);
    chk.check("spec_o", e.spec, got.spec);
    chk.check("spec_r_o", e.rgb[0], got.rgb[0]);
    chk.check("spec_g_o", e.rgb[1], got.rgb[1]);
    chk.check("spec_b_o", e.rgb[2], got.rgb[2]);
    r.results += e.valid ? 1 : 0;
  }
  dut->finish();
  r.cycles = v.in.size();
  r.fst_path = opts.fst_path;
  return r;
}

ReplayResult replaySpan(const std::string& path, const ReplayOptions& opts) {
  const SpanVectors v = loadSpanVectors(path);
  ReplayResult r;
  r.unit = "span";
  r.config = v.config;
  if (!opts.fst_path.empty()) outputTarget(opts.fst_path);  // after the input (see replaySpec)
  auto dut = makeSpanDut(v.config, opts.fst_path);  // names the built configurations if unknown
  const SpanParams& p = v.params;
  if (dut->params().toJson() != p.toJson())
    throw std::invalid_argument(fmt::format("{}: made for parameters {}, the verilated '{}' has {}: regenerate the file",
                                            path, p.toJson().dump(), v.config, dut->params().toJson().dump()));
  dut->reset();
  Checker chk(r, opts);
  SpanOut got;
  for (size_t i = 0; i < v.cycles.size(); ++i) {
    const SpanVectorCycle& c = v.cycles[i];
    SpanIn in;
    in.desc_valid = c.desc_valid;
    in.out_ready = c.out_ready;
    in.desc = c.desc >= 0 ? &v.descs[static_cast<size_t>(c.desc)] : nullptr;
    dut->tick(in, got);
    const SpanOut& e = c.expected;
    chk.beginCycle(i + 1);
    chk.check("desc_ready_o", e.desc_ready, got.desc_ready);
    chk.check("out_valid_o", e.out_valid, got.out_valid);
    if (e.out_valid) chk.check("out_tag_o", bits(e.tag, p.TagBits), bits(got.tag, p.TagBits));
    uint64_t emask = 0, gmask = 0;
    for (size_t l = 0; l < e.lane.size(); ++l) emask |= uint64_t{e.lane[l].valid} << l;
    for (size_t l = 0; l < got.lane.size(); ++l) gmask |= uint64_t{got.lane[l].valid} << l;
    chk.check("out_lane_valid_o", emask, gmask);
    for (size_t l = 0; l < e.lane.size(); ++l) {
      const SpanLaneOut& el = e.lane[l];
      if (!el.valid) continue;
      ++r.results;
      const SpanLaneOut& gl = got.lane[l];
      // The harness leaves a lane it sees invalid without data: such a lane already differs
      // in out_lane_valid_o; its data are not compared.
      if (!gl.valid) continue;
      chk.check(fmt::format("out_x_o[lane {}]", l), bits(el.x, p.PixBits), bits(gl.x, p.PixBits));
      chk.check(fmt::format("out_y_o[lane {}]", l), bits(el.y, p.PixBits), bits(gl.y, p.PixBits));
      for (size_t a = 0; a < el.attr.size(); ++a)
        chk.check(fmt::format("out_attr_o[lane {} attr {}]", l, a), bits(el.attr[a], p.AttrBits),
                  bits(gl.attr[a], p.AttrBits));
    }
  }
  dut->finish();
  r.cycles = v.cycles.size();
  r.fst_path = opts.fst_path;
  return r;
}

}  // namespace

ReplayResult replayVectorFile(const std::string& path, const ReplayOptions& opts) {
  const std::string unit = vectorFileUnit(path);
  return unit == "spec" ? replaySpec(path, opts) : replaySpan(path, opts);
}

}  // namespace shd
