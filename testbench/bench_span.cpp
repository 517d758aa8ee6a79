// Throughput of the span unit per mode: the model alone, the verilated RTL alone, and the full
// co-simulation (RTL + model + per-cycle compare, the harness included). Figures, not pass/fail:
// the target is at least 10 M fragments/s through the verilated unit with harness and checker.
// BM_TriangleGenerator: the random-triangle stream that feeds them (target: 10^6 triangles well
// under a second).
//   build/testbench/bench_span [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <filesystem>

#include "config/registry.h"
#include "raster/desc_stream.h"
#include "cosim/span_cosim.h"

using namespace shd;

namespace {

constexpr uint64_t kTriangles = 20000;  // the mixed generator stream, about 57 pixels each

std::vector<SpanDesc> descriptors(const std::string& m) {
  RasterConfig c;
  c.unit = spanConfig(m).rtl;
  DescriptorStream s(7, kTriangles, c);
  std::vector<SpanDesc> out;
  SpanDesc d;
  while (s.next(d)) out.push_back(d);
  return out;
}

// The span configurations (lane modes) of the registry, by benchmark argument.
std::string modeOf(const benchmark::State& st) { return builtinConfigNames("span")[static_cast<size_t>(st.range(0))]; }
const int kLastMode = static_cast<int>(builtinConfigNames("span").size()) - 1;

void BM_SpanModel(benchmark::State& state) {
  const std::string m = modeOf(state);
  const auto descs = descriptors(m);
  SpanUnitModel unit(spanConfig(m).rtl);
  uint64_t frags = 0, tris = 0;
  for (auto _ : state)
    for (const SpanDesc& d : descs) {
      frags += runSpanUnit(unit, d).fragments.size();
      ++tris;
    }
  state.counters["fragments/s"] = benchmark::Counter(static_cast<double>(frags), benchmark::Counter::kIsRate);
  state.counters["triangles/s"] = benchmark::Counter(static_cast<double>(tris), benchmark::Counter::kIsRate);
  state.SetLabel(m);
}

void BM_SpanRtl(benchmark::State& state) {
  const std::string m = modeOf(state);
  const auto descs = descriptors(m);
  auto dut = makeSpanDut(m, "");
  dut->reset();
  uint64_t frags = 0, tris = 0;
  SpanOut o;
  for (auto _ : state)
    for (const SpanDesc& d : descs) {
      SpanIn in;
      in.desc_valid = true;
      in.desc = &d;
      for (bool accepted = false;;) {
        dut->tick(in, o);
        if (!accepted) {
          accepted = o.desc_ready;
          in.desc_valid = false;
          continue;
        }
        for (const SpanLaneOut& l : o.lane) frags += l.valid ? 1 : 0;
        if (o.desc_ready) break;  // back in IDLE: the triangle is done
      }
      ++tris;
    }
  state.counters["fragments/s"] = benchmark::Counter(static_cast<double>(frags), benchmark::Counter::kIsRate);
  state.counters["triangles/s"] = benchmark::Counter(static_cast<double>(tris), benchmark::Counter::kIsRate);
  state.SetLabel(m);
}

void BM_SpanCosim(benchmark::State& state) {
  const std::string m = modeOf(state);
  const auto descs = descriptors(m);
  uint64_t frags = 0, tris = 0, mism = 0;
  for (auto _ : state) {
    size_t i = 0;
    SpanCosimOptions o;
    o.ready_prob = 1.0;
    o.desc_gap_prob = 0.0;
    o.fail_dir = std::filesystem::temp_directory_path().string();
    const SpanCosimResult r = runSpanCosim(m, [&](SpanDesc& d) {
      if (i == descs.size()) return false;
      d = descs[i++];
      return true;
    }, o);
    frags += r.fragments;
    tris += r.triangles;
    mism += r.mismatches;
  }
  state.counters["fragments/s"] = benchmark::Counter(static_cast<double>(frags), benchmark::Counter::kIsRate);
  state.counters["triangles/s"] = benchmark::Counter(static_cast<double>(tris), benchmark::Counter::kIsRate);
  state.counters["mismatches"] = static_cast<double>(mism);
  state.SetLabel(m);
}

void BM_TriangleGenerator(benchmark::State& state) {
  TriangleGenerator gen(7);
  for (auto _ : state) benchmark::DoNotOptimize(gen.next());
  state.counters["triangles/s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

}  // namespace

BENCHMARK(BM_TriangleGenerator);
BENCHMARK(BM_SpanModel)->DenseRange(0, kLastMode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SpanRtl)->DenseRange(0, kLastMode)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_SpanCosim)->DenseRange(0, kLastMode)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
