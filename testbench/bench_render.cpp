// Frame time of the golden model on builtin:sphere (512 x 512, the idx3d sphere), per shading
// method, with the frame buffers reused from frame to frame as a renderer does. Figures, not
// pass/fail. The peer is idx3d III on the same sphere (its flat and lookup-table "Phong"):
// compare only runs taken side by side, interleaved, and report ratios (docs/performance.md).
// phong-fixed's label says whether the AVX-512 kernel ran. The RTL-in-the-loop frame time is
// printed by `shadesim render --rtl`.
//   build/testbench/bench_render [--benchmark_filter=...]
#include <benchmark/benchmark.h>

#include "device/prom.h"
#include "config/registry.h"
#include "render/fixed_simd.h"
#include "render/render.h"
#include "scene/scene.h"

using namespace shd;

namespace {

// brdf "": the sphere's own material (Blinn, exact pow per pixel); "quadratic": the specular
// unit's polynomial from its PROM (the paper's device: no pow), evaluated by its model.
void BM_Frame(benchmark::State& state, Method method, const char* mode, const char* brdf) {
  const Scene scene = loadScene("builtin:sphere");
  RenderOptions opt;
  opt.method = method;
  opt.brdf = brdf;
  ModelSpanEngine span(spanConfig(mode).rtl);
  const SpecUnitConfig cfg = specConfig("default");
  ModelSpecEngine quadratic(buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl));
  SpecEngines spec;
  spec.quadratic = &quadratic;
  RenderResult frame;
  render(scene, opt, span, spec, frame);  // the buffers' first growth is not a frame
  for (auto _ : state) {
    render(scene, opt, span, spec, frame);
    benchmark::DoNotOptimize(frame.fb.rgb.data());
  }
  // phong-fixed's kernel on this CPU: the AVX-512 one, or the scalar one (SHD_SCALAR=1 forces it).
  if (method == Method::PhongFixed) state.SetLabel(fixed_simd::available() ? "avx512 kernel" : "scalar kernel");
  state.counters["fragments"] = static_cast<double>(frame.stats.fragments);
  state.counters["span_cycles"] = static_cast<double>(frame.stats.span_cycles);
  state.counters["frag/s"] = benchmark::Counter(static_cast<double>(frame.stats.fragments),
                                                benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_Frame, flat, Method::Flat, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, gouraud, Method::Gouraud, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, gouraud_classical, Method::GouraudClassical, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, phong, Method::Phong, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, phong_incremental, Method::PhongIncremental, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, phong_fixed, Method::PhongFixed, "serial", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, gouraud_sierpinski, Method::Gouraud, "sierpinski", "")->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, phong_incremental_sierpinski, Method::PhongIncremental, "sierpinski", "")
    ->Unit(benchmark::kMillisecond);

BENCHMARK_CAPTURE(BM_Frame, phong_incremental_device, Method::PhongIncremental, "serial", "quadratic")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, phong_fixed_device, Method::PhongFixed, "serial", "quadratic")
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Frame, gouraud_device, Method::Gouraud, "serial", "quadratic")->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
