// test_bounds: the measured side of scripts/bounds.py, which sets it beside the proved bounds
// (Sollya, Gappa) and fails when a measured error exceeds its proof (docs/proved-bounds.md).
// It prints one JSON object on stdout; it proves nothing itself.
//
//   test_bounds spec CONFIG        every PROM entry of a specular configuration, at every cos code
//   test_bounds span CONFIG [--triangles N] [--seed S]   generated triangles through the span unit
//   test_bounds nh [--samples N] [--seed S] [--lobe-n 8,32]   phong-fixed's N.H and lobe
//
// spec: the ideal device is f*(c) = clamp01(c + (c^2 - c)(u c + v)), 0 below the cut code, with
//   the coefficients AS STORED (u = a or a1, v = a1 + b1, exact dyadic rationals; degree 2:
//   u = 0, v = a). Per entry:
//     approx_cont  sup over c in [0, 1] of |f* - c^n|, the model's exact maxima (lobe_error.h
//                  maxErrorExact on the stored coefficients and cut)
//     approx_disc  max over the cos codes of |f* - c^n| (long double)
//     dp_f, dp_out the signed datapath error at every cos code, EXACT (128-bit integers): the
//                  unit's spec_o minus f*, and its colour output at full light L minus L f*,
//                  as num * 2^-exp; min and max
//     total        max over the cos codes of |out - L c^n| (long double), as spec-error's total
//   Codes above 1.0 saturate to 1.0 in the unit and the ideal device alike, so 0..2^Wc covers
//   every input.
// span: the fragments of the configuration's lane mode (walkSpanUnit, bit-exact to
//   SpanUnitModel) against the exact plane of the snapped vertex codes, exactly (err * 2 det is
//   an integer); the worst error in codes, in output LSBs, and against the per-pixel bound
//   0.5 (1 + |px - xref| + |py - yref|).
// nh: rsqrtCore<10> at both ends of every seed interval (where the Newton step's error peaks),
//   the seed table (for the proof), and random normals and half vectors through the datapath
//   of fixed_shading.h (dot58, cosineScale, scaleCosine, lobeAt) against long double.
#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <iostream>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "approx/brdf.h"
#include "approx/lobe_error.h"
#include "config/registry.h"
#include "device/prom.h"
#include "device/spec_unit.h"
#include "raster/setup.h"
#include "raster/span_unit.h"
#include "raster/trigen.h"
#include "render/fixed_shading.h"
#include "render/normalize.h"

namespace {

using namespace shd;
using i128 = __int128;
using json = nlohmann::json;

std::string toString(i128 v) {
  if (v == 0) return "0";
  const bool neg = v < 0;
  unsigned __int128 u = neg ? static_cast<unsigned __int128>(-(v + 1)) + 1 : static_cast<unsigned __int128>(v);
  std::string s;
  while (u != 0) {
    s.insert(s.begin(), static_cast<char>('0' + static_cast<int>(u % 10)));
    u /= 10;
  }
  return neg ? "-" + s : s;
}

// An exact dyadic value num * 2^-exp, and its double for people.
json dyadic(i128 num, int exp) {
  return {{"num", toString(num)}, {"exp", exp}, {"value", std::ldexp(static_cast<double>(num), -exp)}};
}

// Signed extremes of an exact error num * 2^-exp.
struct Extremes {
  i128 lo = 0, hi = 0;
  int64_t lo_at = 0, hi_at = 0;
  void add(i128 e, int64_t at) {
    if (e < lo) lo = e, lo_at = at;
    if (e > hi) hi = e, hi_at = at;
  }
};

json specMeasure(const std::string& config) {
  const SpecUnitConfig cfg = specConfig(config);
  const SpecUnitParams& p = cfg.rtl;
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), p);
  const SpecUnitModel model(p, table.words, table.seg_words);
  const int wc = p.CosFracBits, cf = p.CoefFracBits, wf = p.SpecFracBits;
  const int64_t one = p.cosOne();
  const uint32_t L = static_cast<uint32_t>(p.lightMax());
  // f* = num * 2^-E: degree 2 c + v d with d = (k^2 - k 2^Wc) 2^-2Wc, v = V 2^-Cf: E = 2 Wc + Cf;
  // degree 3 d (U k + V 2^Wc) 2^-(Cf + Wc): E = 3 Wc + Cf. Check that every product fits 127
  // bits: |d num| <= 2^(2 Wc - 2), |g num| < 2^(KW + Wc + 1) (degree 2: 2^KW), and out 2^E,
  // L num with out, L < 2^LightBits once num is clamped to [0, 2^E].
  const int kw = p.coefFormat().width();
  const int E = p.Degree == 2 ? 2 * wc + cf : 3 * wc + cf;
  const int num_bits = (2 * wc - 2) + (p.Degree == 2 ? kw : kw + wc + 1) + 1;
  if (num_bits + p.LightBits + 1 > 126 || E + p.LightBits + 1 > 126 || E < wf)
    throw std::invalid_argument(fmt::format("spec {}: too wide for the exact 128-bit measurement", cfg.name));
  // Per entry: the stored coefficients, and the extremes over the cos codes. The codes are the
  // outer loop so that c^n steps by one multiplication from entry to entry when the shininess
  // list is consecutive integers (every registry PROM): 10^8 pow calls would take minutes.
  struct Acc {
    i128 U = 0, V = 0;
    int64_t cut = 0;
    bool step_from_prev = false;  // n = previous n + 1
    Extremes dpf, dpo;
    long double approx = 0, total = 0;
    int64_t approx_at = 0, total_at = 0;
  };
  std::vector<Acc> acc(table.entries.size());
  for (size_t i = 0; i < acc.size(); ++i) {
    const PromEntry& e = table.entries[i];
    acc[i].U = p.Degree == 2 ? 0 : e.code.u;
    acc[i].V = p.Degree == 2 ? e.code.u : e.code.v;
    acc[i].cut = p.Degree == 3 ? e.code.cut : 0;
    acc[i].step_from_prev = i > 0 && e.n == table.entries[i - 1].n + 1.0 && std::floor(e.n) == e.n;
  }
  const i128 den = i128{1} << E;
  const long double inv_den = std::ldexp(1.0L, -E);  // exact: fs = num 2^-E
  for (int64_t c = 0; c <= one; ++c) {
    const i128 dnum = i128{c} * c - (i128{c} << wc);
    const long double x = std::ldexp(static_cast<long double>(c), -wc);
    long double cn = 0;
    for (size_t i = 0; i < acc.size(); ++i) {
      Acc& a = acc[i];
      const double n = table.entries[i].n;
      cn = a.step_from_prev ? cn * x : std::pow(x, static_cast<long double>(n));
      i128 num = 0;  // f* * 2^E
      if (c >= a.cut) {
        num = p.Degree == 2 ? (i128{c} << (wc + cf)) + a.V * dnum
                            : (i128{c} << (2 * wc + cf)) + dnum * (a.U * c + a.V * (i128{1} << wc));
        num = num < 0 ? 0 : (num > den ? den : num);
      }
      const SpecOut o = model.evaluate(table.entries[i].address, static_cast<uint32_t>(c), {L, L, L});
      a.dpf.add((i128{o.spec} << (E - wf)) - num, c);
      a.dpo.add((i128{o.rgb[0]} << E) - i128{L} * num, c);
      const long double fs = static_cast<long double>(num) * inv_den;
      const long double ae = std::fabs(fs - cn), te = std::fabs(static_cast<long double>(o.rgb[0]) - L * cn);
      if (ae > a.approx) a.approx = ae, a.approx_at = c;
      if (te > a.total) a.total = te, a.total_at = c;
    }
  }
  json entries = json::array();
  for (size_t i = 0; i < acc.size(); ++i) {
    const PromEntry& e = table.entries[i];
    const Acc& a = acc[i];
    // The ideal device on the stored coefficients, for the model's exact maxima.
    Approx stored = p.Degree == 2 ? Approx::quadratic(std::ldexp(static_cast<double>(a.V), -cf))
                                  : Approx::cubic(std::ldexp(static_cast<double>(a.U), -cf),
                                                  std::ldexp(static_cast<double>(a.V - a.U), -cf));
    if (p.Degree == 3) stored.cut = std::ldexp(static_cast<double>(a.cut), -wc);
    const RegionError cont = maxErrorExact(stored, e.n, 0.0, 1.0, false);
    entries.push_back({
        {"n", e.n},
        {"address", e.address},
        {"u", static_cast<int64_t>(a.U)},
        {"v", static_cast<int64_t>(a.V)},
        {"cut", a.cut},
        {"approx_cont", cont.max_abs},
        {"approx_cont_c", cont.worst_abs_c},
        {"approx_disc", static_cast<double>(a.approx)},
        {"approx_disc_code", a.approx_at},
        {"dp_f_lo", dyadic(a.dpf.lo, E)},
        {"dp_f_hi", dyadic(a.dpf.hi, E)},
        {"dp_out_lo", dyadic(a.dpo.lo, E)},
        {"dp_out_hi", dyadic(a.dpo.hi, E)},
        {"dp_out_lo_code", a.dpo.lo_at},
        {"dp_out_hi_code", a.dpo.hi_at},
        {"total", static_cast<double>(a.total)},
        {"total_code", a.total_at},
    });
  }
  return {{"unit", "spec"}, {"config", cfg.name}, {"rtl", p.toJson()}, {"light_max", L}, {"entries", entries}};
}

json spanMeasure(const std::string& config, int triangles, uint64_t seed) {
  const SpanUnitConfig sc = spanConfig(config);
  RasterConfig rc;
  rc.unit = sc.rtl;
  rc.validate();
  TriGenOptions opt;
  opt.width = rc.width;
  opt.height = rc.height;
  opt.subpixel_bits = rc.subpixel_bits;
  opt.num_attr = sc.rtl.NumAttr;
  // More large and screen-filling triangles than the stream's default: they reach far from the
  // reference pixel, where the bound is largest.
  opt.size_weight = {0.2, 0.2, 0.3, 0.3, 0.001};
  TriangleGenerator gen(seed, opt);
  std::vector<SpanFragment> frags;
  const int K = sc.rtl.NumAttr, S = rc.subpixel_bits;
  const int f0 = defaultAttrFracBits(rc.width, rc.height, 0);
  std::vector<double> worst_codes(static_cast<size_t>(K), 0.0), worst_lsb(static_cast<size_t>(K), 0.0);
  double worst_ratio = 0;
  int64_t fragments = 0, worst_reach = 0, over_bound = 0;
  for (int t = 0; t < triangles; ++t) {
    const GenTriangle g = gen.next();
    std::array<SetupVertex, 3> v;
    for (size_t i = 0; i < 3; ++i) {
      v[i].x = g.v[i].x;
      v[i].y = g.v[i].y;
      for (int k = 0; k < K; ++k) v[i].attr.push_back(g.v[i].attr[static_cast<size_t>(k)]);
    }
    const SetupResult s = setupTriangle(v, g.id, rc);
    if (!s.desc) continue;
    // walkSpanUnit: the unit's fragments in its output order, bit-exact to SpanUnitModel
    // (test_span_unit compares them in every mode), without a cycle loop or an allocation per
    // triangle.
    frags.clear();
    walkSpanUnit(sc.rtl, *s.desc, frags);
    const SnappedTriangle& tri = s.tri;
    const i128 det = tri.det;
    for (const SpanFragment& f : frags) {
      ++fragments;
      const int64_t reach = std::llabs(f.x - s.plane.xref) + std::llabs(f.y - s.plane.yref);
      worst_reach = std::max(worst_reach, reach);
      const i128 cx = (2 * i128{f.x} + 1) << S, cy = (2 * i128{f.y} + 1) << S;
      for (int k = 0; k < K; ++k) {
        const auto& a = tri.a[static_cast<size_t>(k)];
        const i128 nx = i128{a[1] - a[0]} * (tri.Y[2] - tri.Y[0]) - i128{a[2] - a[0]} * (tri.Y[1] - tri.Y[0]);
        const i128 ny = i128{tri.X[1] - tri.X[0]} * (a[2] - a[0]) - i128{tri.X[2] - tri.X[0]} * (a[1] - a[0]);
        // err * 2 det = 2 det I - (2 det a0 + nx (cx - 2 X0) + ny (cy - 2 Y0)), in u = 2^-(S+1) px
        const i128 err2det = 2 * det * f.attr[static_cast<size_t>(k)] -
                             (2 * det * a[0] + nx * (cx - 2 * i128{tri.X[0]}) + ny * (cy - 2 * i128{tri.Y[0]}));
        const double codes = std::fabs(static_cast<double>(err2det)) / (2.0 * static_cast<double>(det));
        const size_t ks = static_cast<size_t>(k);
        worst_codes[ks] = std::max(worst_codes[ks], codes);
        worst_lsb[ks] = std::max(worst_lsb[ks], std::ldexp(codes, -f0));  // out LSB = 2^(F_k - f0) codes
        // the per-pixel bound 0.5 (1 + reach) codes: |err 2 det| <= det (1 + reach), exactly
        const i128 lim = det * (1 + reach);
        const i128 mag = err2det < 0 ? -err2det : err2det;
        worst_ratio = std::max(worst_ratio, static_cast<double>(mag) / static_cast<double>(lim));
        over_bound += mag > lim;  // exact: a ratio that rounds to 1 still counts
      }
    }
  }
  json attrs = json::array();
  for (int k = 0; k < K; ++k)
    attrs.push_back({{"attr", k},
                     {"frac_bits", rc.attrFracBits(k)},
                     {"out_frac_bits", rc.attrFracBits(k) - f0},
                     {"worst_codes", worst_codes[static_cast<size_t>(k)]},
                     {"worst_out_lsb", worst_lsb[static_cast<size_t>(k)]}});
  return {{"unit", "span"},
          {"config", sc.name},
          {"rtl", sc.rtl.toJson()},
          {"width", rc.width},
          {"height", rc.height},
          {"triangles", triangles},
          {"seed", seed},
          {"fragments", fragments},
          {"worst_reach", worst_reach},
          {"worst_ratio", worst_ratio},
          {"over_bound", over_bound},
          {"attrs", attrs}};
}

// Q1.30 codes of a direction, as FixedPointShader's unitCodes: round half away from zero.
std::array<int32_t, 3> unitCodes(const double* v) {
  auto c = [](double a) { return static_cast<int32_t>(std::lround(std::ldexp(a, kFixedUnitFrac))); };
  return {c(v[0]), c(v[1]), c(v[2])};
}

json nhMeasure(int samples, uint64_t seed, const std::vector<double>& lobe_n) {
  // 1. rsqrtCore<10> at the ends of every seed interval: the bottom and the top of the first
  //    and the last mq of the interval (mq = m >> 30, m = v with shift 0).
  constexpr int kSeed = kFixedSeedBits;
  const auto& seed_table = RsqrtSeed<kSeed>::table;
  constexpr long double kInf = std::numeric_limits<long double>::infinity();
  long double rho_lo = kInf, rho_hi = -kInf;
  auto rho = [](uint64_t v) {  // r 2^-32 sqrt(v 2^-62) for v in [2^60, 2^62)
    const RsqrtCore c = rsqrtCore<kSeed>(v);
    return std::ldexp(static_cast<long double>(c.r), -32) * std::sqrt(std::ldexp(static_cast<long double>(v), -62));
  };
  json table = json::array();
  for (size_t i = 0; i < seed_table.size(); ++i) {
    table.push_back(seed_table[i]);
    const uint64_t step = uint64_t{3} << (30 - kSeed);  // 3 2^30 / 2^SeedBits mq codes per entry
    const uint64_t mq_first = (uint64_t{1} << 30) + i * step, mq_last = mq_first + step - 1;
    for (uint64_t mq : {mq_first, mq_last})
      for (uint64_t low : {uint64_t{0}, (uint64_t{1} << 30) - 1}) {
        const long double r = rho((mq << 30) | low);
        rho_lo = std::min(rho_lo, r);
        rho_hi = std::max(rho_hi, r);
      }
  }
  // 2. Random normals (a direction times a length in [2^-8, 2^4), as 28-fraction-bit codes) and
  //    half vectors normalised in double, as the renderer makes them; the exact cosine takes
  //    the double components as they are.
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  long double nh_lo = kInf, nh_hi = -kInf;
  std::vector<std::shared_ptr<const LobeTable>> tables;
  for (double n : lobe_n) tables.push_back(lobeTable(Lobe::Blinn, n));
  std::vector<long double> lobe_lo(lobe_n.size(), kInf), lobe_hi(lobe_n.size(), -kInf);
  for (int s = 0; s < samples; ++s) {
    double h[3];
    long double nd[3];
    double hn = 0;
    long double nn = 0;
    for (int k = 0; k < 3; ++k) h[k] = gauss(rng), hn += h[k] * h[k];
    for (int k = 0; k < 3; ++k) nd[k] = gauss(rng), nn += nd[k] * nd[k];
    if (hn == 0 || nn == 0) continue;
    hn = std::sqrt(hn);
    for (double& x : h) x /= hn;
    // Half of the samples near the lobe's peak: N close to H.
    if (s % 2 == 0)
      for (int k = 0; k < 3; ++k) nd[k] = h[k] + 0.05L * nd[k] / std::sqrt(nn);
    const double len = std::exp2(-8.0 + 12.0 * uni(rng));
    long double m2 = 0;
    for (long double x : nd) m2 += x * x;
    int64_t n28[3];
    for (int k = 0; k < 3; ++k)
      n28[k] = std::llround(std::ldexp(static_cast<double>(nd[k] / std::sqrt(m2) * len), 28));
    const unsigned __int128 sq = static_cast<unsigned __int128>(static_cast<i128>(n28[0]) * n28[0] +
                                                                static_cast<i128>(n28[1]) * n28[1] +
                                                                static_cast<i128>(n28[2]) * n28[2]);
    if (sq == 0 || (sq >> 64) != 0) continue;
    const uint64_t sqnorm = static_cast<uint64_t>(sq);
    const std::array<int32_t, 3> hq = unitCodes(h);
    const int64_t nh = scaleCosine(fixed_detail::dot58(n28, hq), cosineScale(sqnorm));
    // exact: N.h / |N| with the unit h, in long double
    const long double norm = std::sqrt(static_cast<long double>(sqnorm));
    const long double exact = (n28[0] * static_cast<long double>(h[0]) + n28[1] * static_cast<long double>(h[1]) +
                               n28[2] * static_cast<long double>(h[2])) / norm;
    const long double err = std::ldexp(static_cast<long double>(nh), -32) - exact;
    nh_lo = std::min(nh_lo, err);
    nh_hi = std::max(nh_hi, err);
    for (size_t i = 0; i < tables.size(); ++i) {
      const uint32_t f = fixed_detail::lobeAt(tables[i]->code.data(), nh);
      const long double ex = exact > 0 ? std::pow(std::min(exact, 1.0L), static_cast<long double>(lobe_n[i])) : 0.0L;
      const long double le = std::ldexp(static_cast<long double>(f), -24) - ex;
      lobe_lo[i] = std::min(lobe_lo[i], le);
      lobe_hi[i] = std::max(lobe_hi[i], le);
    }
  }
  json lobes = json::array();
  for (size_t i = 0; i < lobe_n.size(); ++i)
    lobes.push_back({{"lobe", "blinn"}, {"n", lobe_n[i]}, {"lo", static_cast<double>(lobe_lo[i])},
                     {"hi", static_cast<double>(lobe_hi[i])}});
  return {{"unit", "nh"},
          {"seed_bits", kSeed},
          {"seed_table", table},
          {"rho_minus_1_lo", static_cast<double>(rho_lo - 1)},
          {"rho_minus_1_hi", static_cast<double>(rho_hi - 1)},
          {"samples", samples},
          {"seed", seed},
          {"nh_lo", static_cast<double>(nh_lo)},
          {"nh_hi", static_cast<double>(nh_hi)},
          {"lobes", lobes}};
}

[[noreturn]] void usage(const std::string& why) {
  std::cerr << "test_bounds: " << why
            << "\nusage: test_bounds spec CONFIG | span CONFIG [--triangles N] [--seed S] |"
               " nh [--samples N] [--seed S] [--lobe-n 8,32]\n";
  std::exit(2);
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    if (args.empty()) usage("no subcommand");
    const std::string cmd = args[0];
    std::string config;
    int count = -1;
    uint64_t seed = 1;
    std::vector<double> lobe_n{32};
    for (size_t i = 1; i < args.size(); ++i) {
      auto value = [&]() -> const std::string& {
        if (i + 1 >= args.size()) usage(args[i] + " needs a value");
        return args[++i];
      };
      if (args[i] == "--triangles" || args[i] == "--samples") {
        count = std::stoi(value());
      } else if (args[i] == "--seed") {
        seed = std::stoull(value());
      } else if (args[i] == "--lobe-n") {
        lobe_n.clear();
        const std::string& list = value();
        size_t pos = 0;
        while (pos <= list.size()) {
          const size_t comma = std::min(list.find(',', pos), list.size());
          lobe_n.push_back(std::stod(list.substr(pos, comma - pos)));
          pos = comma + 1;
        }
      } else if (config.empty() && args[i].rfind("--", 0) != 0) {
        config = args[i];
      } else {
        usage("unknown argument " + args[i]);
      }
    }
    json out;
    if (cmd == "spec") {
      if (config.empty()) usage("spec needs a configuration");
      out = specMeasure(config);
    } else if (cmd == "span") {
      if (config.empty()) usage("span needs a configuration");
      out = spanMeasure(config, count < 0 ? 20000 : count, seed);
    } else if (cmd == "nh") {
      out = nhMeasure(count < 0 ? 1000000 : count, seed, lobe_n);
    } else {
      usage("unknown subcommand " + cmd);
    }
    std::cout << out.dump() << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "test_bounds: " << e.what() << "\n";
    return 1;
  }
}
