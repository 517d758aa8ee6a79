// Frame time of the golden model on builtin:sphere (512 x 512, the idx3d sphere), per shading
// method, with the frame buffers reused from frame to frame as a renderer does. Figures, not
// pass/fail. The peer is idx3d III on the same sphere (its flat and lookup-table "Phong"):
// compare only runs taken side by side, interleaved, and report ratios (docs/performance.md).
// phong-fixed's label says whether the AVX-512 kernel ran. The RTL-in-the-loop frame time is
// printed by `shadesim render --rtl`. Setup and Walk time two parts of a Gouraud frame alone,
// per triangle: triangle setup and the span walk; RowSpans what the frame runs instead, the
// same triangles set up straight to their rows' spans.
//   build/testbench/bench_render [--benchmark_filter=...]
#include <random>

#include <benchmark/benchmark.h>

#include "device/prom.h"
#include "raster/row_spans.h"
#include "raster/setup.h"
#include "raster/span_walk.h"
#include "render/pipeline.h"
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
  opt.tags = opt.triangles = false;  // as `shadesim render` draws without the RTL check
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
  // phong-fixed's kernel on this CPU: AVX-512, AVX2, or the scalar one (SHD_SCALAR=1 forces it,
  // SHD_NO_AVX512=1 the AVX2 one).
  if (method == Method::PhongFixed)
    state.SetLabel(fixed_simd::available() ? "avx512 kernel" : fixed_simd::availableAvx2() ? "avx2 kernel" : "scalar kernel");
  state.counters["fragments"] = static_cast<double>(frame.stats.fragments);
  state.counters["span_cycles"] = static_cast<double>(frame.stats.span_cycles);
  state.counters["frag/s"] = benchmark::Counter(static_cast<double>(frame.stats.fragments),
                                                benchmark::Counter::kIsIterationInvariantRate);
}

// The screen triangles a Gouraud frame of builtin:sphere draws, as setup takes them (the
// renderer's serial unit and attribute widths): their vertices, with colours and depths drawn
// at random in the ranges of the frame's (setup's arithmetic and the walk do not depend on
// their values beyond their widths).
struct SphereTriangles {
  RasterConfig rc;
  std::vector<std::array<SetupVertex, 3>> v;
};
SphereTriangles sphereTriangles() {
  const Scene scene = loadScene("builtin:sphere");
  RenderOptions opt;
  opt.method = Method::Gouraud;
  ModelSpanEngine span(spanConfig("serial").rtl);
  RenderResult frame;
  render(scene, opt, span, SpecEngines{}, frame);
  SphereTriangles s;
  s.rc.width = frame.fb.width;
  s.rc.height = frame.fb.height;
  s.rc.subpixel_bits = opt.subpixel_bits;
  s.rc.unit = span.params();
  s.rc.attr_frac_bits = {kColourFrac, kColourFrac, kColourFrac, kUnitFrac};
  std::mt19937_64 rng(19);
  std::uniform_real_distribution<double> colour(0, 255), w(0.05, 0.2);
  for (const ScreenTriangleInfo& t : frame.triangles) {
    std::array<SetupVertex, 3>& v = s.v.emplace_back();
    for (size_t i = 0; i < 3; ++i) {
      v[i].x = t.xy[i][0];
      v[i].y = t.xy[i][1];
      v[i].attr = {colour(rng), colour(rng), colour(rng), w(rng)};
    }
  }
  return s;
}

void perTriangle(benchmark::State& state, size_t n) {
  state.counters["triangles"] = static_cast<double>(n);
  state.counters["ns/triangle"] =
      benchmark::Counter(static_cast<double>(n), benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

// Triangle setup alone (setupTriangle) of sphereTriangles(): the frame's setup share.
void BM_Setup(benchmark::State& state) {
  const SphereTriangles tris = sphereTriangles();
  SetupResult res;
  for (auto _ : state)
    for (size_t i = 0; i < tris.v.size(); ++i) {
      setupTriangle(tris.v[i], static_cast<uint32_t>(i), tris.rc, res);
      benchmark::DoNotOptimize(res.desc);
    }
  perTriangle(state, tris.v.size());
}

// The same triangles set up straight to their rows' spans (setupRowSpans), where the renderer
// takes them so (every one of the sphere's); the plane in AVX2 lanes where the renderer's is
// (SHD_SCALAR=1: the scalar plane).
void BM_RowSpans(benchmark::State& state) {
  const SphereTriangles tris = sphereTriangles();
  RowSpansConfig rc(tris.rc);
  rc.vector = fixed_simd::availableAvx2();
  std::vector<std::array<RowSpans::Vertex, 3>> v;
  for (const auto& t : tris.v) {
    std::array<RowSpans::Vertex, 3>& r = v.emplace_back();
    for (size_t i = 0; i < 3; ++i) {
      r[i].x = t[i].x;
      r[i].y = t[i].y;
      for (size_t k = 0; k < 4; ++k) r[i].attr[k] = t[i].attr[k];
    }
  }
  RowSpans res;
  size_t general = 0;
  for (auto _ : state)
    for (const auto& t : v) {
      general += setupRowSpans(t, rc, res) == RowSpansSetup::General;
      benchmark::DoNotOptimize(res.rows);
    }
  perTriangle(state, v.size());
  state.counters["general"] = static_cast<double>(general) / static_cast<double>(state.iterations());
}

// The span walk alone (walkSpanUnit with a run consumer, as the colour methods walk) of
// sphereTriangles()' descriptors, the runs summed instead of drawn.
void BM_Walk(benchmark::State& state) {
  const SphereTriangles tris = sphereTriangles();
  std::vector<SpanDesc> descs;
  for (const auto& v : tris.v) {
    const SetupResult r = setupTriangle(v, 0, tris.rc);
    if (r.desc) descs.push_back(*r.desc);
  }
  uint64_t sum = 0;
  for (auto _ : state)
    for (const SpanDesc& d : descs) {
      walkSpanUnit(tris.rc.unit, d, [&](int32_t x, int32_t, const int64_t*) { sum += static_cast<uint64_t>(x); },
                   [&](const RowRun& r) { sum += static_cast<uint64_t>(r.count) + static_cast<uint64_t>(r.a0[0]); });
      benchmark::DoNotOptimize(sum);
    }
  perTriangle(state, descs.size());
}

}  // namespace

BENCHMARK(BM_Setup)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Walk)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_RowSpans)->Unit(benchmark::kMicrosecond);
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
