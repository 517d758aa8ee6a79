// The alternative specular units (SpecKind table, schlick, explog and piecewise): the model
// against the functions they stand for, computed here another way (bucket edges found by scanning
// the codes, the rational and the power in long double, the segments' real polynomials), at every
// input of small configurations; their PROMs; their pipeline timing; and the checks that keep a
// kind and its parameters together.
#include "device/spec_unit.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>

#include "approx/lobe_error.h"
#include "device/prom.h"
#include "device/prom_io.h"

using namespace shd;

namespace {

SpecUnitParams tableParams() {
  SpecUnitParams p;
  p.Kind = static_cast<int>(SpecKind::Table);
  p.CosFracBits = 10;
  p.ShinBits = 2;
  p.TableBits = 4;
  p.SpecFracBits = 12;
  p.PipeStages = 1;
  return p;
}

SpecUnitParams schlickParams() {
  SpecUnitParams p;
  p.Kind = static_cast<int>(SpecKind::Schlick);
  p.CosFracBits = 11;
  p.ShinBits = 3;
  p.CoefIntBits = 10;
  p.CoefFracBits = 2;  // n = 37.25 is exact
  p.SpecFracBits = 16;
  p.PipeStages = 5;
  return p;
}

SpecUnitParams expLogParams() {
  SpecUnitParams p;
  p.Kind = static_cast<int>(SpecKind::ExpLog);
  p.CosFracBits = 11;
  p.ShinBits = 3;
  p.CoefIntBits = 10;
  p.CoefFracBits = 2;  // n = 37.25 is exact
  p.SpecFracBits = 14;
  p.TableBits = 6;
  p.PipeStages = 3;
  return p;
}

SpecUnitParams piecewiseParams() {
  SpecUnitParams p;
  p.Kind = static_cast<int>(SpecKind::Piecewise);
  p.Degree = 2;
  p.Segments = 4;
  p.CosFracBits = 11;
  p.ShinBits = 3;
  p.CoefIntBits = 2;
  p.CoefFracBits = 18;
  p.SpecFracBits = 14;
  p.PipeStages = 3;
  return p;
}

PromTable build(const SpecUnitParams& p, const std::string& n_list) {
  PromRequest r;
  r.fit = p.kind() == SpecKind::Piecewise ? FitKind::Minimax : FitKind::Exact;
  r.n = NSpec::parse(n_list, true);
  return buildPromTable(r, p);
}

const std::array<uint32_t, 3> kFull = {255, 255, 255};

}  // namespace

TEST(SpecKindTable, EveryInputReadsTheMinimaxValueOfItsBucket) {
  const SpecUnitParams p = tableParams();
  const PromTable t = build(p, "1,8,100");
  const SpecUnitModel m(p, t.words, t.seg_words);
  ASSERT_EQ(p.promDepth(), 4 << 4);
  const double scale = std::ldexp(1.0, -p.CosFracBits);
  for (const PromEntry& e : t.entries) {
    // The buckets as the codes fall into them: the codes c in 0..2^Wc (inputs above 1.0 read
    // c = 1.0) grouped by the index the unit forms, with their smallest and largest code.
    std::map<int64_t, std::pair<int64_t, int64_t>> bucket;
    for (int64_t c = 0; c <= p.cosOne(); ++c) {
      const int64_t k = std::min<int64_t>(static_cast<int64_t>(std::floor(c * scale * 16)), 15);
      auto [it, fresh] = bucket.emplace(k, std::make_pair(c, c));
      if (!fresh) it->second.second = c;
    }
    ASSERT_EQ(bucket.size(), 16u);
    for (uint32_t cos = 0; cos < (2u << p.CosFracBits); ++cos) {
      const int64_t c = std::min<int64_t>(cos, p.cosOne());
      const int64_t k = std::min<int64_t>(static_cast<int64_t>(std::floor(c * scale * 16)), 15);
      const auto [lo, hi] = bucket.at(k);
      const double want = 0.5 * (std::pow(lo * scale, e.n) + std::pow(hi * scale, e.n));
      const SpecOut o = m.evaluate(e.address, cos, kFull);
      ASSERT_EQ(o.spec, static_cast<uint32_t>(std::nearbyint(std::ldexp(want, p.SpecFracBits))))
          << "n " << e.n << " cos " << cos;
      ASSERT_EQ(m.trace(e.address, cos).f.raw(), o.spec);
      // Within half the bucket's spread of c^n plus half an LSB of f.
      const double spread = 0.5 * (std::pow(hi * scale, e.n) - std::pow(lo * scale, e.n));
      ASSERT_LE(std::fabs(std::ldexp(o.spec, -p.SpecFracBits) - std::pow(c * scale, e.n)),
                spread + std::ldexp(0.5, -p.SpecFracBits) + 1e-15);
    }
  }
  // The unused address reads the all-zero row.
  EXPECT_EQ(m.evaluate(3, p.cosOne(), kFull).spec, 0u);
  // A word above 1.0 is no table of c^n: the RTL would drop the top bit of f * L.
  std::vector<PromWord> bad = t.words;
  bad[5] = (PromWord{1} << p.SpecFracBits) + 1;
  EXPECT_THROW(SpecUnitModel(p, bad), std::invalid_argument);
}

TEST(SpecKindTable, ApproximationErrorCoversEveryCode) {
  const SpecUnitParams p = tableParams();
  const PromTable t = build(p, "8");
  const Approx& f = t.entries[0].approx;
  ASSERT_EQ(f.form, Approx::Form::Table);
  double worst = 0;
  for (int64_t c = 0; c <= p.cosOne(); ++c) {
    const double x = std::ldexp(static_cast<double>(c), -p.CosFracBits);
    worst = std::max(worst, std::fabs(f.eval(x) - std::pow(x, 8.0)));
  }
  // Over continuous c the error is at least the codes' (each bucket's value is fitted to its codes).
  const RegionError lobe = summarizeError(f, 8).at("lobe");
  EXPECT_GE(lobe.max_abs, worst);
  EXPECT_LE(lobe.max_abs, worst + 8.0 * std::ldexp(1.0, -p.CosFracBits));  // one code's step of c^8
}

TEST(SpecKindSchlick, EveryInputIsTheTruncatedRational) {
  const SpecUnitParams p = schlickParams();
  const PromTable t = build(p, "1,1.5,37.25,1000");
  const SpecUnitModel m(p, t.words, t.seg_words);
  const long double lsb = std::ldexp(1.0L, -p.SpecFracBits);
  for (const PromEntry& e : t.entries) {
    EXPECT_EQ(e.code.u, static_cast<int64_t>(std::ldexp(e.n - 1.0, p.CoefFracBits)));
    for (uint32_t cos = 0; cos < (2u << p.CosFracBits); ++cos) {
      const long double c = std::ldexp(static_cast<long double>(std::min<int64_t>(cos, p.cosOne())), -p.CosFracBits);
      const long double q = c / (e.n - e.n * c + c);  // Schlick's rational
      const SpecOut o = m.evaluate(e.address, cos, kFull);
      const long double f = o.spec * lsb;
      // floor: f <= q < f + 1 LSB (long double carries 64 bits, the quotient 17).
      ASSERT_LE(f, q + 1e-15L) << "n " << e.n << " cos " << cos;
      ASSERT_LT(q, f + lsb + 1e-15L) << "n " << e.n << " cos " << cos;
      ASSERT_EQ(m.trace(e.address, cos).f.raw(), o.spec);
    }
  }
  // Padding holds m = 0: f = c.
  EXPECT_EQ(m.evaluate(7, 1234, kFull).spec, 1234u << (p.SpecFracBits - p.CosFracBits));
}

TEST(SpecKindSchlick, ApproximationErrorMatchesDenseSampling) {
  const Approx f = Approx::schlick(100);
  double worst = 0;
  for (int i = 0; i <= 1000000; ++i) {
    const double c = i / 1e6;
    worst = std::max(worst, std::fabs(f.eval(c) - std::pow(c, 100.0)));
  }
  const RegionError lobe = summarizeError(f, 100).at("lobe");
  EXPECT_NEAR(lobe.max_abs, worst, 1e-6);
  EXPECT_GE(lobe.max_abs, worst);
}

TEST(SpecKindExpLog, TablesHoldTheFunctionsRoundedToTheirBits) {
  SpecUnitParams p = expLogParams();
  p.TableBits = 8;
  p.SpecFracBits = 16;
  const ExpLogWidths w = p.expLogWidths();
  const ExpLogTables t = makeExpLogTables(p);
  ASSERT_EQ(t.g.size(), 257u);
  ASSERT_EQ(t.e.size(), 257u);
  for (size_t i = 0; i < t.g.size(); ++i) {
    const long double d = std::ldexp(static_cast<long double>(i), -(p.TableBits + 1));
    const long double g = i == 0 ? 1.0L / std::log(2.0L) : -std::log2(1.0L - d) / d;
    const long double e = std::exp2(-std::ldexp(static_cast<long double>(i), -p.TableBits));
    // Rounded half up from 60 bits: within half a unit of the function (and a 2^-50 margin).
    EXPECT_LE(std::fabs(t.g[i] - std::ldexp(g, w.GF)), 0.5L + 1e-9L) << "g " << i;
    EXPECT_LE(std::fabs(t.e[i] - std::ldexp(e, w.EF)), 0.5L + 1e-9L) << "e " << i;
  }
  // The ends the datapath relies on: g(1/2) = 2 and 2^-1 exactly, e(0) = 1.
  EXPECT_EQ(t.g.back(), int64_t{2} << w.GF);
  EXPECT_EQ(t.e.front(), int64_t{1} << w.EF);
  EXPECT_EQ(t.e.back(), int64_t{1} << (w.EF - 1));
}

// |f - c^n| in f-LSBs is at most: 1/2 (the final rounding); the log table's interpolation,
// relative error g''(1/2) h^2 / 8 / g(0) with h = 2^-(T+1), which moves f by at most 1/e of it
// (f ln2 y rel and y 2^-y <= 1/(e ln2)); the exp table's, (ln 2)^2 h^2 / 8 with h = 2^-T; the
// truncations of L (n 2^-LF <= 2^-(Wf+3) in y) and of y (2^-EX = 2^-(Wf+3)), each moving f by
// ln 2 times; the roundings of the table entries and the floor of the exp interpolation, 1.5 units of
// 2^-EF; the log table's rounding, relative 2^-GF, below 2^-20 LSB here (neglected).
double expLogBoundLsb(const SpecUnitParams& p) {
  const ExpLogWidths w = p.expLogWidths();
  const double one = std::ldexp(1.0, p.SpecFracBits), ln2 = std::log(2.0);
  const double hl = std::ldexp(1.0, -(p.TableBits + 1)), he = std::ldexp(1.0, -p.TableBits);
  const double log_interp = 4.4585 * hl * hl / 8 / (1 / ln2) / std::exp(1.0);
  const double exp_interp = ln2 * ln2 * he * he / 8;
  const double truncs = 2 * ln2 * std::ldexp(1.0, -(p.SpecFracBits + 3));
  return 0.5 + (log_interp + exp_interp + truncs + 1.5 * std::ldexp(1.0, -w.EF)) * one;
}

TEST(SpecKindExpLog, EveryInputIsThePowerWithinItsBound) {
  for (int T : {4, 6, 11}) {
    SpecUnitParams p = expLogParams();
    p.TableBits = T;
    const PromTable t = build(p, "1,1.5,37.25,1000");
    const SpecUnitModel m(p, t.words, t.seg_words);
    const double bound = expLogBoundLsb(p);
    double worst = 0;
    for (const PromEntry& e : t.entries) {
      EXPECT_EQ(e.code.u, static_cast<int64_t>(std::ldexp(e.n, p.CoefFracBits)));
      for (uint32_t cos = 0; cos < (2u << p.CosFracBits); ++cos) {
        const long double c = std::ldexp(static_cast<long double>(std::min<int64_t>(cos, p.cosOne())), -p.CosFracBits);
        const SpecOut o = m.evaluate(e.address, cos, kFull);
        const double err = static_cast<double>(std::fabs(o.spec - std::ldexp(std::pow(c, static_cast<long double>(e.n)), p.SpecFracBits)));
        ASSERT_LE(err, bound) << "T " << T << " n " << e.n << " cos " << cos;
        worst = std::max(worst, err);
        ASSERT_EQ(m.trace(e.address, cos).f.raw(), o.spec);
      }
    }
    // The bound's terms peak at different inputs, so it is not reached; it stays within a factor
    // of two (worst/bound: 0.61, 0.70, 0.85 for T = 4, 6, 11).
    EXPECT_GT(worst, bound / 2) << "T " << T;
  }
  // Padding holds n = 0: f = 1 above c = 0, 0 at c = 0.
  const SpecUnitModel m(expLogParams(), build(expLogParams(), "8").words);
  EXPECT_EQ(m.evaluate(7, 1234, kFull).spec, 1u << expLogParams().SpecFracBits);
  EXPECT_EQ(m.evaluate(7, 0, kFull).spec, 0u);
}

// Each segment's polynomial in the unit's integers against the real fit it came from, at every
// cosine code: the difference is the final rounding (1/2 LSB of f), the coefficients' rounding
// (half a unit of 2^-Kf each, u^j <= 1) and Horner's floors (one unit of 2^-Kf per step), so
// at most 1/2 + 2^(Wf-Kf) ((d+1)/2 + d) LSB; below the cut both are 0. The whole-lobe error
// against c^n (long double) is then within the fit's own error plus that bound.
TEST(SpecKindPiecewise, EveryInputIsItsSegmentsPolynomialWithinItsBound) {
  for (int segments : {1, 2, 4})
    for (int degree : {1, 2, 3}) {
      SpecUnitParams p = piecewiseParams();
      p.Segments = segments;
      p.Degree = degree;
      p.PipeStages = 1;
      p.CoefIntBits = 6;  // one segment, or a cubic, needs coefficients beyond [-2, 2) (up to 14)
      const PromTable t = build(p, "1,8,100,1000");
      const SpecUnitModel m(p, t.words, t.seg_words);
      const double lsb = std::ldexp(1.0, -p.SpecFracBits);
      const double bound = 0.5 + std::ldexp((degree + 1) / 2.0 + degree, p.SpecFracBits - p.CoefFracBits);
      for (const PromEntry& e : t.entries) {
        const PiecewiseFit& fit = *e.approx.pieces;
        double worst = 0, worst_lobe = 0;
        for (uint32_t c = 0; c <= static_cast<uint32_t>(p.cosOne()); ++c) {
          const double x = std::ldexp(static_cast<double>(c), -p.CosFracBits);
          const double f = m.evaluate(e.address, c, kFull).spec * lsb;
          worst = std::max(worst, std::fabs(f - e.approx.eval(x)) / lsb);
          worst_lobe = std::max(worst_lobe, static_cast<double>(std::fabs(f - std::pow(static_cast<long double>(x), e.n))));
        }
        EXPECT_LE(worst, bound) << "S " << segments << " d " << degree << " n " << e.n;
        EXPECT_LE(worst_lobe, fit.err + bound * lsb) << "S " << segments << " d " << degree << " n " << e.n;
        EXPECT_LE(fit.segments.size(), static_cast<size_t>(segments));
      }
    }
}

TEST(SpecKindPiecewise, MalformedSegmentWordsAreRefused) {
  const SpecUnitParams p = piecewiseParams();
  const PromTable t = build(p, "8,100");
  EXPECT_NO_THROW(SpecUnitModel(p, t.words, t.seg_words));
  EXPECT_THROW(SpecUnitModel(p, t.words), std::invalid_argument);  // no segment ROM
  const int cw = p.CosFracBits + 1;
  // First codes that decrease: B_1 above B_2 at address 1.
  std::vector<PromWord> words = t.words;
  const PromWord field = (PromWord{1} << cw) - 1;
  const PromWord b2 = (words[1] >> (2 * cw)) & field;
  words[1] = (words[1] & ~(field << cw)) | ((b2 + 1) << cw);
  EXPECT_THROW(SpecUnitModel(p, words, t.seg_words), std::invalid_argument);
  // A scale above CosFracBits, and one that carries u past 1.0 in the top segment.
  std::vector<PromWord> seg = t.seg_words;
  const PromWord scale = (PromWord{1} << p.segScaleBits()) - 1;
  seg[4 * 1 + 3] = (seg[4 * 1 + 3] & ~scale) | PromWord{static_cast<uint64_t>(p.CosFracBits + 1)};
  EXPECT_THROW(SpecUnitModel(p, t.words, seg), std::invalid_argument);
  seg = t.seg_words;
  const int e = static_cast<int>(static_cast<uint64_t>(seg[4 * 1 + 3] & scale));
  ASSERT_LT(e, p.CosFracBits);
  seg[4 * 1 + 3] = (seg[4 * 1 + 3] & ~scale) | PromWord{static_cast<uint64_t>(e + 1)};
  EXPECT_THROW(SpecUnitModel(p, t.words, seg), std::invalid_argument);
  // The padding words: every B = 0 and zero coefficients give f = 0.
  const SpecUnitModel m(p, t.words, t.seg_words);
  for (uint32_t c : {0u, 1u, 1000u, static_cast<uint32_t>(p.cosOne())}) EXPECT_EQ(m.evaluate(7, c, kFull).spec, 0u);
}

TEST(SpecKinds, PipelineLatencyIsTwoPlusPipeStages) {
  for (const SpecUnitParams& p : {tableParams(), schlickParams(), expLogParams(), piecewiseParams()}) {
    const PromTable t = build(p, "8");
    SpecUnitModel m(p, t.words, t.seg_words);
    SpecIn in;
    in.valid = true;
    in.shin = 0;
    in.cos = static_cast<uint32_t>(p.cosOne());
    in.light = kFull;
    int ticks = 1;
    for (SpecOut o = m.tick(in); !o.valid; o = m.tick(SpecIn{})) ++ticks;
    EXPECT_EQ(ticks, p.latency()) << specKindInfo(p.kind()).name;
  }
}

TEST(SpecKinds, ParametersAndFitMustSuitTheKind) {
  SpecUnitParams p = tableParams();
  p.TableBits = p.CosFracBits + 1;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = tableParams();
  p.PipeStages = 2;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = schlickParams();
  p.PipeStages = p.SpecFracBits + 2;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.Kind = static_cast<int>(specKinds().size());
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = expLogParams();
  p.PipeStages = 0;  // the exp table's read is a register rank
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p = expLogParams();
  p.TableBits = p.SpecFracBits + 4;
  p.CosFracBits = p.TableBits;
  EXPECT_THROW(p.validate(), std::invalid_argument);
  p.TableBits = p.SpecFracBits + 3;
  EXPECT_NO_THROW(p.validate());
  for (auto [degree, segments, pipe, kf] : {std::array<int, 4>{4, 4, 1, 18}, {0, 4, 1, 18}, {2, 3, 1, 18},
                                            {2, 8, 1, 18}, {2, 4, 0, 18}, {2, 4, 4, 18}, {2, 4, 1, 13}}) {
    p = piecewiseParams();
    p.Degree = degree;
    p.Segments = segments;
    p.PipeStages = pipe;
    p.CoefFracBits = kf;
    EXPECT_THROW(p.validate(), std::invalid_argument) << degree << " " << segments << " " << pipe << " " << kf;
  }
  EXPECT_NO_THROW(piecewiseParams().validate());
  // exact is the fit of the kinds other than poly, and only theirs.
  PromRequest r;
  r.n = NSpec::parse("8", true);
  r.fit = FitKind::Inflection;
  EXPECT_THROW(buildPromTable(r, schlickParams()), std::invalid_argument);
  r.fit = FitKind::Exact;
  EXPECT_THROW(buildPromTable(r, SpecUnitParams{}), std::invalid_argument);
  EXPECT_THROW(buildPromTable(r, piecewiseParams()), std::invalid_argument);  // piecewise: minimax only
  r.fit = FitKind::Minimax;
  EXPECT_THROW(buildPromTable(r, expLogParams()), std::invalid_argument);
  // Coefficients beyond [-1, 1): CoefIntBits 1 cannot hold the quadratics' (they need 2).
  SpecUnitParams narrow = piecewiseParams();
  narrow.CoefIntBits = 1;
  r.n = NSpec::parse("1,8,100,1000", true);
  EXPECT_THROW(buildPromTable(r, narrow), std::invalid_argument);
  // More n than shininess codes: the table's depth counts cosine buckets too, not more n.
  EXPECT_THROW(build(tableParams(), "1,2,3,4,5"), std::invalid_argument);
}

TEST(SpecKinds, PromFilesRoundTrip) {
  for (const SpecUnitParams& p : {tableParams(), schlickParams(), expLogParams(), piecewiseParams()}) {
    const PromTable t = build(p, "1,8,100");
    const std::string csv = renderProm(t, PromFormat::Csv);
    size_t rows = p.kind() == SpecKind::Table ? 3u << p.TableBits : 3u;
    if (p.kind() == SpecKind::Piecewise) {
      rows = 0;
      for (const PromEntry& e : t.entries) rows += e.approx.pieces->segments.size();
    }
    EXPECT_EQ(static_cast<size_t>(std::count(csv.begin(), csv.end(), '\n')), rows + 1);
    for (PromFormat f : {PromFormat::Hex, PromFormat::Mem, PromFormat::Coe, PromFormat::Mif}) {
      const PromFiles files = renderPromFiles(t, f);
      ASSERT_EQ(files.size(), p.kind() == SpecKind::Piecewise ? 2u : 1u);
      for (const auto& [suffix, text] : files) EXPECT_NE(text.find(specKindInfo(p.kind()).name), std::string::npos);
    }
  }
  // The hex files of the piecewise kind read back to both memories' words.
  const PromTable t = build(piecewiseParams(), "1,8,100");
  const std::string path = ::testing::TempDir() + "/piecewise_roundtrip.hex";
  writePromHexFiles(path, t);
  EXPECT_EQ(romImageDiff(readPromHexFiles(path, t.unit), RomImage::of(t), t.unit), "");
  std::remove(path.c_str());
  std::remove((path + kSegRomSuffix).c_str());
}
