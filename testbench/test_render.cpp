// Whole-scene rendering: the lane mode does not change the image, the RTL in the loop gives the
// model's image pixel for pixel, and the methods order as expected against the reference.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <random>
#include <set>
#include <tuple>

#include "render/draw.h"
#include "render/fixed_simd.h"
#include "render/methods.h"
#include "render/pipeline.h"
#include "render/render.h"
#include "render/split_choice.h"
#include "report/scene_use.h"
#include "cosim/render_rtl.h"
#include "cosim/replay.h"
#include "scene/scene.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::spanModes;
using shd::testutil::spanParams;
namespace fs = std::filesystem;

namespace {

struct ModelEngines {
  ModelSpanEngine span;
  std::unique_ptr<ModelSpecEngine> quad;
  SpecEngines view;
  explicit ModelEngines(const std::string& m) : span(spanParams(m)) {
    const SpecUnitConfig c = specConfig("default");
    quad = std::make_unique<ModelSpecEngine>(buildPromTable(PromRequest::fromContent(c.prom), c.rtl));
    view.quadratic = quad.get();
  }
};

// The first entry where two frames' colour, depth or triangle buffers differ, or "".
std::string bufferDiff(const Framebuffer& a, const Framebuffer& b) {
  auto first = [](const char* what, const auto& x, const auto& y) -> std::string {
    if (x.size() != y.size()) return fmt::format("{}: {} entries against {}", what, x.size(), y.size());
    const auto d = std::mismatch(x.begin(), x.end(), y.begin());
    return d.first == x.end() ? "" : fmt::format("{} {} differs", what, d.first - x.begin());
  };
  for (const std::string& d : {first("colour byte", a.rgb, b.rgb), first("depth of pixel", a.depth, b.depth),
                               first("triangle id of pixel", a.tri, b.tri)})
    if (!d.empty()) return d;
  return "";
}

RenderResult renderModel(const Scene& s, Method m, const std::string& brdf, const std::string& mode) {
  ModelEngines e(mode);
  RenderOptions o;
  o.method = m;
  o.brdf = brdf;
  return render(s, o, e.span, e.view);
}

// phong-fixed with the quadratic lobe on the unit `quad` (an engine standing in for the model's).
RenderResult renderPhongFixedQuadratic(const Scene& s, SpanEngine& span, SpecEngine& quad) {
  SpecEngines view;
  view.quadratic = &quad;
  RenderOptions o;
  o.method = Method::PhongFixed;
  o.brdf = "quadratic";
  return render(s, o, span, view);
}

// The eye just above builtin:plane's 8 x 8 plane, looking along it: the near plane (1e-6 ahead)
// cuts the triangles under the eye up to 4 units to the side, which project to 4e12 px, beyond
// the clipper's range.
Scene planeBeyondTheClipper() {
  Scene s = loadScene("builtin:plane");
  s.camera.px_per_unit = 1e6;
  s.camera.z_near = 1e-6;
  s.camera.eye = {0.01, 0.1, 0.01};
  s.camera.target = {0.01, 0.1, 1};
  return s;
}

double maxError(const Framebuffer& a, const Framebuffer& ref) {
  double worst = 0;
  for (size_t i = 0; i < a.rgb.size(); ++i)
    if (ref.tri[i / 3] >= 0) worst = std::max(worst, std::fabs(a.rgb[i] - std::clamp(ref.lsb[i], 0.0, 255.0)));
  return worst;
}

}  // namespace

// Every method of the table (a new one included): the lane mode changes the span unit's cycles,
// never the image or the fragments.
TEST(Render, ImageDoesNotDependOnTheLaneMode) {
  const Scene s = loadScene("builtin:sphere");
  for (Method m : allMethods()) {
    const RenderResult serial = renderModel(s, m, "quadratic", "serial");
    for (const std::string& mode : spanModes()) {
      const RenderResult r = renderModel(s, m, "quadratic", mode);
      EXPECT_EQ(r.fb.rgb, serial.fb.rgb) << toString(m) << " " << mode;
      EXPECT_EQ(r.stats.fragments, serial.stats.fragments);
      if (mode != "serial" && m != Method::Reference) {  // the reference walks no span unit
        EXPECT_LT(r.stats.span_cycles, serial.stats.span_cycles) << mode;
      }
    }
  }
}

TEST(Render, RtlInTheLoopEqualsTheModelPixelForPixel) {
  const Scene s = loadScene("builtin:sphere");
  const fs::path tmp = fs::path(testing::TempDir()) / "render_rtl";
  fs::create_directories(tmp);
  // The full-rate units' span cycles are the frame's stream's, which a second RTL instance takes
  // back to back (RtlSpanEngine::endFrame checks its cycles).
  for (const char* mode : {"serial", "sierpinski", "serialfull", "sierpinskifull"}) {
    for (Method m : {Method::Gouraud, Method::Phong, Method::PhongFixed}) {
      const RenderResult model = renderModel(s, m, "quadratic", mode);
      RtlSpanEngine span(spanConfig(mode));
      const SpecUnitConfig c = specConfig("default");
      RtlSpecEngine spec(specConfig("default"), buildPromTable(PromRequest::fromContent(c.prom), c.rtl), (tmp / "spec.hex").string());
      SpecEngines view;
      view.quadratic = &spec;
      RenderOptions o;
      o.method = m;
      o.brdf = "quadratic";
      const RenderResult hw = render(s, o, span, view);
      EXPECT_EQ(hw.fb.rgb, model.fb.rgb) << toString(m) << " " << mode;
      EXPECT_EQ(hw.fb.depth, model.fb.depth);
      EXPECT_EQ(hw.stats.span_cycles, model.stats.span_cycles);
      EXPECT_EQ(hw.stats.spec_cycles, model.stats.spec_cycles);
      // The specular unit is exercised: per lit pixel (phong, about 90,000), or per lit vertex
      // of the triangles that survive culling (gouraud: 826 of the sphere's 4160 vertices).
      EXPECT_GT(model.stats.spec_evaluations, m == Method::Gouraud ? 500u : 10000u);
    }
  }
}

// The engines compare the RTL with the model on every cycle (span) and every result (spec): a
// model of another lane layout, or a PROM word flipped in the model only, must stop the render
// with the triangle or request saved alone as a vector file that fails when replayed, and an FST.
TEST(Render, RtlDisagreementSavesTheCaseAlone) {
  const Scene s = loadScene("builtin:sphere");
  const fs::path dir = fs::path(testing::TempDir()) / "render_rtl_fault";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const SpecUnitConfig c = specConfig("default");
  const PromTable table = buildPromTable(PromRequest::fromContent(c.prom), c.rtl);
  RenderOptions o;
  o.method = Method::Phong;
  o.brdf = "quadratic";
  auto messageOf = [&](SpanEngine& span, SpecEngine& spec) {
    SpecEngines view;
    view.quadratic = &spec;
    try {
      render(s, o, span, view);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  {  // span: the seg2 RTL against a model with the even/odd lane layout
    RtlSpanEngine span(spanConfig("seg2"), dir.string(), spanParams("evenodd"));
    RtlSpecEngine spec(specConfig("default"), table, (dir / "spec.hex").string(), dir.string());
    const std::string msg = messageOf(span, spec);
    std::printf("%s\n", msg.c_str());
    EXPECT_NE(msg.find("span unit (seg2): the RTL differs from the model on triangle"), std::string::npos) << msg;
    EXPECT_NE(msg.find("replays alone"), std::string::npos) << msg;
    const fs::path vec = dir / "render_span_seg2_fail.vec";
    ASSERT_TRUE(fs::exists(vec));
    EXPECT_GT(fs::file_size(dir / "render_span_seg2_fail.fst"), 1000u);
    const ReplayResult r = replayVectorFile(vec.string());
    ASSERT_TRUE(r.first.has_value());
    EXPECT_EQ(r.first->cycle, r.cycles) << "the failing cycle is the file's last";
  }
  {  // spec: one PROM word differs in the model only (the word of the sphere's shininess)
    std::vector<PromWord> words = table.words;
    const int addr = table.addressOf(std::round(s.materials.at(0).shininess));
    ASSERT_GE(addr, 0);
    words[static_cast<size_t>(addr)] ^= PromWord{1} << 3;
    RtlSpanEngine span(spanConfig("serial"), dir.string());
    RtlSpecEngine spec(specConfig("default"), table, (dir / "spec.hex").string(), dir.string(), words);
    const std::string msg = messageOf(span, spec);
    std::printf("%s\n", msg.c_str());
    EXPECT_NE(msg.find("specular unit (default): the RTL differs from the model for shininess code"), std::string::npos)
        << msg;
    EXPECT_NE(msg.find("replays alone"), std::string::npos) << msg;
    const fs::path vec = dir / "render_spec_default_fail.vec";
    ASSERT_TRUE(fs::exists(vec));
    ASSERT_TRUE(fs::exists(dir / "render_spec_default_fail.hex"));
    EXPECT_GT(fs::file_size(dir / "render_spec_default_fail.fst"), 500u);
    EXPECT_TRUE(replayVectorFile(vec.string()).first.has_value());
  }
  {  // and agreeing units save nothing
    const fs::path clean = dir / "clean";
    fs::create_directories(clean);
    RtlSpanEngine span(spanConfig("serial"), clean.string());
    RtlSpecEngine spec(specConfig("default"), table, (clean / "spec.hex").string(), clean.string());
    EXPECT_EQ(messageOf(span, spec), "");
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(clean)) files += e.path().extension() == ".vec" ? 1 : 0;
    EXPECT_EQ(files, 0u);
  }
}

TEST(Render, MethodsAgainstTheReference) {
  const Scene s = loadScene("builtin:sphere");
  RenderOptions ro;
  ro.method = Method::Reference;
  ModelEngines e("serial");
  const RenderResult ref = render(s, ro, e.span, e.view);
  const double flat = maxError(renderModel(s, Method::Flat, "", "serial").fb, ref.fb);
  const double gouraud = maxError(renderModel(s, Method::Gouraud, "", "serial").fb, ref.fb);
  const double phong = maxError(renderModel(s, Method::Phong, "", "serial").fb, ref.fb);
  const double phong_inc = maxError(renderModel(s, Method::PhongIncremental, "", "serial").fb, ref.fb);
  const double phong_fixed = maxError(renderModel(s, Method::PhongFixed, "", "serial").fb, ref.fb);
  const double biquad = maxError(renderModel(s, Method::Biquadratic, "", "serial").fb, ref.fb);
  std::printf(
      "max error vs reference (LSB): flat %.2f gouraud %.2f biquadratic %.2f phong %.2f phong-incremental %.2f "
      "phong-fixed %.2f\n",
      flat, gouraud, biquad, phong, phong_inc, phong_fixed);
  EXPECT_GT(flat, gouraud);
  EXPECT_GT(gouraud, biquad);  // the quadratic surface follows the curvature Gouraud misses
  EXPECT_GT(biquad, phong);
  EXPECT_GT(gouraud, phong);
  // Per-pixel normalisation: only the affine screen-space interpolation of the normal and the
  // final rounding separate phong from the reference; the fixed-point 1/sqrt adds < 2^-14.
  EXPECT_LE(phong, 3.0);
  EXPECT_LE(std::fabs(phong_inc - phong), 1.0);
  EXPECT_LE(std::fabs(phong_fixed - phong), 1.0);  // the fixed-point datapath adds at most a rounding
}

// phong-fixed with a device lobe on the unit's model answers requests from the memo; through an
// engine without a model it sends every request to evaluate() in batches, as with the RTL.
// Both give the same image and the same specular-unit statistics.
TEST(Render, PhongFixedMemoEqualsTheBatchedRequests) {
  for (const char* scene : {"builtin:sphere", "builtin:plane"}) {
    const Scene s = loadScene(scene);
    const RenderResult memo = renderModel(s, Method::PhongFixed, "quadratic", "serial");
    ModelEngines e("serial");
    testutil::BatchOnly batch(*e.quad);
    const RenderResult batched = renderPhongFixedQuadratic(s, e.span, batch);
    EXPECT_EQ(batched.fb.rgb, memo.fb.rgb) << scene;
    EXPECT_EQ(batched.stats.spec_evaluations, memo.stats.spec_evaluations) << scene;
    EXPECT_EQ(batched.stats.spec_cycles, memo.stats.spec_cycles) << scene;
    EXPECT_GT(memo.stats.spec_evaluations, 10000u) << scene;
  }
}

// The culled triangles by reason, each counted once: the sphere's are back faces (and the few
// too small for a pixel centre), the plane's (facing the camera, wider than the view) are outside
// the guard band or off the viewport. Every triangle is drawn or culled.
TEST(Render, CulledTrianglesAreCountedByReason) {
  for (const char* scene : {"builtin:sphere", "builtin:plane", "builtin:materials", "builtin:torus"}) {
    const RenderStats st = renderModel(loadScene(scene), Method::Gouraud, "blinn", "serial").stats;
    EXPECT_EQ(st.culled(), st.culled_back + st.culled_outside + st.culled_no_pixel) << scene;
    EXPECT_LE(st.culled() + (st.drawn > 0 ? 1 : 0), st.triangles) << scene;
  }
  const RenderStats sphere = renderModel(loadScene("builtin:sphere"), Method::Gouraud, "blinn", "serial").stats;
  EXPECT_GT(sphere.culled_back, sphere.triangles / 3);
  EXPECT_EQ(sphere.culled_outside, 0u);
  const RenderStats plane = renderModel(loadScene("builtin:plane"), Method::Gouraud, "blinn", "serial").stats;
  EXPECT_EQ(plane.culled_back, 0u);
  EXPECT_GT(plane.culled_outside, 0u);
  EXPECT_GT(plane.culled_no_pixel, 0u);
}

// The recording engine (report/scene_use.h) of shadesim prune: the image is the model's, the
// distinct requests and the per-address figures are those of every request the frame made (kept
// here by an engine of the test's own), and the zero code is where the unit's output turns
// positive.
TEST(Render, RecordingSpecEngineSeesEveryRequest) {
  struct Collect final : SpecEngine {
    SpecEngine& e;
    std::vector<SpecRequest> all;
    explicit Collect(SpecEngine& inner) : e(inner) {}
    const PromTable& table() const override { return e.table(); }
    const SpecUnitModel* model() const override { return e.model(); }  // the recorder's zero code
    uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override {
      all.insert(all.end(), in.begin(), in.end());
      return e.evaluate(in, out);
    }
  };
  const Scene s = loadScene("builtin:sphere");
  const RenderResult memo = renderModel(s, Method::PhongFixed, "quadratic", "serial");
  ModelEngines e("serial");
  Collect all(*e.quad);
  RecordingSpecEngine rec(all, true);
  const RenderResult r = renderPhongFixedQuadratic(s, e.span, rec);
  EXPECT_EQ(r.fb.rgb, memo.fb.rgb);
  std::set<std::array<uint32_t, 5>> distinct;
  for (const SpecRequest& q : all.all) distinct.insert({q.shin, q.cos, q.light[0], q.light[1], q.light[2]});
  EXPECT_EQ(rec.distinctRequests().size(), distinct.size());
  const nlohmann::json use = shinUseJson(rec);
  ASSERT_EQ(use.size(), 1u);  // one material, n = 32
  const uint32_t shin = use[0]["address"];
  const int64_t zero = use[0]["zero_code"];
  const SpecUnitModel& m = *e.quad->model();
  EXPECT_EQ(m.evaluate(shin, static_cast<uint32_t>(zero), {255, 255, 255}).spec, 0u);
  EXPECT_GT(m.evaluate(shin, static_cast<uint32_t>(zero + 1), {255, 255, 255}).spec, 0u);
  uint64_t below = 0, lo = UINT32_MAX, hi = 0;
  for (const SpecRequest& q : all.all) {
    below += static_cast<int64_t>(q.cos) <= zero;
    lo = std::min<uint64_t>(lo, q.cos);
    hi = std::max<uint64_t>(hi, q.cos);
  }
  EXPECT_EQ(use[0]["requests"].get<uint64_t>(), all.all.size());
  EXPECT_EQ(use[0]["at_or_below_zero"].get<uint64_t>(), below);
  EXPECT_EQ(use[0]["cos_code_min"].get<uint64_t>(), lo);
  EXPECT_EQ(use[0]["cos_code_max"].get<uint64_t>(), hi);
  EXPECT_GT(below, 0u);
  EXPECT_LT(below, all.all.size());
}

// A request whose N.H code lies at or below the unit's zero for its shininess is answered 0
// without an evaluation and counted (RenderStats::spec_at_zero). Against an engine of the test's
// own that evaluates every request on a model of the PROM and counts them from its own scan of
// the codes, on every path to the unit (the memo of phong-fixed, phong's per-pixel requests,
// the vertices of gouraud, biquadratic's samples): the same image, the same requests and
// cycles, the same count; and the memo was never filled below the zero.
TEST(Render, SpecRequestsAtTheZeroAreSkippedWithTheSameImage) {
  struct EveryRequest final : SpecEngine {
    const PromTable& t;
    SpecUnitModel m;
    std::map<uint32_t, std::vector<bool>> zero_prefix;  // per shin: f is 0 at every code <= c
    uint64_t at_zero = 0;
    explicit EveryRequest(const PromTable& table) : t(table), m(table.unit, table.words, table.seg_words) {}
    const PromTable& table() const override { return t; }
    uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override {
      out.clear();
      for (const SpecRequest& r : in) {
        std::vector<bool>& z = zero_prefix[r.shin];
        if (z.empty()) {
          bool all = true;
          for (int64_t c = 0; c <= m.params().cosOne(); ++c)
            z.push_back(all = all && m.evaluate(r.shin, static_cast<uint32_t>(c), {255, 255, 255}).spec == 0);
        }
        at_zero += z[r.cos];
        out.push_back(m.evaluate(r.shin, r.cos, r.light).rgb);
      }
      return batchCycles(in.size(), m.params().latency());
    }
  };
  for (const char* scene : {"builtin:sphere", "builtin:materials"})
    for (const Method method : {Method::PhongFixed, Method::Phong, Method::Gouraud, Method::Biquadratic}) {
      const Scene s = loadScene(scene);
      const std::string what = std::string(scene) + " " + toString(method);
      ModelEngines e("serial");
      RenderOptions o;
      o.method = method;
      o.brdf = "quadratic";
      const RenderResult model = render(s, o, e.span, e.view);
      EveryRequest every(e.quad->table());
      SpecEngines view;
      view.quadratic = &every;
      const RenderResult all = render(s, o, e.span, view);
      EXPECT_EQ(model.fb.rgb, all.fb.rgb) << what;
      EXPECT_EQ(model.stats.spec_evaluations, all.stats.spec_evaluations) << what;
      EXPECT_EQ(model.stats.spec_cycles, all.stats.spec_cycles) << what;
      EXPECT_EQ(model.stats.spec_at_zero, every.at_zero) << what;
      EXPECT_EQ(all.stats.spec_at_zero, every.at_zero) << what;
      EXPECT_GT(every.at_zero, model.stats.spec_evaluations / 2) << what;
      EXPECT_LT(every.at_zero, model.stats.spec_evaluations) << what;
      if (method != Method::PhongFixed) continue;
      // The memo's rows (by shininess and light) hold no result at or below the zero: never
      // evaluated; and results above it.
      uint64_t above = 0;
      for (const auto& [shin, prefix] : every.zero_prefix) {
        const int64_t zero = e.quad->zeroCode(shin);
        ASSERT_GE(zero, 0) << what;
        EXPECT_TRUE(prefix[static_cast<size_t>(zero)] && !prefix[static_cast<size_t>(zero) + 1]) << what;
        for (const Material& mat : s.materials) {
          const uint64_t* row = e.quad->memo()->row(shin, lightFactors(makeShadeContext(s), mat).lights[0].device);
          for (int64_t c = 0; c <= zero; ++c) EXPECT_EQ(row[c], 0u) << what << " code " << c;
          for (int64_t c = zero + 1; c <= e.quad->model()->params().cosOne(); ++c) above += row[c] != 0;
        }
      }
      EXPECT_GT(above, 100u) << what;
    }
}

// The z-test comes before shading (docs/rendering.md): a fragment that fails it is counted
// (RenderStats::depth_rejected) and never shaded. Against a replay of the test's own: every
// fragment the span unit emitted, triangle by triangle in the order they were sent, z-tested
// against a depth buffer of its own. The counts and the depth buffers agree for every method
// that draws with the span unit, on the model's walk (its run loops) and on the collected
// fragments (the RTL's path), on scenes whose triangles hide others.
TEST(Render, EarlyDepthTestRejectionsAreCounted) {
  struct Logged final : SpanEngine {
    ModelSpanEngine inner;
    std::vector<SpanFragment> log;  // every fragment, in the order emitted
    explicit Logged(const SpanParams& p) : inner(p) {}
    const SpanParams& params() const override { return inner.params(); }
    SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override {
      const SpanWalk w = inner.run(d, out);
      log.insert(log.end(), out.end() - static_cast<ptrdiff_t>(w.fragments), out.end());
      return w;
    }
  };
  const std::string teapots = "/usr/share/assimp/models/Collada/teapots.DAE";
  ASSERT_TRUE(fs::exists(teapots)) << teapots << " missing: scripts/install_deps.sh installs assimp-testmodels";
  uint64_t rejected = 0;
  for (const std::string& scene : {teapots, std::string("builtin:torus")}) {
    const Scene s = loadScene(scene);
    for (const Method method : allMethods()) {
      if (traits(method).exact) continue;  // no span unit
      for (const char* mode : {"serial", "sierpinski"}) {  // runs of rows, and lanes without runs
        const std::string what = scene + " " + toString(method) + " " + mode;
        ModelEngines e(mode);
        RenderOptions o;
        o.method = method;
        o.brdf = "quadratic";
        const RenderResult walked = render(s, o, e.span, e.view);
        Logged logged(spanParams(mode));
        const RenderResult collected = render(s, o, logged, e.view);
        std::vector<int32_t> depth(walked.fb.depth.size(), 0);
        uint64_t want = 0;
        for (const SpanFragment& fr : logged.log) {
          int32_t& d = depth[static_cast<size_t>(fr.y) * static_cast<size_t>(s.camera.width) + static_cast<size_t>(fr.x)];
          if (fr.attr[3] <= d) ++want;
          else d = static_cast<int32_t>(fr.attr[3]);
        }
        ASSERT_EQ(logged.log.size(), collected.stats.fragments) << what;
        EXPECT_EQ(collected.stats.depth_rejected, want) << what;
        EXPECT_EQ(walked.stats.depth_rejected, want) << what;
        EXPECT_EQ(walked.fb.depth, depth) << what;
        EXPECT_EQ(collected.fb.rgb, walked.fb.rgb) << what;
        rejected += want;
      }
    }
  }
  EXPECT_GT(rejected, 10000u);
}

TEST(Render, BadOptionsAreNamed) {
  const Scene s = loadScene("builtin:sphere");
  ModelSpanEngine span(spanParams("serial"));
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

TEST(RenderMethods, OneTableNamesEveryMethodOnceInOrder) {
  const std::vector<Method> all = allMethods();
  std::set<std::string> names;
  for (size_t i = 0; i < all.size(); ++i) {
    EXPECT_EQ(static_cast<size_t>(all[i]), i);
    EXPECT_EQ(traits(all[i]).method, all[i]);
    EXPECT_EQ(parseMethod(toString(all[i])), all[i]);
    EXPECT_NE(traits(all[i]).make, nullptr);
    names.insert(toString(all[i]));
  }
  EXPECT_EQ(names.size(), all.size());
  EXPECT_EQ(all.back(), Method::Reference);
  try {
    parseMethod("toon");
    FAIL();
  } catch (const std::invalid_argument& e) {
    for (const Method m : all) EXPECT_NE(std::string(e.what()).find(toString(m)), std::string::npos) << e.what();
  }
}

TEST(RenderPipeline, ClipToFanCutsAtTheNearPlaneAndTheGuardBand) {
  const Camera cam;  // 512 x 512, z_near 0.1
  const Projection proj(cam);
  auto vertex = [&](Vec3 c) {
    PVertex v;
    v.cam = c;
    if (c.z >= cam.z_near) proj.project(v);
    return v;
  };
  std::vector<PVertex> verts;  // the triangle's (fan may point into them)
  Poly poly;
  Fan fan;
  auto clip = [&](const std::array<PVertex, 3>& t, RenderStats& st) {
    verts.assign(t.begin(), t.end());
    const TriangleView tv = viewTriangle(verts, {0, 1, 2}, cam.z_near);
    if (culledEarly(tv)) {
      ++st.culled_back;
      return false;
    }
    return clipToFan(tv, proj, cam.width, cam.height, poly, fan, st);
  };
  // A front face (negative screen area, y down) on the screen: drawn as it is.
  RenderStats st;
  const PVertex a = vertex({0, 0, 1}), b = vertex({0.1, 0, 1}), c = vertex({0, 0.1, 1});
  EXPECT_TRUE(clip({a, b, c}, st));
  EXPECT_EQ(st.clipped + st.culled(), 0u);
  // Its back: culled before anything is copied.
  EXPECT_FALSE(clip({a, c, b}, st));
  EXPECT_EQ(st.culled(), 1u);
  // One vertex behind the eye: a quadrilateral in front of the near plane, projected.
  st = RenderStats{};
  const PVertex behind = vertex({0, 0.1, -1});
  ASSERT_TRUE(clip({a, b, behind}, st));
  EXPECT_EQ(st.clipped, 1u);
  ASSERT_EQ(fan.size(), 4u);
  for (const PVertex* v : fan) {
    EXPECT_GE(v->cam.z, cam.z_near * (1 - 1e-12));
    EXPECT_NEAR(v->w, cam.z_near / v->cam.z, 1e-12);
  }
  // The same facing away once clipped: culled.
  EXPECT_FALSE(clip({b, a, behind}, st));
  EXPECT_EQ(st.culled(), 1u);
  // Far beyond the viewport (to the right and up, left and up, right and down): cut to the
  // guard band on all four sides, the vertices' camera points from (x, y, w).
  double x0 = 0, x1 = 0, y0 = 0, y1 = 0;
  for (const auto& t : {std::array<Vec3, 2>{Vec3{100, 0, 2}, Vec3{0, 100, 2}},
                        std::array<Vec3, 2>{Vec3{0, 100, 2}, Vec3{-100, 0, 2}},
                        std::array<Vec3, 2>{Vec3{0, -100, 2}, Vec3{100, 0, 2}}}) {
    st = RenderStats{};
    ASSERT_TRUE(clip({a, vertex(t[0]), vertex(t[1])}, st));
    EXPECT_EQ(st.clipped, 1u);
    EXPECT_GE(fan.size(), 4u);
    for (const PVertex* v : fan) {
      x0 = std::min(x0, v->x);
      x1 = std::max(x1, v->x);
      y0 = std::min(y0, v->y);
      y1 = std::max(y1, v->y);
      PVertex p = *v;  // its camera point projects back to it
      proj.project(p);
      EXPECT_NEAR(p.x, v->x, 1e-9);
      EXPECT_NEAR(p.y, v->y, 1e-9);
      EXPECT_NEAR(p.w, v->w, 1e-12);
    }
  }
  EXPECT_NEAR(x0, -kGuard, 1e-9);
  EXPECT_NEAR(x1, cam.width + kGuard, 1e-9);
  EXPECT_NEAR(y0, -kGuard, 1e-9);
  EXPECT_NEAR(y1, cam.height + kGuard, 1e-9);
  // A vertex that projects beyond the range the clipper resolves exactly (kMaxClipCoord) is an
  // error, not a silently wrong polygon: the limit itself is still taken.
  st = RenderStats{};
  const double edge = kMaxClipCoord * cam.z_near / cam.px_per_unit;  // x = cx + 2^40 px at Z = z_near
  EXPECT_TRUE(clip({a, vertex({-a.cam.x + edge * 0.999, 0, cam.z_near}), vertex({0, 0.1, cam.z_near})}, st));
  try {
    clip({a, vertex({edge * 2, 0, cam.z_near}), vertex({0, 0.1, cam.z_near})}, st);
    ADD_FAILURE() << "a vertex at 2^41 px was clipped";
  } catch (const std::range_error& e) {
    EXPECT_NE(std::string(e.what()).find("beyond the +-2^40 px"), std::string::npos) << e.what();
  }
}

// The renderer names the object and the triangle whose projection leaves the clipper's range.
TEST(RenderPipeline, ProjectionBeyondTheClippersRangeIsAnErrorNamingTheTriangle) {
  const Scene s = planeBeyondTheClipper();
  try {
    renderModel(s, Method::Gouraud, "", "serial");
    FAIL() << "rendered";
  } catch (const std::range_error& e) {
    EXPECT_NE(std::string(e.what()).find("builtin:plane: object 'plane' triangle "), std::string::npos) << e.what();
  }
}

// The vertex transform four at a time in AVX2 lanes against one at a time: every field of every
// vertex the same bits, on random meshes (zero, tiny and huge normals among them; vertices on
// both sides of the near plane and at Z = 0), under a mirroring transform and others, over
// ranges that start and end off a multiple of four; and without normals (flat), the same with
// the normal left 0 both ways; and triangleNormals after that, vector and scalar, the normals
// with normals of the listed triangles' vertices alone.
TEST(RenderPipeline, VectorTransformEqualsTheScalarOne) {
  if (!fixed_simd::availableAvx2()) GTEST_SKIP() << "no AVX2 here (or SHD_SCALAR set): only the scalar path runs";
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> u(-4, 4);
  SceneObject obj;
  const size_t n = 4099;
  for (size_t i = 0; i < n; ++i) {
    obj.mesh.positions.push_back({u(rng), u(rng), u(rng)});
    Vec3 nv{u(rng), u(rng), u(rng)};
    if (i % 7 == 0) nv = {0, 0, 0};
    if (i % 11 == 0) nv = {1e-160 * nv.x, 1e-160 * nv.y, 1e-160 * nv.z};
    if (i % 13 == 0) nv = {1e150 * nv.x, 1e150 * nv.y, 1e150 * nv.z};
    obj.mesh.normals.push_back(nv);
  }
  obj.mesh.positions[5] = {0, 0, 0};  // Z = 0 under the default camera with the identity transform
  Camera cam;
  const Mat4 transforms[] = {Mat4{}, Mat4::translate({0.5, -1, 2}) * Mat4::rotateDeg({30, 45, 60}) * Mat4::scale({2, 0.5, 1}),
                             Mat4::rotateDeg({10, 0, -20}) * Mat4::scale({-1, 1, 3})};  // mirroring
  size_t behind = 0, projected = 0, zero_normals = 0;
  for (const Mat4& t : transforms)
    for (const Vec3 eye : {Vec3{0, 0, -3}, Vec3{1, 2, -2}}) {
      obj.transform = t;
      cam.eye = eye;
      const CameraBasis basis = cameraBasis(cam);
      const Projection proj(cam);
      for (const auto& [b, e] : {std::pair<size_t, size_t>{0, n}, {1, n - 2}, {3, 6}, {2, 3}}) {
        std::vector<PVertex> vec(n), scalar(n);
        for (size_t i = 0; i < n; ++i) {  // different garbage on either side: every field is written
          vec[i].x = vec[i].w = vec[i].colour[1] = 7;
          scalar[i].y = scalar[i].n.z = -9;
        }
        transformVertexRange(obj, basis, cam, proj, vec.data(), b, e, true);
        transformVertexRange(obj, basis, cam, proj, scalar.data(), b, e, false);
        // Without normals (flat): the same but for the normal, left 0 both ways.
        std::vector<PVertex> vec_nn = vec, scalar_nn = scalar;
        for (size_t i = 0; i < n; ++i) vec_nn[i].n = scalar_nn[i].n = {5, 5, 5};
        transformVertexRange(obj, basis, cam, proj, vec_nn.data(), b, e, true, false);
        transformVertexRange(obj, basis, cam, proj, scalar_nn.data(), b, e, false, false);
        for (size_t i = b; i < e; ++i) {
          ASSERT_EQ(std::memcmp(&vec[i], &scalar[i], sizeof(PVertex)), 0)
              << "vertex " << i << " of [" << b << ", " << e << "): cam " << vec[i].cam.x << " " << scalar[i].cam.x
              << ", n " << vec[i].n.x << " " << scalar[i].n.x << ", x " << vec[i].x << " " << scalar[i].x;
          for (PVertex* v : {&vec_nn[i], &scalar_nn[i]}) {
            ASSERT_TRUE(v->n.x == 0 && v->n.y == 0 && v->n.z == 0) << "vertex " << i << ": a normal without normals";
            PVertex with = *v;
            with.n = scalar[i].n;
            ASSERT_EQ(std::memcmp(&with, &scalar[i], sizeof(PVertex)), 0) << "vertex " << i << " without normals";
          }
          behind += scalar[i].cam.z < cam.z_near;
          projected += scalar[i].w != 0;
          zero_normals += scalar[i].n.x == 0 && scalar[i].n.y == 0 && scalar[i].n.z == 0;
        }
        if (b != 0 || e != n) continue;
        // triangleNormals, after a transform without normals: the normals of the vertices of
        // the listed triangles (every other one of some random triangles), as with normals,
        // vector or not; the other vertices' left 0.
        std::uniform_int_distribution<uint32_t> vertex(0, static_cast<uint32_t>(n - 1));
        obj.mesh.triangles.assign(1501, {});
        std::vector<uint32_t> kept;
        std::vector<uint8_t> used(n, 0);
        for (uint32_t t = 0; t < obj.mesh.triangles.size(); ++t) {
          obj.mesh.triangles[t] = {vertex(rng), vertex(rng), vertex(rng)};
          if (t % 2 == 1) continue;
          kept.push_back(t);
          for (const uint32_t i : obj.mesh.triangles[t]) used[i] = 1;
        }
        for (const bool vector : {true, false}) {
          std::vector<PVertex> v = vector ? vec_nn : scalar_nn;
          std::vector<uint8_t> mark(3, 7);  // scratch with garbage in it
          std::vector<uint32_t> idx(5, 9);
          triangleNormals(obj, basis, kept, v.data(), mark, idx, vector);
          for (size_t i = 0; i < n; ++i) {
            PVertex want = scalar_nn[i];
            if (used[i]) want.n = scalar[i].n;
            ASSERT_EQ(std::memcmp(&v[i], &want, sizeof(PVertex)), 0)
                << "vertex " << i << (used[i] ? " (used)" : " (not used)") << (vector ? ", vector" : ", scalar")
                << ": n " << v[i].n.x << " " << want.n.x;
          }
        }
        EXPECT_GT(std::count(used.begin(), used.end(), 1), 1000) << "the listed triangles' vertices";
        EXPECT_GT(std::count(used.begin(), used.end(), 0), 1000) << "vertices of no listed triangle";
      }
    }
  EXPECT_GT(behind, 1000u);
  EXPECT_GT(projected, 1000u);
  EXPECT_GT(zero_normals, 100u);
}

#if defined(__x86_64__) && defined(__GNUC__)
namespace {
// a b - c d in a function whose target has FMA, as the AVX-512 kernels' do.
__attribute__((target("fma"), noinline)) double differenceOfProducts(double a, double b, double c, double d) {
  return a * b - c * d;
}
}  // namespace

// The build contracts no a b - c d into a fused multiply-add (-ffp-contract=off, CMakeLists.txt),
// even where the function's target has FMA: (1 + 2^-30)(1 - 2^-30) = 1 - 2^-60 rounds to 1, so
// the difference with 1 * 1 is 0, where an FMA would give -2^-60.
TEST(Build, NoProductFusedIntoASum) {
  if (!__builtin_cpu_supports("fma")) GTEST_SKIP() << "no FMA on this CPU";
  volatile double a = 1 + std::ldexp(1.0, -30), b = 1 - std::ldexp(1.0, -30), one = 1;
  EXPECT_EQ(differenceOfProducts(a, b, one, one), 0.0);
}
#endif

TEST(EdgeMaximum, MatchesDenseSamplingOfTheNormalisedCosine) {
  // paper 4.4 as corrected (docs/paper-corrections.md): the root t1 maximises (N_A + t (N_B - N_A)).H / |N_A + t (N_B - N_A)| on (0, 1)
  // when cos alpha + cos chi > 0; otherwise the maximum is at an end.
  std::mt19937_64 rng(8);
  std::uniform_real_distribution<double> u(-1, 1);
  auto unit = [&] { return normalize(Vec3{u(rng), u(rng), u(rng)}); };
  int interior = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const Vec3 na = unit(), nb = unit(), h = unit();
    auto f = [&](double t) {
      const Vec3 n = na + t * (nb - na);
      const double len = length(n);
      return len > 1e-12 ? dot(n, h) / len : -2.0;
    };
    double best_t = 0, best = f(0);
    for (int i = 1; i <= 4000; ++i) {
      const double t = i / 4000.0;
      if (f(t) > best) best = f(t), best_t = t;
    }
    const double t1 = edgeMaximumT(na, nb, h);
    if (best_t > 0.001 && best_t < 0.999 && dot(na, nb) > -0.999) {
      ASSERT_GE(t1, 0) << "an interior maximum at " << best_t << " was missed";
      EXPECT_NEAR(t1, best_t, 1e-3);
      EXPECT_GE(f(t1), best - 1e-9);
      ++interior;
    } else if (t1 >= 0) {
      EXPECT_GE(f(t1), std::max(f(0), f(1)) - 1e-9);  // a reported maximum beats both ends
    }
  }
  EXPECT_GT(interior, 1000);
  EXPECT_LT(edgeMaximumT({0, 0, -1}, {0, 0, -1}, {0, 0, -1}), 0);  // equal normals
}

TEST(Render, ModifiedGouraudSplitsWhereAHighlightCrossesAnEdge) {
  // A coarse sphere (8 segments): highlights fall inside large triangles and across edges.
  Scene s = loadScene("builtin:sphere");
  s.objects[0].mesh = idx3dSphere(1, 8);
  ModelEngines e("serial");
  RenderOptions o;
  o.method = Method::ModifiedGouraud;
  const RenderResult mod = render(s, o, e.span, e.view);
  o.method = Method::Gouraud;
  const RenderResult gou = render(s, o, e.span, e.view);
  o.method = Method::Reference;
  const RenderResult ref = render(s, o, e.span, e.view);
  EXPECT_GT(mod.stats.split_parts, 0u);
  EXPECT_GT(mod.stats.drawn, gou.stats.drawn);
  // Splitting at the edge maxima brings the image closer to the reference than plain Gouraud.
  double err_mod = 0, err_gou = 0;
  for (size_t i = 0; i < mod.fb.rgb.size(); ++i)
    if (ref.fb.tri[i / 3] >= 0) {
      const double r = std::clamp(ref.fb.lsb[i], 0.0, 255.0);
      err_mod += std::fabs(mod.fb.rgb[i] - r);
      err_gou += std::fabs(gou.fb.rgb[i] - r);
    }
  std::printf("coarse sphere: %llu parts; mean abs error gouraud %.3f, modified %.3f LSB\n",
              static_cast<unsigned long long>(mod.stats.split_parts), err_gou / mod.fb.rgb.size(),
              err_mod / mod.fb.rgb.size());
  EXPECT_LT(err_mod, err_gou);
}

TEST(Render, AdaptiveFollowsItsThresholds) {
  const Scene s = loadScene("builtin:sphere");
  ModelEngines e("serial");
  RenderOptions o;
  o.method = Method::Adaptive;
  const RenderResult strict = render(s, o, e.span, e.view);  // the listing's thresholds
  o.adaptive_q = o.adaptive_p = 2;  // any lighting difference allowed: normals decide
  o.adaptive_m = -1;
  const RenderResult loose = render(s, o, e.span, e.view);
  EXPECT_EQ(loose.stats.adaptive_phong, 0u);
  EXPECT_EQ(loose.stats.adaptive_gouraud, loose.stats.drawn);
  o.method = Method::Gouraud;
  EXPECT_EQ(render(s, o, e.span, e.view).fb.rgb, loose.fb.rgb);  // all-Gouraud equals gouraud
  std::printf("adaptive with the listing's thresholds: %llu gouraud, %llu phong triangles\n",
              static_cast<unsigned long long>(strict.stats.adaptive_gouraud),
              static_cast<unsigned long long>(strict.stats.adaptive_phong));
  EXPECT_EQ(strict.stats.adaptive_gouraud + strict.stats.adaptive_phong, strict.stats.drawn);
}

TEST(Render, NormalBisectionBetweenPhongAndLinearNormals) {
  const Scene s = loadScene("builtin:sphere");
  ModelEngines e("serial");
  RenderOptions o;
  o.method = Method::Phong;
  const RenderResult phong = render(s, o, e.span, e.view);
  o.method = Method::NormalBisection;
  o.bisection_threshold = 0;  // bisect down to every pixel: each normal exact
  const RenderResult all = render(s, o, e.span, e.view);
  EXPECT_EQ(all.stats.normalisations, all.stats.fragments);
  EXPECT_EQ(all.fb.rgb, phong.fb.rgb);
  o.bisection_threshold = 0.02;  // the listing's
  const RenderResult listing = render(s, o, e.span, e.view);
  EXPECT_LT(listing.stats.normalisations, listing.stats.fragments / 2);
  EXPECT_NE(listing.fb.rgb, phong.fb.rgb);
  std::printf("normal-bisection (0.02): %llu exact normalisations for %llu fragments\n",
              static_cast<unsigned long long>(listing.stats.normalisations),
              static_cast<unsigned long long>(listing.stats.fragments));
}

// The vector run paths (fixed_simd.h: flat and Gouraud runs, and phong-fixed's batches, which
// collect the runs of several triangles of an object, in AVX-512, AVX2 or, where neither runs,
// plain C++) against the scalar paths (RenderOptions::vector_kernel false: phong-fixed's run
// loop), on whole frames: the same colours, depths, triangle ids and statistics, on scenes
// where triangles overlap (the teapots, the torus) and objects change shaders (materials), in
// lane modes with runs and without. ctest runs it again with SHD_NO_AVX512 and with SHD_SCALAR.
TEST(Render, VectorPathsEqualTheScalarPaths) {
  const std::string teapots = "/usr/share/assimp/models/Collada/teapots.DAE";
  ASSERT_TRUE(fs::exists(teapots)) << teapots << " missing: scripts/install_deps.sh installs assimp-testmodels";
  struct Case {
    Method m;
    const char* brdf;
  };
  const Case cases[] = {{Method::Flat, ""}, {Method::Gouraud, ""}, {Method::PhongFixed, ""},
                        {Method::PhongFixed, "pow"}, {Method::PhongFixed, "schlick"}};
  uint64_t pixels = 0;
  for (const std::string scene : {"builtin:sphere", "builtin:torus", "builtin:materials", "builtin:plane", teapots.c_str()}) {
    const Scene s = loadScene(scene);
    for (const char* mode : {"serial", "evenodd", "sierpinski"})
      for (const Case& c : cases) {
        ModelEngines e(mode);
        RenderOptions o;
        o.method = c.m;
        // (materials: a lobe of N.H for its cubic object too, which needs the cubic unit; its
        // objects still change the shader's constants from one to the next)
        o.brdf = std::string(c.brdf).empty() && scene == "builtin:materials" ? "blinn" : c.brdf;
        const RenderResult vec = render(s, o, e.span, e.view);
        o.vector_kernel = false;
        const RenderResult scalar = render(s, o, e.span, e.view);
        const std::string what = scene + " " + toString(c.m) + " " + c.brdf + " " + mode;
        ASSERT_EQ(bufferDiff(vec.fb, scalar.fb), "") << what;
        const RenderStats &a = vec.stats, &b = scalar.stats;
        EXPECT_EQ(a.fragments, b.fragments) << what;
        EXPECT_EQ(a.pixels_covered, b.pixels_covered) << what;
        EXPECT_EQ(a.depth_rejected, b.depth_rejected) << what;
        EXPECT_EQ(a.span_cycles, b.span_cycles) << what;
        EXPECT_EQ(a.drawn, b.drawn) << what;
        pixels += a.pixels_covered;
      }
  }
  EXPECT_GT(pixels, 5000000u);  // 6.1 million covered pixels compared
}

// Small triangles set up straight to their rows' spans (raster/row_spans.h) against setup and
// the walk for every triangle, on whole frames: the same colours, depths, triangle ids, screen
// triangles and statistics, for every method whose units take rows' spans (and modified-gouraud
// and adaptive, which draw with them), device lobes at the vertices and per pixel, on one thread
// and two, in the paper's units and a full-rate one, on scenes of small and of large triangles.
TEST(Render, RowSpansEqualTheSpanWalk) {
  auto counts = [](const RenderStats& t) {  // every count but the rows' spans
    return std::vector<uint64_t>{t.triangles, t.culled_back, t.culled_outside, t.culled_no_pixel, t.clipped, t.drawn,
                                 t.fragments, t.pixels_covered, t.span_cycles, t.spec_cycles, t.spec_evaluations,
                                 t.spec_at_zero, t.depth_rejected, t.divisions, t.split_parts, t.normalisations,
                                 t.adaptive_gouraud, t.adaptive_phong};
  };
  const std::string teapots = "/usr/share/assimp/models/Collada/teapots.DAE";
  ASSERT_TRUE(fs::exists(teapots)) << teapots << " missing: scripts/install_deps.sh installs assimp-testmodels";
  struct Case {
    Method m;
    const char* brdf;
    int threads;
  };
  const Case cases[] = {{Method::Flat, "", 1},          {Method::Gouraud, "", 1},
                        {Method::Gouraud, "quadratic", 1}, {Method::Phong, "", 1},
                        {Method::PhongIncremental, "quadratic", 1}, {Method::PhongFixed, "", 1},
                        {Method::PhongFixed, "quadratic", 1}, {Method::ModifiedGouraud, "", 1},
                        {Method::Adaptive, "", 1},       {Method::Flat, "", 2},
                        {Method::Gouraud, "", 2},        {Method::PhongFixed, "", 2}};
  uint64_t by_rows = 0, drawn = 0;
  for (const std::string scene : {"builtin:sphere", "builtin:torus", "builtin:materials", "builtin:plane", teapots.c_str()}) {
    const Scene s = loadScene(scene);
    for (const char* mode : {"serial", "evenodd", "seg8full"})
      for (const Case& c : cases) {
        if (std::string(mode) == "evenodd" && c.threads == 1 && c.m != Method::Gouraud && c.m != Method::PhongFixed) continue;
        ModelEngines e(mode);
        RenderOptions o;
        o.method = c.m;
        o.threads = c.threads;
        o.brdf = std::string(c.brdf).empty() && scene == "builtin:materials" ? "blinn" : c.brdf;
        const RenderResult rows = render(s, o, e.span, e.view);
        o.row_spans = false;
        const RenderResult walked = render(s, o, e.span, e.view);
        const std::string what = fmt::format("{} {} {} {} thread(s) {}", scene, toString(c.m), c.brdf, c.threads, mode);
        ASSERT_EQ(bufferDiff(rows.fb, walked.fb), "") << what;
        ASSERT_EQ(rows.triangles.size(), walked.triangles.size()) << what;
        for (size_t i = 0; i < rows.triangles.size(); ++i) {
          const ScreenTriangleInfo &a = rows.triangles[i], &b = walked.triangles[i];
          ASSERT_TRUE(a.object == b.object && a.mesh_triangle == b.mesh_triangle && a.xy == b.xy) << what << ": triangle " << i;
        }
        const RenderStats &a = rows.stats, &b = walked.stats;
        EXPECT_EQ(b.row_spans, 0u) << what;
        by_rows += a.row_spans;
        drawn += a.drawn;
        EXPECT_EQ(counts(a), counts(b)) << what;
      }
  }
  // Most of these scenes' screen triangles are small: rows' spans drew them.
  EXPECT_GT(by_rows, drawn / 2) << by_rows << " of " << drawn;
}

// A frame rendered into the result of an earlier one, whose clear then covers only the
// rectangle drawn before (prepareClear, clearRect), equals the frame rendered afresh: every buffer,
// byte for byte, for a colour method, phong-fixed and the exact reference (its LSB buffers).
TEST(Render, AFrameOverAnotherEqualsItRenderedAfresh) {
  const Scene sphere = loadScene("builtin:sphere"), torus = loadScene("builtin:torus");
  for (Method m : {Method::Gouraud, Method::PhongFixed, Method::Reference}) {
    for (const auto& [first, second] : {std::pair{&torus, &sphere}, std::pair{&sphere, &torus}}) {
      ModelEngines e("serial");
      RenderOptions o;
      o.method = m;
      RenderResult reused = render(*first, o, e.span, e.view);
      ASSERT_LE(reused.fb.drawn_x0, reused.fb.drawn_x1) << toString(m);
      // The drawn rectangle holds every pixel the first frame covered.
      for (int y = 0; y < reused.fb.height; ++y)
        for (int x = 0; x < reused.fb.width; ++x)
          if (reused.fb.covered(x, y)) {
            ASSERT_TRUE(x >= reused.fb.drawn_x0 && x <= reused.fb.drawn_x1 && y >= reused.fb.drawn_y0 &&
                        y <= reused.fb.drawn_y1)
                << toString(m) << " pixel (" << x << ", " << y << ") outside the drawn rectangle";
          }
      render(*second, o, e.span, e.view, reused);
      ModelEngines fresh_e("serial");
      const RenderResult fresh = render(*second, o, fresh_e.span, fresh_e.view);
      EXPECT_EQ(reused.fb.rgb, fresh.fb.rgb) << toString(m);
      EXPECT_EQ(reused.fb.tri, fresh.fb.tri) << toString(m);
      EXPECT_EQ(reused.fb.depth, fresh.fb.depth) << toString(m);
      EXPECT_EQ(reused.fb.lsb, fresh.fb.lsb) << toString(m);
      EXPECT_EQ(reused.fb.spec_lsb, fresh.fb.spec_lsb) << toString(m);
    }
  }
}

// Two frames alike: their buffers, triangle lists and every count (not the time).
void expectSameFrames(const RenderResult& a, const RenderResult& b, const std::string& what) {
  EXPECT_EQ(a.fb.rgb, b.fb.rgb) << what;
  EXPECT_EQ(a.fb.depth, b.fb.depth) << what;
  EXPECT_EQ(a.fb.tri, b.fb.tri) << what;
  ASSERT_EQ(a.triangles.size(), b.triangles.size()) << what;
  for (size_t i = 0; i < a.triangles.size(); ++i) {
    ASSERT_EQ(a.triangles[i].object, b.triangles[i].object) << what;
    ASSERT_EQ(a.triangles[i].mesh_triangle, b.triangles[i].mesh_triangle) << what;
    ASSERT_EQ(a.triangles[i].xy, b.triangles[i].xy) << what << ": triangle " << i;
  }
  RenderStats sa = a.stats, sb = b.stats;  // every count: 8-byte fields, no padding
  sa.ms = sb.ms = 0;
  EXPECT_EQ(std::memcmp(&sa, &sb, sizeof sa), 0) << what << ": the counts differ";
}

// The triangle buffer and the triangle list left out (RenderOptions::tags, triangles) change
// nothing else: for every method, on one thread and on two where it allows, the same colours,
// depths, exact buffers and counts as with both, and the buffer and the list as with both where
// asked for, empty where not. With the buffer, a pixel has a triangle exactly where its depth is
// above 0 (Framebuffer::covered reads the depth), and those pixels are the frame's
// pixels_covered. Frames of each choice over the frame before in the same buffers equal the
// frames drawn afresh.
TEST(Render, TagsAndTriangleListLeftOutChangeNothingElse) {
  const SpecUnitConfig cubic_config = specConfig("cubic");
  ModelSpecEngine cubic(buildPromTable(PromRequest::fromContent(cubic_config.prom), cubic_config.rtl));
  int compared = 0;
  for (const char* name : {"builtin:sphere", "builtin:materials"}) {
    const Scene s = loadScene(name);
    for (Method m : allMethods()) {
      for (int threads : {1, 2}) {
        if (threads == 2 && traits(m).two_threads == TwoThreads::No) continue;
        const std::string what = fmt::format("{} {} on {} thread(s)", name, toString(m), threads);
        ModelEngines e("serial");
        e.view.cubic = &cubic;  // builtin:materials has a cubic material
        RenderOptions o;
        o.method = m;
        o.threads = threads;
        const RenderResult with = render(s, o, e.span, e.view);
        ASSERT_EQ(with.fb.tri.size(), with.fb.depth.size()) << what;
        EXPECT_FALSE(with.triangles.empty()) << what;
        uint64_t covered = 0;
        for (size_t p = 0; p < with.fb.depth.size(); ++p) {
          ASSERT_EQ(with.fb.depth[p] > 0, with.fb.tri[p] >= 0) << what << " pixel " << p;
          covered += with.fb.depth[p] > 0 ? 1 : 0;
        }
        EXPECT_EQ(covered, with.stats.pixels_covered) << what;
        EXPECT_GT(covered, 0u) << what;
        RenderResult over = with;  // its buffers, tags and all, then each choice's frame over them
        for (const auto& [tags, list] : {std::pair{false, true}, {true, false}, {false, false}, {true, true}}) {
          const std::string how = fmt::format("{}, tags {}, triangle list {}", what, tags, list);
          o.tags = tags;
          o.triangles = list;
          const RenderResult fresh = render(s, o, e.span, e.view);
          render(s, o, e.span, e.view, over);
          for (const RenderResult* r : {&fresh, static_cast<const RenderResult*>(&over)}) {
            EXPECT_EQ(r->fb.tri.empty(), !tags) << how;
            EXPECT_EQ(r->triangles.empty(), !list) << how;
            RenderResult as_with = *r;
            if (!tags) as_with.fb.tri = with.fb.tri;
            if (!list) as_with.triangles = with.triangles;
            expectSameFrames(with, as_with, how);
            EXPECT_EQ(r->fb.lsb, with.fb.lsb) << how;
            EXPECT_EQ(r->fb.spec_lsb, with.fb.spec_lsb) << how;
          }
        }
        ++compared;
      }
    }
  }
  EXPECT_GE(compared, 2 * static_cast<int>(allMethods().size()));
}

// A scene drawn with options o on one thread and on two, frame over frame: the same frames.
// Returns the one-thread frame.
RenderResult expectTwoThreadsEqualOne(const Scene& s, RenderOptions o, ModelEngines& one, ModelEngines& two,
                                      const std::string& what) {
  o.threads = 1;
  RenderResult a = render(s, o, one.span, one.view);
  o.threads = 2;
  RenderResult b = render(s, o, two.span, two.view);
  render(s, o, two.span, two.view, b);  // over the frame before
  EXPECT_GT(a.stats.pixels_covered, 0u) << what;
  expectSameFrames(a, b, what);
  return a;
}

// Two threads (RenderOptions::threads, render.cpp): the same bytes and counts as one, for every
// method that allows it, on every built-in scene (builtin:materials: several objects, each its
// material), with the materials' own lobes and with the specular unit's quadratic lobe (at the
// vertices of gouraud, per polygon in flat, per pixel in phong-fixed), in the paper's serial
// unit and the full-rate Sierpinski unit, and again frame over frame into the same buffers.
// With the materials' lobes, flat's polygons are lit ahead on one thread (a pass over each
// object's triangles, MethodTraits::face_colours) and as they are drawn on two.
TEST(Render, TwoThreadsEqualOneThread) {
  const SpecUnitConfig cubic_config = specConfig("cubic");
  ModelSpecEngine cubic(buildPromTable(PromRequest::fromContent(cubic_config.prom), cubic_config.rtl));
  int compared = 0;
  for (const char* name : {"builtin:sphere", "builtin:plane", "builtin:torus", "builtin:materials"}) {
    const Scene s = loadScene(name);
    for (Method m : allMethods()) {
      if (traits(m).two_threads == TwoThreads::No) continue;
      for (const char* brdf : {"", "quadratic"}) {
        for (const char* mode : {"serial", "sierpinskifull"}) {
          const std::string what = fmt::format("{} {} brdf '{}' {}", name, toString(m), brdf, mode);
          ModelEngines one(mode), two(mode);
          one.view.cubic = two.view.cubic = &cubic;  // builtin:materials has a cubic material
          RenderOptions o;
          o.method = m;
          o.brdf = brdf;
          const RenderResult a = expectTwoThreadsEqualOne(s, o, one, two, what);
          if (std::string(brdf) == "quadratic") {
            EXPECT_GT(a.stats.spec_evaluations, 0u) << what;
          }
          ++compared;
        }
      }
    }
  }
  EXPECT_EQ(compared, 4 * 3 * 2 * 2);
  // phong-fixed's walk done ahead and replayed to a consumer without runs: a specular unit that
  // is not the model batches each triangle's requests, and that path takes fragments alone.
  struct Batched final : SpecEngine {
    SpecEngine& inner;
    explicit Batched(SpecEngine& i) : inner(i) {}
    const PromTable& table() const override { return inner.table(); }
    uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override {
      return inner.evaluate(in, out);
    }
  };
  const Scene sphere = loadScene("builtin:sphere");
  ModelEngines e("evenodd");
  Batched batched(*e.quad);
  SpecEngines view;
  view.quadratic = &batched;
  RenderOptions o;
  o.method = Method::PhongFixed;
  o.brdf = "quadratic";
  const RenderResult a = render(sphere, o, e.span, view);
  o.threads = 2;
  const RenderResult b = render(sphere, o, e.span, view);
  EXPECT_EQ(a.fb.rgb, b.fb.rgb);
  EXPECT_EQ(a.fb.depth, b.fb.depth);
  EXPECT_EQ(a.fb.tri, b.fb.tri);
  EXPECT_EQ(a.stats.spec_evaluations, b.stats.spec_evaluations);
  EXPECT_EQ(a.stats.span_cycles, b.stats.span_cycles);
  EXPECT_GT(a.stats.spec_evaluations, 0u);
}

// The rows of a triangle walked ahead, shared between a two-thread frame's sides (RowShare): each
// row is one side's, the front end's 3 bands of 8 rows in every 64 (anyIn: whether a triangle's
// rows hold one of a side's); and phong-fixed at runtime
// widths (its other unit, render/methods/phong_fixed_widths.cpp), which draws them through the
// same walk, frame over frame on two threads equals one thread, rows' spans and walks alike.
TEST(Render, TwoThreadsShareTheRowsWalkedAhead) {
  const RowShare all{}, front{RowShare::Side::Front}, back{RowShare::Side::Back};
  const RowShare top{RowShare::Side::Rows, 0, 77}, bottom{RowShare::Side::Rows, 77, 4096};
  int front_rows = 0;
  for (int32_t y = 0; y < 4096; ++y) {
    ASSERT_TRUE(all.mine(y));
    ASSERT_NE(front.mine(y), back.mine(y)) << "row " << y;
    ASSERT_NE(top.mine(y), bottom.mine(y)) << "row " << y;
    EXPECT_EQ(top.mine(y), y < 77) << "row " << y;
    front_rows += front.mine(y);
    EXPECT_EQ(front.mine(y), y % 64 < 24) << "row " << y;
  }
  EXPECT_EQ(front_rows, 4096 * 3 / 8);
  for (const RowShare& share : {all, front, back, top, bottom})
    for (int32_t y0 = 0; y0 < 200; ++y0)
      for (int32_t y1 = y0; y1 < y0 + 70; ++y1) {
        bool any = false;
        for (int32_t y = y0; y <= y1; ++y) any = any || share.mine(y);
        ASSERT_EQ(share.anyIn(y0, y1), any) << "rows " << y0 << ".." << y1;
      }
  for (const char* name : {"builtin:torus", "builtin:materials"}) {
    const Scene s = loadScene(name);
    for (const char* mode : {"serial", "sierpinskifull"}) {
      const std::string what = fmt::format("{} {}", name, mode);
      ModelEngines one(mode), two(mode);
      RenderOptions o;
      o.method = Method::PhongFixed;
      o.brdf = "blinn";  // builtin:materials' cubic material would need the cubic unit
      o.split = RenderOptions::Split::FrontBack;  // the walk ahead, not the split by rows
      PhongWidths w;
      w.NormalFracBits = 20;
      w.CosFracBits = 24;
      o.phong_widths = w;
      expectTwoThreadsEqualOne(s, o, one, two, what);
    }
  }
}

// flat and gouraud on two threads, the back end setting up none, one in a while, some (the
// default: while it is short of work) or all of the triangles (RenderOptions::hand_off_below):
// the same frames as one thread, with the materials' lobes and with the quadratic device lobe
// (whose vertex requests the front end counts). A setup that fails (NaN colours, of a material
// whose kd is NaN) fails with one thread's message on either side: the back end names the
// triangle's tag, which the front end cannot know.
TEST(Render, TwoThreadsSetUpOnEitherSide) {
  const std::vector<size_t> shares = {0, 1, RenderOptions{}.hand_off_below, SIZE_MAX};
  for (const char* name : {"builtin:sphere", "builtin:torus", "builtin:materials"}) {
    const Scene s = loadScene(name);
    for (Method m : {Method::Flat, Method::Gouraud})
      for (const char* brdf : {"blinn", "quadratic"})  // blinn: builtin:materials' cubic would need its unit
        for (size_t below : shares) {
          const std::string what = fmt::format("{} {} {} hand_off_below {}", name, toString(m), brdf, below);
          ModelEngines one("serial"), two("serial");
          RenderOptions o;
          o.method = m;
          o.brdf = brdf;
          o.hand_off_below = below;
          o.split = RenderOptions::Split::FrontBack;
          expectTwoThreadsEqualOne(s, o, one, two, what);
        }
  }
  Scene bad = loadScene("builtin:sphere");
  bad.materials.at(0).kd = std::nan("");
  ModelEngines e("serial");
  for (Method m : {Method::Flat, Method::Gouraud})
    for (const char* brdf : {"blinn", "quadratic"}) {
      const std::string what = fmt::format("{} {}", toString(m), brdf);
      RenderOptions o;
      o.method = m;
      o.brdf = brdf;
      const auto fails = [&] { render(bad, o, e.span, e.view); };
      const std::string want = testutil::errorOf<std::invalid_argument>(fails);
      EXPECT_NE(want.find("triangle 2: attribute 0 = nan"), std::string::npos) << what << ": " << want;  // after 2 drawn
      o.threads = 2;
      o.split = RenderOptions::Split::Rows;
      EXPECT_EQ(testutil::errorOf<std::invalid_argument>(fails), want) << what << " split by rows";
      o.split = RenderOptions::Split::FrontBack;
      for (size_t below : shares) {
        o.hand_off_below = below;
        EXPECT_EQ(testutil::errorOf<std::invalid_argument>(fails), want) << what << " hand_off_below " << below;
      }
    }
}

// Two threads split by rows (RenderOptions::Split::Rows, render.cpp's SplitSide): the same
// bytes, triangle list, counts and drawn rectangle as one thread for flat, Gouraud and
// phong-fixed on every built-in scene (builtin:plane: triangles clipped at the near plane and
// the guard band), wherever the frame splits: all rows the bottom's or the top's, one row, a
// third, the middle, and the adaptive split frame over frame. With and without the triangle
// buffer (each side's tags made the frame's), the rows' spans (every triangle walked from its
// descriptor, each side replaying its rows) and the vector kernels (the scalar paths).
TEST(Render, TwoThreadsSplitByRowsEqualOneThread) {
  int compared = 0;
  for (const char* name : {"builtin:sphere", "builtin:plane", "builtin:torus", "builtin:materials"}) {
    const Scene s = loadScene(name);
    const int H = s.camera.height;
    for (Method m : {Method::Flat, Method::Gouraud, Method::PhongFixed})
      for (const char* variant : {"", "no tags", "no row spans", "scalar"})
        for (int split : {-1, 0, 1, H / 3, H / 2 + 1, H}) {
          const std::string what = fmt::format("{} {} {} split at {}", name, toString(m), variant, split);
          ModelEngines one("serial"), two("serial");
          RenderOptions o;
          o.method = m;
          o.brdf = "blinn";  // builtin:materials' cubic material would need the cubic unit
          o.split = RenderOptions::Split::Rows;
          o.split_row = split;
          o.tags = std::string(variant) != "no tags";
          o.row_spans = std::string(variant) != "no row spans";
          o.vector_kernel = std::string(variant) != "scalar";
          o.threads = 2;
          ASSERT_TRUE(splitsByRows(s, o, two.span)) << what;
          const RenderResult a = expectTwoThreadsEqualOne(s, o, one, two, what);
          o.threads = 2;
          const RenderResult b = render(s, o, two.span, two.view);
          EXPECT_EQ(std::make_tuple(a.fb.drawn_x0, a.fb.drawn_y0, a.fb.drawn_x1, a.fb.drawn_y1),
                    std::make_tuple(b.fb.drawn_x0, b.fb.drawn_y0, b.fb.drawn_x1, b.fb.drawn_y1))
              << what;
          ++compared;
        }
  }
  EXPECT_EQ(compared, 4 * 3 * 4 * 6);
  // Auto (measured) and Rows may split by rows, every two-thread method. Never: with a device
  // lobe, the full-rate unit's stream, or Split::FrontBack.
  const Scene sphere = loadScene("builtin:sphere");
  ModelEngines serial("serial"), full("sierpinskifull");
  RenderOptions o;
  o.threads = 2;
  for (Method m : {Method::Flat, Method::Gouraud, Method::PhongFixed}) {
    o.method = m;
    EXPECT_TRUE(splitsByRows(sphere, o, serial.span)) << toString(m);
  }
  o.split = RenderOptions::Split::Rows;
  EXPECT_TRUE(splitsByRows(sphere, o, serial.span));
  EXPECT_FALSE(splitsByRows(sphere, o, full.span));
  o.brdf = "quadratic";
  EXPECT_FALSE(splitsByRows(sphere, o, serial.span));
  o.brdf = "";
  o.split = RenderOptions::Split::FrontBack;
  EXPECT_FALSE(splitsByRows(sphere, o, serial.span));
}

// Frames split by rows place their triangles into the list the frame before left (renderSplit):
// frame after frame into one result, over scenes of more and fewer triangles and over frames
// drawn on one thread, each equals a frame drawn afresh on one thread (image, triangle list
// with positions, counts) and has its drawn rectangle.
TEST(Render, SplitFramesOverOtherFramesEqualFreshOnes) {
  ModelEngines one("serial"), two("serial");
  RenderResult reused;
  int compared = 0;
  for (const char* name : {"builtin:sphere", "builtin:plane", "builtin:torus", "builtin:sphere", "builtin:materials"})
    for (int threads : {2, 1, 2}) {
      const Scene s = loadScene(name);
      const std::string what = fmt::format("{} on {} thread(s), frame {}", name, threads, compared);
      RenderOptions o;
      o.method = Method::Gouraud;
      o.brdf = "blinn";
      o.split = RenderOptions::Split::Rows;
      o.split_row = s.camera.height / 2;
      o.threads = 1;
      const RenderResult fresh = render(s, o, one.span, one.view);
      o.threads = threads;
      render(s, o, two.span, two.view, reused);
      EXPECT_EQ(reused.split_by_rows, threads == 2) << what;
      expectSameFrames(fresh, reused, what);
      EXPECT_EQ(std::make_tuple(fresh.fb.drawn_x0, fresh.fb.drawn_y0, fresh.fb.drawn_x1, fresh.fb.drawn_y1),
                std::make_tuple(reused.fb.drawn_x0, reused.fb.drawn_y0, reused.fb.drawn_x1, reused.fb.drawn_y1))
          << what;
      ++compared;
    }
  EXPECT_EQ(compared, 5 * 3);
}

// SplitChoice (Split::Auto): the first frame the preferred way; each cycle's last kProbe frames
// the other way; the other way chosen for the next cycle when the fastest of those beat the
// fastest of the kProbe chosen frames just before them. Earlier frames do not count.
TEST(Render, SplitChoiceKeepsTheFasterWay) {
  constexpr int C = SplitChoice::kCycle, P = SplitChoice::kProbe;
  static_assert(C > 2 * P, "a cycle has chosen frames before the ones compared");
  SplitChoice c;
  // One cycle with the frame times ms(k, by rows); the ways drawn, R or F (front and back end).
  const auto cycle = [&c](const std::function<double(int, bool)>& ms) {
    std::string ways;
    for (int k = 0; k < C; ++k) {
      const bool rows = c.next(false);
      ways += rows ? 'R' : 'F';
      c.record(ms(k, rows));
    }
    return ways;
  };
  const auto constant = [](double rows_ms, double fb_ms) {
    return [=](int, bool rows) { return rows ? rows_ms : fb_ms; };
  };
  const std::string F = std::string(C - P, 'F') + std::string(P, 'R'), R = std::string(C - P, 'R') + std::string(P, 'F');
  EXPECT_EQ(cycle(constant(2.0, 1.0)), F);  // the preferred way, faster: kept
  EXPECT_EQ(cycle(constant(2.0, 1.0)), F);
  EXPECT_FALSE(c.rows());
  EXPECT_EQ(cycle(constant(0.9, 1.0)), F);  // the other way faster: chosen for the next cycle
  EXPECT_TRUE(c.rows());
  EXPECT_EQ(cycle(constant(1.0, 1.0)), R);  // a tie keeps the way
  EXPECT_TRUE(c.rows());
  // A fast chosen frame before the compared ones does not count: the other way was faster.
  EXPECT_EQ(cycle([](int k, bool rows) { return rows ? (k == 0 ? 0.1 : 3.0) : 1.5; }), R);
  EXPECT_FALSE(c.rows());
  // Of the compared frames the fastest counts on each side: 0.95 against 1.0.
  EXPECT_EQ(cycle([](int k, bool rows) { return rows ? (k == C - 1 ? 0.95 : 2.0) : (k == C - 2 * P ? 1.0 : 2.0); }), F);
  EXPECT_TRUE(c.rows());
  EXPECT_EQ(cycle([](int k, bool rows) { return rows ? (k == C - 2 * P + 1 ? 1.0 : 2.0) : (k == C - 2 ? 1.01 : 3.0); }),
            R);
  EXPECT_TRUE(c.rows());  // 1.01 did not beat 1.0
  SplitChoice first;
  EXPECT_TRUE(first.next(true));  // the first frame: the preferred way
  EXPECT_TRUE(first.next(false));  // (its preference is read once)
}

// Split::Auto over the frames drawn into one RenderResult: the first frame by rows, both ways
// within a cycle, and every frame the same bytes, triangle list and counts as one thread.
TEST(Render, TwoThreadsAutoSplitMeasuresBothWays) {
  const Scene s = loadScene("builtin:sphere");
  for (Method m : {Method::Flat, Method::Gouraud, Method::PhongFixed}) {
    ModelEngines one("serial"), two("serial");
    RenderOptions o;
    o.method = m;
    const RenderResult a = render(s, o, one.span, one.view);
    o.threads = 2;
    RenderResult b;
    int by_rows = 0;
    for (int frame = 0; frame <= SplitChoice::kCycle; ++frame) {
      const std::string what = fmt::format("{} frame {}", toString(m), frame);
      render(s, o, two.span, two.view, b);
      if (frame == 0) {
        EXPECT_TRUE(b.split_by_rows) << what;
      }
      by_rows += b.split_by_rows ? 1 : 0;
      expectSameFrames(a, b, what);
    }
    EXPECT_GE(by_rows, SplitChoice::kProbe) << toString(m);
    EXPECT_LE(by_rows, SplitChoice::kCycle + 1 - SplitChoice::kProbe) << toString(m);
  }
}

// What cannot run on two threads is refused, naming why; an error on either thread reaches the
// caller as on one thread, and nothing is left running.
TEST(Render, TwoThreadsRefuseWhatTheyCannotDrawAndPassErrorsOn) {
  const Scene sphere = loadScene("builtin:sphere");
  ModelEngines e("serial");
  RenderOptions o;
  o.threads = 2;
  o.method = Method::Phong;
  try {
    render(sphere, o, e.span, e.view);
    FAIL() << "phong on two threads";
  } catch (const std::invalid_argument& x) {
    EXPECT_NE(std::string(x.what()).find("phong runs on one thread (two: flat, gouraud, phong-fixed)"),
              std::string::npos)
        << x.what();
  }
  o.method = Method::Gouraud;
  o.threads = 3;
  EXPECT_THROW(render(sphere, o, e.span, e.view), std::invalid_argument);
  // A span engine that is not the model's walk (the RTL's, here a stand-in).
  struct NotTheWalker final : SpanEngine {
    ModelSpanEngine inner{spanParams("serial")};
    const SpanParams& params() const override { return inner.params(); }
    SpanWalk run(const SpanDesc& d, std::vector<SpanFragment>& out) override { return inner.run(d, out); }
  } rtl;
  o.threads = 2;
  EXPECT_THROW(render(sphere, o, rtl, e.view), std::invalid_argument);
  // An error before the back end began (a device lobe without its specular unit): the frame
  // after it, into the same buffers, still equals a frame drawn afresh (the clear was not lost).
  {
    const Scene torus = loadScene("builtin:torus");
    RenderOptions g;
    g.threads = 2;
    RenderResult reused = render(torus, g, e.span, e.view);
    g.brdf = "quadratic";
    EXPECT_THROW(render(sphere, g, e.span, SpecEngines{}, reused), std::invalid_argument);
    g.brdf = "";
    render(sphere, g, e.span, e.view, reused);
    const RenderResult fresh = render(sphere, g, e.span, e.view);
    EXPECT_EQ(reused.fb.rgb, fresh.fb.rgb);
    EXPECT_EQ(reused.fb.depth, fresh.fb.depth);
    EXPECT_EQ(reused.fb.tri, fresh.fb.tri);
  }
  // The front end's error: a projection beyond the clipper's range.
  try {
    render(planeBeyondTheClipper(), o, e.span, e.view);
    FAIL() << "rendered";
  } catch (const std::range_error& x) {
    EXPECT_NE(std::string(x.what()).find("builtin:plane: object 'plane' triangle "), std::string::npos) << x.what();
  }
  // The back end's error: a specular unit that fails on its 10th batch (phong-fixed's per-pixel
  // requests, batched per triangle: the unit is not the model).
  struct Failing final : SpecEngine {
    SpecEngine& inner;
    int batches = 0;
    explicit Failing(SpecEngine& i) : inner(i) {}
    const PromTable& table() const override { return inner.table(); }
    uint64_t evaluate(const std::vector<SpecRequest>& in, std::vector<std::array<uint32_t, 3>>& out) override {
      if (++batches == 10) throw std::runtime_error("the unit failed");
      return inner.evaluate(in, out);
    }
  } failing(*e.quad);
  SpecEngines view;
  view.quadratic = &failing;
  o.method = Method::PhongFixed;
  o.brdf = "quadratic";
  for (int threads : {1, 2}) {
    o.threads = threads;
    failing.batches = 0;
    try {
      render(sphere, o, e.span, view);
      FAIL() << threads << " threads: rendered";
    } catch (const std::runtime_error& x) {
      EXPECT_STREQ(x.what(), "the unit failed") << threads << " threads";
    }
    EXPECT_EQ(failing.batches, 10) << threads << " threads";
  }
}
