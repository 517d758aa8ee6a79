// Whole-scene rendering: the lane mode does not change the image, the RTL in the loop gives the
// model's image pixel for pixel, and the methods order as expected against the reference.
#include <gtest/gtest.h>

#include <filesystem>

#include "render/render.h"
#include "render_rtl.h"
#include "scene/scene.h"

using namespace shd;
namespace fs = std::filesystem;

namespace {

struct ModelEngines {
  ModelSpanEngine span;
  std::unique_ptr<ModelSpecEngine> quad;
  SpecEngines view;
  explicit ModelEngines(SpanMode m) : span(SpanParams::forMode(m)) {
    const SpecUnitConfig c = SpecUnitConfig::load(configPath("default"));
    quad = std::make_unique<ModelSpecEngine>(buildPromTable(PromRequest::fromContent(c.prom), c.rtl));
    view.quadratic = quad.get();
  }
};

RenderResult renderModel(const Scene& s, Method m, const std::string& brdf, SpanMode mode) {
  ModelEngines e(mode);
  RenderOptions o;
  o.method = m;
  o.brdf = brdf;
  o.span_mode = mode;
  return render(s, o, e.span, e.view);
}

double maxError(const Framebuffer& a, const Framebuffer& ref) {
  double worst = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    if (ref.tri[i / 3] >= 0) worst = std::max(worst, std::fabs(a.rgb[i] - std::clamp(ref.lsb[i], 0.0, 255.0)));
  return worst;
}

}  // namespace

TEST(Render, ImageDoesNotDependOnTheLaneMode) {
  const Scene s = loadScene("builtin:sphere");
  for (Method m : {Method::Gouraud, Method::Phong}) {
    const RenderResult serial = renderModel(s, m, "quadratic", SpanMode::Serial);
    for (SpanMode mode : allSpanModes()) {
      const RenderResult r = renderModel(s, m, "quadratic", mode);
      EXPECT_EQ(r.fb.rgb, serial.fb.rgb) << toString(m) << " " << toString(mode);
      EXPECT_EQ(r.stats.fragments, serial.stats.fragments);
      if (mode != SpanMode::Serial) {
        EXPECT_LT(r.stats.span_cycles, serial.stats.span_cycles) << toString(mode);
      }
    }
  }
}

TEST(Render, RtlInTheLoopEqualsTheModelPixelForPixel) {
  const Scene s = loadScene("builtin:sphere");
  const fs::path tmp = fs::path(testing::TempDir()) / "render_rtl";
  fs::create_directories(tmp);
  for (SpanMode mode : {SpanMode::Serial, SpanMode::Sierpinski}) {
    for (Method m : {Method::Gouraud, Method::Phong}) {
      const RenderResult model = renderModel(s, m, "quadratic", mode);
      RtlSpanEngine span(mode);
      const SpecUnitConfig c = SpecUnitConfig::load(configPath("default"));
      RtlSpecEngine spec("default", buildPromTable(PromRequest::fromContent(c.prom), c.rtl), (tmp / "spec.hex").string());
      SpecEngines view;
      view.quadratic = &spec;
      RenderOptions o;
      o.method = m;
      o.brdf = "quadratic";
      o.span_mode = mode;
      const RenderResult hw = render(s, o, span, view);
      EXPECT_EQ(hw.fb.rgb, model.fb.rgb) << toString(m) << " " << toString(mode);
      EXPECT_EQ(hw.fb.depth, model.fb.depth);
      EXPECT_EQ(hw.stats.span_cycles, model.stats.span_cycles);
      EXPECT_EQ(hw.stats.spec_cycles, model.stats.spec_cycles);
      EXPECT_GT(model.stats.spec_evaluations, 1000u);
    }
  }
}

TEST(Render, MethodsAgainstTheReference) {
  const Scene s = loadScene("builtin:sphere");
  RenderOptions ro;
  ro.method = Method::Reference;
  ModelEngines e(SpanMode::Serial);
  const RenderResult ref = render(s, ro, e.span, e.view);
  const double flat = maxError(renderModel(s, Method::Flat, "", SpanMode::Serial).fb, ref.fb);
  const double gouraud = maxError(renderModel(s, Method::Gouraud, "", SpanMode::Serial).fb, ref.fb);
  const double phong = maxError(renderModel(s, Method::Phong, "", SpanMode::Serial).fb, ref.fb);
  const double phong_inc = maxError(renderModel(s, Method::PhongIncremental, "", SpanMode::Serial).fb, ref.fb);
  std::printf("max error vs reference (LSB): flat %.2f gouraud %.2f phong %.2f phong-incremental %.2f\n", flat, gouraud,
              phong, phong_inc);
  EXPECT_GT(flat, gouraud);
  EXPECT_GT(gouraud, phong);
  // Per-pixel normalisation: only the affine screen-space interpolation of the normal and the
  // final rounding separate phong from the reference; the fixed-point 1/sqrt adds < 2^-14.
  EXPECT_LE(phong, 3.0);
  EXPECT_LE(std::fabs(phong_inc - phong), 1.0);
}

TEST(Render, BadOptionsAreNamed) {
  const Scene s = loadScene("builtin:sphere");
  ModelSpanEngine span(SpanParams::forMode(SpanMode::Serial));
  RenderOptions o;
  o.brdf = "glossy";
  EXPECT_THROW(render(s, o, span, SpecEngines{}), std::invalid_argument);
  o.brdf = "quadratic";  // needs the specular unit
  try {
    render(s, o, span, SpecEngines{});
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("specular unit"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseMethod("toon"), std::invalid_argument);
}
