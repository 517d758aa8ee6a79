// shadesim render: a scene drawn with a shading method by the golden model, its error against
// the double-precision reference (image, heat map, metrics), and optionally the same frame with
// the verilated span and specular units in the loop, which must give the same image.
#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <optional>

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "cli/command.h"
#include "cosim/render_rtl.h"
#include "device/prom_io.h"
#include "image/image.h"
#include "image/metrics.h"
#include "render/fixed_simd.h"
#include "render/lobe_units.h"
#include "render/methods.h"
#include "render/render.h"
#include "scene/scene.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd::cli {

namespace {

// The engines of one path (model or RTL) for the device lobes the scene uses.
struct Engines {
  std::unique_ptr<SpanEngine> span;
  std::vector<std::unique_ptr<SpecEngine>> spec;
  SpecEngines view;
};

// The image against the reference: metrics over the covered pixels and the highlight.
struct Comparison {
  ImageMetrics all, highlight;
  Image reference, heat;
};

// The RTL-in-the-loop frame against the model's.
struct RtlCheck {
  nlohmann::json json;
  uint64_t mismatches = 0;
  std::string first_mismatch;
  bool ok() const { return mismatches == 0 && json["cycles_equal"].get<bool>(); }
};

Image toImage(const Framebuffer& fb) {
  Image img(fb.width, fb.height);
  img.rgb = fb.rgb;
  return img;
}

class RenderCmd final : public Command {
 public:
  void add(CLI::App& app) override;
  int run(const CLI::App&) override;

 private:
  std::string scene_ = "builtin:sphere", method_ = "gouraud", brdf_, mode_ = "serial", output_, json_path_;
  LobeConfigs lobes_;
  bool rtl_ = false, quiet_ = false;
  int bench_ = 0;
  double heat_scale_ = 8, highlight_lsb_ = 32;

  void say(const std::string& m) const {
    if (!quiet_) std::fprintf(stderr, "render: %s\n", m.c_str());
  }
  std::string failDir() const {
    const fs::path dir = fs::path(output_).parent_path();
    return dir.empty() ? "." : dir.string();
  }
  SpecUnitConfig lobeConfig(Lobe l) const;
  // Before any work: the verilated models --rtl needs exist (ArgError naming the option).
  void requireRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span) const;
  Engines makeEngines(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span, bool with_rtl,
                      const fs::path& tmp) const;
  Comparison compare(const RenderResult& res, const RenderResult& ref) const;
  RtlCheck renderRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span, const RenderResult& res,
                     const fs::path& tmp) const;
  nlohmann::json statistics(const Scene& sc, const RenderOptions& ro, const RenderResult& res, double ms,
                            size_t frames, const Comparison& c) const;
};

void RenderCmd::add(CLI::App& app) {
  app.add_option("--scene", scene_, "builtin:sphere | builtin:plane | builtin:torus | builtin:materials, a scene JSON "
                                    "file or a mesh file");
  std::vector<std::string> methods;
  for (const Method m : allMethods()) methods.emplace_back(toString(m));
  app.add_option("--method", method_, fmt::format("{}", fmt::join(methods, " | ")))->check(CLI::IsMember(methods));
  app.add_option("--brdf", brdf_, "override every material's brdf: phong | blinn | normalized-blinn | schlick | "
                                  "quadratic | cubic | cook-torrance | pow")
      ->check(CLI::IsMember({"phong", "blinn", "normalized-blinn", "schlick", "quadratic", "cubic", "cook-torrance",
                             "pow"}));
  app.add_option("--mode", mode_, "span unit configuration (lane mode): " + configChoices("span"));
  app.add_option("--quadratic-config", lobes_.quadratic,
                 "specular unit of the quadratic lobe (degree 2): " + configChoices("spec"))
      ->default_val(lobes_.quadratic);
  app.add_option("--cubic-config", lobes_.cubic, "specular unit of the cubic lobe (degree 3): " + configChoices("spec"))
      ->default_val(lobes_.cubic);
  app.add_flag("--rtl", rtl_, "also render with the verilated span and specular units; the images must be identical");
  app.add_option("-o,--output", output_, "the image (PNG); beside it <name>_reference.png and <name>_error.png")
      ->required();
  app.add_option("--json", json_path_, "write the statistics as JSON to this file");
  app.add_option("--heat-scale", heat_scale_, "error (LSB) shown white in the heat map")
      ->check(realIn(0, 255, Ends::OpenLow));
  app.add_option("--highlight", highlight_lsb_,
                 "the highlight: pixels whose reference specular part exceeds this many LSBs")
      ->check(realIn(0, 255));
  app.add_option("--bench", bench_, "render this many frames and report the median time")->check(countIn(0, 10000));
  app.add_flag("--quiet", quiet_, "no progress lines");
}

Engines RenderCmd::makeEngines(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span, bool with_rtl,
                               const fs::path& tmp) const {
  Engines e;
  // A disagreement between a unit and its model saves the failing case beside the image.
  if (with_rtl) e.span = std::make_unique<RtlSpanEngine>(span, failDir());
  else e.span = std::make_unique<ModelSpanEngine>(span.rtl);
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    const SpecUnitConfig cfg = lobeConfig(l);
    PromTable t = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
    if (with_rtl) {
      fs::create_directories(tmp);
      e.spec.push_back(std::make_unique<RtlSpecEngine>(cfg, std::move(t), (tmp / ("spec_" + cfg.name + ".hex")).string(),
                                                       failDir()));
    } else {
      e.spec.push_back(std::make_unique<ModelSpecEngine>(std::move(t)));
    }
    (l == Lobe::Cubic ? e.view.cubic : e.view.quadratic) = e.spec.back().get();
  }
  return e;
}

SpecUnitConfig RenderCmd::lobeConfig(Lobe l) const {
  try {
    return lobes_.load(l);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--{}-config: {}", toString(l), e.what()));
  }
}

void RenderCmd::requireRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span) const {
  try {
    requireVerilated(span);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--mode {}: {}", mode_, e.what()));
  }
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    try {
      requireVerilated(lobeConfig(l));
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--{}-config {}: {}", toString(l), lobes_.forLobe(l), e.what()));
    }
  }
}

Comparison RenderCmd::compare(const RenderResult& res, const RenderResult& ref) const {
  const Image img = toImage(res.fb);
  ImageF reff(ref.fb.width, ref.fb.height), spec_ref(ref.fb.width, ref.fb.height);
  // What a display shows: the reference clamped to the output range (an over-exposed
  // highlight is 255, not its unclamped value).
  reff.rgb = ref.fb.lsb;
  for (double& v : reff.rgb) v = std::clamp(v, 0.0, 255.0);
  spec_ref.rgb = ref.fb.spec_lsb;
  PixelMask covered(img.width, img.height);
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (res.fb.covered(x, y) && ref.fb.covered(x, y)) covered.set(x, y);
  const PixelMask highlight = intersect(covered, thresholdMask(spec_ref, highlight_lsb_));
  return {imageMetrics(img, reff, covered), imageMetrics(img, reff, highlight), roundToUnorm8(reff),
          errorHeatmap(img, reff, heat_scale_, covered)};
}

RtlCheck RenderCmd::renderRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span,
                              const RenderResult& res, const fs::path& tmp) const {
  say("the same frame with the verilated span and specular units");
  Engines hw = makeEngines(sc, ro, span, true, tmp);
  const RenderResult hres = render(sc, ro, *hw.span, hw.view);
  fs::remove_all(tmp);
  const Image img = toImage(res.fb), himg = toImage(hres.fb);
  RtlCheck c;
  c.mismatches = differingPixels(img, himg).count();
  if (auto d = firstDifference(img, himg)) {
    const size_t p = static_cast<size_t>(d->y) * img.width + d->x;
    auto who = [&](const RenderResult& r, int32_t t) {
      if (t < 0) return std::string("no triangle");
      const ScreenTriangleInfo& i = r.triangles[static_cast<size_t>(t)];
      return fmt::format("triangle {} of object '{}' (mesh triangle {}, screen ({:.2f},{:.2f}) ({:.2f},{:.2f}) "
                         "({:.2f},{:.2f}))",
                         t, sc.objects[static_cast<size_t>(i.object)].name, i.mesh_triangle, i.xy[0][0], i.xy[0][1],
                         i.xy[1][0], i.xy[1][1], i.xy[2][0], i.xy[2][1]);
    };
    c.first_mismatch = fmt::format("pixel ({}, {}): model ({}, {}, {}) written by {}; rtl ({}, {}, {}) written by {}",
                                   d->x, d->y, d->a.r, d->a.g, d->a.b, who(res, res.fb.tri[p]), d->b.r, d->b.g,
                                   d->b.b, who(hres, hres.fb.tri[p]));
  }
  c.json = {{"ms", hres.stats.ms},
            {"span_cycles", hres.stats.span_cycles},
            {"spec_cycles", hres.stats.spec_cycles},
            {"cycles_equal",
             hres.stats.span_cycles == res.stats.span_cycles && hres.stats.spec_cycles == res.stats.spec_cycles}};
  return c;
}

nlohmann::json RenderCmd::statistics(const Scene& sc, const RenderOptions& ro, const RenderResult& res, double ms,
                                     size_t frames, const Comparison& c) const {
  const RenderStats& st = res.stats;
  nlohmann::json j = {{"scene", sc.name},
                      {"method", method_},
                      {"brdf", brdf_.empty() ? "per material" : brdf_},
                      {"mode", mode_},
                      {"width", res.fb.width},
                      {"height", res.fb.height},
                      {"triangles", st.triangles},
                      {"culled", st.culled},
                      {"clipped", st.clipped},
                      {"drawn", st.drawn},
                      {"fragments", st.fragments},
                      {"pixels_covered", st.pixels_covered},
                      {"cycles", st.span_cycles},
                      {"spec_cycles", st.spec_cycles},
                      {"spec_evaluations", st.spec_evaluations},
                      {"divisions", st.divisions},
                      {"split_parts", st.split_parts},
                      {"normalisations", st.normalisations},
                      {"adaptive_gouraud", st.adaptive_gouraud},
                      {"adaptive_phong", st.adaptive_phong},
                      {"ms", ms},
                      {"frames", frames},
                      {"max_abs_lsb", c.all.max_abs_lsb},
                      {"psnr_db", toJson(c.all)["psnr_db"]},
                      {"metrics", toJson(c.all)},
                      {"highlight_lsb_threshold", highlight_lsb_},
                      {"highlight", toJson(c.highlight)}};
  // phong-fixed: whether the AVX-512 kernel shades its one-light N.H-lobe fragments here.
  if (ro.method == Method::PhongFixed) j["fixed_kernel"] = fixed_simd::available() ? "avx512" : "scalar";
  return j;
}

int RenderCmd::run(const CLI::App& app) {
  std::string ext = fs::path(output_).extension().string();
  for (char& ch : ext) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  if (ext != ".png")
    throw ArgError(fmt::format("-o {}: the images are PNG files; name the output <name>.png", output_));
  const Scene sc = loadScene(scene_);
  const SpanUnitConfig span = spanConfigArg("--mode", mode_);
  RenderOptions ro;
  ro.method = parseMethod(method_);
  ro.brdf = brdf_;
  // A lobe configuration no object evaluates with the specular unit would be silently unused.
  const std::vector<Lobe> lobes = deviceLobesUsed(sc, ro);
  for (const auto& [option, lobe] : {std::pair{"--quadratic-config", Lobe::Quadratic}, {"--cubic-config", Lobe::Cubic}})
    if (app.count(option) > 0 && std::find(lobes.begin(), lobes.end(), lobe) == lobes.end())
      throw ArgError(traits(ro.method).exact
                         ? fmt::format("{} does not apply: --method {} evaluates every lobe exactly, without the "
                                       "specular unit",
                                       option, method_)
                         : fmt::format("{} does not apply: no object of {} has the {} lobe (choose it with --brdf {})",
                                       option, sc.name, toString(lobe), toString(lobe)));
  if (rtl_) requireRtl(sc, ro, span);
  // The outputs are checked now, after the inputs are read and before any work (io/files.h),
  // and written at the end as one set.
  const fs::path out(output_);
  const std::string stem = (out.parent_path() / out.stem()).string();
  const std::vector<std::string> outputs = {output_, stem + "_reference.png", stem + "_error.png"};
  for (const std::string& o : outputs) outputTarget(o);
  if (!json_path_.empty()) outputTarget(json_path_);
  const fs::path tmp = fs::temp_directory_path() / fmt::format("shadesim-render-{}", getpid());
  // The golden model, frame after frame into the same buffers as a renderer does.
  Engines model = makeEngines(sc, ro, span, false, tmp);
  say(fmt::format("{} with {} ({}), model", sc.name, method_, mode_));
  RenderResult res = render(sc, ro, *model.span, model.view);
  std::vector<double> frame_ms{res.stats.ms};
  RenderResult frame;
  for (int i = 1; i < bench_; ++i) {
    render(sc, ro, *model.span, model.view, frame);
    frame_ms.push_back(frame.stats.ms);
  }
  std::sort(frame_ms.begin(), frame_ms.end());
  const double ms = frame_ms[frame_ms.size() / 2];
  // The reference and the error against it.
  RenderOptions rref = ro;
  rref.method = Method::Reference;
  ModelSpanEngine serial(SpanParams{});
  say("reference (double precision, exact pow)");
  const Comparison c = compare(res, render(sc, rref, serial, SpecEngines{}));
  nlohmann::json j = statistics(sc, ro, res, ms, frame_ms.size(), c);
  if (res.stats.pixels_covered == 0) {  // a blank image is not a result: say so (and in the JSON)
    const std::string w = fmt::format("nothing drawn: all {} triangles are culled or outside the view (check the "
                                      "camera and the transforms)",
                                      res.stats.triangles);
    j["warnings"].push_back(w);
    std::fprintf(stderr, "render: warning: %s\n", w.c_str());
  }
  std::optional<RtlCheck> hw;
  if (rtl_) {
    hw = renderRtl(sc, ro, span, res, tmp);
    j["pixel_mismatches"] = hw->mismatches;
    j["rtl"] = hw->json;
    if (!hw->first_mismatch.empty()) j["first_mismatch"] = hw->first_mismatch;
  }
  // Every output is written only now, as one set (io/files.h): a failure leaves none of them.
  OutputFiles files;
  files.add(outputs[0], encodePng(outputs[0], toImage(res.fb)));
  files.add(outputs[1], encodePng(outputs[1], c.reference));
  files.add(outputs[2], encodePng(outputs[2], c.heat));
  if (!json_path_.empty()) files.add(json_path_, j.dump(2) + "\n");
  files.commit();
  const RenderStats& st = res.stats;
  std::printf("%s %s %s: %llu triangles (%llu culled), %llu fragments, %llu pixels, %llu span cycles, %.2f ms; "
              "vs reference: max %.2f LSB, PSNR %s dB, %.2f%% of pixels over 1 LSB; highlight (%llu px): max %.2f LSB\n",
              sc.name.c_str(), method_.c_str(), mode_.c_str(), static_cast<unsigned long long>(st.triangles),
              static_cast<unsigned long long>(st.culled), static_cast<unsigned long long>(st.fragments),
              static_cast<unsigned long long>(st.pixels_covered), static_cast<unsigned long long>(st.span_cycles), ms,
              c.all.max_abs_lsb, toJson(c.all)["psnr_db"].dump().c_str(), 100 * c.all.share_over_1lsb,
              static_cast<unsigned long long>(c.highlight.pixels), c.highlight.max_abs_lsb);
  if (!hw) return 0;
  std::printf("rtl in the loop: %llu pixel mismatches, %.1f ms per frame, span cycles %s\n",
              static_cast<unsigned long long>(hw->mismatches), hw->json["ms"].get<double>(),
              hw->json["cycles_equal"].get<bool>() ? "equal" : "DIFFERENT");
  if (hw->ok()) return 0;
  std::fprintf(stderr, "MISMATCH: %s\n", hw->first_mismatch.c_str());
  return 1;
}

}  // namespace

std::unique_ptr<Command> makeRenderCmd() { return std::make_unique<RenderCmd>(); }

}  // namespace shd::cli
