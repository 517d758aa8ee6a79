#include "device/spec_explog.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace shd {

namespace {

using u128 = unsigned __int128;
constexpr int kQ = 60;
constexpr u128 kOne = u128{1} << kQ;
constexpr u128 kLog2eQ = 1663314137230540311ULL;  // floor(log2(e) 2^60)
constexpr u128 kLn2Q = 799144290325165978ULL;     // floor(ln(2) 2^60)

int64_t roundTo(u128 q60, int frac) {
  return static_cast<int64_t>((q60 + (u128{1} << (kQ - frac - 1))) >> (kQ - frac));
}

int64_t logCode(int64_t i, int T, int GF) {
  const u128 d = static_cast<u128>(i) << (kQ - T - 1);
  u128 sum = 0, term = kOne;
  for (int k = 0; k < 62; ++k) {
    sum += term / static_cast<u128>(k + 1);
    term = (term * d) >> kQ;
  }
  return roundTo((sum * kLog2eQ) >> kQ, GF);
}

int64_t expCode(int64_t j, int T, int EF) {
  const u128 z = ((static_cast<u128>(j) << (kQ - T)) * kLn2Q) >> kQ;
  u128 pos = 0, neg = 0, term = kOne;
  for (int k = 0; k < 30; ++k) {
    (k % 2 == 0 ? pos : neg) += term;
    term = ((term * z) >> kQ) / static_cast<u128>(k + 1);
  }
  return roundTo(pos - neg, EF);
}

int bitLength(int64_t v) {
  int b = 0;
  while (v >> b) ++b;
  return b;
}

}  // namespace

ExpLogTables makeExpLogTables(const SpecUnitParams& p) {
  const ExpLogWidths w = p.expLogWidths();
  const int T = p.TableBits;
  ExpLogTables t;
  t.w = w;
  for (int64_t i = 0; i <= (int64_t{1} << T); ++i) {
    t.g.push_back(logCode(i, T, w.GF));
    t.e.push_back(expCode(i, T, w.EF));
  }
  for (size_t i = 0; i + 1 < t.g.size(); ++i) {
    const int64_t dg = t.g[i + 1] - t.g[i], de = t.e[i] - t.e[i + 1];
    if (dg < 0 || bitLength(dg) > w.gStepBits(T) || de < 0 || bitLength(de) > w.eStepBits(T))
      throw std::logic_error(fmt::format("explog table step {} ({}, {}) outside its {}/{}-bit field", i, dg, de,
                                         w.gStepBits(T), w.eStepBits(T)));
  }
  return t;
}

int64_t expLogSpec(const SpecUnitParams& p, const ExpLogTables& t, int64_t n_code, int64_t c) {
  const ExpLogWidths& w = t.w;
  const int wc = p.CosFracBits, cw = wc + 1, T = p.TableBits;
  if (c == 0) return 0;                                    // log2 0: f = 0
  // Cycle 0: c = 2^(1-z) u with u = M / 2^CW in [1/2, 1); D = 1 - u = DN / 2^CW in (0, 1/2].
  const int z = cw - bitLength(c);
  const int64_t dn = (int64_t{1} << cw) - ((c << z) & ((int64_t{1} << cw) - 1));
  const int64_t i = std::min<int64_t>(dn >> (wc - T), (int64_t{1} << T) - 1);  // log ROM address
  const int64_t r = dn - (i << (wc - T));
  // Stage A: G = g(D) interpolated, P = D G = -log2 u.
  const int64_t G = t.g[i] + (((t.g[i + 1] - t.g[i]) * r) >> (wc - T));
  const int64_t P = dn * G;                                // CW + GF fraction bits
  // Stage B: L = -log2 c = (z - 1) + P, y = n L.
  const int64_t L = c == p.cosOne() ? 0 : (int64_t{z - 1} << w.LF) + (P >> (cw + w.GF - w.LF));
  const int64_t y = n_code * L;                            // Cf + LF fraction bits
  const int yfrac = p.CoefFracBits + w.LF;
  const int64_t ys = std::min<int64_t>(y >> yfrac, p.SpecFracBits + 2);
  const int64_t yfx = (y >> (yfrac - w.EX)) & ((int64_t{1} << w.EX) - 1);
  const int64_t j = yfx >> (w.EX - T);                     // exp ROM address
  const int64_t r2 = yfx & ((int64_t{1} << (w.EX - T)) - 1);
  // Stage C: E = 2^-frac(y) interpolated, f = E 2^-floor(y) rounded half up to Wf bits.
  const int64_t E = t.e[j] - (((t.e[j] - t.e[j + 1]) * r2) >> (w.EX - T));
  const int64_t s = w.EF - p.SpecFracBits + ys;
  return (E + (int64_t{1} << (s - 1))) >> s;
}

}  // namespace shd
