// phong-fixed at runtime widths (render/phong_widths.h, render/fixed_widths.h) and the sweep
// over them (sweep/phong_sweep.h): the defaults give today's images bit for bit, narrower
// widths raise the error, validate() names the derivation a width breaks, the JSON form is
// strict, and a sweep point's record is deterministic.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "image/image.h"
#include "image/metrics.h"
#include "render/fixed_widths.h"
#include "render/lobe_units.h"
#include "render/normalize.h"
#include "render/render.h"
#include "scene/scene.h"
#include "sweep/grid.h"
#include "sweep/phong_sweep.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::errorOf;
namespace fs = std::filesystem;

namespace {

// The bundled scene files, sorted.
std::vector<std::string> bundledScenes() {
  std::vector<std::string> files;
  for (const auto& e : fs::directory_iterator(fs::path(SHD_SOURCE_DIR) / "vectors" / "scenes"))
    if (e.path().extension() == ".json") files.push_back(e.path().string());
  std::sort(files.begin(), files.end());
  return files;
}

RenderResult renderFixed(const Scene& s, const std::string& brdf, const std::optional<PhongWidths>& widths,
                         Method method = Method::PhongFixed) {
  RenderOptions o;
  o.method = method;
  o.brdf = brdf;
  o.phong_widths = widths;
  LobeEngines e = modelLobeEngines(s, o, LobeConfigs{});
  ModelSpanEngine span(SpanParams{});
  return render(s, o, span, e.view);
}

// The largest |a - b| of two images' channels over the pixels both cover.
int maxDiff(const Framebuffer& a, const Framebuffer& b) {
  int worst = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    if (a.tri[i / 3] >= 0 && b.tri[i / 3] >= 0) worst = std::max(worst, std::abs(int{a.rgb[i]} - int{b.rgb[i]}));
  return worst;
}

// rmse (LSB) of a against b over the pixels both cover.
double rmseDiff(const Framebuffer& a, const Framebuffer& b) {
  double sum = 0;
  size_t n = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    if (a.tri[i / 3] >= 0 && b.tri[i / 3] >= 0) {
      const double d = static_cast<double>(a.rgb[i]) - static_cast<double>(b.rgb[i]);
      sum += d * d;
      ++n;
    }
  return n == 0 ? 0 : std::sqrt(sum / static_cast<double>(n));
}

const char* const kLobes[] = {"", "phong", "blinn", "pow", "normalized-blinn", "schlick", "cook-torrance",
                              "quadratic", "cubic"};

}  // namespace

// Every bundled scene, every lobe (and each material's own): phong-fixed at PhongWidths{} (the
// scalar datapath at runtime widths, fragment by fragment) gives the framebuffer of phong-fixed
// without widths (run kernels, AVX-512 where the CPU has it), byte for byte, with the same
// statistics. One width one bit narrower changes the sphere's image: the comparison can fail.
TEST(PhongWidths, DefaultsAreBitIdenticalOnEveryScene) {
  const std::vector<std::string> files = bundledScenes();
  ASSERT_GE(files.size(), 2u);
  uint64_t pixels = 0;
  for (const std::string& file : files) {
    const Scene s = loadScene(file);
    for (const char* brdf : kLobes) {
      const RenderResult fixed = renderFixed(s, brdf, std::nullopt);
      const RenderResult widths = renderFixed(s, brdf, PhongWidths{});
      const std::string what = file + " brdf '" + brdf + "'";
      const auto d = std::mismatch(fixed.fb.rgb.begin(), fixed.fb.rgb.end(), widths.fb.rgb.begin());
      ASSERT_TRUE(d.first == fixed.fb.rgb.end())
          << what << ": first differing byte " << (d.first - fixed.fb.rgb.begin()) << ": " << int{*d.first} << " vs "
          << int{*d.second};
      EXPECT_EQ(fixed.fb.depth, widths.fb.depth) << what;
      EXPECT_EQ(fixed.fb.tri, widths.fb.tri) << what;
      EXPECT_EQ(fixed.stats.fragments, widths.stats.fragments) << what;
      EXPECT_EQ(fixed.stats.pixels_covered, widths.stats.pixels_covered) << what;
      EXPECT_EQ(fixed.stats.spec_evaluations, widths.stats.spec_evaluations) << what;
      EXPECT_EQ(fixed.stats.spec_cycles, widths.stats.spec_cycles) << what;
      pixels += fixed.stats.pixels_covered;
    }
  }
  EXPECT_GT(pixels, 2000000u);
  const Scene sphere = loadScene("builtin:sphere");
  for (const char* name : {"ColourFracBits", "RsqrtSeedBits", "NewtonSteps"}) {
    PhongWidths w;
    --w.at(name);
    EXPECT_GT(maxDiff(renderFixed(sphere, "", std::nullopt).fb, renderFixed(sphere, "", w).fb), 0) << name;
  }
}

// The RTL's way with device lobes (no model: every request batched per triangle) at the
// defaults equals the memo's image.
TEST(PhongWidths, DefaultsBatchedDeviceRequestsEqualTheMemo) {
  const Scene s = loadScene("builtin:sphere");
  RenderOptions o;
  o.method = Method::PhongFixed;
  o.brdf = "quadratic";
  LobeEngines e = modelLobeEngines(s, o, LobeConfigs{});
  testutil::BatchOnly batch(*e.view.quadratic);
  SpecEngines view;
  view.quadratic = &batch;
  ModelSpanEngine span(SpanParams{});
  const RenderResult fixed = render(s, o, span, e.view);
  o.phong_widths = PhongWidths{};
  const RenderResult batched = render(s, o, span, view);
  EXPECT_EQ(batched.fb.rgb, fixed.fb.rgb);
  EXPECT_EQ(batched.stats.spec_evaluations, fixed.stats.spec_evaluations);
  EXPECT_GT(fixed.stats.spec_evaluations, 10000u);
}

// The runtime reciprocal square root at the defaults equals rsqrtCore<10> (the fixed path's),
// on random squared norms of every magnitude.
TEST(PhongWidths, RsqrtEqualsTheFixedPathsAtTheDefaults) {
  const PhongWidths w;
  const auto seeds = rsqrtSeedTable(w.RsqrtSeedBits, w.RsqrtSeedFracBits);
  ASSERT_EQ(seeds->size(), RsqrtSeed<10>::table.size());
  EXPECT_TRUE(std::equal(seeds->begin(), seeds->end(), RsqrtSeed<10>::table.begin()));
  std::mt19937_64 rng(7);
  for (int i = 0; i < 200000; ++i) {
    const uint64_t v = std::max<uint64_t>(1, rng() >> (rng() % 64));
    const RsqrtCore c = rsqrtCore<10>(v);
    const WidthsRsqrt r = widthsRsqrt(v, w, seeds->data());
    ASSERT_EQ(static_cast<int64_t>(r.r), c.r) << v;
    ASSERT_EQ(r.shift, c.shift) << v;
  }
}

// The shaders at the defaults on inputs no bundled scene reaches: lights so bright that the
// factor codes saturate (FactorIntBits), cook-torrance near grazing angles beyond f = 256
// (LobeIntBits), normalized-blinn at n = 1000, an ambient term, a point light, normals of every
// length down to zero: FixedWidthsShader(PhongWidths{}) gives FixedPointShader's codes (and
// with FactorIntBits 17 or 19, or LobeIntBits 7, it does not: checked when this was written).
TEST(PhongWidths, DefaultShaderEqualsTheFixedShaderOnExtremeInputs) {
  Scene s = loadScene("builtin:sphere");
  s.ambient = {0.3, 0.2, 0.1};
  s.lights[0].colour = {3000, 0.5, 1};
  Light p;
  p.kind = Light::Kind::Point;
  p.position = {2, 3, -4};
  p.colour = {1, 700, 0.6};
  s.lights.push_back(p);
  const ShadeContext ctx = makeShadeContext(s);
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01;
  for (double n : {1.0, 32.0, 1000.0})
    for (Lobe lobe : {Lobe::Blinn, Lobe::Pow, Lobe::Phong, Lobe::NormalizedBlinn, Lobe::Schlick, Lobe::CookTorrance}) {
      Material m = s.materials.at(0);
      m.shininess = n;
      m.roughness = lobe == Lobe::CookTorrance && n == 1.0 ? 0.05 : 0.3;
      FixedPointShader fixed(ctx, m, lobe, nullptr, nullptr);
      FixedWidthsShader widths(ctx, m, lobe, nullptr, nullptr, PhongWidths{});
      for (int t = 0; t < 20000; ++t) {
        Vec3 v{g(rng), g(rng), g(rng)};
        if (t % 2 != 0) v = normalize(normalize(v) + 3.0 * ctx.lights[0].half);
        v = (t % 97 == 0 ? 0.0 : std::pow(2.0, -20 * u01(rng)) * (0.3 + 0.9 * u01(rng)) / length(v)) * v;
        std::array<int64_t, 3> code{std::llround(std::ldexp(v.x, 28)), std::llround(std::ldexp(v.y, 28)),
                                    std::llround(std::ldexp(v.z, 28))};
        uint64_t sq = 0;
        for (int64_t x : code) sq += static_cast<uint64_t>(x * x);
        const Vec3 pc{u01(rng) - 0.5, u01(rng) - 0.5, 2 + u01(rng)};
        const FixedShade a = fixed.shade(code.data(), sq, pc, nullptr), b = widths.shade(code.data(), sq, pc, nullptr);
        ASSERT_EQ(a.code, b.code) << toString(lobe) << " n " << n << " normal " << v.x << " " << v.y << " " << v.z;
        ASSERT_EQ(fixedColour(a), widths.colour(b));
      }
    }
}

// Narrower widths on the sphere: the error against the double-precision phong (the datapath
// error a sweep records) grows as NormalFracBits, LobeCosBits or ColourFracBits narrow, in rmse
// never down by more than a hair and at the narrowest by a clear margin over the defaults; the
// largest error too for the first two (ColourFracBits rounds each term to at worst half an LSB
// and the sum once more: the largest error stays at 1 LSB while the rmse grows 50-fold).
TEST(PhongWidths, NarrowerWidthsRaiseTheError) {
  const Scene s = loadScene("builtin:sphere");
  const Framebuffer phong = renderFixed(s, "", std::nullopt, Method::Phong).fb;
  struct Axis {
    const char* name;
    std::vector<int> values;  // widest first
  };
  const Axis axes[] = {{"NormalFracBits", {28, 16, 12, 10}},
                       {"LobeCosBits", {16, 8, 6, 4}},
                       {"ColourFracBits", {12, 4, 2, 1}}};
  for (const Axis& a : axes) {
    std::vector<double> rmse;
    std::vector<int> max;
    for (int v : a.values) {
      PhongWidths w;
      w.at(a.name) = v;
      const Framebuffer fb = renderFixed(s, "", w).fb;
      rmse.push_back(rmseDiff(fb, phong));
      max.push_back(maxDiff(fb, phong));
    }
    for (size_t i = 1; i < rmse.size(); ++i) {
      EXPECT_GE(rmse[i], rmse[i - 1] * 0.98) << a.name << " = " << a.values[i];
      EXPECT_GE(max[i], max[i - 1] - 1) << a.name << " = " << a.values[i];
    }
    EXPECT_GT(rmse.back(), rmse.front() + 0.1) << a.name;
    if (std::string(a.name) != "ColourFracBits") {
      EXPECT_GE(max.back(), max.front() + 2) << a.name;
    }
    std::string line;
    for (size_t i = 0; i < rmse.size(); ++i)
      line += fmt::format(" {}: {} LSB (rmse {:.4f})", a.values[i], max[i], rmse[i]);
    std::printf("%s%s\n", a.name, line.c_str());
  }
}

// Random valid widths (every width over its whole range, the invalid draws dropped), each on
// a small still_life with another lobe: every one renders (no product or shift leaves its
// container: the sanitizer run checks the arithmetic) the pixels the defaults cover.
TEST(PhongWidths, RandomValidWidthsRender) {
  Scene s = loadScene(std::string(SHD_SOURCE_DIR) + "/vectors/scenes/still_life.json");
  s.camera.width = s.camera.height = 96;
  s.camera.px_per_unit /= 5;
  const RenderResult def = renderFixed(s, "", PhongWidths{});
  struct Range {
    const char* name;
    int lo, hi;
  };
  const Range ranges[] = {{"NormalFracBits", 1, 30}, {"UnitFracBits", 1, 60},   {"RsqrtSeedBits", 0, 20},
                          {"RsqrtSeedFracBits", 1, 30}, {"NewtonSteps", 0, 4}, {"NewtonFracBits", 1, 62},
                          {"CosFracBits", 2, 60},      {"LobeCosBits", 1, 20},  {"LobeCodeBits", 0, 31},
                          {"LobeIntBits", 1, 32},      {"ColourFracBits", 1, 38}, {"FactorIntBits", 8, 38}};
  std::mt19937_64 rng(3);
  int rendered = 0, tries = 0;
  while (rendered < 40 && ++tries < 100000) {
    PhongWidths w;
    for (const Range& r : ranges) w.at(r.name) = std::uniform_int_distribution<int>(r.lo, r.hi)(rng);
    if (!errorOf<std::invalid_argument>([&] { w.validate(); }).empty()) continue;
    const char* brdf = kLobes[static_cast<size_t>(rendered) % std::size(kLobes)];
    const RenderResult r = renderFixed(s, brdf, w);
    ASSERT_EQ(r.fb.tri, def.fb.tri) << w.toJson().dump() << " " << brdf;
    ++rendered;
  }
  EXPECT_EQ(rendered, 40) << "valid draws in " << tries;
}

// validate() names the width, and the derivation it breaks; render() refuses widths with
// another method, and invalid widths.
TEST(PhongWidths, ValidateNamesTheDerivation) {
  EXPECT_NO_THROW(PhongWidths{}.validate());
  auto message = [](auto set) {
    PhongWidths w;
    set(w);
    return errorOf<std::invalid_argument>([&] { w.validate(); });
  };
  auto has = [](const std::string& m, const std::string& part) { return m.find(part) != std::string::npos; };
  std::string m = message([](PhongWidths& w) { w.NormalFracBits = 31; });
  EXPECT_TRUE(has(m, "NormalFracBits = 31") && has(m, "AttrBits")) << m;
  m = message([](PhongWidths& w) { w.CosFracBits = 40, w.UnitFracBits = 4, w.NewtonFracBits = 30; });
  EXPECT_TRUE(has(m, "CosFracBits = 40") && has(m, "UnitFracBits + NewtonFracBits = 34") && has(m, "positive")) << m;
  m = message([](PhongWidths& w) { w.NewtonFracBits = 48; });
  EXPECT_TRUE(has(m, "NewtonFracBits = 48") && has(m, "m r^2") && has(m, "128 bits")) << m;
  m = message([](PhongWidths& w) { w.LobeCosBits = 20, w.CosFracBits = 18; });
  EXPECT_TRUE(has(m, "LobeCosBits = 20") && has(m, "top LobeCosBits")) << m;
  m = message([](PhongWidths& w) { w.LobeCodeBits = 28; });
  EXPECT_TRUE(has(m, "LobeCodeBits + LobeIntBits = 36") && has(m, "32")) << m;
  m = message([](PhongWidths& w) { w.ColourFracBits = 24; });
  EXPECT_TRUE(has(m, "FactorIntBits + ColourFracBits + LobeIntBits = 50") && has(m, "53 bits")) << m;
  m = message([](PhongWidths& w) { w.RsqrtSeedFracBits = 0; });
  EXPECT_TRUE(has(m, "RsqrtSeedFracBits = 0") && has(m, "Newton")) << m;
  // And through render().
  const Scene s = loadScene("builtin:sphere");
  PhongWidths bad;
  bad.CosFracBits = 1;
  m = errorOf<std::invalid_argument>([&] { renderFixed(s, "", bad); });
  EXPECT_TRUE(has(m, "CosFracBits = 1")) << m;
  m = errorOf<std::invalid_argument>([&] { renderFixed(s, "", PhongWidths{}, Method::Phong); });
  EXPECT_TRUE(has(m, "phong-fixed only")) << m;
}

// toJson/fromJson round-trip; fromJson refuses unknown members, non-integers, values beyond an
// int, a non-object and invalid widths, naming `where` and the member; left-out members keep
// their defaults.
TEST(PhongWidths, JsonRoundTripAndStrictness) {
  PhongWidths w;
  EXPECT_EQ(PhongWidths::fromJson(w.toJson(), "t"), w);
  w.NormalFracBits = 16;
  w.NewtonSteps = 2;
  w.ColourFracBits = 8;
  EXPECT_EQ(PhongWidths::fromJson(w.toJson(), "t"), w);
  EXPECT_NE(PhongWidths::fromJson(PhongWidths{}.toJson(), "t"), w);
  EXPECT_EQ(PhongWidths::fromJson(nlohmann::json::parse(R"({"NewtonSteps": 2})"), "t").NewtonSteps, 2);
  EXPECT_EQ(PhongWidths::fromJson(nlohmann::json::object(), "t"), PhongWidths{});
  std::vector<std::string> names, expected = PhongWidths::names();
  const nlohmann::json defaults = PhongWidths{}.toJson();
  for (const auto& item : defaults.items()) names.push_back(item.key());
  std::sort(expected.begin(), expected.end());
  EXPECT_EQ(names, expected);
  auto refused = [](const std::string& text, const std::string& part) {
    const std::string m =
        errorOf<std::invalid_argument>([&] { PhongWidths::fromJson(nlohmann::json::parse(text), "base"); });
    EXPECT_NE(m.find("base: "), std::string::npos) << text << ": " << m;
    EXPECT_NE(m.find(part), std::string::npos) << text << ": " << m;
  };
  refused(R"({"NormalFracBit": 28})", "unknown width \"NormalFracBit\"");
  refused(R"({"NormalFracBits": 27.5})", "NormalFracBits must be an integer");
  refused(R"({"NormalFracBits": 28.0})", "NormalFracBits must be an integer");
  refused(R"({"NormalFracBits": "28"})", "NormalFracBits must be an integer");
  refused(R"({"NormalFracBits": true})", "NormalFracBits must be an integer");
  refused(R"({"NormalFracBits": null})", "NormalFracBits must be an integer");
  refused(R"({"NormalFracBits": 4294967324})", "NormalFracBits must be an integer that fits 32 bits");
  refused(R"({"NormalFracBits": -1})", "NormalFracBits = -1");
  refused(R"([28])", "must be an object");
  EXPECT_THROW(PhongWidths{}.at("Colour"), std::invalid_argument);
}

// A sweep point's record: the same bytes evaluated twice, by one unit and by a unit rebuilt
// from the base; the default point's datapath error about a rounding and 0 against the fixed
// path; a narrower point's larger; the grid's check names the point and the derivation.
TEST(PhongSweep, RecordIsDeterministicAndValidateNamesThePoint) {
  const nlohmann::json base = phongSweepBase({"sphere"});
  const SweepUnit u = phongSweepUnit(base);
  EXPECT_EQ(u.params, PhongWidths::names());
  EXPECT_EQ(u.params_member, "widths");
  EXPECT_EQ(u.base_options, "--scene sphere");
  const PointValues def = {{"NormalFracBits", 28}, {"LobeCosBits", 16}};
  const PointValues narrow = {{"NormalFracBits", 12}, {"LobeCosBits", 16}};
  const std::string a = u.evaluate(0, def).dump();
  EXPECT_EQ(u.evaluate(0, def).dump(), a);
  EXPECT_EQ(phongSweepUnit(base).evaluate(0, def).dump(), a);
  const nlohmann::json r = nlohmann::json::parse(a);
  EXPECT_EQ(r.at("widths"), PhongWidths{}.toJson());
  EXPECT_EQ(r.at("hash"), textHash(PhongWidths{}.toJson().dump()));
  EXPECT_LE(r.at("error").at("datapath_max_lsb").get<double>(), 1.0);
  EXPECT_EQ(r.at("error").at("scenes").at("sphere").at("default_max_lsb").get<double>(), 0.0);
  EXPECT_EQ(r.at("rom_bits").get<int64_t>(), 1024 * 17 + 65537 * 32);
  EXPECT_EQ(r.at("mul_bits").get<int64_t>(), phongMulBits(PhongWidths{}));
  const nlohmann::json n = u.evaluate(1, narrow);
  EXPECT_GT(n.at("error").at("datapath_max_lsb").get<double>(), r.at("error").at("datapath_max_lsb").get<double>());
  EXPECT_GT(n.at("error").at("scenes").at("sphere").at("default_max_lsb").get<double>(), 0.0);
  EXPECT_LT(n.at("mul_bits").get<int64_t>(), r.at("mul_bits").get<int64_t>());
  // The grid's check: point 2 of CosFracBits 32,33,40 x UnitFracBits 4 breaks the shift.
  const Grid grid({parseGridAxis("CosFracBits=32,33,40", u.params), parseGridAxis("UnitFracBits=4", u.params)});
  const std::string m = errorOf<std::invalid_argument>([&] { u.validate(grid); });
  EXPECT_NE(m.find("point 2 (CosFracBits=40 UnitFracBits=4)"), std::string::npos) << m;
  EXPECT_NE(m.find("UnitFracBits + NewtonFracBits = 36"), std::string::npos) << m;
  EXPECT_NO_THROW(u.validate(Grid({parseGridAxis("CosFracBits=20:32:4", u.params)})));
  EXPECT_THROW(phongSweepBase({"no_such_scene"}), std::invalid_argument);
  EXPECT_THROW(phongSweepBase({"../sphere"}), std::invalid_argument);
  EXPECT_THROW(phongSweepBase({"sphere", "sphere"}), std::invalid_argument);
}
