// The stiff and extreme cases (docs/stiff-cases.md): each test drives one edge of the input
// space, checks the behaviour chosen there (exact values where it is defined, otherwise an error
// bound derived in the test), prints the worst error it observed (also as a test property), and,
// where the hardware sees the case, runs the same inputs through the verilated RTL and compares
// it with the model on every cycle.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "config/registry.h"
#include "cosim/render_rtl.h"
#include "cosim/span_cosim.h"
#include "cosim/spec_cosim.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "device/spec_unit.h"
#include "io/files.h"
#include "raster/setup.h"
#include "raster/span_unit.h"
#include "render/fixed_shading.h"
#include "render/draw.h"
#include "render/normalize.h"
#include "render/pipeline.h"
#include "render/render.h"
#include "render/shading.h"
#include "scene/scene.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::spanModes;
using shd::testutil::spanParams;
namespace fs = std::filesystem;

namespace {

using i128 = __int128;

// A measured figure: printed, and kept as a test property (the XML report).
void record(const std::string& key, double value, const std::string& unit) {
  std::printf("  %s = %.6g %s\n", key.c_str(), value, unit.c_str());
  testing::Test::RecordProperty(key, fmt::format("{:.6g} {}", value, unit));
}

// ============================================================================ specular unit

PromTable registryTable(const std::string& config) {
  const SpecUnitConfig c = specConfig(config);
  return buildPromTable(PromRequest::fromContent(c.prom), c.rtl);
}

// The configuration's unit and fit with another shininess list.
PromTable tableWithN(const std::string& config, const std::string& n_list) {
  const SpecUnitConfig c = specConfig(config);
  PromContent content = c.prom;
  content.n = n_list;
  content.is_list = true;
  return buildPromTable(PromRequest::fromContent(content), c.rtl);
}

// The registry's units of the paper's kind (poly): the bounds below are its datapath's. The
// other kinds are checked at every input against their own functions in test_spec_kinds and
// against the RTL in test_spec_cosim.
const std::vector<std::string>& specConfigs() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> v;
    for (const std::string& n : builtinConfigNames("spec"))
      if (specConfig(n).rtl.kind() == SpecKind::Poly) v.push_back(n);
    return v;
  }();
  return names;
}

// The polynomial of the STORED coefficients at cos code k, clamped to [0, 1] (and 0 below the
// degree 3 cut), exactly: the ideal device the datapath approximates. Degree 2:
// p = c + a (c^2 - c); degree 3: p = c + (c^2 - c)(u c + v); c = k 2^-Wc, a, u, v = code 2^-Cf.
// The numerator fits 128 bits (at most 2^74 for the registry's widths), and once clamped to
// [0, 1] its value (denominator at most 2^57) is exact in long double (64-bit mantissa).
struct IdealPoint {
  i128 num = 0;  // p * 2^den_bits, unclamped
  int den_bits = 0;
  bool cut = false;
  long double clamped() const {
    if (cut || num <= 0) return 0;
    if (num >= (i128{1} << den_bits)) return 1;
    return std::ldexp(static_cast<long double>(num), -den_bits);
  }
  // p < 2^-bits, exactly
  bool below(int bits) const { return num < 0 || (num << bits) < (i128{1} << den_bits); }
};

IdealPoint idealAt(const SpecUnitParams& p, const SpecCoef& k, int64_t code) {
  const int wc = p.CosFracBits, cf = p.CoefFracBits;
  const i128 c = std::min<int64_t>(code, p.cosOne());
  const i128 d = c * c - (c << wc);  // (c^2 - c) 2^(2 Wc)
  IdealPoint r;
  if (p.Degree == 2) {
    r.den_bits = 2 * wc + cf;
    r.num = (c << (wc + cf)) + k.u * d;
  } else {
    r.den_bits = 3 * wc + cf;
    r.num = (c << (2 * wc + cf)) + d * (k.u * c + static_cast<i128>(k.v) * (i128{1} << wc));
    r.cut = c < k.cut;
  }
  return r;
}

// The datapath's derived bound on |f - clamp(p_q)| (rtl/shd_spec_unit.v, "Rounding"): degree 2,
// truncating c^2 - c to Df bits errs by less than 2^-Df, times a_q, and the product's rounding
// by at most 2^-(Wf+1); the clamp is 1-Lipschitz. Degree 3 adds the truncation of g = u c + v
// to Hf bits: |d g - dt gt| <= 2^-Df |gt| + |d| 2^-Hf, |d| <= 1/4, |gt| <= max(|v|, |u + v|) + 2^-Hf.
long double datapathBound(const SpecUnitParams& p, const SpecCoef& k) {
  const long double half_lsb = std::ldexp(1.0L, -(p.SpecFracBits + 1));
  if (p.Degree == 2) return std::ldexp(static_cast<long double>(k.u), -(p.CoefFracBits + p.DiffFracBits)) + half_lsb;
  const long double g = std::ldexp(static_cast<long double>(std::max(std::llabs(k.v), std::llabs(k.u + k.v))), -p.CoefFracBits);
  return std::ldexp(g + std::ldexp(1.0L, -p.HornerFracBits), -p.DiffFracBits) + std::ldexp(1.0L, -(p.HornerFracBits + 2)) +
         half_lsb;
}

long double specValue(const SpecUnitParams& p, uint32_t code) { return std::ldexp(static_cast<long double>(code), -p.SpecFracBits); }
long double cosValue(const SpecUnitParams& p, int64_t code) {
  return std::ldexp(static_cast<long double>(std::min<int64_t>(code, p.cosOne())), -p.CosFracBits);
}

// A fixed list of inputs for the co-simulation; every seventh cycle has valid_i low (a gap).
class ListStimulus final : public SpecStimulus {
 public:
  explicit ListStimulus(std::vector<SpecIn> v) : v_(std::move(v)) {}
  bool next(SpecIn& in) override {
    if (i_ >= v_.size()) return false;
    if (++cycle_ % 7 == 0) {
      in = SpecIn{};
      return true;
    }
    in = v_[i_++];
    return true;
  }
  uint64_t total() const override { return v_.size(); }

 private:
  std::vector<SpecIn> v_;
  size_t i_ = 0;
  uint64_t cycle_ = 0;
};

// Light codes that exercise MUL3..MUL5: full scale, a middle value, one LSB.
std::array<uint32_t, 3> lightsFor(const SpecUnitParams& p, size_t i) {
  const uint32_t max = static_cast<uint32_t>(p.lightMax());
  switch (i % 3) {
    case 0: return {max, max / 2 + 1, 1};
    case 1: return {1, max, max / 2 + 1};
    default: return {max / 2 + 1, 1, max};
  }
}

// The inputs (address, cos code) with rotating light codes.
std::vector<SpecIn> specInputs(const SpecUnitParams& p, const std::vector<std::pair<uint32_t, uint32_t>>& points) {
  std::vector<SpecIn> v;
  for (size_t i = 0; i < points.size(); ++i) {
    SpecIn in;
    in.valid = true;
    in.shin = points[i].first;
    in.cos = points[i].second;
    in.light = lightsFor(p, i);
    v.push_back(in);
  }
  return v;
}

// The inputs through the verilated configuration `config` loaded with `t`'s PROM, against the
// model, every output on every cycle.
void expectRtlEqualsModel(const std::string& config, const PromTable& t, const std::vector<SpecIn>& inputs,
                          const fs::path& dir, const std::string& label) {
  const std::string prom = (dir / fmt::format("{}_{}.hex", config, label)).string();
  writePromHexFiles(prom, t);
  SpecUnitModel model(t.unit, t.words, t.seg_words);
  ListStimulus stim(inputs);
  SpecCosimOptions o;
  o.prom_path = prom;
  o.fail_dir = dir.string();
  const SpecCosimResult r = runSpecCosim(config, model, stim, o);
  EXPECT_EQ(r.vectors, inputs.size()) << config << " " << label;
  EXPECT_EQ(r.mismatches, 0u) << config << " " << label << ": " << (r.first ? r.first->describe(t.unit) : "")
                              << "\nwaveform: " << r.fst_path << "\nvectors: " << r.vector_path;
  std::printf("  rtl %s (%s): %llu vectors, %llu cycles, %llu mismatches\n", config.c_str(), label.c_str(),
              static_cast<unsigned long long>(r.vectors), static_cast<unsigned long long>(r.cycles),
              static_cast<unsigned long long>(r.mismatches));
}

uint32_t roundHalfUpProduct(uint32_t f, uint32_t light, int wf) {
  return static_cast<uint32_t>((static_cast<uint64_t>(f) * light + (uint64_t{1} << (wf - 1))) >> wf);
}

// ============================================================================ span unit

SetupVertex vtx(double x, double y, std::initializer_list<double> a) {
  SetupVertex v;
  v.x = x;
  v.y = y;
  v.attr = a;
  return v;
}

using Tri = std::array<SetupVertex, 3>;

RasterConfig rasterConfig(const std::string& mode, int w, int h) {
  RasterConfig c;
  c.width = w;
  c.height = h;
  c.unit = spanParams(mode);
  c.validate();
  return c;
}

// |attr - exact plane| at pixel (px, py) of attribute k, as a fraction of the derived bound
// 0.5 (1 + |px - xref| + |py - yref|) codes (raster/setup.h), exactly: the plane of the snapped
// codes is I = (2 det a0 + nx (cx - U0) + ny (cy - V0)) / (2 det) in u units (setup.cpp), and
// |2 det attr - num| <= det (1 + |px - xref| + |py - yref|) is compared in 128-bit integers.
struct PlaneError {
  long double codes = 0;  // |attr - exact|
  bool within = true;
};
PlaneError planeError(const SetupResult& s, const RasterConfig& cfg, int k, int64_t px, int64_t py, int64_t attr) {
  const SnappedTriangle& t = s.tri;
  const int S = cfg.subpixel_bits;
  const auto& a = t.a[static_cast<size_t>(k)];
  const i128 nx = static_cast<i128>(a[1] - a[0]) * (t.Y[2] - t.Y[0]) - static_cast<i128>(a[2] - a[0]) * (t.Y[1] - t.Y[0]);
  const i128 ny = static_cast<i128>(t.X[1] - t.X[0]) * (a[2] - a[0]) - static_cast<i128>(t.X[2] - t.X[0]) * (a[1] - a[0]);
  const i128 cx = (2 * static_cast<i128>(px) + 1) << S, cy = (2 * static_cast<i128>(py) + 1) << S;
  const i128 det = t.det;
  const i128 num = 2 * det * a[0] + nx * (cx - 2 * static_cast<i128>(t.X[0])) + ny * (cy - 2 * static_cast<i128>(t.Y[0]));
  i128 diff = 2 * det * attr - num;
  if (diff < 0) diff = -diff;
  const i128 allowed = det * (1 + std::llabs(px - s.plane.xref) + std::llabs(py - s.plane.yref));
  PlaneError e;
  e.codes = static_cast<long double>(diff) / static_cast<long double>(2 * det);
  e.within = diff <= allowed;
  return e;
}

std::vector<SpanFragment> sortedFragments(std::vector<SpanFragment> f) {
  std::sort(f.begin(), f.end(), [](const SpanFragment& a, const SpanFragment& b) {
    return a.y != b.y ? a.y < b.y : a.x < b.x;
  });
  return f;
}

// What a triangle gave in every mode.
struct ModesResult {
  bool drawn = false;
  std::string dropped;
  size_t fragments = 0;   // per mode (all equal)
  long double worst_codes = 0;  // worst |attr - exact plane| over the attributes, in codes
  long double worst_lsb = 0;    // the same in output LSBs (codes 2^-F, colour attributes 0..2)
  std::vector<SpanDesc> descs;  // per mode (for the RTL), empty if dropped
};

// The triangle through setup and the cycle model of every lane mode: each mode's fragments
// (sorted) equal the direct edge-function rasterisation with the plane's exact integer value
// at every pixel, and each value lies within the derived bound of the exact plane.
ModesResult checkAllModes(const Tri& v, int w, int h, const std::string& what, int subpixel_bits = 4) {
  ModesResult res;
  bool first = true;
  for (const std::string& mode : spanModes()) {
    RasterConfig cfg = rasterConfig(mode, w, h);
    cfg.subpixel_bits = subpixel_bits;
    const SetupResult s = setupTriangle(v, 1, cfg);
    if (first) {
      res.drawn = s.desc.has_value();
      res.dropped = s.dropped;
    }
    EXPECT_EQ(s.desc.has_value(), res.drawn) << what << " " << mode;
    if (!s.desc) {
      res.descs.emplace_back();
      first = false;
      continue;
    }
    res.descs.push_back(*s.desc);
    SpanUnitModel unit(cfg.unit);
    const std::vector<SpanFragment> got = sortedFragments(runSpanUnit(unit, *s.desc).fragments);
    const std::vector<SpanFragment> ref = rasterizeReference(s, cfg);
    EXPECT_EQ(got.size(), ref.size()) << what << " " << mode;
    if (first) res.fragments = got.size();
    for (size_t i = 0; i < std::min(got.size(), ref.size()); ++i) {
      if (!(got[i].x == ref[i].x && got[i].y == ref[i].y && got[i].attr == ref[i].attr)) {
        ADD_FAILURE() << what << " " << mode << ": fragment " << i << " (" << got[i].x << ", " << got[i].y
                      << ") differs from the direct rasterisation's (" << ref[i].x << ", " << ref[i].y << ")";
        break;
      }
    }
    for (const SpanFragment& f : got)
      for (int k = 0; k < cfg.unit.NumAttr; ++k) {
        const PlaneError e = planeError(s, cfg, k, f.x, f.y, f.attr[static_cast<size_t>(k)]);
        if (!e.within) {
          ADD_FAILURE() << what << " " << mode << ": attribute " << k << " at (" << f.x << ", " << f.y << ") is "
                        << static_cast<double>(e.codes) << " codes from the exact plane, beyond the derived bound";
          return res;
        }
        res.worst_codes = std::max(res.worst_codes, e.codes);
        if (k < 3) res.worst_lsb = std::max(res.worst_lsb, std::ldexp(e.codes, -cfg.attrFracBits(k)));
      }
    first = false;
  }
  return res;
}

// The descriptors through the verilated unit of every mode against the model, cycle by cycle,
// with random back-pressure and descriptor gaps.
void expectSpanRtlEqualsModel(const std::vector<ModesResult>& cases, const std::string& label) {
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  const std::vector<std::string> modes = spanModes();
  for (size_t mi = 0; mi < modes.size(); ++mi) {
    std::vector<SpanDesc> descs;
    for (const ModesResult& c : cases)
      if (c.drawn) descs.push_back(c.descs[mi]);
    if (descs.empty()) continue;
    size_t next = 0;
    SpanCosimOptions o;
    o.seed = 11;
    o.fail_dir = (dir / modes[mi]).string();
    fs::create_directories(o.fail_dir);
    const SpanCosimResult r = runSpanCosim(
        modes[mi],
        [&](SpanDesc& d) {
          if (next >= descs.size()) return false;
          d = descs[next];
          d.tag = static_cast<uint32_t>(next++);
          return true;
        },
        o);
    EXPECT_EQ(r.triangles, descs.size()) << label << " " << modes[mi];
    EXPECT_EQ(r.mismatches, 0u) << label << " " << modes[mi] << ": " << (r.first ? r.first->what : "")
                                << "\nwaveform " << r.fst_path << "\ncase " << r.case_path;
    std::printf("  rtl span %s (%s): %llu triangles, %llu fragments, %llu cycles, %llu mismatches\n", modes[mi].c_str(),
                label.c_str(), static_cast<unsigned long long>(r.triangles), static_cast<unsigned long long>(r.fragments),
                static_cast<unsigned long long>(r.cycles), static_cast<unsigned long long>(r.mismatches));
  }
}

// ============================================================================ rendering

// A scene of one triangle in the plane z = 0, given by its screen positions: the camera at
// (0, 0, -3) looks at the origin with 48 px per unit, so screen x = 256 + 16 X, y = 256 - 16 Y
// (exact for coordinates with few fraction bits). One white directional light toward the upper
// left front (camera space (-1, 1, -1)/sqrt 3, the default scene's), ambient 0.2.
Scene triangleScene(const std::array<std::array<double, 2>, 3>& xy, const std::array<Vec3, 3>& n, Material m = {}) {
  Scene s;
  s.name = "stiff";
  s.camera.px_per_unit = 48;
  Light l;
  l.direction = normalize(Vec3{-1, 1, -1});
  s.lights.push_back(l);
  s.ambient = {0.2, 0.2, 0.2};
  s.materials.push_back(m);
  SceneObject o;
  o.name = "triangle";
  for (size_t i = 0; i < 3; ++i) {
    o.mesh.positions.push_back({(xy[i][0] - 256) / 16, -(xy[i][1] - 256) / 16, 0});
    o.mesh.normals.push_back(n[i]);
  }
  o.mesh.triangles.push_back({0, 1, 2});
  s.objects.push_back(o);
  return s;
}

struct Engines {
  ModelSpanEngine span{spanParams("serial")};
  std::unique_ptr<ModelSpecEngine> quad = std::make_unique<ModelSpecEngine>(registryTable("default"));
  SpecEngines view() { return SpecEngines{quad.get(), nullptr}; }
};

RenderResult renderWith(const Scene& s, Method m, const std::string& brdf) {
  Engines e;
  RenderOptions o;
  o.method = m;
  o.brdf = brdf;
  return render(s, o, e.span, e.view());
}

std::array<uint8_t, 3> pixel(const Framebuffer& fb, int x, int y) {
  const size_t p = static_cast<size_t>(y) * static_cast<size_t>(fb.width) + static_cast<size_t>(x);
  return {fb.rgb[p * 3], fb.rgb[p * 3 + 1], fb.rgb[p * 3 + 2]};
}

// The ambient colour alone: round(255 ambient base), as combine() rounds.
std::array<uint8_t, 3> ambientColour(const Scene& s) {
  const Material& m = s.materials[0];
  const std::array<double, 3> base{m.colour.x, m.colour.y, m.colour.z}, amb{s.ambient.x, s.ambient.y, s.ambient.z};
  std::array<double, 3> lsb{};
  for (size_t k = 0; k < 3; ++k) lsb[k] = 255.0 * amb[k] * base[k];
  return combine(lsb, nullptr, 0);
}

}  // namespace

// ============================================================================ specular unit

TEST(Stiff, SpecShininessOneIsExactlyTheCosine) {
  // n = 1: every fit stores a = 0 (degree 3: u = v = 0, no cut), so f = c exactly at every cos
  // code, in every configuration; codes above 1.0 saturate to 1.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    ASSERT_EQ(t.entries.at(0).n, 1.0) << name;
    const SpecUnitModel m(p, t.words, t.seg_words);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    for (uint32_t k = 0; k < (2u << p.CosFracBits); ++k) {
      const std::array<uint32_t, 3> light = lightsFor(p, k);
      const SpecOut o = m.evaluate(0, k, light);
      const uint32_t expect = static_cast<uint32_t>(std::min<int64_t>(k, p.cosOne())) << (p.SpecFracBits - p.CosFracBits);
      ASSERT_EQ(o.spec, expect) << name << " cos " << k;
      for (size_t ch = 0; ch < 3; ++ch) ASSERT_EQ(o.rgb[ch], roundHalfUpProduct(expect, light[ch], p.SpecFracBits));
      if (k <= p.cosOne()) points.push_back({0, k});  // above 1: SpecCosAboveOneSaturates
    }
    record(fmt::format("n1_error_{}", name), 0, "f LSB (exact)");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "n1");
  }
}

TEST(Stiff, SpecShininessNearOne) {
  // n -> 1: f tends to c continuously. With |c^n - c| = c (1 - c^(n-1)) <= c (n - 1) ln(1/c)
  // <= (n - 1)/e and |p_q(c) - c| = |c^2 - c| |g_q(c)| <= max|g_q| / 4 (g = a for degree 2,
  // u c + v for degree 3), |f - c^n| <= datapath bound + max|g_q|/4 + (n - 1)/e at every code.
  // Each configuration's own fit, with a PROM of shininess values just above 1.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  const std::vector<double> ns = {1, 1.0001, 1.001, 1.01, 1.1, 1.5};
  for (const std::string& name : specConfigs()) {
    const PromTable t = tableWithN(name, "1,1.0001,1.001,1.01,1.1,1.5");
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    long double worst_1e4 = 0, worst_all = 0;
    for (const PromEntry& e : t.entries) {
      ASSERT_EQ(e.code.cut, 0) << name << " n " << e.n << ": no cut-off so close to n = 1";
      const long double g = std::ldexp(static_cast<long double>(std::max(std::llabs(e.code.u), std::llabs(e.code.u + e.code.v))),
                                       -p.CoefFracBits);
      const long double bound = datapathBound(p, e.code) + g / 4 + (e.n - 1) / std::exp(1.0L);
      for (int64_t k = 0; k <= p.cosOne(); ++k) {
        const long double c = cosValue(p, k);
        const long double f = specValue(p, m.evaluate(e.address, static_cast<uint32_t>(k), {0, 0, 0}).spec);
        const long double err = std::fabs(f - std::pow(static_cast<double>(c), e.n));  // double: the bound has room
        ASSERT_LE(err, bound) << name << " n " << e.n << " cos " << k;
        if (e.n <= 1.0001) worst_1e4 = std::max(worst_1e4, err);
        worst_all = std::max(worst_all, err);
        if (k % 7 == 0 || k == p.cosOne()) points.push_back({e.address, static_cast<uint32_t>(k)});
      }
    }
    record(fmt::format("n1.0001_vs_cos_n_{}", name), static_cast<double>(worst_1e4 * 255), "output LSB");
    record(fmt::format("n1..1.5_vs_cos_n_{}", name), static_cast<double>(worst_all * 255), "output LSB");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "near1");
  }
}

TEST(Stiff, SpecCosZeroGivesNoLight) {
  // c = 0: c^2 - c = 0, so f = 0 and every colour output 0, exactly, at every address (unused
  // ones hold the zero word) in every configuration.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    for (uint32_t a = 0; a < static_cast<uint32_t>(p.promDepth()); ++a) {
      const SpecOut o = m.evaluate(a, 0, lightsFor(p, a));
      ASSERT_EQ(o.spec, 0u) << name << " address " << a;
      ASSERT_EQ(o.rgb, (std::array<uint32_t, 3>{0, 0, 0})) << name << " address " << a;
      points.push_back({a, 0});
    }
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "cos0");
  }
}

TEST(Stiff, SpecCosOneLsbAboveZero) {
  // c = 2^-Wc: p_q(c) = c (1 - a_q (1 - c)) is negative for a_q > 1/(1 - c): the clamp gives
  // exactly 0. In general f = 0 exactly wherever p_q < half an f LSB (the device sum is at most
  // p_q + 2^-(Wf+1): the truncation only lowers a_q (c^2 - c)), and |f - clamp(p_q)| is within
  // the datapath bound. n = 1 (address 0): f = c exactly.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    long double worst_dp = 0, worst_total = 0;
    int zeros = 0;
    for (const PromEntry& e : t.entries) {
      const IdealPoint ideal = idealAt(p, e.code, 1);
      const uint32_t f = m.evaluate(e.address, 1, {0, 0, 0}).spec;
      if (ideal.cut || ideal.below(p.SpecFracBits + 1)) {
        ASSERT_EQ(f, 0u) << name << " n " << e.n;
        ++zeros;
      }
      const long double err = std::fabs(specValue(p, f) - ideal.clamped());
      ASSERT_LE(err, datapathBound(p, e.code)) << name << " n " << e.n;
      worst_dp = std::max(worst_dp, err);
      worst_total = std::max(worst_total, std::fabs(specValue(p, f) - std::pow(cosValue(p, 1), static_cast<long double>(e.n))));
      points.push_back({e.address, 1});
    }
    ASSERT_EQ(m.evaluate(0, 1, {0, 0, 0}).spec, 1u << (p.SpecFracBits - p.CosFracBits)) << name << ": n = 1 gives c";
    std::printf("  %s: f = 0 at %d of %zu shininess codes\n", name.c_str(), zeros, t.entries.size());
    record(fmt::format("lsb_above_0_datapath_{}", name), static_cast<double>(worst_dp * 255), "output LSB");
    record(fmt::format("lsb_above_0_vs_cos_n_{}", name), static_cast<double>(worst_total * 255), "output LSB");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "lsb_above_0");
  }
}

TEST(Stiff, SpecCosOneLsbBelowOne) {
  // c = 1 - 2^-Wc, where c^2 - c = -2^-Wc (1 - 2^-Wc) is smallest in magnitude before the peak
  // and a_q (c^2 - c) is all that keeps f below 1 (a_q up to 786 at n = 1000): f within the
  // datapath bound of clamp(p_q) at every address; the error against cos^n is the fit's.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    const uint32_t k = static_cast<uint32_t>(p.cosOne() - 1);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    long double worst_dp = 0, worst_total = 0, total_max_n = 0;
    for (const PromEntry& e : t.entries) {
      const IdealPoint ideal = idealAt(p, e.code, k);
      const uint32_t f = m.evaluate(e.address, k, {0, 0, 0}).spec;
      const long double err = std::fabs(specValue(p, f) - ideal.clamped());
      ASSERT_LE(err, datapathBound(p, e.code)) << name << " n " << e.n;
      worst_dp = std::max(worst_dp, err);
      const long double total = std::fabs(specValue(p, f) - std::pow(cosValue(p, k), static_cast<long double>(e.n)));
      worst_total = std::max(worst_total, total);
      if (&e == &t.entries.back()) total_max_n = total;
      points.push_back({e.address, k});
    }
    record(fmt::format("lsb_below_1_datapath_{}", name), static_cast<double>(worst_dp * 255), "output LSB");
    record(fmt::format("lsb_below_1_vs_cos_n_{}", name), static_cast<double>(worst_total * 255), "output LSB");
    record(fmt::format("lsb_below_1_vs_cos_n_at_n{}_{}", t.entries.back().n, name), static_cast<double>(total_max_n * 255),
           "output LSB");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "lsb_below_1");
  }
}

TEST(Stiff, SpecCosOneGivesFullLight) {
  // c = 1: c^2 - c = 0, f = 1 exactly and each colour output equals its light code, at every
  // address (unused ones too) and for the light codes 0, 1, a middle one and full scale.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    const uint32_t one = static_cast<uint32_t>(p.cosOne()), max = static_cast<uint32_t>(p.lightMax());
    std::vector<SpecIn> inputs;
    for (uint32_t a = 0; a < static_cast<uint32_t>(p.promDepth()); ++a) {
      const std::array<uint32_t, 3> light = a % 2 ? std::array<uint32_t, 3>{0, 1, max}
                                                  : std::array<uint32_t, 3>{max, max / 2 + 1, 0};
      const SpecOut o = m.evaluate(a, one, light);
      ASSERT_EQ(o.spec, 1u << p.SpecFracBits) << name << " address " << a;
      ASSERT_EQ(o.rgb, light) << name << " address " << a;
      inputs.push_back(SpecIn{true, a, one, light});
    }
    expectRtlEqualsModel(name, t, inputs, dir, "cos1");
  }
}

TEST(Stiff, SpecCosAboveOneSaturates) {
  // Codes above 1.0 (an N.H computed upstream may overshoot) saturate to 1.0 at the input
  // register: the output equals that of c = 1 (f = 1, colour = light) at every address.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    const uint32_t one = static_cast<uint32_t>(p.cosOne());
    std::vector<std::pair<uint32_t, uint32_t>> points;
    for (uint32_t a = 0; a < static_cast<uint32_t>(p.promDepth()); ++a)
      for (uint32_t k : {one + 1, one + one / 2, 2 * one - 1}) {
        const std::array<uint32_t, 3> light = lightsFor(p, a);
        ASSERT_EQ(m.evaluate(a, k, light), m.evaluate(a, one, light)) << name << " address " << a << " cos " << k;
        points.push_back({a, k});
      }
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "above_1");
  }
}

TEST(Stiff, SpecCosOutsideTheUnitIntervalIsClampedBeforeTheUnit) {
  // The unit's port is unsigned uQ1.Wc: c < 0 cannot reach it. The renderer clamps N.H to
  // [0, 1] when it codes a request: a normal that faces the light but not the viewer
  // (N.L > 0 > N.H, as interpolated normals do near a silhouette) asks for cos 0 (f = 0); an
  // unnormalised normal longer than 1 (phong-incremental's approximate 1/|N|) asks for 1.0.
  ShadeContext ctx;
  CameraLight l;
  l.dir = Vec3{1, 0, 0};
  l.half = normalize(l.dir + ctx.view);
  ctx.lights.push_back(l);
  Material mat;
  mat.brdf = "quadratic";
  DeviceCoding coding;
  coding.cos_frac_bits = 15;
  coding.shin = 31;
  const PointShader shader(ctx, mat, Lobe::Quadratic, &coding);
  std::vector<SpecRequest> req;
  const Vec3 away{0.6, 0, 0.8};  // N.L = 0.6, N.H = -0.14
  ASSERT_GT(dot(away, l.dir), 0);
  ASSERT_LT(dot(away, l.half), 0);
  shader.shade(away, Vec3{0, 0, 1}, &req);
  ASSERT_EQ(req.size(), 1u);
  EXPECT_EQ(req[0].cos, 0u);
  req.clear();
  shader.shade(1.01 * l.half, Vec3{0, 0, 1}, &req);  // |N| = 1.01 along H: N.H = 1.01
  ASSERT_EQ(req.size(), 1u);
  EXPECT_EQ(req[0].cos, 1u << 15);
  // phong-fixed codes its Q2.32 cosines the same way.
  EXPECT_EQ(fixed_detail::cosCode(-(int64_t{1} << 30), 15), 0u);
  EXPECT_EQ(fixed_detail::cosCode(-1, 15), 0u);
  EXPECT_EQ(fixed_detail::cosCode((int64_t{1} << 32) + (int64_t{1} << 20), 15), 1u << 15);
  EXPECT_EQ(fixed_detail::cosCode(int64_t{3} << 31, 15), 1u << 15);
  // And the unit answers those codes with f = 0 and f = 1 (SpecCosZeroGivesNoLight,
  // SpecCosOneGivesFullLight).
}

TEST(Stiff, SpecNarrowCancellationAtThousand) {
  // c^2 - c near c = 1 is the small difference of two numbers near 1; the narrow configuration
  // keeps Df = 16 of its 2 Wc = 20 exact fraction bits, and a_q = 721 at n = 1000 multiplies the
  // truncation (< 2^-16) into up to 721 2^-16 = 0.011 of f. Every cos code at n = 1000: within
  // the datapath bound a_q 2^-Df + 2^-(Wf+1) of clamp(p_q). The other degree-2 configurations
  // at n = 1000 for comparison.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string name : {"narrow", "default", "wide"}) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    const int a1000 = t.addressOf(1000);
    ASSERT_GE(a1000, 0) << name;
    const PromEntry& e = t.entries[static_cast<size_t>(a1000)];
    const long double bound = datapathBound(p, e.code);
    long double worst_dp = 0, worst_dp_c = 0, worst_total = 0, worst_coef = 0;
    const long double aq = std::ldexp(static_cast<long double>(e.code.u), -p.CoefFracBits);
    std::vector<std::pair<uint32_t, uint32_t>> points;
    for (int64_t k = 0; k < 2 * p.cosOne(); ++k) {
      points.push_back({static_cast<uint32_t>(a1000), static_cast<uint32_t>(k)});
      if (k > p.cosOne()) continue;
      const long double c = cosValue(p, k);
      const long double f = specValue(p, m.evaluate(static_cast<uint32_t>(a1000), static_cast<uint32_t>(k), {0, 0, 0}).spec);
      const long double err = std::fabs(f - idealAt(p, e.code, k).clamped());
      ASSERT_LE(err, bound) << name << " cos " << k;
      if (err > worst_dp) worst_dp = err, worst_dp_c = c;
      // The coefficient's own rounding: |p_q - p_a| = |a_q - a| |c^2 - c|.
      worst_coef = std::max(worst_coef, std::fabs(aq - static_cast<long double>(e.u_real)) * (c - c * c));
      worst_total = std::max(worst_total, std::fabs(f - std::pow(static_cast<double>(c), 1000.0)));
    }
    std::printf("  %s n = 1000: a = %.6f stored as %.6Lf; bound %.4Lg\n", name.c_str(), e.u_real, aq, bound);
    record(fmt::format("n1000_datapath_{}", name), static_cast<double>(worst_dp * 255), "output LSB");
    record(fmt::format("n1000_datapath_at_c_{}", name), static_cast<double>(worst_dp_c), "");
    record(fmt::format("n1000_datapath_bound_{}", name), static_cast<double>(bound * 255), "output LSB");
    record(fmt::format("n1000_coefficient_rounding_{}", name), static_cast<double>(worst_coef * 255), "output LSB");
    record(fmt::format("n1000_vs_cos_n_{}", name), static_cast<double>(worst_total * 255), "output LSB");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "n1000");
  }
}

TEST(Stiff, SpecClampBoundaries) {
  // The lower clamp (degree 2, a_q > 1: p_q < 0 on (0, 1 - 1/a_q)): f = 0 exactly wherever
  // p_q < 2^-(Wf+1), f > 0 wherever p_q exceeds the datapath bound, and f <= c always (a_q >= 0
  // and c^2 - c <= 0: the product rounds to at most 0). Degree 3: f = 0 exactly below the cut
  // code, f = 1 exactly wherever p_q exceeds 1 + the bound, f in [0, 1]. Checked on the whole
  // cos range of a spread of shininess codes and around each boundary of every code, then those
  // boundary inputs through the RTL.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  for (const std::string& name : specConfigs()) {
    const PromTable t = registryTable(name);
    const SpecUnitParams& p = t.unit;
    const SpecUnitModel m(p, t.words, t.seg_words);
    const int64_t one = p.cosOne();
    std::vector<std::pair<uint32_t, uint32_t>> points;
    long double worst_dp = 0;
    int64_t lower_clamped = 0, upper_clamped = 0, cut_zero = 0;
    auto check = [&](const PromEntry& e, int64_t k) {
      const IdealPoint ideal = idealAt(p, e.code, k);
      const uint32_t fc = m.evaluate(e.address, static_cast<uint32_t>(k), {0, 0, 0}).spec;
      const long double bound = datapathBound(p, e.code);
      if (ideal.cut) {
        EXPECT_EQ(fc, 0u) << name << " n " << e.n << " cos " << k << ": below the cut";
        ++cut_zero;
      } else {
        const long double pv = std::ldexp(static_cast<long double>(ideal.num), -ideal.den_bits);
        if (p.Degree == 2 && ideal.below(p.SpecFracBits + 1)) {
          EXPECT_EQ(fc, 0u) << name << " n " << e.n << " cos " << k << ": p_q below half an LSB";
        }
        if (pv < -bound) {
          EXPECT_EQ(fc, 0u) << name << " n " << e.n << " cos " << k;
        }
        if (pv > bound) {
          EXPECT_GT(fc, 0u) << name << " n " << e.n << " cos " << k;
        }
        if (pv > 1 + bound) {
          EXPECT_EQ(fc, 1u << p.SpecFracBits) << name << " n " << e.n << " cos " << k << ": above 1";
        }
        lower_clamped += pv < 0;
        upper_clamped += pv > 1;
      }
      if (p.Degree == 2) {
        EXPECT_LE(fc, static_cast<uint32_t>(k) << (p.SpecFracBits - p.CosFracBits)) << name << " cos " << k;
      }
      EXPECT_LE(fc, 1u << p.SpecFracBits);
      const long double err = std::fabs(specValue(p, fc) - ideal.clamped());
      EXPECT_LE(err, bound) << name << " n " << e.n << " cos " << k;
      worst_dp = std::max(worst_dp, err);
    };
    for (const PromEntry& e : t.entries) {
      const bool whole = e.address % 199 == 0 || &e == &t.entries.back();
      std::vector<int64_t> ks;
      if (whole)
        for (int64_t k = 0; k <= one; ++k) ks.push_back(k);
      // Around the boundaries: degree 2 the root c0 = 1 - 1/a_q of p_q; degree 3 the cut code
      // and every code where p_q crosses 0 or 1 (a scan of the exact p_q above the cut).
      std::vector<int64_t> edges;
      if (p.Degree == 2 && e.code.u > (int64_t{1} << p.CoefFracBits)) {
        const long double aq = std::ldexp(static_cast<long double>(e.code.u), -p.CoefFracBits);
        edges.push_back(static_cast<int64_t>(std::floor((1 - 1 / aq) * one)));
      }
      if (p.Degree == 3) {
        edges.push_back(e.code.cut);
        bool prev_neg = false, prev_hi = false;
        for (int64_t k = e.code.cut; k <= one; ++k) {
          const IdealPoint ip = idealAt(p, e.code, k);
          const bool neg = ip.num < 0, hi = ip.num > (i128{1} << ip.den_bits);
          if (k > e.code.cut && (neg != prev_neg || hi != prev_hi)) edges.push_back(k);
          prev_neg = neg;
          prev_hi = hi;
        }
      }
      for (int64_t c : edges)
        for (int64_t k = std::max<int64_t>(0, c - 3); k <= std::min(one, c + 3); ++k) {
          if (!whole) ks.push_back(k);
          points.push_back({e.address, static_cast<uint32_t>(k)});
        }
      for (int64_t k : ks) check(e, k);
    }
    std::printf("  %s: %lld codes clamped to 0 (p_q < 0), %lld cut to 0, %lld clamped to 1\n", name.c_str(),
                static_cast<long long>(lower_clamped), static_cast<long long>(cut_zero),
                static_cast<long long>(upper_clamped));
    record(fmt::format("clamp_datapath_{}", name), static_cast<double>(worst_dp * 255), "output LSB");
    expectRtlEqualsModel(name, t, specInputs(p, points), dir, "clamp");
  }
}

// ============================================================================ setup and the span walk

TEST(Stiff, ZeroAreaAndCollinearTrianglesAreDropped) {
  // det == 0 after snapping (repeated or collinear vertices): no descriptor, dropped as "zero
  // area" before any division, in every mode; the RTL never sees them. A triangle collinear
  // before snapping but not after is a real (tiny) triangle: set up like any other, and dropped
  // because no pixel centre lies inside it (setup trims rows without a pixel).
  const std::vector<std::pair<const char*, Tri>> zero = {
      {"two equal vertices", {vtx(10.3, 10.3, {1, 2, 3, 0.5}), vtx(10.3, 10.3, {4, 5, 6, 0.5}), vtx(30.7, 20.1, {7, 8, 9, 0.5})}},
      {"three equal vertices", {vtx(20.5, 20.5, {1, 2, 3, 0.5}), vtx(20.5, 20.5, {4, 5, 6, 0.5}), vtx(20.5, 20.5, {7, 8, 9, 0.5})}},
      {"collinear, horizontal", {vtx(2.5, 7.5, {1, 2, 3, 0.5}), vtx(40.25, 7.5, {4, 5, 6, 0.5}), vtx(60.5, 7.5, {7, 8, 9, 0.5})}},
      {"collinear, diagonal", {vtx(1, 2, {1, 2, 3, 0.5}), vtx(11, 32, {4, 5, 6, 0.5}), vtx(21, 62, {7, 8, 9, 0.5})}},
      {"collinear only after snapping", {vtx(0, 0, {1, 2, 3, 0.5}), vtx(10, 10, {4, 5, 6, 0.5}), vtx(20, 20.01, {7, 8, 9, 0.5})}},
      {"collinear, outside the viewport", {vtx(-100, -50, {1, 2, 3, 0.5}), vtx(-90, -40, {4, 5, 6, 0.5}), vtx(-80, -30, {7, 8, 9, 0.5})}},
  };
  for (const auto& [what, v] : zero) {
    const ModesResult r = checkAllModes(v, 64, 48, what);
    EXPECT_FALSE(r.drawn) << what;
    EXPECT_EQ(r.dropped, "zero area") << what;
  }
  // Collinear exactly (slope 1/3) but snapped off the line: (1.03125, 0.34375) rounds half to
  // even to (16.5 -> 16, 5.5 -> 6) sixteenths, det = 16*1600 - 4800*6 != 0.
  const Tri snapped = {vtx(0.5, 0.5, {0, 0, 0, 0.5}), vtx(1.53125, 0.84375, {255, 0, 0, 0.5}),
                       vtx(300.5, 100.5, {0, 255, 0, 0.5})};
  const ModesResult r = checkAllModes(snapped, 512, 512, "collinear before snapping only");
  EXPECT_FALSE(r.drawn);
  EXPECT_EQ(r.dropped, "no pixel centre inside it in the viewport");
  std::printf("  collinear before snapping only: %s\n", r.dropped.c_str());
}

TEST(Stiff, OnePixelTriangles) {
  // Triangles of about a pixel: one that covers exactly the centre of pixel (10, 10); the two
  // halves of the unit square of pixel (3, 3), whose shared diagonal runs through its centre;
  // one whose box holds a pixel-centre row and column but no centre (dropped by setup: no
  // cycle of the unit, where the unit once spent two on it); one with no pixel-centre row at
  // all (dropped). The fragments are exact pixel sets.
  struct Case {
    const char* what;
    Tri v;
    std::vector<std::pair<int, int>> pixels;  // expected, row-major
  };
  const std::vector<Case> cases = {
      {"one centre", {vtx(10.2, 10.2, {1, 2, 3, 0.5}), vtx(10.8, 10.3, {4, 5, 6, 0.5}), vtx(10.5, 10.9, {7, 8, 9, 0.5})}, {{10, 10}}},
      {"half a unit square", {vtx(3, 3, {1, 2, 3, 0.5}), vtx(4, 3, {4, 5, 6, 0.5}), vtx(3, 4, {7, 8, 9, 0.5})}, {}},
      {"the other half", {vtx(4, 3, {1, 2, 3, 0.5}), vtx(4, 4, {4, 5, 6, 0.5}), vtx(3, 4, {7, 8, 9, 0.5})}, {{3, 3}}},
      {"a row, no column", {vtx(10.6, 10.2, {1, 2, 3, 0.5}), vtx(10.9, 10.2, {4, 5, 6, 0.5}), vtx(10.75, 10.9, {7, 8, 9, 0.5})}, {}},
      {"no row", {vtx(10.2, 10.6, {1, 2, 3, 0.5}), vtx(10.8, 10.6, {4, 5, 6, 0.5}), vtx(10.5, 10.9, {7, 8, 9, 0.5})}, {}},
  };
  std::vector<ModesResult> drawn;
  for (const Case& c : cases) {
    const ModesResult r = checkAllModes(c.v, 64, 48, c.what);
    const RasterConfig cfg = rasterConfig("serial", 64, 48);
    const SetupResult s = setupTriangle(c.v, 1, cfg);
    std::vector<std::pair<int, int>> got;
    if (s.desc) {
      SpanUnitModel unit(cfg.unit);
      const SpanRun run = runSpanUnit(unit, *s.desc);
      for (const SpanFragment& f : sortedFragments(run.fragments)) got.push_back({f.x, f.y});
      std::printf("  %s: %zu fragment(s), %llu cycles (serial)\n", c.what, got.size(), static_cast<unsigned long long>(run.cycles));
      EXPECT_EQ(run.cycles, 3u) << c.what << ": accept, one ROW, one SPAN";
    } else {
      std::printf("  %s: dropped (%s)\n", c.what, s.dropped.c_str());
      EXPECT_TRUE(c.pixels.empty()) << c.what;
    }
    EXPECT_EQ(got, c.pixels) << c.what;
    if (r.drawn) drawn.push_back(r);
  }
  // The two halves of the unit square share the diagonal through the centre (3.5, 3.5): the
  // top-left rule gives it to the half for which it is a left edge (the lower right one), and
  // setup drops the other. Only the two with a pixel reach the unit.
  EXPECT_EQ(drawn.size(), 2u);
  expectSpanRtlEqualsModel(drawn, "one-pixel triangles");
}

TEST(Stiff, SliversOfAspectTenThousand) {
  // Length 1000 px, height 0.1 px (1:10^4), horizontal, vertical, diagonal, and tilted by
  // 10^-4 rad, with colours that change by a full 255 across the 0.1 px: the gradient across
  // the sliver is 2550 per pixel. Every mode draws exactly the direct rasterisation, and every
  // value lies within the derived 0.5 (1 + |dx| + |dy|) codes of the exact plane.
  auto sliver = [](double x0, double y0, double dx, double dy) {
    // long edge from (x0, y0) along (dx, dy) (unit), apex 0.1 px to its left at the middle
    const double L = 1000, h = 0.1;
    return Tri{vtx(x0, y0, {0, 255, 30, 0.25}), vtx(x0 + L * dx, y0 + L * dy, {0, 255, 200, 0.75}),
               vtx(x0 + 0.5 * L * dx - h * dy, y0 + 0.5 * L * dy + h * dx, {255, 0, 100, 0.5})};
  };
  const double t = 1e-4, d = std::sqrt(0.5);
  const std::vector<std::pair<const char*, Tri>> cases = {
      {"horizontal", sliver(10.3, 500.45, 1, 0)},
      {"vertical", sliver(500.55, 10.3, 0, 1)},
      {"diagonal", sliver(100.2, 100.15, d, d)},
      {"tilted 1e-4 rad", sliver(10.3, 500.45, std::cos(t), std::sin(t))},
  };
  std::vector<ModesResult> drawn;
  long double worst = 0;
  for (const auto& [what, v] : cases) {
    const ModesResult r = checkAllModes(v, 1024, 1024, what);
    std::printf("  %s: %zu fragments per mode, worst plane error %.4Lg codes\n", what, r.fragments, r.worst_codes);
    EXPECT_TRUE(r.drawn) << what;
    worst = std::max(worst, r.worst_lsb);
    drawn.push_back(r);
  }
  record("sliver_plane_error", static_cast<double>(worst), "output LSB (1024x1024, F = 12)");
  expectSpanRtlEqualsModel(drawn, "slivers");
}

TEST(Stiff, WidestTriangleLongestSpan) {
  // The widest viewport the default unit allows (PixBits 12: 4096 px; the guard band of
  // CoordBits 16, 8192 px, must hold twice the viewport), 4096 x 16, fully covered by a
  // triangle with vertices at the guard band: every row is one 4096-pixel span. The colour
  // runs from -100000 to +100000 (F = 14) across the triangle, about 12 units (2e5 codes) per
  // pixel, so an increment off by one code would drift 4095 codes by the end of a span. The
  // walk adds exact integer increments: every pixel is the plane's value, within the derived
  // 0.5 (1 + |dx| + |dy|) codes of the exact plane (0.5 (1 + 4095 + 15) = 2056 codes = 0.125 LSB).
  const Tri v = {vtx(-8192, -16, {-100000, 0, 100000, 0.25}), vtx(8192, -16, {100000, 100000, -100000, 0.5}),
                 vtx(0, 8192, {0, -100000, 0, 0.75})};
  const ModesResult r = checkAllModes(v, 4096, 16, "widest");
  EXPECT_EQ(r.fragments, 4096u * 16u);
  record("longest_span_plane_error", static_cast<double>(r.worst_codes), "codes (F = 14)");
  record("longest_span_plane_error_lsb", static_cast<double>(r.worst_lsb), "output LSB (4096x16)");
  expectSpanRtlEqualsModel({r}, "widest");
}

TEST(Stiff, VerticesAtTheCoordinateLimits) {
  // The guard band is |x|, |y| <= 2^(CoordBits-3) = 8192 px: vertices exactly on it are
  // accepted and every descriptor field fits its register (setup would throw otherwise); one
  // sixteenth of a pixel beyond it, NaN or infinity is an error naming the vertex.
  const double g = 8192;
  const std::vector<std::pair<const char*, Tri>> cases = {
      {"corners of the guard band", {vtx(-g, -g, {0, 0, 0, 0.1}), vtx(g, -g, {255, 0, 0, 0.9}), vtx(g, g, {0, 255, 0, 0.5})}},
      {"the opposite corners", {vtx(g, g, {0, 0, 255, 0.1}), vtx(-g, g, {255, 0, 0, 0.9}), vtx(g, -g, {0, 255, 0, 0.5})}},
      {"a thin wedge from the far left", {vtx(-g, 20, {0, 0, 0, 0.1}), vtx(g, 20.5, {255, 0, 0, 0.9}), vtx(g, 30.25, {0, 255, 0, 0.5})}},
      {"a vertex on the limit, the rest on screen", {vtx(g, 10, {0, 0, 0, 0.1}), vtx(2, 40, {255, 0, 0, 0.9}), vtx(3, 2, {0, 255, 0, 0.5})}},
  };
  std::vector<ModesResult> drawn;
  long double worst = 0;
  for (const auto& [what, v] : cases) {
    const ModesResult r = checkAllModes(v, 64, 48, what);
    EXPECT_TRUE(r.drawn) << what;
    std::printf("  %s: %zu fragments per mode\n", what, r.fragments);
    worst = std::max(worst, r.worst_lsb);
    drawn.push_back(r);
  }
  record("coordinate_limits_plane_error", static_cast<double>(worst), "output LSB (64x48)");
  expectSpanRtlEqualsModel(drawn, "coordinate limits");
  const RasterConfig cfg = rasterConfig("serial", 64, 48);
  for (const double bad : {g + 1.0 / 16, -g - 1.0 / 16, std::nan(""), std::numeric_limits<double>::infinity()}) {
    const Tri v = {vtx(0, 0, {0, 0, 0, 0.5}), vtx(10, 0, {0, 0, 0, 0.5}), vtx(0, bad, {0, 0, 0, 0.5})};
    const std::string err = shd::testutil::errorOf<std::invalid_argument>([&] { setupTriangle(v, 3, cfg); });
    EXPECT_NE(err.find("vertex 2"), std::string::npos) << bad << ": " << err;
  }
}

TEST(Stiff, SubpixelBitsAtTheGuardBand) {
  // RasterConfig::validate accepts 1..8 subpixel bits. Whatever it accepts, setup must take
  // every triangle inside the guard band: an edge's DDA divisor D = |dY| 2^(S+2) (u units)
  // reaches 2 * 8192 * 2^S * 2^(S+2) = 2^(2S+16) for a full-height edge, so RemBits 27 holds
  // S <= 5. A configuration whose unit cannot hold its subpixel grid must be refused by
  // validate() (std::invalid_argument), not fail later inside setup.
  const double g = 8192;
  const Tri v = {vtx(-g, -g, {0, 0, 0, 0.1}), vtx(g, -g, {255, 0, 0, 0.9}), vtx(g, g, {0, 255, 0, 0.5})};
  std::vector<ModesResult> drawn;
  for (int S = 1; S <= 8; ++S) {
    RasterConfig cfg = rasterConfig("serial", 64, 48);
    cfg.subpixel_bits = S;
    bool valid = true;
    try {
      cfg.validate();
    } catch (const std::invalid_argument& e) {
      valid = false;
      std::printf("  S = %d refused: %s\n", S, e.what());
    }
    if (!valid) continue;
    try {
      const ModesResult r = checkAllModes(v, 64, 48, fmt::format("S = {}", S), S);
      EXPECT_TRUE(r.drawn) << "S = " << S;
      std::printf("  S = %d: %zu fragments per mode\n", S, r.fragments);
      drawn.push_back(r);
    } catch (const std::exception& e) {
      ADD_FAILURE() << "S = " << S << ": validate() accepts the configuration, then setup throws: " << e.what();
    }
  }
  expectSpanRtlEqualsModel(drawn, "subpixel bits");
}

TEST(Stiff, FarOffScreen) {
  // Within the guard band but wholly off the viewport: dropped ("outside the viewport"), no
  // descriptor. Mostly off screen with a corner on it: only the on-screen part is walked (the
  // rows and columns are clipped in the descriptor), equal to the direct rasterisation; in
  // sierpinski some sub-triangles are then wholly off screen.
  const std::vector<std::pair<const char*, Tri>> off = {
      {"left", {vtx(-8000, 10, {0, 0, 0, 0.5}), vtx(-10, 10, {0, 0, 0, 0.5}), vtx(-5000, 40, {0, 0, 0, 0.5})}},
      {"below", {vtx(3, 48.6, {0, 0, 0, 0.5}), vtx(60, 8000, {0, 0, 0, 0.5}), vtx(-40, 5000, {0, 0, 0, 0.5})}},
      {"beyond a corner", {vtx(64.6, -1, {0, 0, 0, 0.5}), vtx(8000, -8000, {0, 0, 0, 0.5}), vtx(8000, 30, {0, 0, 0, 0.5})}},
  };
  for (const auto& [what, v] : off) {
    const ModesResult r = checkAllModes(v, 64, 48, what);
    EXPECT_FALSE(r.drawn) << what;
    EXPECT_EQ(r.dropped, "no pixel centre of its bounding box in the viewport") << what;
  }
  const std::vector<std::pair<const char*, Tri>> partly = {
      {"a corner on screen", {vtx(-8000, -7000, {0, 0, 0, 0.1}), vtx(30.5, 20.5, {255, 0, 0, 0.9}), vtx(-6000, 8000, {0, 255, 0, 0.5})}},
      {"a huge triangle around the viewport", {vtx(-8000, -8000, {0, 0, 0, 0.1}), vtx(8000, -100, {255, 0, 0, 0.9}), vtx(-100, 8000, {0, 255, 0, 0.5})}},
      {"an edge through the viewport", {vtx(-5000, 3000, {0, 0, 0, 0.1}), vtx(5000, -2980, {255, 0, 0, 0.9}), vtx(7000, 7000, {0, 255, 0, 0.5})}},
  };
  std::vector<ModesResult> drawn;
  long double worst = 0;
  for (const auto& [what, v] : partly) {
    const ModesResult r = checkAllModes(v, 64, 48, what);
    EXPECT_TRUE(r.drawn) << what;
    EXPECT_GT(r.fragments, 0u) << what;
    std::printf("  %s: %zu fragments per mode\n", what, r.fragments);
    worst = std::max(worst, r.worst_lsb);
    drawn.push_back(r);
  }
  record("off_screen_plane_error", static_cast<double>(worst), "output LSB (64x48)");
  expectSpanRtlEqualsModel(drawn, "off screen");
}

// ============================================================================ normals and normalisation

namespace {

// A right triangle with vertices on pixel centres, 128 px legs (front facing: area2 < 0).
const std::array<std::array<double, 2>, 3> kRight = {{{100.5, 100.5}, {100.5, 228.5}, {228.5, 100.5}}};

// The covered pixels' colours of a frame.
std::vector<std::array<uint8_t, 3>> coveredColours(const Framebuffer& fb) {
  std::vector<std::array<uint8_t, 3>> out;
  for (int y = 0; y < fb.height; ++y)
    for (int x = 0; x < fb.width; ++x)
      if (fb.covered(x, y)) out.push_back(pixel(fb, x, y));
  return out;
}

int channelDiff(const std::array<uint8_t, 3>& a, const std::array<uint8_t, 3>& b) {
  int d = 0;
  for (size_t k = 0; k < 3; ++k) d = std::max(d, std::abs(int{a[k]} - int{b[k]}));
  return d;
}

}  // namespace

TEST(Stiff, EqualVertexNormalsShadeUniformly) {
  // Three equal vertex normals: the interpolated normal is the same code at every pixel (zero
  // gradients), so every method paints the triangle in one colour, and modified Gouraud finds
  // no edge maximum (the cosine is constant along each edge) and splits nothing. Every method
  // but flat (which shades the face normal) gives phong's colour; with the device lobe the
  // reference (exact Blinn) differs by the lobe's approximation.
  const Vec3 n = normalize(Vec3{-0.2, 0.3, -1});
  Material mat;
  mat.colour = {0.3, 0.4, 0.5};
  mat.ks = 0.4;
  const Scene s = triangleScene(kRight, {n, n, n}, mat);
  for (const std::string brdf : {"blinn", "quadratic"}) {
    std::map<Method, std::array<uint8_t, 3>> colour;
    for (Method m : allMethods()) {
      const RenderResult r = renderWith(s, m, brdf);
      const auto cols = coveredColours(r.fb);
      ASSERT_GT(cols.size(), 8000u) << toString(m);
      for (const auto& c : cols) ASSERT_EQ(c, cols[0]) << toString(m) << " " << brdf << ": not uniform";
      if (m == Method::ModifiedGouraud) {
        EXPECT_EQ(r.stats.split_parts, 0u) << brdf;
      }
      colour[m] = cols[0];
    }
    for (const auto& [m, c] : colour) {
      std::printf("  %s %s: (%d, %d, %d)\n", brdf.c_str(), toString(m), c[0], c[1], c[2]);
      if (m == Method::Flat || (m == Method::Reference && brdf == "quadratic")) continue;
      EXPECT_EQ(c, colour[Method::Phong]) << toString(m) << " " << brdf;
    }
  }
}

TEST(Stiff, OppositeVertexNormalsPassThroughZero) {
  // Vertex normals -z, +z, -z: along the legs from the first vertex the interpolated normal
  // shrinks to exactly 0 at row 164 (the gradient 2^28 * 2 / 128 = 2^22 codes per row is exact)
  // and grows again reversed. The behaviour chosen: a zero normal has every cosine 0 (ambient
  // only, exactly), a tiny one is normalised like any other (its direction is its code's), and
  // no method divides by zero, throws or writes a NaN. Modified Gouraud splits nothing (opposite
  // or equal normals on every edge). Beside the zero row phong-incremental and phong-fixed
  // follow phong.
  const Scene s = triangleScene(kRight, {Vec3{0, 0, -1}, Vec3{0, 0, 1}, Vec3{0, 0, -1}});
  const std::array<uint8_t, 3> ambient = ambientColour(s);
  for (const std::string brdf : {"blinn", "quadratic"}) {
    std::map<Method, Framebuffer> fbs;
    for (Method m : allMethods()) {
      const RenderResult r = renderWith(s, m, brdf);
      ASSERT_GT(coveredColours(r.fb).size(), 8000u) << toString(m);
      if (m == Method::ModifiedGouraud) {
        EXPECT_EQ(r.stats.split_parts, 0u) << brdf;
      }
      fbs[m] = r.fb;
    }
    // Row 164: x from 100 to the hypotenuse (x + y <= 328.5 - ...): the pixels with zero normal.
    int zero_pixels = 0;
    for (int x = 100; x < 164; ++x) {
      for (Method m : {Method::Phong, Method::PhongIncremental, Method::PhongFixed, Method::NormalBisection, Method::Reference}) {
        ASSERT_TRUE(fbs[m].covered(x, 164));
        EXPECT_EQ(pixel(fbs[m], x, 164), ambient) << toString(m) << " " << brdf << " at (" << x << ", 164)";
      }
      ++zero_pixels;
    }
    int worst_inc = 0, worst_fixed = 0;
    for (int y = 100; y < 229; ++y)
      for (int x = 100; x < 229; ++x) {
        if (!fbs[Method::Phong].covered(x, y)) continue;
        worst_inc = std::max(worst_inc, channelDiff(pixel(fbs[Method::PhongIncremental], x, y), pixel(fbs[Method::Phong], x, y)));
        worst_fixed = std::max(worst_fixed, channelDiff(pixel(fbs[Method::PhongFixed], x, y), pixel(fbs[Method::Phong], x, y)));
      }
    // phong-incremental: 1/|N| within 2^-15 relative; phong-fixed: cosines within 2^-20 and
    // the lobe tables / the device's cos code (one code moves a 32-lobe by ~32 2^-15 = 0.001):
    // less than half an LSB of colour either way, so at most one rounding step apart.
    EXPECT_LE(worst_inc, 1) << brdf;
    EXPECT_LE(worst_fixed, 1) << brdf;
    std::printf("  %s: %d pixels with a zero normal, all ambient\n", brdf.c_str(), zero_pixels);
    record(fmt::format("opposite_normals_phong_incremental_vs_phong_{}", brdf), worst_inc, "output LSB");
    record(fmt::format("opposite_normals_phong_fixed_vs_phong_{}", brdf), worst_fixed, "output LSB");
  }
  // The RTL in the loop (span unit and specular unit verilated) paints the same frame.
  const fs::path dir = shd::testutil::freshTestDir("stiff");
  const SpecUnitConfig spec = specConfig("default");
  RtlSpanEngine span(spanConfig("sierpinski"), dir.string());
  RtlSpecEngine quad(spec, registryTable("default"), (dir / "default.hex").string(), dir.string());
  for (Method m : {Method::Phong, Method::PhongIncremental, Method::PhongFixed}) {
    RenderOptions o;
    o.method = m;
    o.brdf = "quadratic";
    const RenderResult rtl = render(s, o, span, SpecEngines{&quad, nullptr});
    EXPECT_EQ(rtl.fb.rgb, renderWith(s, m, "quadratic").fb.rgb) << toString(m) << ": the RTL's frame differs";
  }
}

TEST(Stiff, ZeroVertexNormal) {
  // A vertex normal of length 0 (a mesh built in code; files are repaired on load): it stays 0
  // after the transform (normalize leaves 0 alone), its Gouraud colour is the ambient one, and
  // at its own pixel the interpolated normal is exactly 0, so every per-pixel method paints
  // the ambient colour there. No method throws or writes a NaN.
  const Scene s = triangleScene(kRight, {Vec3{0, 0, 0}, Vec3{0, 0, -1}, normalize(Vec3{0.2, 0.1, -1})});
  const std::array<uint8_t, 3> ambient = ambientColour(s);
  for (const std::string brdf : {"blinn", "quadratic"})
    for (Method m : allMethods()) {
      const RenderResult r = renderWith(s, m, brdf);
      ASSERT_GT(coveredColours(r.fb).size(), 8000u) << toString(m);
      ASSERT_TRUE(r.fb.covered(100, 100));
      if (m == Method::Phong || m == Method::PhongIncremental || m == Method::PhongFixed ||
          m == Method::NormalBisection || m == Method::Reference || m == Method::Gouraud) {
        EXPECT_EQ(pixel(r.fb, 100, 100), ambient) << toString(m) << " " << brdf;
      }
    }
}

TEST(Stiff, SquaredNormRecurrenceOverTheLongestSpan) {
  // The recurrence F_{i+1} = F_i + 2B + C_{i+1}, C_{i+1} = C_i + 2C along a 4096-pixel span
  // (the widest viewport) whose normal turns from N to -N: the normal codes (28 fraction bits,
  // from the span unit's plane) are exact integers N_0 + i dN, so F_i must equal |N_i|^2 exactly
  // at every pixel, though its partial sums wrap modulo 2^64; and rsqrtFixed's 1/sqrt(F_i) must
  // stay within its derived relative error where F_i is tiny (mid-span) as where it is 1:
  // seed e0 <= 0.75 2^-8 + 2^-17, one Newton step 1.5 e0^2 = 1.30e-5, the Q16 result's
  // truncation 2^-16: below 2^-15 in all.
  RasterConfig cfg = rasterConfig("serial", 4096, 4);
  cfg.attr_frac_bits = {28, 28, 28, 28};
  const Vec3 n = normalize(Vec3{0.6, -0.48, 0.64});
  const Tri v = {vtx(-8192, -4, {n.x, n.y, n.z, 0.5}), vtx(8192, -4, {-n.x, -n.y, -n.z, 0.5}), vtx(0, 8192, {0.1, 0.1, 0.1, 0.5})};
  const SetupResult s = setupTriangle(v, 1, cfg);
  ASSERT_TRUE(s.desc);
  std::vector<SpanFragment> frags;
  walkSpanUnit(cfg.unit, *s.desc, frags);
  ASSERT_EQ(frags.size(), 4096u * 4u);
  SquaredNorms recurrence({s.plane.didx[0], s.plane.didx[1], s.plane.didx[2]});
  long double worst_rel = 0;
  uint64_t min_f = UINT64_MAX, max_f = 0;
  for (const SpanFragment& f : frags) {
    const uint64_t got = recurrence(f.x, f.y, f.attr.data());
    i128 direct = 0;
    for (size_t k = 0; k < 3; ++k) direct += static_cast<i128>(f.attr[k]) * f.attr[k];
    ASSERT_EQ(static_cast<i128>(got), direct) << "at (" << f.x << ", " << f.y << ")";
    ASSERT_LT(got, uint64_t{1} << 58);
    min_f = std::min(min_f, got);
    max_f = std::max(max_f, got);
    if (got == 0) continue;
    const long double exact = 1 / std::sqrt(std::ldexp(static_cast<long double>(got), -56));
    const long double rel = std::fabs(rsqrtFixed(got, 56) / exact - 1);
    ASSERT_LE(rel, std::ldexp(1.0L, -15)) << "F = " << got;
    worst_rel = std::max(worst_rel, rel);
  }
  std::printf("  F from %llu (|N| = %.3g) to %llu (|N| = %.3g)\n", static_cast<unsigned long long>(min_f),
              std::sqrt(std::ldexp(static_cast<double>(min_f), -56)), static_cast<unsigned long long>(max_f),
              std::sqrt(std::ldexp(static_cast<double>(max_f), -56)));
  record("longest_span_recurrence_error", 0, "(exact)");
  record("longest_span_rsqrt_relative_error", static_cast<double>(worst_rel), "");
  // The span unit walks that descriptor the same in the RTL.
  ModesResult r;
  r.drawn = true;
  for (const std::string& mode : spanModes()) {
    RasterConfig c = cfg;
    c.unit = spanParams(mode);
    r.descs.push_back(*setupTriangle(v, 1, c).desc);
  }
  expectSpanRtlEqualsModel({r}, "normals over the longest span");
}

TEST(Stiff, TinyNormNormalisation) {
  // Interpolated normals of tiny norm (codes of a few units, |N| ~ 2^-28): rsqrtFixed (phong-
  // incremental) within 2^-15 relative (above), and phong-fixed's cosines d / |N| (cosineScale,
  // a 10-bit seed: e0 <= 0.75 2^-10 + 2^-17, 1.5 e0^2 < 2^-20) within 2^-20 relative plus the
  // half code of the final rounding, for every normal with components in [-4, 4] against a
  // spread of unit vectors. A zero normal gives 0 (every cosine 0).
  EXPECT_EQ(rsqrtFixed(0, 56), 0.0);
  EXPECT_EQ(scaleCosine(int64_t{1} << 40, cosineScale(0)), 0);
  long double worst_rsqrt = 0, worst_cos = 0;
  for (uint64_t f = 1; f <= 4096; ++f) {
    const long double rel = std::fabs(rsqrtFixed(f, 56) * std::sqrt(std::ldexp(static_cast<long double>(f), -56)) - 1);
    ASSERT_LE(rel, std::ldexp(1.0L, -15)) << "F = " << f;
    worst_rsqrt = std::max(worst_rsqrt, rel);
  }
  const std::vector<Vec3> dirs = {{0, 0, -1}, normalize(Vec3{-1, 1, -1}), normalize(Vec3{0.3, -0.2, 0.9}), {1, 0, 0}};
  for (int a = -4; a <= 4; ++a)
    for (int b = -4; b <= 4; ++b)
      for (int c = -4; c <= 4; ++c) {
        const std::array<int64_t, 3> n28 = {a, b, c};
        const uint64_t sq = static_cast<uint64_t>(a * a + b * b + c * c);
        if (sq == 0) continue;
        const CosineScale sc = cosineScale(sq);
        for (const Vec3& d : dirs) {
          const std::array<int32_t, 3> u = {static_cast<int32_t>(std::lround(std::ldexp(d.x, 30))),
                                            static_cast<int32_t>(std::lround(std::ldexp(d.y, 30))),
                                            static_cast<int32_t>(std::lround(std::ldexp(d.z, 30)))};
          const int64_t dot = fixed_detail::dot58(n28.data(), u);
          // d 2^-58 / (sqrt(sq) 2^-28) in Q2.32
          const long double exact = std::ldexp(static_cast<long double>(dot), 2) / std::sqrt(static_cast<long double>(sq));
          const long double err = std::fabs(static_cast<long double>(scaleCosine(dot, sc)) - exact);
          ASSERT_LE(err, std::ldexp(std::fabs(exact), -20) + 0.5L) << a << " " << b << " " << c;
          if (exact != 0) worst_cos = std::max(worst_cos, err / std::fabs(exact));
        }
      }
  record("tiny_norm_rsqrt_relative_error", static_cast<double>(worst_rsqrt), "");
  record("tiny_norm_cosine_relative_error", static_cast<double>(worst_cos), "");
}

TEST(Stiff, EdgeMaximaOutsideTheEdge) {
  // edgeMaximumT returns the interior maximum t1 of N(t).H / |N(t)| on an edge, or -1 when
  // there is none: t1 outside (0, 1), cos alpha + cos chi <= 0, equal or opposite normals (to
  // within 1e-12 in cos psi). It never returns NaN; a -1 edge has its maximum at an end, and
  // a returned t1 is at least as high as every sampled point (up to the rounding of evaluating
  // the normalised cosine in double, 1e-12). Random edges with t1 pushed to just outside and
  // inside the ends, and the special inputs.
  auto value = [](Vec3 na, Vec3 nb, Vec3 h, double t) {
    const Vec3 n = na + t * (nb - na);
    const double len = length(n);
    return len > 0 ? dot(n, h) / len : -2.0;
  };
  // The largest excess of a sample over the claimed maximum (the better end, or t1).
  auto excess = [&](Vec3 na, Vec3 nb, Vec3 h, double t) {
    const double best = t == -1 ? std::max(value(na, nb, h, 0), value(na, nb, h, 1)) : value(na, nb, h, t);
    double e = 0;
    for (int i = 0; i <= 1000; ++i) e = std::max(e, value(na, nb, h, i / 1000.0) - best);
    return e;
  };
  const Vec3 z{0, 0, -1}, h{std::sin(0.3), 0, -std::cos(0.3)};
  double gap = 0;
  for (const auto& [na, nb, hh] : std::vector<std::array<Vec3, 3>>{
           {z, z, h},                                                          // equal
           {z, Vec3{0, 0, 1}, h},                                              // opposite
           {z, normalize(Vec3{1e-7, 0, -1}), h},                               // 1 - cos psi = 5e-15
           {normalize(Vec3{1, 0, -1}), normalize(Vec3{-1, 0, -1}), Vec3{0, 0, 1}},  // cos alpha + cos chi < 0
           {Vec3{1, 0, 0}, Vec3{0, 1, 0}, Vec3{0, 0, 1}},                      // both cosines 0
       }) {
    const double t = edgeMaximumT(na, nb, hh);
    EXPECT_EQ(t, -1);
    gap = std::max(gap, excess(na, nb, hh, t));
  }
  // Nearly opposite normals (|N_A + N_B| = d = 1e-7, inside the 1e-12 band of cos psi):
  // treated as opposite (-1). N(t) = N_A (1 - 2t) + t (N_A + N_B) then swings through the half
  // circle from N_A to N_B around t = 1/2, tilted from +-N_A by atan(t d / |1 - 2t|), and passes
  // H's direction there (cosine 1 against 0.955 at the ends): that maximum is missed. Beyond
  // w = 1e-4 of the middle the tilt is at most d / (4 w) = 2.5e-4 rad, so no point beats the
  // ends by more than that.
  {
    const double d = 1e-7, w = 1e-4;
    const Vec3 nb = normalize(Vec3{d, 0, 1});
    EXPECT_EQ(edgeMaximumT(z, nb, h), -1);
    const double ends = std::max(value(z, nb, h, 0), value(z, nb, h, 1));
    double outside = -1, inside = -1;
    for (int i = 0; i <= 100000; ++i) {
      const double t = i / 100000.0;
      if (std::fabs(t - 0.5) > w) outside = std::max(outside, value(z, nb, h, t));
    }
    for (int i = -2000; i <= 2000; ++i) inside = std::max(inside, value(z, nb, h, 0.5 + i * 1e-9));
    EXPECT_LE(outside, ends + d / (4 * w));
    EXPECT_GT(inside, ends + 0.04);
    record("nearly_opposite_missed_maximum", inside - ends, "(cosine, at t = 1/2 +- 1e-7)");
    record("nearly_opposite_excess_beyond_1e-4", outside - ends, "(cosine)");
  }
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(-1, 1);
  int at_end = 0, interior = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const Vec3 na = normalize(Vec3{u(rng), u(rng), u(rng)}), nb = normalize(Vec3{u(rng), u(rng), u(rng)});
    if (1 + dot(na, nb) < 1e-6 || 1 - dot(na, nb) < 1e-6) continue;
    // H near the normal of one end (the maximum there, or just inside), tilted off the plane.
    const double s = (trial % 2 ? 1 : 0) + 1e-3 * u(rng);
    const Vec3 hh = normalize(na + s * (nb - na) + 0.05 * Vec3{u(rng), u(rng), u(rng)});
    const double t = edgeMaximumT(na, nb, hh);
    ASSERT_FALSE(std::isnan(t));
    if (t != -1) {
      ASSERT_GT(t, 0);
      ASSERT_LT(t, 1);
    }
    (t == -1 ? at_end : interior) += 1;
    gap = std::max(gap, excess(na, nb, hh, t));
  }
  EXPECT_LE(gap, 1e-12);
  EXPECT_GT(at_end, 1000);
  EXPECT_GT(interior, 1000);
  std::printf("  %d random edges near the ends: %d with the maximum at an end, %d interior\n", at_end + interior, at_end,
              interior);
  record("edge_maximum_sampled_excess", gap, "(cosine)");
}

// ============================================================================ biquadratic

namespace {

// The colour the renderer computes for a point of unit normal n: ambient + diffuse + the lobe
// (PointShader, the same code the methods call), in LSBs.
std::array<double, 3> shadeOf(const Scene& s, Vec3 n) {
  const ShadeContext ctx = makeShadeContext(s);
  const PointShader sh(ctx, s.materials[0], parseLobe(s.materials[0].brdf), nullptr);
  return sh.shade(normalize(n), Vec3{0, 0, 3}, nullptr).lsb;
}

// Camera-space normal of a mesh normal in the triangle scenes (the camera's axes are the world's).
Material dullGrey() {
  Material m;
  m.colour = {0.5, 0.5, 0.5};
  m.kd = 0.5;
  m.ks = 0;  // no highlight: the samples vary slowly
  return m;
}

}  // namespace

TEST(Stiff, BiquadraticUniformSamplesGiveTheirColour) {
  // The quadratic Lagrange basis sums to 1 (sum l_i (2 l_i - 1) + 4 sum l_i l_j = 2 (sum l)^2 - 1
  // = 1), so six equal samples give their colour at every pixel, exactly up to rounding: a
  // 128-px triangle, a one-pixel triangle, and a sliver that snapping made visible.
  const Vec3 n{0, 0, -1};
  const std::vector<std::pair<const char*, std::array<std::array<double, 2>, 3>>> shapes = {
      {"128 px right triangle", kRight},
      {"one pixel", {{{300.2, 300.2}, {300.5, 300.9}, {300.8, 300.3}}}},
      // On screen the third vertex is 5e-12 px off the line through the others (area2 = -1e-9
      // px^2); snapped to sixteenths it sits 1/32 px above the line y - 100.5 = (x - 100.5)/2
      // through pixel centres, onto which the other two snap, and the triangle covers the
      // centres on that line (its top-left edge), 0.0045 px beside the unsnapped edge.
      {"sliver of area 5e-10 px^2", {{{100.51, 100.5}, {300.51, 200.5}, {200.55, 150.52 - 5e-12}}}},
  };
  for (const auto& [what, xy] : shapes) {
    const Scene s = triangleScene(xy, {n, n, n}, dullGrey());
    const std::array<uint8_t, 3> expect = combine(shadeOf(s, n), nullptr, 0);
    const RenderResult r = renderWith(s, Method::Biquadratic, "");
    const auto cols = coveredColours(r.fb);
    EXPECT_GT(cols.size(), 0u) << what;
    int worst = 0;
    for (const auto& c : cols) worst = std::max(worst, channelDiff(c, expect));
    EXPECT_EQ(worst, 0) << what << ": " << cols.size() << " pixels, expected (" << int{expect[0]} << ", "
                        << int{expect[1]} << ", " << int{expect[2]} << ")";
    std::printf("  %s: %zu pixels, worst %d LSB from the samples' colour\n", what, cols.size(), worst);
    record(fmt::format("biquadratic_uniform_{}", what), worst, "output LSB");
  }
}

TEST(Stiff, BiquadraticSliverStaysWithinItsSamples) {
  // The listing's 6x6 system is singular when sample points coincide (zero area: dropped at
  // setup and culled before) and ill-conditioned for slivers. The direct Lagrange evaluation
  // has no solve, but its barycentric coordinates divide by the unsnapped triangle's area. The
  // behaviour required: on the triangle the quadratic interpolant stays within the range
  // [m, M] of its six samples widened by 3/8 (M - m) (only the vertex functions l (2l - 1) go
  // negative on the triangle, each down to -1/8; with the partition of unity that bounds the
  // excess), plus the half LSB of the output rounding. Checked on a well-shaped triangle and on
  // the sliver of BiquadraticUniformSamplesGiveTheirColour with varying normals.
  const std::array<Vec3, 3> normals = {normalize(Vec3{-0.3, 0.2, -1}), normalize(Vec3{0.4, 0.1, -1}),
                                       normalize(Vec3{0.1, -0.5, -1})};
  const std::vector<std::pair<const char*, std::array<std::array<double, 2>, 3>>> shapes = {
      {"128 px right triangle", kRight},
      {"sliver of area 5e-10 px^2", {{{100.51, 100.5}, {300.51, 200.5}, {200.55, 150.52 - 5e-12}}}},
      {"sliver of area 5e-7 px^2", {{{100.51, 100.5}, {300.51, 200.5}, {200.55, 150.52 - 5e-9}}}},
  };
  for (const auto& [what, xy] : shapes) {
    const Scene s = triangleScene(xy, normals, dullGrey());
    // The six samples: vertices and edge midpoints (normalised mean normals), as biquadratic.
    std::array<double, 3> lo{}, hi{};
    lo.fill(1e300);
    hi.fill(-1e300);
    for (size_t i = 0; i < 3; ++i)
      for (const Vec3 nn : {normals[i], normalize(0.5 * (normals[i] + normals[(i + 1) % 3]))}) {
        const std::array<double, 3> c = shadeOf(s, nn);
        for (size_t k = 0; k < 3; ++k) lo[k] = std::min(lo[k], c[k]), hi[k] = std::max(hi[k], c[k]);
      }
    const RenderResult r = renderWith(s, Method::Biquadratic, "");
    double worst = 0;  // beyond the allowed range, in LSB
    int pixels = 0;
    for (int y = 0; y < r.fb.height; ++y)
      for (int x = 0; x < r.fb.width; ++x) {
        if (!r.fb.covered(x, y)) continue;
        ++pixels;
        const std::array<uint8_t, 3> c = pixel(r.fb, x, y);
        for (size_t k = 0; k < 3; ++k) {
          const double spread = 0.375 * (hi[k] - lo[k]);
          worst = std::max({worst, c[k] - (hi[k] + spread + 0.5), (lo[k] - spread - 0.5) - c[k]});
        }
      }
    EXPECT_GT(pixels, 0) << what;
    EXPECT_LE(worst, 0) << what << ": a pixel " << worst << " LSB outside the samples' range [" << lo[0] << ", " << hi[0]
                        << "] (channel 0) widened by 3/8";
    std::printf("  %s: %d pixels, samples %.2f..%.2f LSB (channel 0), worst excess %.2f LSB\n", what, pixels, lo[0], hi[0],
                worst);
    record(fmt::format("biquadratic_excess_{}", what), worst, "output LSB");
  }
}
