// Throughput of the specular unit: the golden model, the verilated RTL alone, and the full
// co-simulation (RTL + model + compare). Figures, not pass/fail: the target is at least
// 20 M vectors/s through the verilated unit on one core, so the exhaustive check of the
// default configuration (67 M vectors) takes seconds.
//   build/testbench/bench_spec [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include <filesystem>
#include <map>

#include <fmt/format.h>

#include "config/registry.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "cosim/spec_cosim.h"
#include "io/files.h"

using namespace shd;

namespace {

struct Fixture {
  PromTable table;
  std::string prom_path;
  explicit Fixture(const std::string& name) {
    const SpecUnitConfig c = specConfig(name);
    table = buildPromTable(PromRequest::fromContent(c.prom), c.rtl);
    prom_path = (std::filesystem::temp_directory_path() / fmt::format("bench_spec_{}.hex", name)).string();
    writePromHexFiles(prom_path, table);
  }
};

const Fixture& fixture(const std::string& name) {
  static std::map<std::string, Fixture> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, Fixture(name)).first;
  return it->second;
}

const char* kConfigs[] = {"default", "narrow", "wide", "cubic"};

void BM_ModelEvaluate(benchmark::State& state) {
  const Fixture& f = fixture(kConfigs[state.range(0)]);
  const SpecUnitModel m(f.table.unit, f.table.words, f.table.seg_words);
  const uint32_t ncos = 2u << f.table.unit.CosFracBits, depth = static_cast<uint32_t>(f.table.unit.promDepth());
  uint32_t shin = 0, cos = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(m.evaluate(shin, cos, {255, 128, 7}));
    if (++cos == ncos) cos = 0, shin = (shin + 1) % depth;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(kConfigs[state.range(0)]);
}

void BM_VerilatedTick(benchmark::State& state) {
  const char* name = kConfigs[state.range(0)];
  const Fixture& f = fixture(name);
  auto dut = makeSpecDut(name, SpecDutOptions{f.prom_path, ""});
  dut->reset();
  SpecIn in;
  in.valid = true;
  in.light = {255, 128, 7};
  const uint32_t ncos = 2u << f.table.unit.CosFracBits, depth = static_cast<uint32_t>(f.table.unit.promDepth());
  for (auto _ : state) {
    benchmark::DoNotOptimize(dut->tick(in));
    if (++in.cos == ncos) in.cos = 0, in.shin = (in.shin + 1) % depth;
  }
  state.SetItemsProcessed(state.iterations());
  state.SetLabel(name);
}

// The whole exhaustive check of a configuration: every (shininess, cos) pair through the RTL
// and the model, compared every cycle.
void BM_ExhaustiveCosim(benchmark::State& state) {
  const char* name = kConfigs[state.range(0)];
  const Fixture& f = fixture(name);
  uint64_t vectors = 0, mismatches = 0;
  for (auto _ : state) {
    SpecUnitModel m(f.table.unit, f.table.words, f.table.seg_words);
    ExhaustiveSpecStimulus stim(f.table.unit, 1);
    SpecCosimOptions o;
    o.prom_path = f.prom_path;
    o.fail_dir = std::filesystem::temp_directory_path().string();
    const SpecCosimResult r = runSpecCosim(name, m, stim, o);
    vectors += r.vectors;
    mismatches += r.mismatches;
  }
  state.SetItemsProcessed(static_cast<int64_t>(vectors));
  state.counters["mismatches"] = static_cast<double>(mismatches);
  state.SetLabel(name);
}

}  // namespace

BENCHMARK(BM_ModelEvaluate)->DenseRange(0, 3);
BENCHMARK(BM_VerilatedTick)->DenseRange(0, 3);
BENCHMARK(BM_ExhaustiveCosim)->Arg(0)->Arg(1)->Arg(3)->Iterations(1)->Unit(benchmark::kSecond);

BENCHMARK_MAIN();
