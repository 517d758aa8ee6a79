// SpecUnitModel: the datapath against an independent straight-line integer formulation, its
// accuracy bound, the pipeline timing, and the configuration checks.
#include "config/registry.h"
#include "device/spec_unit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include <nlohmann/json.hpp>

#include "device/prom.h"

using namespace shd;

namespace {

PromTable tableFor(const std::string& name) {
  const SpecUnitConfig c = specConfig(name);
  return buildPromTable(PromRequest::fromContent(c.prom), c.rtl);
}

}  // namespace

TEST(SpecUnitConfig, CheckedInConfigurationsLoad) {
  for (const std::string& name : builtinConfigNames("spec")) {
    const SpecUnitConfig c = specConfig(name);
    EXPECT_EQ(c.name, name);
    EXPECT_NO_THROW(c.rtl.validate());
    EXPECT_NO_THROW(tableFor(name)) << name;
  }
}

TEST(SpecUnitConfig, RejectsWidthsTheUnitCannotHold) {
  SpecUnitParams p;
  p.DiffFracBits = 31;  // above 2 * CosFracBits
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = SpecUnitParams{};
  p.CosFracBits = 24;
  p.DiffFracBits = 48;
  p.CoefFracBits = 20;  // MUL2 would need 79 bits
  p.SpecFracBits = 26;
  try {
    p.validate();
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("MUL2"), std::string::npos) << e.what();
  }
  p = SpecUnitParams{};
  p.SpecFracBits = 12;  // below CosFracBits
  EXPECT_THROW(p.validate(), std::invalid_argument);
  nlohmann::json j = {{"CosFracBits", 15}, {"Bogus", 1}};
  EXPECT_THROW(SpecUnitParams::fromJson(j, "t.json"), std::invalid_argument);
  j = {{"CosFracBits", "15"}};
  EXPECT_THROW(SpecUnitParams::fromJson(j, "t.json"), std::invalid_argument);
}

TEST(SpecUnitConfig, ExpectedFiguresAreCheckedStrictly) {
  // The narrow configuration's parameters with `expected` as its "expected" member.
  const auto with = [](const std::string& expected) {
    const nlohmann::json j = {{"name", "t"},
                              {"rtl", specConfig("narrow").rtl.toJson()},
                              {"prom", {{"fit", "level"}, {"level", 0.5}, {"n", "1:1000"}}},
                              {"expected", nlohmann::json::parse(expected)}};
    return j.dump();
  };
  const auto error = [&](const std::string& expected) {
    try {
      SpecUnitConfig::parse(with(expected), "t.json");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NO_THROW(SpecUnitConfig::parse(
      with(R"({"error": {"total_max_lsb": 1.5}, "latency": 2, "xc7": {"luts": 10}})"), "t.json"));
  EXPECT_EQ(error(R"({"error": {"total_max": 1}})"),
            "t.json: expected.error.total_max: unknown figure (known: total_max_lsb, total_peak_max_lsb, "
            "datapath_max_lsb, datapath_max_f_lsb)");
  EXPECT_EQ(error(R"({"ice40": {"luts": "10"}})"), "t.json: expected.ice40.luts = \"10\" is not a number");
  EXPECT_EQ(error(R"({"latency": {"cycles": 2}})"), "t.json: expected.latency = {\"cycles\":2} is not a number");
  EXPECT_NE(error(R"({"torus": {}})").find("t.json: expected.torus: unknown group"), std::string::npos);
  EXPECT_EQ(error(R"([1])"), "t.json: \"expected\" must be an object of figure groups");
  // The span unit's groups are its own: no error figures.
  for (const BuiltinConfig& b : builtinConfigs()) {
    if (std::string(b.unit) != "span") continue;
    nlohmann::json j = nlohmann::json::parse(b.json);
    j["expected"] = {{"sphere", {{"cycles", 1}, {"fragments", 2}}}};
    EXPECT_NO_THROW(SpanUnitConfig::parse(j.dump(), "t.json"));
    j["expected"] = {{"error", nlohmann::json::object()}};
    EXPECT_THROW(SpanUnitConfig::parse(j.dump(), "t.json"), std::invalid_argument);
    break;
  }
}

TEST(SpecUnitConfig, CoefficientThatDoesNotFitIsNamed) {
  SpecUnitParams p;
  p.CoefIntBits = 9;  // inflection a reaches 786.4 at n = 1000
  try {
    buildPromTable(PromRequest{}, p);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("uQ9.14"), std::string::npos) << e.what();
  }
}

TEST(SpecPromWord, EncodeDecodeRoundTrip) {
  for (const std::string& name : builtinConfigNames("spec")) {
    const PromTable t = tableFor(name);
    // The table: a row of words per entry; piecewise: the segments' first codes (test_spec_kinds).
    if (t.unit.kind() == SpecKind::Table || t.unit.kind() == SpecKind::Piecewise) continue;
    for (const PromEntry& e : t.entries) {
      const SpecCoef d = decodePromWord(t.words[e.address], t.unit);
      ASSERT_EQ(d.u, e.code.u);
      ASSERT_EQ(d.v, e.code.v);
      ASSERT_EQ(d.cut, e.code.cut);
    }
  }
}

TEST(SpecUnitModel, FastPathEqualsFixedFormulation) {
  // evaluate() (raw integers) against trace() (Fixed values in their formats): every
  // (shininess, cos) pair of the narrow configuration, a sample of the others.
  for (const std::string& name : builtinConfigNames("spec")) {
    const PromTable t = tableFor(name);
    const SpecUnitModel m(t.unit, t.words, t.seg_words);
    const uint32_t ncos = 2u << t.unit.CosFracBits;
    const bool exhaustive = name == "narrow";
    std::mt19937 rng(7);
    const long count = exhaustive ? static_cast<long>(t.unit.shinCodes()) * ncos : 400000;
    for (long i = 0; i < count; ++i) {
      const uint32_t shin = exhaustive ? static_cast<uint32_t>(i / ncos) : rng() % t.unit.shinCodes();
      const uint32_t cos = exhaustive ? static_cast<uint32_t>(i % ncos) : rng() % ncos;
      const SpecOut o = m.evaluate(shin, cos, {0, 0, 0});
      const SpecTrace tr = m.trace(shin, cos);
      ASSERT_EQ(o.spec, static_cast<uint32_t>(tr.f.raw())) << name << " shin " << shin << " cos " << cos;
    }
  }
}

TEST(SpecUnitModel, DatapathErrorWithinDerivedBound) {
  // Against the ideal polynomial with the STORED coefficient a_q, degree 2:
  //   truncating c^2 - c to Df bits errs by < 2^-Df, times a_q; rounding the product by
  //   <= 2^-(Wf+1); the clamp only moves f toward the clamped ideal.
  for (const char* name : {"default", "narrow", "wide"}) {
    const PromTable t = tableFor(name);
    const SpecUnitModel m(t.unit, t.words, t.seg_words);
    const SpecUnitParams& p = t.unit;
    double worst = 0;
    for (const PromEntry& e : t.entries) {
      if (static_cast<int>(e.n) % 37 != 1) continue;  // a spread of n
      const double aq = std::ldexp(static_cast<double>(e.code.u), -p.CoefFracBits);
      const double bound = aq * std::ldexp(1.0, -p.DiffFracBits) + std::ldexp(1.0, -(p.SpecFracBits + 1));
      for (int64_t cos = 0; cos <= p.cosOne(); ++cos) {
        const double c = std::ldexp(static_cast<double>(cos), -p.CosFracBits);
        const double ideal = std::max(0.0, aq * c * c + (1 - aq) * c);
        const double hw = std::ldexp(static_cast<double>(m.evaluate(e.address, static_cast<uint32_t>(cos), {0, 0, 0}).spec),
                                     -p.SpecFracBits);
        ASSERT_LE(std::fabs(hw - ideal), bound * (1 + 1e-9)) << name << " n " << e.n << " cos " << cos;
        worst = std::max(worst, std::fabs(hw - ideal) / std::ldexp(1.0, -p.SpecFracBits));
      }
    }
    RecordProperty(std::string("worst_f_lsb_") + name, std::to_string(worst));
  }
}

TEST(SpecUnitModel, ExactCasesAndSaturation) {
  const PromTable t = tableFor("default");
  const SpecUnitModel m(t.unit, t.words, t.seg_words);
  const SpecUnitParams& p = t.unit;
  const uint32_t one = static_cast<uint32_t>(p.cosOne()), spec_one = 1u << p.SpecFracBits;
  for (const PromEntry& e : t.entries) {
    // f(1) = 1 and f(0) = 0 for every n; codes above 1.0 saturate to 1.0.
    ASSERT_EQ(m.evaluate(e.address, one, {255, 128, 0}).spec, spec_one);
    ASSERT_EQ(m.evaluate(e.address, one, {255, 128, 0}).rgb, (std::array<uint32_t, 3>{255, 128, 0}));
    ASSERT_EQ(m.evaluate(e.address, 2 * one - 1, {255, 128, 0}), m.evaluate(e.address, one, {255, 128, 0}));
    ASSERT_EQ(m.evaluate(e.address, 0, {255, 255, 255}).spec, 0u);
  }
  // n = 1: a = 0, f = c exactly at every cos code.
  for (uint32_t cos = 0; cos <= one; ++cos)
    ASSERT_EQ(m.evaluate(0, cos, {0, 0, 0}).spec, cos << (p.SpecFracBits - p.CosFracBits));
  EXPECT_THROW(m.evaluate(static_cast<uint32_t>(p.promDepth()), 0, {0, 0, 0}), std::out_of_range);
  EXPECT_THROW(m.evaluate(0, 2 * one, {0, 0, 0}), std::out_of_range);
  EXPECT_THROW(m.evaluate(0, 0, {256, 0, 0}), std::out_of_range);
  std::vector<PromWord> short_prom(t.words.begin(), t.words.end() - 1);
  EXPECT_THROW(SpecUnitModel(p, short_prom), std::invalid_argument);
}

TEST(SpecUnitModel, PipelineLatencyHoldAndReset) {
  for (const std::string& name : builtinConfigNames("spec")) {
    const PromTable t = tableFor(name);
    SpecUnitModel m(t.unit, t.words, t.seg_words);
    const int lat = t.unit.latency();
    SpecIn in;
    in.valid = true;
    in.shin = 3;
    in.cos = static_cast<uint32_t>(t.unit.cosOne() * 3 / 4);
    in.light = {10, 20, 30};
    const SpecOut expect = m.evaluate(in.shin, in.cos, in.light);
    SpecOut o = m.tick(in);
    for (int k = 1; k < lat; ++k) {
      EXPECT_FALSE(o.valid) << name << " cycle " << k;
      EXPECT_EQ(o.spec, 0u);
      o = m.tick(SpecIn{});
    }
    EXPECT_TRUE(o.valid);
    EXPECT_EQ(o.spec, expect.spec);
    // Outputs hold the last valid result while valid_o is low.
    o = m.tick(SpecIn{});
    EXPECT_FALSE(o.valid);
    EXPECT_EQ(o.spec, expect.spec);
    EXPECT_EQ(o.rgb, expect.rgb);
    m.reset();
    EXPECT_EQ(m.tick(SpecIn{}), SpecOut{});
  }
}
