#include "cli/render_common.h"

#include <algorithm>
#include <map>
#include <mutex>
#include <utility>

#include <fmt/format.h>

#include "cli/options.h"
#include "cosim/render_rtl.h"
#include "device/prom_io.h"

namespace fs = std::filesystem;

namespace shd::cli {

SpecUnitConfig lobeConfigArg(const LobeConfigs& lobes, Lobe l) {
  try {
    return lobes.load(l);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--{}-config: {}", toString(l), e.what()));
  }
}

const PromTable& promTable(const SpecUnitConfig& cfg) {
  // Keyed by everything buildPromTable reads: every "rtl" parameter and the "prom" section (the
  // level exactly, in hexadecimal floating point).
  const std::string key = fmt::format("{} {} {:a} {} {}", cfg.rtl.toJson().dump(), cfg.prom.fit, cfg.prom.level,
                                      cfg.prom.is_list, cfg.prom.n);
  static std::mutex mutex;
  static std::map<std::string, PromTable> tables;  // a map: its elements stay where they are
  const std::lock_guard<std::mutex> lock(mutex);
  auto it = tables.find(key);
  if (it == tables.end()) it = tables.emplace(key, buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl)).first;
  return it->second;
}

Engines makeEngines(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span, const LobeConfigs& lobes,
                    bool with_rtl, const fs::path& tmp, const std::string& fail_dir) {
  Engines e;
  if (with_rtl) e.span = std::make_unique<RtlSpanEngine>(span, fail_dir);
  else e.span = std::make_unique<ModelSpanEngine>(span.rtl);
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    const SpecUnitConfig cfg = lobeConfigArg(lobes, l);
    if (with_rtl) {
      fs::create_directories(tmp);
      e.spec.push_back(
          std::make_unique<RtlSpecEngine>(cfg, promTable(cfg), (tmp / ("spec_" + cfg.name + ".hex")).string(), fail_dir));
    } else {
      e.spec.push_back(modelSpecEngine(cfg, promTable(cfg)));
    }
    e.view.set(l, e.spec.back().get());
  }
  return e;
}

RenderResult renderReference(const Scene& sc, const RenderOptions& ro) {
  RenderOptions rref = ro;
  rref.method = Method::Reference;
  rref.threads = 1;  // the reference draws on one thread
  ModelSpanEngine serial(SpanParams{});
  return render(sc, rref, serial, SpecEngines{});
}

ReferenceImage referenceImage(RenderResult ref, double highlight_lsb) {
  const ImageF spec(ref.fb.width, ref.fb.height, std::move(ref.fb.spec_lsb));  // taken over, not copied
  return {exactImage(ref.fb), coveredPixels(ref.fb), thresholdMask(spec, highlight_lsb)};
}

Comparison compareWithReference(const Image& img, const PixelMask& covered, const ReferenceImage& ref,
                                double heat_scale) {
  const PixelMask both = intersect(covered, ref.covered);
  const PixelMask highlight = intersect(both, ref.highlight);
  return {imageMetrics(img, ref.exact, both), imageMetrics(img, ref.exact, highlight),
          errorHeatmap(img, ref.exact, heat_scale, both)};
}

RtlCheck checkRtlFrame(const Scene& sc, const RenderResult& res, const RenderResult& hres) {
  const Image img = frameImage(res.fb), himg = frameImage(hres.fb);
  RtlCheck c;
  c.mismatches = differingPixels(img, himg).count();
  if (auto d = firstDifference(img, himg)) {
    const size_t p = static_cast<size_t>(d->y) * img.width + d->x;
    auto who = [&](const RenderResult& r, size_t pixel) {
      if (r.fb.tri.empty()) return std::string("a triangle not recorded (drawn without RenderOptions::tags)");
      const int32_t t = r.fb.tri[pixel];
      if (t < 0) return std::string("no triangle");
      const ScreenTriangleInfo& i = r.triangles[static_cast<size_t>(t)];
      return fmt::format("triangle {} of object '{}' (mesh triangle {}, screen ({:.2f},{:.2f}) ({:.2f},{:.2f}) "
                         "({:.2f},{:.2f}))",
                         t, sc.objects[static_cast<size_t>(i.object)].name, i.mesh_triangle, i.xy[0][0], i.xy[0][1],
                         i.xy[1][0], i.xy[1][1], i.xy[2][0], i.xy[2][1]);
    };
    c.first_mismatch = fmt::format("pixel ({}, {}): model ({}, {}, {}) written by {}; rtl ({}, {}, {}) written by {}",
                                   d->x, d->y, d->a.r, d->a.g, d->a.b, who(res, p), d->b.r, d->b.g, d->b.b,
                                   who(hres, p));
  }
  c.json = {{"ms", hres.stats.ms},
            {"span_cycles", hres.stats.span_cycles},
            {"spec_cycles", hres.stats.spec_cycles},
            {"cycles_equal",
             hres.stats.span_cycles == res.stats.span_cycles && hres.stats.spec_cycles == res.stats.spec_cycles}};
  return c;
}

nlohmann::json frameCounts(const RenderStats& st) {
  return {{"triangles", st.triangles},
          {"culled", st.culled()},
          {"culled_back", st.culled_back},
          {"culled_outside", st.culled_outside},
          {"culled_no_pixel", st.culled_no_pixel},
          {"clipped", st.clipped},
          {"drawn", st.drawn},
          {"fragments", st.fragments},
          {"pixels_covered", st.pixels_covered},
          {"cycles", st.span_cycles},
          {"spec_cycles", st.spec_cycles},
          {"spec_evaluations", st.spec_evaluations},
          {"spec_at_zero", st.spec_at_zero},
          {"depth_rejected", st.depth_rejected},
          {"divisions", st.divisions},
          {"split_parts", st.split_parts},
          {"normalisations", st.normalisations},
          {"adaptive_gouraud", st.adaptive_gouraud},
          {"adaptive_phong", st.adaptive_phong}};
}

double medianFrameMs(const Scene& sc, const RenderOptions& ro, Engines& model, const RenderResult& first,
                     size_t frames, RenderResult& scratch) {
  // Frame after frame into the same buffers, as a renderer does.
  std::vector<double> frame_ms{first.stats.ms};
  for (size_t i = 1; i < frames; ++i) {
    render(sc, ro, *model.span, model.view, scratch);
    frame_ms.push_back(scratch.stats.ms);
  }
  std::sort(frame_ms.begin(), frame_ms.end());
  return frame_ms[frame_ms.size() / 2];
}

}  // namespace shd::cli
