// Span-unit sweeps (model/sweep/span_sweep.h): a point's record against setup's error bound and
// the exact plane, against the renderer's and the cycle-accurate model's cycle counts, its
// determinism, the lane modes, the refused derivations and the configuration it writes.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/registry.h"
#include "raster/desc_stream.h"
#include "raster/setup.h"
#include "raster/trigen.h"
#include "render/render.h"
#include "report/span_cycles.h"
#include "scene/scene.h"
#include "sweep/grid.h"
#include "sweep/span_sweep.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::errorOf;

namespace {

constexpr uint64_t kSmallSet = 20000;  // triangles of the tests that compare points

nlohmann::json baseOf(const std::string& config, uint64_t triangles, const std::vector<std::string>& scenes) {
  return spanSweepBase(spanConfig(config), triangles, 1, scenes);
}

// The lane layout of a registry mode as grid values.
PointValues modeValues(const std::string& mode) {
  const SpanParams p = testutil::spanParams(mode);
  return {{"NumTri", p.NumTri}, {"LanesPerTri", p.LanesPerTri}, {"AlignLanes", p.AlignLanes}, {"RowAhead", p.RowAhead}};
}

double err(const nlohmann::json& record, const std::string& figure) { return record.at("error").at(figure).get<double>(); }

// The triangle set of a base, as setup takes it (4 attributes).
TriangleList triangleSet(const nlohmann::json& base) {
  TriangleGenerator gen(base.at("seed").get<uint64_t>(), spanSweepTriangleOptions(base));
  TriangleList list;
  for (uint64_t i = 0; i < base.at("triangles").get<uint64_t>(); ++i) list.push_back(toSetupVertices(gen.next(), 4));
  return list;
}

// The error at the record's worst pixel of `kind`, recomputed with exactPlane and
// rasterizeReference (setup's plane at every covered pixel), in output LSBs.
double errorAtWorst(const nlohmann::json& base, const nlohmann::json& record, const std::string& kind, int frac,
                    int out_frac) {
  const nlohmann::json& e = record.at("error");
  const int64_t tri = e.at(kind + "_worst_triangle").get<int64_t>();
  const int x = e.at(kind + "_worst_x").get<int>(), y = e.at(kind + "_worst_y").get<int>();
  const int a = e.at(kind + "_worst_attr").get<int>();
  const TriangleList set = triangleSet(base);
  RasterConfig rc;
  rc.width = base.at("viewport").at("width").get<int>();
  rc.height = base.at("viewport").at("height").get<int>();
  rc.attr_frac_bits = {record.at("params").at("ColourFracBits").get<int>(), record.at("params").at("ColourFracBits").get<int>(),
                       record.at("params").at("ColourFracBits").get<int>(), record.at("params").at("DepthFracBits").get<int>()};
  const SetupResult s = setupTriangle(set.at(static_cast<size_t>(tri)), static_cast<uint32_t>(tri), rc);
  for (const SpanFragment& f : rasterizeReference(s, rc))
    if (f.x == x && f.y == y)
      return std::fabs(static_cast<double>(f.attr[static_cast<size_t>(a)]) - exactPlane(s, rc, a, x, y)) *
             std::ldexp(1.0, out_frac - frac);
  ADD_FAILURE() << kind << ": the worst pixel (" << x << ", " << y << ") is not covered by triangle " << tri;
  return -1;
}

}  // namespace

// The default point (the registry's serial unit, setup's default widths) over the whole default
// set: every code equals setup's integer plane, every error is within setup.h's bound at its
// pixel, the worst error is within the bound's viewport-wide form and the 1/4 LSB the default
// fraction bits aim at, and the worst pixel recomputed with exactPlane gives the recorded figure.
TEST(SpanSweep, DefaultPointMeetsSetupsBound) {
  const nlohmann::json base = baseOf("serial", kSpanSweepTriangles, {"sphere"});
  const nlohmann::json r = spanSweepUnit(base).evaluate(0, {});
  const int W = base.at("viewport").at("width").get<int>(), H = base.at("viewport").at("height").get<int>();
  EXPECT_EQ(r.at("error").at("plane_mismatches").get<uint64_t>(), 0u);
  EXPECT_EQ(r.at("rejected").get<uint64_t>(), 0u);
  EXPECT_EQ(r.at("drawn").get<uint64_t>() + r.at("dropped").get<uint64_t>(), kSpanSweepTriangles);
  EXPECT_GT(r.at("fragments").get<uint64_t>(), 1'000'000u);
  const struct {
    const char* kind;
    int frac, out_frac;
  } kinds[] = {{"colour", base.at("raster").at("ColourFracBits").get<int>(), kSpanColourOutFrac},
               {"depth", base.at("raster").at("DepthFracBits").get<int>(), kSpanDepthOutFrac}};
  for (const auto& k : kinds) {
    const std::string n = k.kind;
    SCOPED_TRACE(n);
    EXPECT_EQ(k.frac, defaultAttrFracBits(W, H, k.out_frac));
    EXPECT_LE(err(r, n + "_bound_ratio"), 1.0);
    EXPECT_GT(err(r, n + "_bound_ratio"), 0.0);  // the plane is rounded: some error somewhere
    const double bound = 0.5 * (1 + W + H) * std::ldexp(1.0, k.out_frac - k.frac);  // setup.h, in output LSBs
    EXPECT_GT(err(r, n + "_max_lsb"), 0.0);
    EXPECT_LE(err(r, n + "_max_lsb"), bound);
    EXPECT_LE(err(r, n + "_max_lsb"), 0.25);
    EXPECT_LE(err(r, n + "_rms_lsb"), err(r, n + "_max_lsb"));
    EXPECT_NEAR(errorAtWorst(base, r, n, k.frac, k.out_frac), err(r, n + "_max_lsb"), 1e-9 * err(r, n + "_max_lsb"));
  }
  EXPECT_EQ(err(r, "max_lsb"), std::max(err(r, "colour_max_lsb"), err(r, "depth_max_lsb")));
}

// Fewer fraction bits of the colour codes: a larger colour error (max and rms), the depth error
// untouched.
TEST(SpanSweep, FewerColourFracBitsRaiseTheError) {
  const SweepUnit u = spanSweepUnit(baseOf("serial", kSmallSet, {"sphere"}));
  nlohmann::json prev;
  for (int f : {12, 9, 6, 3}) {
    SCOPED_TRACE(f);
    const nlohmann::json r = u.evaluate(0, {{"ColourFracBits", f}});
    EXPECT_EQ(r.at("error").at("plane_mismatches").get<uint64_t>(), 0u);
    EXPECT_LE(err(r, "colour_bound_ratio"), 1.0);
    if (!prev.is_null()) {
      EXPECT_GT(err(r, "colour_max_lsb"), err(prev, "colour_max_lsb"));
      EXPECT_GT(err(r, "colour_rms_lsb"), err(prev, "colour_rms_lsb"));
      EXPECT_GE(err(r, "max_lsb"), err(prev, "max_lsb"));
      EXPECT_EQ(err(r, "depth_max_lsb"), err(prev, "depth_max_lsb"));
      EXPECT_EQ(r.at("cycles"), prev.at("cycles"));
    }
    prev = r;
  }
}

// The record is deterministic: byte for byte the same from two units of the same base.
TEST(SpanSweep, RecordIsByteIdenticalEvaluatedTwice) {
  const nlohmann::json base = baseOf("serial", kSmallSet, {"sphere"});
  const PointValues v = {{"ColourFracBits", 10}, {"LanesPerTri", 4}};
  const std::string first = spanSweepUnit(base).evaluate(7, v).dump();
  EXPECT_EQ(spanSweepUnit(base).evaluate(7, v).dump(), first);
  const nlohmann::json r = nlohmann::json::parse(first);
  EXPECT_EQ(r.at("index").get<uint64_t>(), 7u);
  EXPECT_EQ(r.at("hash").get<std::string>(), textHash(r.at("params").dump()));
  EXPECT_EQ(r.at("params").size(), spanParamNames().size());
}

// Every lane mode hands out the same codes (bit-identical by construction), so the same error
// record, worst pixels included; the cycles differ, on the set and on the scene.
TEST(SpanSweep, LaneModesGiveTheSameErrorButNotTheSameCycles) {
  const SweepUnit u = spanSweepUnit(baseOf("serial", kSmallSet, {"sphere"}));
  const nlohmann::json serial = u.evaluate(0, modeValues("serial"));
  std::set<uint64_t> set_cycles, scene_cycles;
  for (const std::string& mode : testutil::spanModes()) {
    SCOPED_TRACE(mode);
    const nlohmann::json r = u.evaluate(0, modeValues(mode));
    EXPECT_EQ(r.at("error"), serial.at("error"));
    EXPECT_EQ(r.at("fragments"), serial.at("fragments"));
    EXPECT_EQ(r.at("fragments_sphere"), serial.at("fragments_sphere"));
    EXPECT_EQ(r.at("lanes").get<int>(), testutil::spanParams(mode).lanes());
    EXPECT_TRUE(set_cycles.insert(r.at("cycles").get<uint64_t>()).second) << "cycles as another mode's";
    EXPECT_TRUE(scene_cycles.insert(r.at("cycles_sphere").get<uint64_t>()).second) << "scene cycles as another mode's";
    if (mode != "serial") {
      EXPECT_LT(r.at("cycles").get<uint64_t>(), serial.at("cycles").get<uint64_t>());
    }
  }
  // The same at the widest widths (codes near 2^61, the exact errors' products near 2^120), where
  // the runs of the one-lane-triangle modes and the fragments of sierpinski take other paths.
  PointValues wide = {{"AttrBits", 62}, {"ColourFracBits", 52}, {"DepthFracBits", 60}, {"CoordBits", 30},
                      {"RemBits", 60},  {"SubpixelBits", 8},    {"PixBits", 29}};
  const nlohmann::json wide_serial = u.evaluate(0, wide);
  wide.push_back({"NumTri", 4});
  EXPECT_EQ(u.evaluate(0, wide).at("error"), wide_serial.at("error"));
  EXPECT_EQ(wide_serial.at("error").at("plane_mismatches").get<uint64_t>(), 0u);
  EXPECT_LE(err(wide_serial, "colour_bound_ratio"), 1.0);
}

// The cycles a record names are those of the existing paths: each scene's those of the renderer
// with the registry's serial unit (what `shadesim render` and scripts/regress.py report), the
// set's those of the cycle-by-cycle SpanUnitModel (measureSpanCycles), for serial and sierpinski.
TEST(SpanSweep, CyclesEqualTheRendererAndTheCycleAccurateModel) {
  const nlohmann::json base = baseOf("serial", 3000, {"sphere", "still_life"});
  const SweepUnit u = spanSweepUnit(base);
  const nlohmann::json r = u.evaluate(0, {});
  for (const std::string scene : {"sphere", "still_life"}) {
    SCOPED_TRACE(scene);
    const Scene sc = loadScene(std::string(SHD_SOURCE_DIR) + "/vectors/scenes/" + scene + ".json");
    ModelSpanEngine engine(spanConfig("serial").rtl);
    RenderOptions ro;
    ro.method = Method::Gouraud;
    const RenderResult res = render(sc, ro, engine, SpecEngines{});
    EXPECT_EQ(r.at("cycles_" + scene).get<uint64_t>(), res.stats.span_cycles);
    EXPECT_EQ(r.at("fragments_" + scene).get<uint64_t>(), res.stats.fragments);
  }
  const TriangleSetCycles m = measureSpanCycles("set", triangleSet(base), RasterConfig{},
                                                {spanConfig("serial"), spanConfig("sierpinski")}, {}, 0);
  EXPECT_EQ(r.at("cycles").get<uint64_t>(), m.modes[0].cycles);
  EXPECT_EQ(r.at("fragments").get<uint64_t>(), m.modes[0].fragments);
  EXPECT_EQ(r.at("drawn").get<uint64_t>(), m.modes[0].triangles);
  const nlohmann::json s = u.evaluate(0, modeValues("sierpinski"));
  EXPECT_EQ(s.at("cycles").get<uint64_t>(), m.modes[1].cycles);
  EXPECT_EQ(s.at("fragments").get<uint64_t>(), m.modes[1].fragments);
}

// validate() refuses, before any work, a point whose widths break a derivation, naming the
// point and the rule; evaluate() refuses it too (--target-lsb evaluates narrower points).
TEST(SpanSweep, ValidateRefusesBrokenDerivationsNamingThem) {
  const SweepUnit u = spanSweepUnit(baseOf("serial", kSmallSet, {"sphere"}));
  auto refusal = [&](const std::vector<std::string>& axes) {
    std::vector<GridAxis> a;
    for (const std::string& t : axes) a.push_back(parseGridAxis(t, u.params));
    return errorOf<std::invalid_argument>([&] { u.validate(Grid(a)); });
  };
  EXPECT_EQ(refusal({"CoordBits=15:17", "ColourFracBits=4,12", "LanesPerTri=1,8"}), "");
  struct Case {
    std::vector<std::string> axes;
    std::vector<std::string> said;
  } cases[] = {
      {{"RemBits=26,24"}, {"point 1 (RemBits=24)", "RemBits >= CoordBits + 2 SubpixelBits + 1 = 25"}},
      {{"SubpixelBits=4:6"}, {"point 2 (SubpixelBits=6)", "RemBits >= CoordBits + 2 SubpixelBits + 1 = 29"}},
      {{"AttrBits=32,29"}, {"point 1 (AttrBits=29)", "2^DepthFracBits", "AttrBits >= 30"}},
      {{"ColourFracBits=24"}, {"point 0 (ColourFracBits=24)", "255 * 2^ColourFracBits", "AttrBits >= 33"}},
      {{"ColourFracBits=31"}, {"AttrBits = 32", "255 * 2^ColourFracBits", "AttrBits >= 40"}},
      {{"DepthFracBits=70"}, {"point 0 (DepthFracBits=70)", "more than AttrBits 62"}},
      {{"CoordBits=14"}, {"point 0 (CoordBits=14)", "guard band", "CoordBits >= 15"}},
      {{"NumAttr=3"}, {"point 0 (NumAttr=3)", "NumAttr >= 4"}},
      {{"PixBits=8"}, {"PixBits = 8", "viewport 512x512"}},
      {{"LanesPerTri=3"}, {"point 0 (LanesPerTri=3)", "must be 1, 2, 4 or 8"}},
  };
  for (const Case& c : cases) {
    const std::string e = refusal(c.axes);
    for (const std::string& s : c.said) EXPECT_NE(e.find(s), std::string::npos) << "\"" << e << "\" lacks \"" << s << "\"";
  }
  EXPECT_NE(errorOf<std::invalid_argument>([&] { u.evaluate(0, {{"RemBits", 24}}); }).find("RemBits >="),
            std::string::npos);
}

// The base holds what a point's evaluation depends on, and names its options; bad scenes and
// counts are refused.
TEST(SpanSweep, BaseAndItsOptions) {
  const nlohmann::json base = baseOf("evenodd", 500, {"sphere", "still_life"});
  EXPECT_EQ(base.at("unit"), "span");
  EXPECT_EQ(base.at("config"), "evenodd");
  EXPECT_EQ(base.at("viewport"), (nlohmann::json{{"width", 512}, {"height", 512}}));
  EXPECT_EQ(base.at("raster"), (nlohmann::json{{"SubpixelBits", RasterConfig{}.subpixel_bits},
                                               {"ColourFracBits", defaultAttrFracBits(512, 512, 0)},
                                               {"DepthFracBits", defaultAttrFracBits(512, 512, 16)}}));
  const SweepUnit u = spanSweepUnit(base);
  EXPECT_EQ(u.base_options, "--config evenodd --triangles 500 --seed 1 --scene sphere,still_life");
  EXPECT_EQ(u.params_member, "params");
  EXPECT_NE(errorOf<std::invalid_argument>([] { baseOf("serial", 10, {}); }), "");
  EXPECT_NE(errorOf<std::invalid_argument>([] { baseOf("serial", 10, {"sphere", "sphere"}); }).find("twice"),
            std::string::npos);
  EXPECT_NE(errorOf<std::invalid_argument>([] { baseOf("serial", 10, {"../x"}); }).find("name"), std::string::npos);
  EXPECT_NE(errorOf<std::invalid_argument>([] { baseOf("serial", 10, {"nosuchscene"}); }).find("nosuchscene"),
            std::string::npos);
  EXPECT_NE(errorOf<std::invalid_argument>([] { baseOf("serial", 0, {"sphere"}); }), "");
}
