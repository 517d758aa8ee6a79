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
#include "cli/render_common.h"
#include "cosim/render_rtl.h"
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

class RenderCmd final : public Command {
 public:
  void add(CLI::App& app) override;
  int run(const CLI::App&) override;

 private:
  std::string scene_ = "builtin:sphere", method_ = "gouraud", brdf_, mode_ = "serial", output_, json_path_;
  LobeConfigs lobes_;
  bool rtl_ = false, quiet_ = false;
  int bench_ = 0;
  int threads_ = 1;
  double heat_scale_ = 8, highlight_lsb_ = 32;

  void say(const std::string& m) const {
    if (!quiet_) std::fprintf(stderr, "render: %s\n", m.c_str());
  }
  std::string failDir() const {
    const fs::path dir = fs::path(output_).parent_path();
    return dir.empty() ? "." : dir.string();
  }
  // Before any work: the verilated models --rtl needs exist (ArgError naming the option).
  void requireRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span) const;
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
  app.add_option("--threads", threads_,
                 fmt::format("1, or 2: the model's frames on two threads, one culling, clipping and setting up the "
                             "triangles, the other drawing them in order: the same image and counts ({} only)",
                             twoThreadMethods()))
      ->check(countIn(1, 2));
  app.add_flag("--quiet", quiet_, "no progress lines");
}

void RenderCmd::requireRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span) const {
  try {
    requireVerilated(span);
  } catch (const std::invalid_argument& e) {
    throw ArgError(fmt::format("--mode {}: {}", mode_, e.what()));
  }
  for (Lobe l : deviceLobesUsed(sc, ro)) {
    try {
      requireVerilated(lobeConfigArg(lobes_, l));
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("--{}-config {}: {}", toString(l), lobes_.forLobe(l), e.what()));
    }
  }
}

RtlCheck RenderCmd::renderRtl(const Scene& sc, const RenderOptions& ro, const SpanUnitConfig& span,
                              const RenderResult& res, const fs::path& tmp) const {
  say("the same frame with the verilated span and specular units");
  Engines hw = makeEngines(sc, ro, span, lobes_, true, tmp, failDir());
  RenderOptions one = ro;  // the verilated units on this thread alone
  one.threads = 1;
  const RenderResult hres = render(sc, one, *hw.span, hw.view);
  fs::remove_all(tmp);
  return checkRtlFrame(sc, res, hres);
}

nlohmann::json RenderCmd::statistics(const Scene& sc, const RenderOptions& ro, const RenderResult& res, double ms,
                                     size_t frames, const Comparison& c) const {
  nlohmann::json j = frameCounts(res.stats);
  j.update({{"scene", sc.name},
            {"method", method_},
            {"brdf", brdf_.empty() ? "per material" : brdf_},
            {"mode", mode_},
            {"width", res.fb.width},
            {"height", res.fb.height},
            {"ms", ms},
            {"frames", frames},
            {"max_abs_lsb", c.all.max_abs_lsb},
            {"psnr_db", toJson(c.all)["psnr_db"]},
            {"metrics", toJson(c.all)},
            {"highlight_lsb_threshold", highlight_lsb_},
            {"highlight", toJson(c.highlight)}});
  // phong-fixed: the vector kernel (AVX-512 or AVX2) that shades its one-light N.H-lobe
  // fragments here, or none.
  if (ro.method == Method::PhongFixed)
    j["fixed_kernel"] = fixed_simd::available() ? "avx512" : fixed_simd::availableAvx2() ? "avx2" : "scalar";
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
  ro.threads = threads_;
  // The triangle buffer and list: for checkRtlFrame's report of the first differing pixel.
  ro.tags = ro.triangles = rtl_;
  if (threads_ == 2 && traits(ro.method).two_threads == TwoThreads::No)
    throw ArgError(fmt::format("--threads 2: --method {} draws on one thread (two: {})", method_, twoThreadMethods()));
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
  Engines model = makeEngines(sc, ro, span, lobes_, false, tmp, failDir());
  say(fmt::format("{} with {} ({}), model", sc.name, method_, mode_));
  const RenderResult res = render(sc, ro, *model.span, model.view);
  const size_t frames = static_cast<size_t>(std::max(1, bench_));
  RenderResult scratch;
  const double ms = medianFrameMs(sc, ro, model, res, frames, scratch);
  // The reference and the error against it.
  say("reference (double precision, exact pow)");
  const Image img = frameImage(res.fb);
  const ReferenceImage ref = referenceImage(renderReference(sc, ro), highlight_lsb_);
  const Comparison c = compareWithReference(img, coveredPixels(res.fb), ref, heat_scale_);
  const Image reference = roundToUnorm8(ref.exact);  // as shown
  nlohmann::json j = statistics(sc, ro, res, ms, frames, c);
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
  files.add(outputs[0], encodePng(outputs[0], img));
  files.add(outputs[1], encodePng(outputs[1], reference));
  files.add(outputs[2], encodePng(outputs[2], c.heat));
  if (!json_path_.empty()) files.add(json_path_, j.dump(2) + "\n");
  files.commit();
  const RenderStats& st = res.stats;
  std::printf("%s %s %s: %llu triangles (%llu culled), %llu fragments, %llu pixels, %llu span cycles, %.2f ms; "
              "vs reference: max %.2f LSB, PSNR %s dB, %.2f%% of pixels over 1 LSB; highlight (%llu px): max %.2f LSB\n",
              sc.name.c_str(), method_.c_str(), mode_.c_str(), static_cast<unsigned long long>(st.triangles),
              static_cast<unsigned long long>(st.culled()), static_cast<unsigned long long>(st.fragments),
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
