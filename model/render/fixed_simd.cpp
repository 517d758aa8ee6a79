#include "render/fixed_simd.h"

#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "render/fixed_shading.h"
#include "render/normalize.h"
#include "render/pipeline.h"
#include "render/x86_targets.h"

namespace shd::fixed_simd {

namespace {
// A triangle of one colour (flat's): its colour codes' gradients 0.
bool oneColour(const RowSpans& s) {
  return (s.didx[0] | s.didx[1] | s.didx[2] | s.didy[0] | s.didy[1] | s.didy[2]) == 0;
}

// shadeNh's loop: the groups of 8 of n fragments, group(i, count) shading fragments i .. i +
// count - 1 (false: it declines them); returns the groups declined. Inlined into each kernel
// with the kernel's group, a lambda with the kernel's target.
template <class Group>
[[gnu::always_inline]] inline uint64_t eachGroup(size_t n, Group group) {
  uint64_t declined = 0;
  for (size_t g = 0; g * 8 < n; ++g)
    if (!group(g * 8, static_cast<int>(std::min<size_t>(8, n - g * 8)))) declined |= uint64_t{1} << g;
  return declined;
}

// A later pass of shadeNh's: shade(i, count, codes) for each group not declined, codes a
// std::bool_constant (kCodes: the kernel stores the codes).
template <bool kCodes, class Shade>
[[gnu::always_inline]] inline void shadePass(size_t n, uint64_t declined, Shade& shade) {
  for (size_t g = 0; g * 8 < n; ++g)
    if (((declined >> g) & 1) == 0)
      shade(g * 8, static_cast<int>(std::min<size_t>(8, n - g * 8)), std::bool_constant<kCodes>{});
}
// shadeNh's three passes: scale(i, count) for every group (eachGroup's group), then, each for
// every group not declined (shadePass), lobe(i, count, std::false_type) and colour(i, count,
// codes) (codes: with codes, the caller wants them). Returns the groups declined. n is at most
// kMaxBatch (the kernels' arrays).
template <class Scale, class Lobe, class Colour>
[[gnu::always_inline]] inline uint64_t threePasses(size_t n, bool codes, Scale scale, Lobe lobe, Colour colour) {
  if (n > kMaxBatch) throw std::logic_error("fixed_simd: a batch of more than kMaxBatch fragments");
  const uint64_t declined = eachGroup(n, scale);
  shadePass<false>(n, declined, lobe);
  if (codes)
    shadePass<true>(n, declined, colour);
  else
    shadePass<false>(n, declined, colour);
  return declined;
}

// A triangle's rows' spans as its runs (NhSpans): the dot products and the squared-norm terms of
// row i's first pixel from the triangle's, the runs buffered by buffer(run, first fragment) from
// `at` on. Where a row's run stops (the batch full), `at` is left at its next fragment.
// The dot products are linear mod 2^64 (dot58 is a sum of products mod 2^64), so at the row's
// first pixel, RowSpans::at(k, lo, i) = a0 + u didx + i didy with u = lo - x0, N.L is
// a0.L + u (didx.L) + i (didy.L), each mod 2^64: the values batchRun takes from dot58 of the
// codes there.
template <class Buffer>
[[gnu::always_inline]] inline bool eachSpanRun(const NhSpans& r, SpanCursor& at, Buffer buffer) {
  const RowSpans& s = *r.s;
  auto dot = [](const std::array<int64_t, 4>& n, const std::array<int32_t, 3>& u) {
    return static_cast<uint64_t>(fixed_detail::dot58(n.data(), u));
  };
  const uint64_t l0 = dot(s.a0, r.l), lx = dot(s.didx, r.l), ly = dot(s.didy, r.l);
  const uint64_t h0 = dot(s.a0, r.h), hx = dot(s.didx, r.h), hy = dot(s.didy, r.h);
  const std::array<int64_t, 3> dn{s.didx[0], s.didx[1], s.didx[2]};
  Run run;
  run.dl = lx;
  run.dh = hx;
  run.px.dz = static_cast<uint32_t>(s.didx[3]);
  for (; at.row < s.rows; ++at.row, at.k = 0) {
    const int32_t i = at.row;
    const int64_t lo = s.span[static_cast<size_t>(i)][0], hi = s.span[static_cast<size_t>(i)][1];
    if (lo > hi || ((r.rows >> i) & 1) == 0) continue;
    const uint64_t u = static_cast<uint64_t>(lo - s.x0), iu = static_cast<uint64_t>(i);
    const SquaredNormRecurrence::Terms sq =
        SquaredNormRecurrence::terms({s.at(0, lo, i), s.at(1, lo, i), s.at(2, lo, i)}, dn);
    run.a = sq.a;
    run.two_b = sq.two_b;
    run.c = sq.c;
    run.l = l0 + u * lx + iu * ly;
    run.h = h0 + u * hx + iu * hy;
    run.px.p = static_cast<size_t>(s.y0 + i) * r.W + static_cast<size_t>(lo);
    run.px.count = static_cast<size_t>(hi - lo + 1);
    run.px.z = static_cast<uint32_t>(s.at(3, lo, i));
    run.room = r.W - static_cast<size_t>(lo);
    at.k = buffer(run, at.k);
    if (at.k < run.px.count) return false;
  }
  return true;
}

}  // namespace

#ifdef SHD_X86_KERNELS

// GCC 12's AVX-512 headers pass _mm512_undefined_epi32() as the unused merge source of the
// unmasked shift and multiply intrinsics, which -Wuninitialized reports at every use (GCC bug
// 105593); the values are never read. Silenced for this file's kernel only.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wuninitialized"
#ifndef __clang__
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"  // GCC's own: clang has no such group
#endif

bool cpuHasAvx512() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
                          __builtin_cpu_supports("avx512cd") && __builtin_cpu_supports("avx512vl") &&
                          __builtin_cpu_supports("avx512bw");
  return yes;
}
bool cpuHasAvx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}
static bool envSet(const char* name) { return std::getenv(name) != nullptr; }
// SHD_SCALAR: the scalar paths; SHD_NO_AVX512: the AVX2 kernels on a CPU with AVX-512, as a CPU
// without it runs them.
bool available() {
  static const bool yes = cpuHasAvx512() && !envSet("SHD_SCALAR") && !envSet("SHD_NO_AVX512");
  return yes;
}
bool availableAvx2() {
  static const bool yes = cpuHasAvx2() && !envSet("SHD_SCALAR");
  return yes;
}

namespace {

// (a b + 2^63) >> 64 for unsigned a and b, lane by lane, from 32 x 32 products: with a = ah 2^32 +
// al, b = bh 2^32 + bl, t = al bl, u = ah bl + (t >> 32) and v = al bh + (u mod 2^32), a b is
// (ah bh + (u >> 32)) 2^64 + v 2^32 + (t mod 2^32), so the low word's top bit, the carry of
// the rounding, is bit 31 of v, and (v >> 32) plus that bit is (v + 2^31) >> 32 (v + 2^31 <
// 2^64: v <= (2^32 - 1)^2 + 2^32 - 1 = 2^64 - 2^32).
SHD_AVX512 inline __m512i mulHiRoundU64(__m512i a, __m512i b) {
  const __m512i low32 = _mm512_set1_epi64(0xFFFFFFFF);
  const __m512i ah = _mm512_srli_epi64(a, 32), bh = _mm512_srli_epi64(b, 32);
  const __m512i t = _mm512_mul_epu32(a, b);                                              // al bl
  const __m512i u = _mm512_add_epi64(_mm512_mul_epu32(ah, b), _mm512_srli_epi64(t, 32));  // ah bl + (al bl >> 32)
  const __m512i v = _mm512_add_epi64(_mm512_mul_epu32(a, bh), _mm512_and_si512(u, low32));  // al bh + low(u)
  return _mm512_add_epi64(_mm512_add_epi64(_mm512_mul_epu32(ah, bh), _mm512_srli_epi64(u, 32)),
                          _mm512_srli_epi64(_mm512_add_epi64(v, _mm512_set1_epi64(int64_t{1} << 31)), 32));
}

// scaleCosine's fast path: (d r64 + 2^63) >> 64 for signed d and 0 <= r64 < 2^63: the unsigned
// product's, less r64 where d < 0 (the signed product is the unsigned one less r64 2^64 there).
SHD_AVX512 inline __m512i scaleCosines(__m512i d, __m512i r64) {
  const __mmask8 neg = _mm512_cmplt_epi64_mask(d, _mm512_setzero_si512());
  const __m512i rounded = mulHiRoundU64(d, r64);
  return _mm512_mask_sub_epi64(rounded, neg, rounded, r64);
}

// (x + 2^(s-1)) >> s, arithmetic: fixed_detail::roundShift.
template <int S>
SHD_AVX512 inline __m512i roundShift(__m512i x) {
  return _mm512_srai_epi64(_mm512_add_epi64(x, _mm512_set1_epi64(int64_t{1} << (S - 1))), S);
}

// Bit i of a 4-bit mask spread to bits 3i .. 3i + 2: the byte mask of 4 packed RGB pixels.
constexpr std::array<uint16_t, 16> kSpread3 = [] {
  std::array<uint16_t, 16> t{};
  for (unsigned m = 0; m < 16; ++m)
    for (unsigned i = 0; i < 4; ++i)
      if ((m >> i) & 1) t[m] = static_cast<uint16_t>(t[m] | (7u << (3 * i)));
  return t;
}();

// shadeNh works in three passes over its fragments, each group of 8 in each:
//   scaleGroup   the squared norm's cosine scale r64 (rsqrtCore and cosineScale), or the group
//                declined;
//   lobeGroup    from r64 and the dot products, the scaled N.L and the lobe table's entries
//                at N.H (its gather);
//   colourGroup  from those, the colours.
// One pass doing all left the processor waiting on the lobe table's gather (a third of the
// kernel's samples on the instruction after it): a group's chain of dependent operations, from
// its squared norm through the seed's lookup, the products with r64 and the gather to its
// stores, is longer than the out-of-order window holds of the groups behind it. Split, each
// pass's groups overlap: on an AMD EPYC (family 26) the first split (scales, then the rest)
// took a phong-fixed frame of builtin:sphere to 0.89 of its time, the AVX2 kernel's frame to
// 0.91; the gather ending a pass of its own took the AVX2 frame to 0.93 of that, the
// AVX-512 one to 0.96-0.98 (docs/performance.md, "What makes a frame fast").
// Each inlines into its pass's loop, where the compiler keeps the broadcast constants out of
// the loop. Lanes past n compute on whatever their entries hold; they read no table (masked
// gathers) and their results are not stored.

// The cosine scale r64 of each of the n <= 8 squared norms at sq, stored at r64_out; false
// (nothing stored) when a fragment needs the scalar path.
SHD_AVX512 inline bool scaleGroup(const uint64_t* sq, int n, uint64_t* r64_out) {
  const __mmask8 valid = static_cast<__mmask8>((1u << n) - 1);
  const __m512i v = _mm512_loadu_si512(sq);

  // rsqrtCore<10> on squared norms in [2^32, 2^62) (the others declined, as shadeNhAvx2's
  // scaleLanes4 declines them): bits = 64 - lzcnt, shift = (62 - bits) / 2 = (lzcnt - 2) / 2 in
  // [0, 14], never the shift down; s = 61 - shift >= 35, cosineScale's fast path.
  const __mmask8 outside = _mm512_cmplt_epu64_mask(v, _mm512_set1_epi64(static_cast<int64_t>(kVectorSqFrom))) |
                           _mm512_cmpge_epu64_mask(v, _mm512_set1_epi64(static_cast<int64_t>(kVectorSqBelow)));
  if ((outside & valid) != 0) return false;
  const __m512i shift = _mm512_srli_epi64(_mm512_sub_epi64(_mm512_lzcnt_epi64(v), _mm512_set1_epi64(2)), 1);
  const __m512i m = _mm512_sllv_epi64(v, _mm512_add_epi64(shift, shift));
  const __m512i mq = _mm512_srli_epi64(m, 30);  // in [2^30, 2^32)
  // idx = ((mq - 2^30) << 10) / (3 2^30) = y / 3, y = (mq - 2^30) >> 20 < 3072: (y 43691) >> 17.
  const __m512i y = _mm512_srli_epi64(_mm512_sub_epi64(mq, _mm512_set1_epi64(int64_t{1} << 30)), 20);
  const __m512i idx = _mm512_srli_epi64(_mm512_mul_epu32(y, _mm512_set1_epi64(43691)), 17);
  // The seed entries: the lanes' indexes are mostly within 16 of each other (the squared norm
  // varies slowly between neighbouring fragments), so one 16-entry load around lane 0's and
  // a permute; else a gather.
  const auto& seeds = RsqrtSeed<kFixedSeedBits>::table;
  const int64_t base = std::clamp<int64_t>(_mm_cvtsi128_si64(_mm512_castsi512_si128(idx)) - 7, 0,
                                           static_cast<int64_t>(seeds.size()) - 16);
  const __m512i rel = _mm512_sub_epi64(idx, _mm512_set1_epi64(base));
  const bool window = (_mm512_cmplt_epu64_mask(rel, _mm512_set1_epi64(16)) & valid) == valid;
  const __m512i r0 =
      window ? _mm512_and_si512(_mm512_permutexvar_epi32(rel, _mm512_loadu_si512(seeds.data() + base)),
                                _mm512_set1_epi64(0xFFFFFFFF))
             : _mm512_cvtepu32_epi64(_mm512_mask_i64gather_epi32(_mm256_setzero_si256(), valid, idx,
                                                                 reinterpret_cast<const int*>(seeds.data()), 4));
  // mr = (mq r0^2) >> 32 with r0^2 = a 2^32 + b: mq a + (mq b >> 32).
  const __m512i r0sq = _mm512_mul_epu32(r0, r0);
  const __m512i mr = _mm512_add_epi64(_mm512_mul_epu32(mq, _mm512_srli_epi64(r0sq, 32)),
                                      _mm512_srli_epi64(_mm512_mul_epu32(mq, r0sq), 32));
  const __m512i r = _mm512_srli_epi64(
      _mm512_mullo_epi64(r0, _mm512_sub_epi64(_mm512_set1_epi64(int64_t{3} << 32), mr)), 17);  // not negative
  // cosineScale: s = 61 - shift, r64 = r << (64 - s) = r << (3 + shift).
  _mm512_storeu_si512(r64_out, _mm512_sllv_epi64(r, _mm512_add_epi64(shift, _mm512_set1_epi64(3))));
  return true;
}

// What lobeGroup leaves colourGroup (shadeNh's second and third passes, above; shadeNhAvx2's
// too): per fragment the scaled N.L, the step from the lobe table's entry at N.H to the next
// (frac) and the pair of entries.
struct LobeLanes {
  uint64_t nl[kMaxBatch], frac[kMaxBatch], pair[kMaxBatch];
};
SHD_AVX512 inline void lobeGroup(const NhParams& p, const uint64_t* r64s, const uint64_t* l, const uint64_t* h, int n,
                                 size_t i, LobeLanes& out) {
  const __mmask8 valid = static_cast<__mmask8>((1u << n) - 1);
  const __m512i r64 = _mm512_loadu_si512(r64s + i);
  const __m512i dot_l = _mm512_loadu_si512(l + i), dot_h = _mm512_loadu_si512(h + i);
  const __m512i nl = scaleCosines(dot_l, r64);
  const __mmask8 lit = _mm512_cmpgt_epi64_mask(nl, _mm512_setzero_si512());
  const __m512i nh = scaleCosines(dot_h, r64);
  // lobeAt: c = clamp(nh, 0, 2^32), entry c >> 16 and the step to the next with c's low 16 bits.
  const __m512i c = _mm512_min_epi64(_mm512_max_epi64(nh, _mm512_setzero_si512()), _mm512_set1_epi64(int64_t{1} << 32));
  const __m512i ti = _mm512_srli_epi64(c, 16);
  // One 8-byte gather per lane at entry ti: t[ti] in the low half, t[ti + 1] in the high half
  // (the table has the copy of its last entry, so ti + 1 <= 2^16 + 1 is inside it).
  // Lanes that are unlit or below zero_below (both entries 0, so f = 0) read nothing.
  const __mmask8 reads = valid & lit & _mm512_cmpge_epi64_mask(ti, _mm512_set1_epi64(p.zero_below));
  _mm512_storeu_si512(out.nl + i, nl);
  _mm512_storeu_si512(out.frac + i, _mm512_and_si512(c, _mm512_set1_epi64(0xFFFF)));
  _mm512_storeu_si512(out.pair + i, _mm512_mask_i64gather_epi64(_mm512_setzero_si512(), reads, ti,
                                                               reinterpret_cast<const long long*>(p.table), 4));
}
// kCodes: codes is not null (a compile-time case: the renderer's loop, without the test and the
// code stores, runs some 20 % faster).
template <bool kCodes>
SHD_AVX512 inline void colourGroup(const NhParams& p, const LobeLanes& in, size_t i, uint32_t* rgb,
                                   int64_t* const codes[3]) {
  const __m512i nl = _mm512_loadu_si512(in.nl + i);
  const __m512i frac = _mm512_loadu_si512(in.frac + i), pair = _mm512_loadu_si512(in.pair + i);
  const __mmask8 lit = _mm512_cmpgt_epi64_mask(nl, _mm512_setzero_si512());
  // The lanes' packedRgb, with the specular terms or without: where every lane's pair of
  // entries is 0 (no lane read the table: most groups outside a highlight), f is 0 and so is
  // each specular term, (0 + 2^23) >> 24.
  auto colours = [&](auto with_specular) SHD_AVX512 {
    __m512i f = _mm512_setzero_si512();
    if constexpr (decltype(with_specular)::value) {
      // f = t0 + ((t1 - t0) frac + 2^15) >> 16 as (t0 (2^16 - frac) + t1 frac + 2^15) >> 16 (see
      // codeLanes4 below); _mm512_mul_epu32 reads the low word of pair: t0.
      const __m512i t1 = _mm512_srli_epi64(pair, 32);
      f = _mm512_srli_epi64(
          _mm512_add_epi64(_mm512_add_epi64(_mm512_mul_epu32(pair, _mm512_sub_epi64(_mm512_set1_epi64(1 << 16), frac)),
                                            _mm512_mul_epu32(t1, frac)),
                           _mm512_set1_epi64(1 << 15)),
          16);
    }
    __m512i packed = _mm512_setzero_si512();
    for (size_t k = 0; k < 3; ++k) {
      __m512i sum = roundShift<32>(_mm512_mullo_epi64(_mm512_set1_epi64(p.diffuse[k]), nl));  // diffuse
      if constexpr (decltype(with_specular)::value)
        sum = _mm512_add_epi64(sum, roundShift<24>(_mm512_mul_epu32(_mm512_set1_epi64(p.specular[k]), f)));  // both below 2^32
      // The sum of non-negative terms: unorm8FromCode's clamp at 0 never acts.
      const __m512i code = _mm512_mask_add_epi64(_mm512_set1_epi64(p.ambient[k]), lit, _mm512_set1_epi64(p.ambient[k]), sum);
      const __m512i out = _mm512_srli_epi64(
          _mm512_add_epi64(_mm512_min_epi64(code, _mm512_set1_epi64(int64_t{255} << 12)), _mm512_set1_epi64(1 << 11)), 12);
      packed = _mm512_or_si512(packed, _mm512_slli_epi64(out, static_cast<unsigned>(8 * k)));
      if constexpr (kCodes) _mm512_storeu_si512(codes[k] + i, code);
    }
    return packed;
  };
  const __m512i packed =
      _mm512_test_epi64_mask(pair, pair) != 0 ? colours(std::true_type{}) : colours(std::false_type{});
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(rgb + i), _mm512_cvtepi64_epi32(packed));
}

// AVX2 helpers, inlined into the AVX2 and the AVX-512 kernels (a subset of either's target).
// Lanes 0 .. 7 as 32-bit values.
SHD_AVX2 inline __m256i lanes8() { return _mm256_set_epi32(7, 6, 5, 4, 3, 2, 1, 0); }
// Lane i's offset i d from its group's first fragment, for a step d (mod 2^32).
SHD_AVX2 inline __m256i laneSteps(uint32_t d) { return _mm256_mullo_epi32(lanes8(), _mm256_set1_epi32(static_cast<int32_t>(d))); }

// Within each 128-bit half: pixels' bytes r g b (of 32-bit lanes r | g << 8 | b << 16) packed
// into the first 12 bytes, the last 4 zero.
SHD_AVX2 inline __m256i packRgb(__m256i x) {
  return _mm256_shuffle_epi8(x, _mm256_setr_epi8(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1,  //
                                                 0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, -1, -1, -1, -1));
}

// A run's constants in 8 lanes: lane i's offset i d from the run's group base, for the depth and
// each colour channel, and the colour's clamp and rounding.
struct RunLanes {
  __m256i dz, dc[3];
  __m256i top, half;
  __m128i frac;
};
SHD_AVX2 inline RunLanes runLanes(uint32_t dz, const std::array<int32_t, 3>& dc, int frac) {
  RunLanes l;
  l.dz = laneSteps(dz);
  for (size_t ch = 0; ch < 3; ++ch) l.dc[ch] = laneSteps(static_cast<uint32_t>(dc[ch]));
  l.top = _mm256_set1_epi32(255 << frac);
  l.half = _mm256_set1_epi32(1 << (frac - 1));
  l.frac = _mm_cvtsi32_si128(frac);
  return l;
}
SHD_AVX2 inline RunLanes runLanes(const ColourRuns& r) { return runLanes(r.dz, r.dc, r.frac); }

// A run's codes at its group of fragments k .. k + 7: the depth code zk and the colour codes ck
// of fragment k (mod 2^32), from the run's first and stepped 8 fragments at a time.
struct GroupCodes {
  uint32_t zk;
  std::array<uint32_t, 3> ck;
  explicit GroupCodes(const ColourRuns::Row& row)
      : zk(row.z), ck{static_cast<uint32_t>(row.c[0]), static_cast<uint32_t>(row.c[1]), static_cast<uint32_t>(row.c[2])} {}
  void next(uint32_t dz, const std::array<int32_t, 3>& dc) {
    zk += 8 * dz;
    for (size_t ch = 0; ch < 3; ++ch) ck[ch] += 8 * static_cast<uint32_t>(dc[ch]);
  }
  void next(const ColourRuns& r) { next(r.dz, r.dc); }
};

// The colour bytes of 8 fragments whose codes are code[ch] (a channel's in its lanes):
// unorm8FromCode of each (clamped to [0, 255 2^frac], rounded half up to an integer), packed by
// packRgb.
SHD_AVX2 inline __m256i colourBytesOf(const RunLanes& l, const __m256i (&code)[3]) {
  __m256i px = _mm256_setzero_si256();
  for (size_t ch = 0; ch < 3; ++ch) {
    const __m256i u8 = _mm256_srl_epi32(
        _mm256_add_epi32(_mm256_min_epi32(_mm256_max_epi32(code[ch], _mm256_setzero_si256()), l.top), l.half), l.frac);
    px = _mm256_or_si256(px, _mm256_slli_epi32(u8, 8 * static_cast<int>(ch)));
  }
  return packRgb(px);
}
// The same of fragments k .. k + 7 of a colour run whose fragment k has the codes ck.
SHD_AVX2 inline __m256i colourBytes8(const RunLanes& l, const std::array<uint32_t, 3>& ck) {
  __m256i code[3];
  for (size_t ch = 0; ch < 3; ++ch) code[ch] = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(ck[ch])), l.dc[ch]);
  return colourBytesOf(l, code);
}

// The z-test of the 8 fragments at pixels p + 0 .. 7 (those below `left`), fragment i with the
// depth code z[i]: against the buffer's, and where they pass the codes and the tag
// written (where t has a tag buffer). Returns the passing lanes; adds to fresh those whose
// depth was 0. The accesses are 8 lanes wide (32 bytes): wider ones, even with their lanes
// masked off, would overlap the next step's and stall its load behind this store.
SHD_AVX512 inline __mmask8 zTest8(const Target& t, size_t p, size_t left, __m256i z, uint64_t& fresh) {
  int32_t* const depth = t.depth + p;
  const __mmask8 valid = static_cast<__mmask8>((1u << std::min<size_t>(8, left)) - 1);
  // The row after next, most likely this triangle's: its depth in the cache by then.
  __builtin_prefetch(depth + 2 * t.width);
  __builtin_prefetch(depth + 2 * t.width + 7);
  const __m256i old = _mm256_maskz_loadu_epi32(valid, depth);
  const __mmask8 pass = _mm256_mask_cmpgt_epi32_mask(valid, z, old);
  fresh += static_cast<uint64_t>(__builtin_popcount(_mm256_mask_cmpeq_epi32_mask(pass, old, _mm256_setzero_si256())));
  _mm256_mask_storeu_epi32(depth, pass, z);
  if (t.tri != nullptr) _mm256_mask_storeu_epi32(t.tri + p, pass, _mm256_set1_epi32(t.tag));
  return pass;
}

}  // namespace

SHD_AVX512 uint64_t shadeNh(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                            uint32_t* rgb, int64_t* const codes[3]) {
  uint64_t r64[kMaxBatch];  // each group's written by scaleGroup before lobeGroup reads it
  LobeLanes lobe;           // each group's written by lobeGroup before colourGroup reads it
  return threePasses(
      n, codes != nullptr, [&](size_t i, int count) SHD_AVX512 { return scaleGroup(sq + i, count, r64 + i); },
      [&](size_t i, int count, auto) SHD_AVX512 { lobeGroup(p, r64, l, h, count, i, lobe); },
      [&](size_t i, int, auto with_codes) SHD_AVX512 {
        colourGroup<decltype(with_codes)::value>(p, lobe, i, rgb, codes);
      });
}

namespace {

// A run's fragments k, k + 8, ... in 64-bit lanes (fragment k + i in lane i): the squared norm,
// its step to the next group (dsq) and that step's (ddsq, constant), the dot products and
// their steps, and in 32-bit lanes the depth code and its step, and the pixel.
struct RunGroups {
  __m512i sq, dsq, ddsq, l, dl8, h, dh8;
  __m256i z, dz8, pixel;
};

// bufferRun's loop from its groups' values at fragment k (g), inlined into bufferRun and
// bufferSpans: each group z-tested, its passing fragments buffered, its values stepped by 8
// fragments with adds (the same values mod 2^64 as the closed forms).
[[gnu::always_inline]] SHD_AVX512 inline size_t bufferGroups(RunGroups g, const RunPixels& px, size_t k,
                                                             const Target& t, Batch& b, uint64_t& fresh) {
  size_t n = b.n;
  uint64_t covered = 0;
  for (; k < px.count && n + 8 <= Batch::kCap; k += 8) {
    const __mmask8 pass = zTest8(t, px.p + k, px.count - k, g.z, covered);
    // The passing lanes, packed (the register forms of compress: the memory forms are slow on
    // some CPUs), stored 8 entries wide.
    _mm512_storeu_si512(b.sq.data() + n, _mm512_maskz_compress_epi64(pass, g.sq));
    _mm512_storeu_si512(b.l.data() + n, _mm512_maskz_compress_epi64(pass, g.l));
    _mm512_storeu_si512(b.h.data() + n, _mm512_maskz_compress_epi64(pass, g.h));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(b.pixel.data() + n), _mm256_maskz_compress_epi32(pass, g.pixel));
    n += static_cast<size_t>(__builtin_popcount(pass));
    g.sq = _mm512_add_epi64(g.sq, g.dsq);
    g.dsq = _mm512_add_epi64(g.dsq, g.ddsq);
    g.l = _mm512_add_epi64(g.l, g.dl8);
    g.h = _mm512_add_epi64(g.h, g.dh8);
    g.z = _mm256_add_epi32(g.z, g.dz8);
    g.pixel = _mm256_add_epi32(g.pixel, _mm256_set1_epi32(8));
  }
  b.n = n;
  fresh += covered;
  return std::min(k, px.count);
}

// bufferRun's loop from fragment `first` (k < 2^32): the quadratic, l and h at fragments k .. k
// + 7 (mod 2^64), the squared norm's step dsq = sq(k + 8) - sq(k) = 16 b + c (16 k + 64), itself
// stepped by 128 c.
[[gnu::always_inline]] SHD_AVX512 inline size_t bufferRunIn(const Run& r, size_t first, const Target& t, Batch& b,
                                                            uint64_t& fresh) {
  const __m512i lane = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  const __m512i two_b = _mm512_set1_epi64(static_cast<int64_t>(r.two_b)), c = _mm512_set1_epi64(static_cast<int64_t>(r.c));
  const __m512i dl = _mm512_set1_epi64(static_cast<int64_t>(r.dl)), dh = _mm512_set1_epi64(static_cast<int64_t>(r.dh));
  const __m512i kv = _mm512_add_epi64(_mm512_set1_epi64(static_cast<int64_t>(first)), lane);
  RunGroups g;
  g.sq = _mm512_add_epi64(_mm512_add_epi64(_mm512_set1_epi64(static_cast<int64_t>(r.a)), _mm512_mullo_epi64(kv, two_b)),
                          _mm512_mullo_epi64(_mm512_mul_epu32(kv, kv), c));
  g.dsq = _mm512_add_epi64(_mm512_slli_epi64(two_b, 3),
                           _mm512_mullo_epi64(c, _mm512_add_epi64(_mm512_slli_epi64(kv, 4), _mm512_set1_epi64(64))));
  g.ddsq = _mm512_slli_epi64(c, 7);
  g.l = _mm512_add_epi64(_mm512_set1_epi64(static_cast<int64_t>(r.l)), _mm512_mullo_epi64(kv, dl));
  g.h = _mm512_add_epi64(_mm512_set1_epi64(static_cast<int64_t>(r.h)), _mm512_mullo_epi64(kv, dh));
  g.dl8 = _mm512_slli_epi64(dl, 3);
  g.dh8 = _mm512_slli_epi64(dh, 3);
  g.z = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(r.px.z + static_cast<uint32_t>(first) * r.px.dz)),
                         laneSteps(r.px.dz));
  g.dz8 = _mm256_set1_epi32(static_cast<int32_t>(8 * r.px.dz));
  g.pixel = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(r.px.p + first)), lanes8());
  return bufferGroups(g, r.px, first, t, b, fresh);
}

}  // namespace

SHD_AVX512 size_t bufferRun(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh) {
  return bufferRunIn(r, first, t, b, fresh);
}

// zTest8 in AVX2, with vector masks: the 8 fragments at pixels p + 0 .. 7 with the depth codes z
// (`valid`: the lanes of the run). Within the run's row (in_row) plain loads, and stores of the
// blend (the lanes that do not pass written back as read); masked stores (vpmaskmovd) are slow
// on AMD (docs/performance.md), so they remain for a group at the row's right end. Returns the
// passing lanes; adds to fresh those whose depth was 0.
SHD_AVX2 inline __m256i zTest8Avx2(const Target& t, size_t p, bool in_row, __m256i valid, __m256i z, uint64_t& fresh) {
  int32_t* const depth = t.depth + p;
  __builtin_prefetch(depth + 2 * t.width);  // as zTest8
  __builtin_prefetch(depth + 2 * t.width + 7);
  const __m256i old = in_row ? _mm256_loadu_si256(reinterpret_cast<const __m256i*>(depth))
                             : _mm256_maskload_epi32(depth, valid);  // 0 in the lanes past the run
  const __m256i pass = _mm256_and_si256(valid, _mm256_cmpgt_epi32(z, old));
  const unsigned m = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(pass)));
  if (m == 0) return pass;
  const unsigned zero =
      static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(old, _mm256_setzero_si256()))));
  fresh += static_cast<uint64_t>(__builtin_popcount(m & zero));
  const __m256i tag = _mm256_set1_epi32(t.tag);
  if (in_row) {
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(depth), _mm256_blendv_epi8(old, z, pass));
    if (t.tri != nullptr) {
      __m256i* const tri = reinterpret_cast<__m256i*>(t.tri + p);
      _mm256_storeu_si256(tri, _mm256_blendv_epi8(_mm256_loadu_si256(tri), tag, pass));
    }
  } else {
    _mm256_maskstore_epi32(depth, pass, z);
    if (t.tri != nullptr) _mm256_maskstore_epi32(t.tri + p, pass, tag);
  }
  return pass;
}

// A run's steps in lanes over 8 fragments: what its codes move by from one group to the next.
struct RunSteps {
  __m256i z, c[3];
};
SHD_AVX2 inline RunSteps runSteps(uint32_t dz, const std::array<int32_t, 3>& dc) {
  RunSteps s;
  s.z = _mm256_set1_epi32(static_cast<int32_t>(8 * dz));
  for (size_t ch = 0; ch < 3; ++ch) s.c[ch] = _mm256_set1_epi32(static_cast<int32_t>(8 * static_cast<uint32_t>(dc[ch])));
  return s;
}

// colourRunsAvx512 in AVX2: zTest8 and the colour of colourRunsAvx512 below with vector masks for
// the mask registers; the depth and tag blended into 32-byte stores within the row (else masked
// 32-bit stores), the colour bytes as below. A run's codes are kept in lanes, stepped by 8
// steps a group (GroupCodes's values, mod 2^32), and a group's 24 colour bytes stored from the
// register (a copy through memory waited on the store's forwarding).
// The loops over the runs and their groups are the AVX-512 kernel's, written out in each (one
// iterator over the groups shared by both made a Gouraud frame 1-6 % slower, 4 interleaved runs).
// colourRunAvx2 is one run: count fragments at pixels p, p + 1, ... (room: to the end of its
// row), its first group's codes in z and code[ch]; it adds to covered and passed as
// colourRunsAvx2. Both AVX2 kernels (colourRunsAvx2, colourSpansAvx2) run their runs through it.
[[gnu::always_inline]] SHD_AVX2_PRFCHW inline void colourRunAvx2(const RunLanes& l, const RunSteps& step,
                                                                  const Target& t, uint8_t* rgb, size_t p, size_t count,
                                                                  size_t room, __m256i z, __m256i (&code)[3],
                                                                  uint64_t& covered, uint64_t& passed) {
  const __m256i join = _mm256_setr_epi32(0, 1, 2, 4, 5, 6, 3, 7);  // the two 12-byte halves, adjacent
  for (size_t k = 0; k < count; k += 8) {
    const int n = static_cast<int>(std::min<size_t>(8, count - k));
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(n), lanes8());
    // The tags and the colours of the row after next are read and written: fetched for writing.
    if (t.tri != nullptr) {
      __builtin_prefetch(t.tri + p + k + 2 * t.width, 1);
      __builtin_prefetch(t.tri + p + k + 2 * t.width + 7, 1);
    }
    __builtin_prefetch(rgb + 3 * (p + k + 2 * t.width), 1);
    __builtin_prefetch(rgb + 3 * (p + k + 2 * t.width) + 31, 1);
    const __m256i pass_v = zTest8Avx2(t, p + k, k + 8 <= room, valid, z, covered);
    const unsigned pass = static_cast<unsigned>(_mm256_movemask_ps(_mm256_castsi256_ps(pass_v)));
    if (pass != 0) {
      passed += static_cast<uint64_t>(__builtin_popcount(pass));
      // The 8 pixels' 24 bytes, in order.
      const __m256i bytes = _mm256_permutevar8x32_epi32(colourBytesOf(l, code), join);
      uint8_t* const out = rgb + 3 * (p + k);
      if (pass == 0xFF) {
        _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm256_castsi256_si128(bytes));
        _mm_storel_epi64(reinterpret_cast<__m128i*>(out + 16), _mm256_extracti128_si256(bytes, 1));
      } else if (k + 11 <= room) {  // 32 bytes = 10 2/3 pixels, all in the row
        // The passing pixels' bytes (their lanes' all-ones packed like the colours), the rest as read.
        const __m256i mask = _mm256_permutevar8x32_epi32(packRgb(pass_v), join);
        const __m256i was = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(out));
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_blendv_epi8(was, bytes, mask));
      } else {
        alignas(32) uint8_t b[32];
        _mm256_store_si256(reinterpret_cast<__m256i*>(b), bytes);
        for (unsigned m = pass; m != 0; m &= m - 1) {
          const int j = __builtin_ctz(m);
          std::memcpy(out + 3 * j, b + 3 * j, 3);
        }
      }
    }
    z = _mm256_add_epi32(z, step.z);
    for (size_t ch = 0; ch < 3; ++ch) code[ch] = _mm256_add_epi32(code[ch], step.c[ch]);
  }
}

SHD_AVX2_PRFCHW uint64_t colourRunsAvx2(const ColourRuns& r, const Target& t, uint8_t* rgb, uint64_t& passed) {
  const RunLanes l = runLanes(r);
  const RunSteps step = runSteps(r.dz, r.dc);
  uint64_t covered = 0, pass_count = 0;
  for (size_t i = 0; i < r.n; ++i) {
    const ColourRuns::Row& row = r.rows[i];
    __m256i code[3];
    for (size_t ch = 0; ch < 3; ++ch) code[ch] = _mm256_add_epi32(_mm256_set1_epi32(row.c[ch]), l.dc[ch]);
    colourRunAvx2(l, step, t, rgb, row.p, row.count, row.room,
                  _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(row.z)), l.dz), code, covered, pass_count);
  }
  passed += pass_count;
  return covered;
}

// 8 pixels' colour bytes (colourBytesOf's packing) at out, each pixel's 3 where it passed.
SHD_AVX512 inline void storeColours8(__m256i bytes, __mmask8 pass, uint8_t* out) {
  // 3 mask bits per pass bit.
  const uint32_t lo = kSpread3[pass & 15], hi = kSpread3[(pass >> 4) & 15];
  _mm_mask_storeu_epi8(out, static_cast<__mmask16>(lo), _mm256_castsi256_si128(bytes));
  _mm_mask_storeu_epi8(out + 12, static_cast<__mmask16>(hi), _mm256_extracti128_si256(bytes, 1));
}

SHD_AVX512 uint64_t colourRunsAvx512(const ColourRuns& r, const Target& t, uint8_t* rgb, uint64_t& passed) {
  const RunLanes l = runLanes(r);
  uint64_t covered = 0, pass_count = 0;
  for (size_t i = 0; i < r.n; ++i) {
    const ColourRuns::Row& row = r.rows[i];
    GroupCodes g(row);
    for (size_t k = 0; k < row.count; k += 8, g.next(r)) {
      const __mmask8 pass =
          zTest8(t, row.p + k, row.count - k, _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(g.zk)), l.dz), covered);
      pass_count += static_cast<uint64_t>(__builtin_popcount(pass));
      if (pass != 0) storeColours8(colourBytes8(l, g.ck), pass, rgb + 3 * (row.p + k));
    }
  }
  passed += pass_count;
  return covered;
}

// A row's codes (z, c0, c1, c2) are adjacent: one 16-byte store of the lanes (attributes 3, 0, 1, 2).
static_assert(offsetof(ColourRuns::Row, c) == offsetof(ColourRuns::Row, z) + 4, "z, c[0], c[1], c[2] adjacent");
// The rows of s with a pixel, top to bottom: row(p, count, room, at) with the pixel index p of
// its first pixel, its pixel count, the pixels from p to the end of its row, and the codes
// there (RowSpans::at mod 2^32) as (z, c0, c1, c2) in 32-bit lanes (W: pixels per framebuffer
// row). One 4-lane multiply-add per row from the row's left (x0) codes.
template <class Row>
[[gnu::always_inline]] SHD_AVX2 inline void eachSpanRow(const RowSpans& s, size_t W, Row row) {
  auto lanes = [](const std::array<int64_t, 4>& v) {
    return _mm_setr_epi32(static_cast<int32_t>(v[3]), static_cast<int32_t>(v[0]), static_cast<int32_t>(v[1]),
                          static_cast<int32_t>(v[2]));
  };
  const __m128i dx = lanes(s.didx), dy = lanes(s.didy);
  __m128i left = lanes(s.a0);  // the codes at column x0 of row y0 + i (mod 2^32)
  size_t p = static_cast<size_t>(s.y0) * W;
  for (int32_t i = 0; i < s.rows; ++i, p += W, left = _mm_add_epi32(left, dy)) {
    const int32_t lo = s.span[static_cast<size_t>(i)][0], hi = s.span[static_cast<size_t>(i)][1];
    if (lo > hi) continue;
    row(p + static_cast<size_t>(lo), static_cast<size_t>(hi - lo + 1), W - static_cast<size_t>(lo),
        _mm_add_epi32(left, _mm_mullo_epi32(dx, _mm_set1_epi32(lo - s.x0))));
  }
}

SHD_AVX2_PRFCHW uint64_t colourSpansAvx2(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb,
                                         uint64_t& passed) {
  const std::array<int32_t, 3> dc = {static_cast<int32_t>(s.didx[0]), static_cast<int32_t>(s.didx[1]),
                                     static_cast<int32_t>(s.didx[2])};
  const RunLanes l = runLanes(static_cast<uint32_t>(s.didx[3]), dc, frac);
  const RunSteps step = runSteps(static_cast<uint32_t>(s.didx[3]), dc);
  uint64_t covered = 0, pass_count = 0;
  eachSpanRow(s, W, [&](size_t p, size_t count, size_t room, __m128i at4) SHD_AVX2_PRFCHW {
    const __m256i at = _mm256_castsi128_si256(at4);
    __m256i code[3];
    for (size_t ch = 0; ch < 3; ++ch)
      code[ch] = _mm256_add_epi32(_mm256_permutevar8x32_epi32(at, _mm256_set1_epi32(static_cast<int32_t>(ch + 1))), l.dc[ch]);
    colourRunAvx2(l, step, t, rgb, p, count, room, _mm256_add_epi32(_mm256_broadcastd_epi32(at4), l.dz), code, covered,
                  pass_count);
  });
  passed += pass_count;
  return covered;
}

// colourRunsAvx512's groups straight from the rows' spans, as colourSpansAvx2 does for the AVX2
// kernel: a row's codes at its first pixel from eachSpanRow's lanes (z, c0, c1, c2). A triangle
// of one colour (its colour gradients 0: flat's) has the same colour bytes in every group:
// packed once.
SHD_AVX512 uint64_t colourSpansAvx512(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb,
                                      uint64_t& passed) {
  const std::array<int32_t, 3> dc = {static_cast<int32_t>(s.didx[0]), static_cast<int32_t>(s.didx[1]),
                                     static_cast<int32_t>(s.didx[2])};
  const uint32_t dz = static_cast<uint32_t>(s.didx[3]);
  const RunLanes l = runLanes(dz, dc, frac);
  uint64_t covered = 0, pass_count = 0;
  // The codes kept in lanes (as colourRunAvx2's), stepped by 8 steps a group; a triangle of one
  // colour has its bytes packed once (one: std::true_type).
  const RunSteps step = runSteps(dz, dc);
  const __m256i bytes = colourBytes8(l, {static_cast<uint32_t>(s.a0[0]), static_cast<uint32_t>(s.a0[1]),
                                         static_cast<uint32_t>(s.a0[2])});
  auto rows = [&](auto one) SHD_AVX512 {
    eachSpanRow(s, W, [&](size_t p, size_t count, size_t, __m128i at4) SHD_AVX512 {
      const __m256i at = _mm256_castsi128_si256(at4);
      __m256i z = _mm256_add_epi32(_mm256_broadcastd_epi32(at4), l.dz), code[3];
      for (size_t ch = 0; ch < 3; ++ch)
        code[ch] = _mm256_add_epi32(_mm256_permutexvar_epi32(_mm256_set1_epi32(static_cast<int32_t>(ch + 1)), at), l.dc[ch]);
      for (size_t k = 0; k < count; k += 8) {
        const __mmask8 pass = zTest8(t, p + k, count - k, z, covered);
        pass_count += static_cast<uint64_t>(__builtin_popcount(pass));
        if (pass != 0) storeColours8(decltype(one)::value ? bytes : colourBytesOf(l, code), pass, rgb + 3 * (p + k));
        z = _mm256_add_epi32(z, step.z);
        if constexpr (!decltype(one)::value)
          for (size_t ch = 0; ch < 3; ++ch) code[ch] = _mm256_add_epi32(code[ch], step.c[ch]);
      }
    });
  };
  if (oneColour(s)) rows(std::true_type{});
  else rows(std::false_type{});
  passed += pass_count;
  return covered;
}


// ---- shadeNh in AVX2: its groups' operations on 4 64-bit lanes, two per group of 8 ----

namespace {

// The low 64 bits of a b (any signs), from 32 x 32 products.
SHD_AVX2 inline __m256i mulLo64(__m256i a, __m256i b) {
  const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(a, 32), b),
                                         _mm256_mul_epu32(a, _mm256_srli_epi64(b, 32)));
  return _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64(cross, 32));
}
// The low 64 bits of a b for 0 <= a < 2^32 (any b): a's high word's product is 0.
SHD_AVX2 inline __m256i mulLo64By32(__m256i a, __m256i b) {
  return _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64(_mm256_mul_epu32(a, _mm256_srli_epi64(b, 32)), 32));
}
// mulHiRoundU64's operations.
SHD_AVX2 inline __m256i mulHiRoundU64x4(__m256i a, __m256i b) {
  const __m256i low32 = _mm256_set1_epi64x(0xFFFFFFFF);
  const __m256i ah = _mm256_srli_epi64(a, 32), bh = _mm256_srli_epi64(b, 32);
  const __m256i t = _mm256_mul_epu32(a, b);
  const __m256i u = _mm256_add_epi64(_mm256_mul_epu32(ah, b), _mm256_srli_epi64(t, 32));
  const __m256i v = _mm256_add_epi64(_mm256_mul_epu32(a, bh), _mm256_and_si256(u, low32));
  return _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epu32(ah, bh), _mm256_srli_epi64(u, 32)),
                          _mm256_srli_epi64(_mm256_add_epi64(v, _mm256_set1_epi64x(int64_t{1} << 31)), 32));
}
SHD_AVX2 inline __m256i min64(__m256i a, __m256i b) { return _mm256_blendv_epi8(a, b, _mm256_cmpgt_epi64(a, b)); }

// scaleGroup's datapath on the 4 squared norms at sq (`valid`: the lanes that are fragments),
// their cosine scales stored at r64_out; false (nothing stored) when a valid lane needs the
// scalar path. As the AVX-512 kernel, it takes squared norms in [2^32, 2^62) only (|N| from
// 2^-12 to 8: an interpolated unit normal's is near 2^56) and declines the rest, which spares it
// what AVX2 lacks for the others:
// - the bit length, 64 less the count of leading zeros (no instruction), is that of the high
//   word y plus 32. y, below 2^32, is exact in a double, d = (2^52 + y) - 2^52, whose exponent
//   field is 1023 + floor(log2 y) for y > 0;
// - rsqrtCore's shift is (62 - bits) / 2, in [0, 14] (no shift down by 4 for bits above 62),
//   so s = 61 - shift >= 35, cosineScale's fast path;
// - r0 (3 2^32 - m r0^2) >> 17 is not negative: the seed's m r0^2 stays near 2^32, below
//   3 2^32 (RsqrtCore.SeedProductsStayBelowThree checks every entry at its interval's top), so
//   the shift is logical.
[[gnu::always_inline]] SHD_AVX2 inline bool scaleLanes4(const uint64_t* sq, __m256i valid, uint64_t* r64_out) {
  const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sq));
  // Outside the range by the high word: 0 below 2^32, above its top's high word less 1 from it on.
  static_assert(kVectorSqFrom == uint64_t{1} << 32 && kVectorSqBelow % (uint64_t{1} << 32) == 0);
  const __m256i hi = _mm256_srli_epi64(v, 32);
  const __m256i outside = _mm256_or_si256(
      _mm256_cmpeq_epi64(hi, _mm256_setzero_si256()),
      _mm256_cmpgt_epi64(hi, _mm256_set1_epi64x(static_cast<int64_t>(kVectorSqBelow >> 32) - 1)));
  if (!_mm256_testz_si256(outside, valid)) return false;
  const __m256d two52 = _mm256_set1_pd(4503599627370496.0);
  const __m256d d = _mm256_sub_pd(_mm256_castsi256_pd(_mm256_or_si256(hi, _mm256_castpd_si256(two52))), two52);
  // bits = exponent - 1023 + 1 + 32; shift = (62 - bits) / 2 = (1052 - exponent) / 2.
  const __m256i exponent = _mm256_srli_epi64(_mm256_castpd_si256(d), 52);
  const __m256i shift = _mm256_srli_epi64(_mm256_sub_epi64(_mm256_set1_epi64x(1052), exponent), 1);
  const __m256i mq = _mm256_srli_epi64(_mm256_sllv_epi64(v, _mm256_add_epi64(shift, shift)), 30);
  const __m256i y = _mm256_srli_epi64(_mm256_sub_epi64(mq, _mm256_set1_epi64x(int64_t{1} << 30)), 20);
  const __m256i idx = _mm256_srli_epi64(_mm256_mul_epu32(y, _mm256_set1_epi64x(43691)), 17);
  // The seed entries, gathered by the valid lanes (the others' indexes are not entries).
  const __m128i valid32 = _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(valid, _mm256_setr_epi32(0, 2, 4, 6, 0, 2, 4, 6)));
  const __m256i r0 = _mm256_cvtepu32_epi64(_mm256_mask_i64gather_epi32(
      _mm_setzero_si128(), reinterpret_cast<const int*>(RsqrtSeed<kFixedSeedBits>::table.data()), idx, valid32, 4));
  const __m256i r0sq = _mm256_mul_epu32(r0, r0);
  const __m256i mr = _mm256_add_epi64(_mm256_mul_epu32(mq, _mm256_srli_epi64(r0sq, 32)),
                                      _mm256_srli_epi64(_mm256_mul_epu32(mq, r0sq), 32));
  const __m256i r = _mm256_srli_epi64(mulLo64By32(r0, _mm256_sub_epi64(_mm256_set1_epi64x(int64_t{3} << 32), mr)), 17);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(r64_out), _mm256_sllv_epi64(r, _mm256_add_epi64(shift, _mm256_set1_epi64x(3))));
  return true;
}

// lobeGroup's and colourGroup's datapaths on 4 fragments:
//   lobeLanes4   from the cosine scales r64 (scaleLanes4's) and the dot products, the scaled N.L
//                (nl), the lobe table's pair of entries at N.H and the step to the next (frac),
//                stored at the lanes' entries of a LobeLanes;
//   codeLanes4   from those, the 12-fraction-bit codes.
[[gnu::always_inline]] SHD_AVX2 inline void lobeLanes4(const NhParams& p, const uint64_t* r64s, const uint64_t* l,
                                                       const uint64_t* h, __m256i valid, LobeLanes& out, size_t i) {
  const __m256i r64 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(r64s));
  const __m256i dot_l = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(l));
  const __m256i dot_h = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(h));
  // scaleCosines less its correction for a negative dot product, whose cosine is not positive
  // (d r64 + 2^63 < 2^63): such a lane is unlit, and its N.H clamps to 0, which they are set to.
  // The others' products are those of scaleCosines, below 2^51 (r64 < 2^51 in scaleLanes4's
  // range): N.H needs no clamp at 0.
  const __m256i zero = _mm256_setzero_si256();
  const __m256i nl = _mm256_andnot_si256(_mm256_cmpgt_epi64(zero, dot_l), mulHiRoundU64x4(dot_l, r64));
  const __m256i lit = _mm256_cmpgt_epi64(nl, zero);
  const __m256i c = _mm256_andnot_si256(_mm256_cmpgt_epi64(zero, dot_h),
                                        min64(mulHiRoundU64x4(dot_h, r64), _mm256_set1_epi64x(int64_t{1} << 32)));
  const __m256i ti = _mm256_srli_epi64(c, 16);
  const __m256i reads = _mm256_and_si256(
      _mm256_and_si256(valid, lit), _mm256_cmpgt_epi64(ti, _mm256_set1_epi64x(static_cast<int64_t>(p.zero_below) - 1)));
  const __m256i pair = _mm256_mask_i64gather_epi64(_mm256_setzero_si256(), reinterpret_cast<const long long*>(p.table),
                                                   ti, reads, 4);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.nl + i), nl);
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.frac + i), _mm256_and_si256(c, _mm256_set1_epi64x(0xFFFF)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out.pair + i), pair);
}
[[gnu::always_inline]] SHD_AVX2 inline void codeLanes4(const NhParams& p, const LobeLanes& in, size_t i,
                                                       __m256i (&code)[3]) {
  const __m256i nl = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in.nl + i));
  const __m256i frac = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in.frac + i));
  const __m256i pair = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in.pair + i));
  const __m256i lit = _mm256_cmpgt_epi64(nl, _mm256_setzero_si256());
  // f = t0 + ((t1 - t0) frac + 2^15) >> 16 (arithmetic), which is (t0 (2^16 - frac) + t1 frac +
  // 2^15) >> 16: t0 and t1 are below 2^32 and frac below 2^16, so the sum is not negative and
  // below 2^48, the shift is logical, and f <= max(t0, t1) < 2^32 needs no cast to 32 bits.
  // _mm256_mul_epu32 reads the low word of pair: t0.
  const __m256i t1 = _mm256_srli_epi64(pair, 32);
  const __m256i f = _mm256_srli_epi64(
      _mm256_add_epi64(_mm256_add_epi64(_mm256_mul_epu32(pair, _mm256_sub_epi64(_mm256_set1_epi64x(1 << 16), frac)),
                                        _mm256_mul_epu32(t1, frac)),
                       _mm256_set1_epi64x(1 << 15)),
      16);
  // The factor codes are below 2^30 and not negative (fixed_shading.cpp's factorCode), and in
  // the lanes where they count (lit) nl > 0 (below 2^34, a Q2.32 cosine) and 0 <= f < 2^32:
  // the products are not negative, diffuse nl is the sum of two 32 x 32 products, specular f
  // one, and the rounding shifts are logical. With nl = nl_high 2^32 + nl_low, (kd nl + 2^31) >>
  // 32 is kd nl_high + ((kd nl_low + 2^31) >> 32).
  const __m256i nl_high = _mm256_srli_epi64(nl, 32);
  for (size_t k = 0; k < 3; ++k) {
    const __m256i kd = _mm256_set1_epi64x(p.diffuse[k]), ks = _mm256_set1_epi64x(p.specular[k]);
    const __m256i diffuse = _mm256_add_epi64(
        _mm256_mul_epu32(kd, nl_high),
        _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(kd, nl), _mm256_set1_epi64x(int64_t{1} << 31)), 32));
    const __m256i specular = _mm256_srli_epi64(_mm256_add_epi64(_mm256_mul_epu32(ks, f), _mm256_set1_epi64x(1 << 23)), 24);
    code[k] = _mm256_add_epi64(_mm256_set1_epi64x(p.ambient[k]), _mm256_and_si256(lit, _mm256_add_epi64(diffuse, specular)));
  }
}

// The valid lanes of a group of n fragments: of its first four (half 0) or last four (half 1).
SHD_AVX2 inline __m256i validLanes4(int n, int half) {
  return _mm256_cmpgt_epi64(_mm256_set1_epi64x(n - 4 * half), _mm256_setr_epi64x(0, 1, 2, 3));
}

// scaleGroup, lobeGroup and colourGroup on two groups of 4 lanes each.
SHD_AVX2 inline bool scaleGroupAvx2(const uint64_t* sq, int n, uint64_t* r64_out) {
  return scaleLanes4(sq, validLanes4(n, 0), r64_out) && scaleLanes4(sq + 4, validLanes4(n, 1), r64_out + 4);
}
SHD_AVX2 inline void lobeGroupAvx2(const NhParams& p, const uint64_t* r64, const uint64_t* l, const uint64_t* h, int n,
                                   size_t i, LobeLanes& out) {
  lobeLanes4(p, r64 + i, l + i, h + i, validLanes4(n, 0), out, i);
  lobeLanes4(p, r64 + i + 4, l + i + 4, h + i + 4, validLanes4(n, 1), out, i + 4);
}
template <bool kCodes>
SHD_AVX2 inline void colourGroupAvx2(const NhParams& p, const LobeLanes& in, size_t i, uint32_t* rgb,
                                     int64_t* const codes[3]) {
  __m256i a[3], b[3];
  codeLanes4(p, in, i, a);
  codeLanes4(p, in, i + 4, b);
  // The output bytes as colourGroup's, min(code, 255 2^12) rounded by 12 bits, here as
  // (code + 2^11) >> 12 saturated at 255 by the packs (the codes are not negative and below
  // 2^39, so the shifted value fits an int32_t's low word; above 255 both give 255). Each
  // channel's 8 values as 32-bit lanes a0 b0 a1 b1 | a2 b2 a3 b3 (fragments 0 4 1 5 | 2 6 3 7),
  // packed to 16 and then 8 bits (per 128-bit half: the 4 red bytes, the 4 green, the 4 blue),
  // gathered into each fragment's word by a byte shuffle, and the words put in fragment order.
  const __m256i half = _mm256_set1_epi64x(1 << 11);
  __m256i x[3];
  for (size_t k = 0; k < 3; ++k) {
    const __m256i ta = _mm256_srli_epi64(_mm256_add_epi64(a[k], half), 12);
    const __m256i tb = _mm256_srli_epi64(_mm256_add_epi64(b[k], half), 12);
    x[k] = _mm256_blend_epi32(ta, _mm256_slli_epi64(tb, 32), 0xAA);
    if constexpr (kCodes) {
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(codes[k] + i), a[k]);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(codes[k] + i + 4), b[k]);
    }
  }
  const __m256i bytes = _mm256_packus_epi16(_mm256_packs_epi32(x[0], x[1]), _mm256_packs_epi32(x[2], x[2]));
  const __m256i words = _mm256_shuffle_epi8(
      bytes, _mm256_setr_epi8(0, 4, 8, -1, 1, 5, 9, -1, 2, 6, 10, -1, 3, 7, 11, -1,  //
                              0, 4, 8, -1, 1, 5, 9, -1, 2, 6, 10, -1, 3, 7, 11, -1));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(rgb + i),
                      _mm256_permutevar8x32_epi32(words, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
}

}  // namespace

SHD_AVX2 uint64_t shadeNhAvx2(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                              uint32_t* rgb, int64_t* const codes[3]) {
  uint64_t r64[kMaxBatch];  // as shadeNh's
  LobeLanes lobe;           // each group's written by lobeGroupAvx2 before colourGroupAvx2 reads it
  return threePasses(
      n, codes != nullptr, [&](size_t i, int count) SHD_AVX2 { return scaleGroupAvx2(sq + i, count, r64 + i); },
      [&](size_t i, int count, auto) SHD_AVX2 { lobeGroupAvx2(p, r64, l, h, count, i, lobe); },
      [&](size_t i, int, auto with_codes) SHD_AVX2 {
        colourGroupAvx2<decltype(with_codes)::value>(p, lobe, i, rgb, codes);
      });
}

// ---- bufferRun in AVX2 ----

namespace {

// The lanes of a 4-bit mask packed to the front: for 64-bit lanes as 32-bit indexes of
// _mm256_permutevar8x32_epi32, for 32-bit lanes as the bytes of _mm_shuffle_epi8 (the lanes
// after the packed ones are don't-cares).
struct Compress4 {
  std::array<std::array<int32_t, 8>, 16> wide{};
  std::array<std::array<int8_t, 16>, 16> narrow{};
};
constexpr Compress4 kCompress4 = [] {
  Compress4 t{};
  for (unsigned m = 0; m < 16; ++m) {
    unsigned j = 0;
    for (unsigned i = 0; i < 4; ++i)
      if ((m >> i) & 1) {
        t.wide[m][2 * j] = static_cast<int32_t>(2 * i);
        t.wide[m][2 * j + 1] = static_cast<int32_t>(2 * i + 1);
        for (unsigned b = 0; b < 4; ++b) t.narrow[m][4 * j + b] = static_cast<int8_t>(4 * i + b);
        ++j;
      }
  }
  return t;
}();

// v's lanes of mask m (4 bits), packed to the front, stored 4 wide at out.
SHD_AVX2 inline void compressStore(uint64_t* out, __m256i v, unsigned m) {
  const __m256i idx = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kCompress4.wide[m].data()));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_permutevar8x32_epi32(v, idx));
}
SHD_AVX2 inline void compressStore(uint32_t* out, __m128i v, unsigned m) {
  const __m128i idx = _mm_loadu_si128(reinterpret_cast<const __m128i*>(kCompress4.narrow[m].data()));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_shuffle_epi8(v, idx));
}

// Fragments k .. k + 3 (kv, 64-bit lanes) of run r: the squared norm a + k two_b + k^2 c and the
// dot products l + k dl, h + k dh, mod 2^64 (k < 2^32).
struct RunInputs4 {
  __m256i sq, l, h;
};
// k x mod 2^64 for k < 2^32.
SHD_AVX2 inline __m256i times(__m256i k, uint64_t x) {
  const __m256i xv = _mm256_set1_epi64x(static_cast<int64_t>(x));
  return _mm256_add_epi64(_mm256_mul_epu32(k, xv), _mm256_slli_epi64(_mm256_mul_epu32(k, _mm256_srli_epi64(xv, 32)), 32));
}
SHD_AVX2 inline RunInputs4 runInputs4(const Run& r, __m256i kv) {
  const __m256i k2 = _mm256_mul_epu32(kv, kv);
  const __m256i c = _mm256_set1_epi64x(static_cast<int64_t>(r.c));
  const __m256i sq = _mm256_add_epi64(_mm256_add_epi64(_mm256_set1_epi64x(static_cast<int64_t>(r.a)), times(kv, r.two_b)),
                                      mulLo64(k2, c));
  return {sq, _mm256_add_epi64(_mm256_set1_epi64x(static_cast<int64_t>(r.l)), times(kv, r.dl)),
          _mm256_add_epi64(_mm256_set1_epi64x(static_cast<int64_t>(r.h)), times(kv, r.dh))};
}

// bufferRun's loop with zTest8Avx2, and the passing fragments' inputs computed in two halves of
// 4 64-bit lanes, each packed by a permutation (AVX2 has no compress); inlined into
// bufferRunAvx2 and bufferSpansAvx2.
[[gnu::always_inline]] SHD_AVX2 inline size_t bufferRunAvx2In(const Run& r, size_t first, const Target& t, Batch& b,
                                                              uint64_t& fresh) {
  const __m256i lanes = lanes8(), dz_lanes = laneSteps(r.px.dz);
  const __m256i lane4 = _mm256_setr_epi64x(0, 1, 2, 3);
  size_t n = b.n, k = first;
  uint64_t covered = 0;
  for (; k < r.px.count && n + 8 <= Batch::kCap; k += 8) {
    const size_t p = r.px.p + k;
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int32_t>(std::min<size_t>(8, r.px.count - k))), lanes);
    const __m256i z = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(r.px.z + static_cast<uint32_t>(k) * r.px.dz)), dz_lanes);
    const unsigned m = static_cast<unsigned>(
        _mm256_movemask_ps(_mm256_castsi256_ps(zTest8Avx2(t, p, k + 8 <= r.room, valid, z, covered))));
    if (m == 0) continue;
    const __m256i pixel = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(p)), lanes);
    for (unsigned half = 0; half < 2; ++half) {
      const unsigned mh = (m >> (4 * half)) & 0xF;
      if (mh == 0) continue;
      const RunInputs4 in = runInputs4(r, _mm256_add_epi64(_mm256_set1_epi64x(static_cast<int64_t>(k + 4 * half)), lane4));
      compressStore(b.sq.data() + n, in.sq, mh);
      compressStore(b.l.data() + n, in.l, mh);
      compressStore(b.h.data() + n, in.h, mh);
      compressStore(b.pixel.data() + n, half == 0 ? _mm256_castsi256_si128(pixel) : _mm256_extracti128_si256(pixel, 1), mh);
      n += static_cast<size_t>(__builtin_popcount(mh));
    }
  }
  b.n = n;
  fresh += covered;
  return std::min(k, r.px.count);
}

}  // namespace

SHD_AVX2 size_t bufferRunAvx2(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh) {
  return bufferRunAvx2In(r, first, t, b, fresh);
}

namespace {
// The values of 8 rows of a triangle (RowSpans) at their first pixels, lane j row base + j: the
// squared norm's terms a and two_b, the dot products l and h, and (in 32-bit lanes) the depth
// code; kept in registers, each row's broadcast from them by a permutation, rather than stored
// and read back 8 bytes at a time (docs/performance.md, "What makes a frame fast").
struct RowLanes {
  __m512i a, two_b, l, h;
  __m256i z;
};

// RowLanes of rows base .. base + 7 of r, the products of two int32_t (vpmuldq, exact in 64
// bits) and the sums mod 2^64, as eachSpanRun takes them: the codes at(k, lo, i) = a0 + u didx
// + i didy with u = lo - x0; the squared norm's terms from them (SquaredNormRecurrence::terms);
// the dot products as dot58 of them, which equals eachSpanRun's a0.L + u (didx.L) + i (didy.L)
// mod 2^64 (both are the integer N.L mod 2^64). Rows without a pixel get values never read.
// False where that does not hold: a normal's code at the first pixel of a row drawn from row
// `from` on (`drawn`) outside int32_t (RowSpans keeps the codes within, and the gradients,
// which the caller checks; the tests' random planes do not).
[[gnu::always_inline]] SHD_AVX512 inline bool rowLanes(const NhSpans& r, int32_t base, int32_t from, RowLanes& out) {
  const RowSpans& s = *r.s;
  // Rows base .. base + 7 (of the 64 of span): lo and hi (int16_t pairs) to 64-bit lanes.
  const __m256i pairs = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(s.span.data() + base));
  const __m512i lo = _mm512_cvtepi32_epi64(_mm256_srai_epi32(_mm256_slli_epi32(pairs, 16), 16));
  const __m512i hi = _mm512_cvtepi32_epi64(_mm256_srai_epi32(pairs, 16));
  const __m512i i = _mm512_add_epi64(_mm512_set1_epi64(base), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7));
  const __m512i u = _mm512_sub_epi64(lo, _mm512_set1_epi64(s.x0));
  __m512i code[4];
  for (size_t k = 0; k < 4; ++k)
    code[k] = _mm512_add_epi64(_mm512_set1_epi64(s.a0[k]),
                               _mm512_add_epi64(_mm512_mul_epi32(u, _mm512_set1_epi64(s.didx[k])),
                                                _mm512_mul_epi32(i, _mm512_set1_epi64(s.didy[k]))));
  const __mmask8 drawn = _mm512_cmpge_epi64_mask(hi, lo) & _mm512_cmplt_epi64_mask(i, _mm512_set1_epi64(s.rows)) &
                         _mm512_cmpge_epi64_mask(i, _mm512_set1_epi64(from)) & static_cast<__mmask8>(r.rows >> base);
  for (size_t k = 0; k < 3; ++k)
    if (_mm512_mask_cmpneq_epi64_mask(drawn, code[k], _mm512_cvtepi32_epi64(_mm512_cvtepi64_epi32(code[k]))) != 0)
      return false;
  __m512i A = _mm512_setzero_si512(), B = A, l = A, h = A;
  for (size_t k = 0; k < 3; ++k) {
    A = _mm512_add_epi64(A, _mm512_mul_epi32(code[k], code[k]));
    B = _mm512_add_epi64(B, _mm512_mul_epi32(code[k], _mm512_set1_epi64(s.didx[k])));
    l = _mm512_add_epi64(l, _mm512_mul_epi32(code[k], _mm512_set1_epi64(r.l[k])));
    h = _mm512_add_epi64(h, _mm512_mul_epi32(code[k], _mm512_set1_epi64(r.h[k])));
  }
  out = {A, _mm512_add_epi64(B, B), l, h, _mm512_cvtepi64_epi32(code[3])};
  return true;
}
}  // namespace

// eachSpanRun's runs, 8 rows' values at a time from rowLanes, each row's lanes from the
// triangle's: at fragments 0 .. 7 the squared norm a + i two_b + i^2 c, its step 8 two_b + c
// (16 i + 64), l + i dl and h + i dh, of which only i two_b is the row's. A row resumed within
// (the batch full before its end) takes bufferRunIn from its fragment. Fewer than 4 rows left,
// a gradient outside int32_t, or a code outside it from that row on: eachSpanRun's rows.
SHD_AVX512 bool bufferSpans(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh) {
  const RowSpans& s = *r.s;
  auto scalarRows = [&] {
    return eachSpanRun(r, at, [&](const Run& run, size_t first) SHD_AVX512 { return bufferRunIn(run, first, t, b, fresh); });
  };
  bool fits = s.rows - at.row >= 4;
  for (size_t k = 0; k < 4; ++k) fits &= s.didx[k] == int32_t(s.didx[k]) && s.didy[k] == int32_t(s.didy[k]);
  if (!fits) return scalarRows();
  const std::array<int64_t, 3> dn{s.didx[0], s.didx[1], s.didx[2]};
  const uint64_t c = SquaredNormRecurrence::terms(dn, dn).a;  // |didx|^2
  const uint64_t dl = static_cast<uint64_t>(fixed_detail::dot58(s.didx.data(), r.l));
  const uint64_t dh = static_cast<uint64_t>(fixed_detail::dot58(s.didx.data(), r.h));
  const __m512i lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  const __m512i cv = _mm512_set1_epi64(static_cast<int64_t>(c));
  const __m512i dlv = _mm512_set1_epi64(static_cast<int64_t>(dl)), dhv = _mm512_set1_epi64(static_cast<int64_t>(dh));
  const __m512i lane_sq_c = _mm512_mullo_epi64(_mm512_mul_epu32(lane, lane), cv);
  const __m512i lane_dsq_c = _mm512_mullo_epi64(cv, _mm512_add_epi64(_mm512_slli_epi64(lane, 4), _mm512_set1_epi64(64)));
  const __m512i lane_dl = _mm512_mullo_epi64(lane, dlv), lane_dh = _mm512_mullo_epi64(lane, dhv);
  const uint32_t dz = static_cast<uint32_t>(s.didx[3]);
  const __m256i lane_dz = laneSteps(dz);
  RunGroups g;
  g.ddsq = _mm512_slli_epi64(cv, 7);
  g.dl8 = _mm512_slli_epi64(dlv, 3);
  g.dh8 = _mm512_slli_epi64(dhv, 3);
  g.dz8 = _mm256_set1_epi32(static_cast<int32_t>(8 * dz));
  RowLanes v;
  for (int32_t base = -8; at.row < s.rows; ++at.row, at.k = 0) {
    const size_t i = static_cast<size_t>(at.row);
    if ((at.row & ~7) != base) {
      base = at.row & ~7;
      if (!rowLanes(r, base, at.row, v)) return scalarRows();
    }
    const int64_t lo = s.span[i][0], hi = s.span[i][1];
    if (lo > hi || ((r.rows >> i) & 1) == 0) continue;
    // Row i's values broadcast from its lane.
    const __m512i j = _mm512_set1_epi64(at.row - base);
    const __m512i two_b = _mm512_permutexvar_epi64(j, v.two_b), a = _mm512_permutexvar_epi64(j, v.a);
    const __m512i l = _mm512_permutexvar_epi64(j, v.l), h = _mm512_permutexvar_epi64(j, v.h);
    const __m256i z = _mm256_permutexvar_epi32(_mm256_set1_epi32(at.row - base), v.z);
    // (The depth code px.z is the resumed row's alone: bufferGroups steps g.z.)
    RunPixels px{static_cast<size_t>(s.y0 + at.row) * r.W + static_cast<size_t>(lo), static_cast<size_t>(hi - lo + 1), 0, dz};
    if (at.k == 0) {
      g.sq = _mm512_add_epi64(_mm512_add_epi64(a, lane_sq_c), _mm512_mullo_epi64(lane, two_b));
      g.dsq = _mm512_add_epi64(_mm512_slli_epi64(two_b, 3), lane_dsq_c);
      g.l = _mm512_add_epi64(l, lane_dl);
      g.h = _mm512_add_epi64(h, lane_dh);
      g.z = _mm256_add_epi32(z, lane_dz);
      g.pixel = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(px.p)), lanes8());
      at.k = bufferGroups(g, px, 0, t, b, fresh);
    } else {
      auto low = [](__m512i x) SHD_AVX512 { return static_cast<uint64_t>(_mm_cvtsi128_si64(_mm512_castsi512_si128(x))); };
      px.z = static_cast<uint32_t>(_mm256_cvtsi256_si32(z));
      Run run;
      run.px = px;
      run.a = low(a);
      run.two_b = low(two_b);
      run.c = c;
      run.l = low(l);
      run.dl = dl;
      run.h = low(h);
      run.dh = dh;
      at.k = bufferRunIn(run, at.k, t, b, fresh);
    }
    if (at.k < px.count) return false;
  }
  return true;
}
SHD_AVX2 bool bufferSpansAvx2(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh) {
  return eachSpanRun(r, at, [&](const Run& run, size_t first) SHD_AVX2 { return bufferRunAvx2In(run, first, t, b, fresh); });
}


#pragma GCC diagnostic pop

#else

bool cpuHasAvx512() { return false; }
bool cpuHasAvx2() { return false; }
bool available() { return false; }
bool availableAvx2() { return false; }
uint64_t shadeNh(const NhParams&, const uint64_t*, const uint64_t*, const uint64_t*, size_t n, uint32_t*,
                 int64_t* const[3]) {
  return allGroups(n);
}
size_t bufferRun(const Run&, size_t, const Target&, Batch&, uint64_t&) {
  throw std::logic_error("fixed_simd::bufferRun: built without the vector kernel");
}
uint64_t colourRunsAvx512(const ColourRuns&, const Target&, uint8_t*, uint64_t&) {
  throw std::logic_error("fixed_simd::colourRunsAvx512: built without the vector kernels");
}
uint64_t colourRunsAvx2(const ColourRuns&, const Target&, uint8_t*, uint64_t&) {
  throw std::logic_error("fixed_simd::colourRunsAvx2: built without the vector kernels");
}
uint64_t shadeNhAvx2(const NhParams&, const uint64_t*, const uint64_t*, const uint64_t*, size_t n, uint32_t*,
                     int64_t* const[3]) {
  return allGroups(n);
}
uint64_t colourSpansAvx2(const RowSpans&, size_t, int, const Target&, uint8_t*, uint64_t&) {
  throw std::logic_error("fixed_simd::colourSpansAvx2: built without the vector kernels");
}
uint64_t colourSpansAvx512(const RowSpans&, size_t, int, const Target&, uint8_t*, uint64_t&) {
  throw std::logic_error("fixed_simd::colourSpansAvx512: built without the vector kernels");
}
size_t bufferRunAvx2(const Run&, size_t, const Target&, Batch&, uint64_t&) {
  throw std::logic_error("fixed_simd::bufferRunAvx2: built without the vector kernels");
}
bool bufferSpans(const NhSpans&, SpanCursor&, const Target&, Batch&, uint64_t&) {
  throw std::logic_error("fixed_simd::bufferSpans: built without the vector kernel");
}
bool bufferSpansAvx2(const NhSpans&, SpanCursor&, const Target&, Batch&, uint64_t&) {
  throw std::logic_error("fixed_simd::bufferSpansAvx2: built without the vector kernels");
}

#endif

// ---- phong-fixed's batch in plain C++ (no intrinsics) ----
// shadeNh's three passes with the scalar datapath's own functions (cosineScale, scaleCosine,
// lobeAt, unorm8FromCode), fragment by fragment: where no vector kernel runs, the batch still
// keeps the runs' z-test and buffering apart from the datapath and lets the processor overlap
// the independent fragments of a pass.
uint64_t shadeNhScalar(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                       uint32_t* rgb, int64_t* const codes[3]) {
  uint64_t r64[kMaxBatch];  // each group's written by the first pass before the second reads it
  int64_t nl[kMaxBatch];    // the second pass's, for the third
  uint32_t f[kMaxBatch];
  return threePasses(
      n, codes != nullptr,
      [&](size_t i, int count) {
        // A group with a squared norm below cosineScale's fast path (r64 == 0) is declined.
        for (size_t e = i + static_cast<size_t>(count); i < e; ++i)
          if ((r64[i] = static_cast<uint64_t>(cosineScale(sq[i]).r64)) == 0) return false;
        return true;
      },
      [&](size_t i, int count, auto) {
        for (size_t e = i + static_cast<size_t>(count); i < e; ++i) {
          const CosineScale c{0, 1, static_cast<int64_t>(r64[i])};
          nl[i] = scaleCosine(static_cast<int64_t>(l[i]), c);
          f[i] = 0;  // N.H scaled only where the light reaches (as shadeDots)
          if (nl[i] > 0) f[i] = fixed_detail::lobeAt(p.table, scaleCosine(static_cast<int64_t>(h[i]), c), p.zero_below);
        }
      },
      [&](size_t i, int count, auto with_codes) {
        using fixed_detail::roundShift;
        for (size_t e = i + static_cast<size_t>(count); i < e; ++i) {
          std::array<uint8_t, 3> out;
          for (size_t k = 0; k < 3; ++k) {
            int64_t code = p.ambient[k];
            if (nl[i] > 0) code += roundShift(p.diffuse[k] * nl[i], 32) + roundShift(p.specular[k] * f[i], 24);
            if constexpr (decltype(with_codes)::value) codes[k][i] = code;
            out[k] = unorm8FromCode(code, kFixedColourFrac);
          }
          rgb[i] = packedRgb(out);
        }
      });
}

// bufferRun's z-test and buffering fragment by fragment, in its groups of 8 (the same stops when
// the batch has room for fewer than 8 more); its values stepped by adds from the run's first
// fragment taken: the squared norm by its difference two_b + c (2 k + 1), mod 2^64.
namespace {
[[gnu::always_inline]] inline size_t bufferRunScalarIn(const Run& r, size_t first, const Target& t, Batch& b,
                                                       uint64_t& fresh) {
  const uint64_t k0 = first;
  uint64_t sq = r.a + k0 * r.two_b + k0 * k0 * r.c, dsq = r.two_b + r.c * (2 * k0 + 1);
  uint64_t l = r.l + k0 * r.dl, h = r.h + k0 * r.dh;
  uint32_t z = r.px.z + static_cast<uint32_t>(k0) * r.px.dz;
  size_t n = b.n, k = first;
  uint64_t covered = 0;
  for (; k < r.px.count && n + 8 <= Batch::kCap;) {
    for (const size_t e = std::min(k + 8, r.px.count); k < e; ++k) {
      const size_t p = r.px.p + k;
      const int32_t old = t.depth[p];
      if (static_cast<int32_t>(z) > old) {
        covered += old == 0 ? 1 : 0;
        t.depth[p] = static_cast<int32_t>(z);
        if (t.tri != nullptr) t.tri[p] = t.tag;
        b.sq[n] = sq;
        b.l[n] = l;
        b.h[n] = h;
        b.pixel[n] = static_cast<uint32_t>(p);
        ++n;
      }
      sq += dsq;
      dsq += 2 * r.c;
      l += r.dl;
      h += r.dh;
      z += r.px.dz;
    }
  }
  b.n = n;
  fresh += covered;
  return k;
}

}  // namespace

size_t bufferRunScalar(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh) {
  return bufferRunScalarIn(r, first, t, b, fresh);
}
bool bufferSpansScalar(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh) {
  return eachSpanRun(r, at, [&](const Run& run, size_t first) { return bufferRunScalarIn(run, first, t, b, fresh); });
}

// colourSpansAvx2's rows pixel by pixel in plain C++ (no intrinsics): the same codes (RowSpans::at
// mod 2^32, in 32-bit lanes), the same z-test of int32_t codes and the same colour bytes. The
// codes of a triangle's pixels are exact in int32_t (setupRowSpans checks the plane there) and
// affine along a row: where both ends of a row lie in [0, 255 2^frac], so do all between, and
// unorm8FromCode is the rounding shift alone. A triangle of one colour (flat's) has its bytes
// found once. Frac: the fraction bits, as an int or a constant.
namespace {
template <bool kTags, class Frac>
uint64_t colourSpansPlain(const RowSpans& s, size_t W, Frac frac, const Target& t, uint8_t* rgb, uint64_t& passed) {
  // The codes (z, c0, c1, c2) as 32-bit lanes: attribute 3 first, as eachSpanRow's.
  auto lanes = [](const std::array<int64_t, 4>& v) {
    return std::array<uint32_t, 4>{static_cast<uint32_t>(v[3]), static_cast<uint32_t>(v[0]),
                                   static_cast<uint32_t>(v[1]), static_cast<uint32_t>(v[2])};
  };
  const std::array<uint32_t, 4> dx = lanes(s.didx), dy = lanes(s.didy);
  std::array<uint32_t, 4> left = lanes(s.a0);  // at column x0 of row y0 + i
  const int32_t top = int32_t{255} << frac, half = int32_t{1} << (frac - 1);
  auto clamped = [&](uint32_t code) {
    return static_cast<uint8_t>((std::clamp(static_cast<int32_t>(code), 0, top) + half) >> frac);
  };
  auto shifted = [&](uint32_t code) { return static_cast<uint8_t>((static_cast<int32_t>(code) + half) >> frac); };
  const bool one_colour = oneColour(s);
  const std::array<uint8_t, 3> colour = {clamped(left[1]), clamped(left[2]), clamped(left[3])};
  uint64_t covered = 0, pass_count = 0;
  // A row's count pixels from p, with the codes c at its first, unorm8 giving the colour bytes
  // (null: the triangle's one colour).
  auto row = [&](size_t p, size_t count, std::array<uint32_t, 4> c, auto unorm8) {
    int32_t* const depth = t.depth + p;
    uint8_t* const out = rgb + 3 * p;
    // The one colour's first two bytes as one 16-bit store and its third as one byte: two stores
    // a pixel instead of three, the values held in a local (the byte stores may alias what a
    // reference reaches, so the compiler would read the colour again after each).
    const std::array<uint8_t, 2> one01 = {colour[0], colour[1]};
    const uint8_t one2 = colour[2];
    for (size_t k = 0; k < count; ++k) {
      const int32_t z = static_cast<int32_t>(c[0]), old = depth[k];
      if (z > old) {
        covered += old == 0 ? 1 : 0;
        ++pass_count;
        depth[k] = z;
        if constexpr (kTags) t.tri[p + k] = t.tag;
        if constexpr (std::is_same_v<decltype(unorm8), std::nullptr_t>) {
          std::memcpy(out + 3 * k, one01.data(), 2);
          out[3 * k + 2] = one2;
        } else {
          for (size_t ch = 0; ch < 3; ++ch) out[3 * k + ch] = unorm8(c[ch + 1]);
        }
      }
      c[0] += dx[0];
      if constexpr (!std::is_same_v<decltype(unorm8), std::nullptr_t>)
        for (size_t ch = 1; ch < 4; ++ch) c[ch] += dx[ch];
    }
  };
  size_t at = static_cast<size_t>(s.y0) * W;
  for (int32_t i = 0; i < s.rows; ++i, at += W) {
    const int32_t lo = s.span[static_cast<size_t>(i)][0], hi = s.span[static_cast<size_t>(i)][1];
    if (lo <= hi) {
      std::array<uint32_t, 4> c;
      bool in_range = true;
      for (size_t k = 0; k < 4; ++k) {
        c[k] = left[k] + dx[k] * static_cast<uint32_t>(lo - s.x0);
        const int32_t a = static_cast<int32_t>(c[k]), b = static_cast<int32_t>(c[k] + dx[k] * static_cast<uint32_t>(hi - lo));
        in_range = in_range && (k == 0 || (std::min(a, b) >= 0 && std::max(a, b) <= top));
      }
      const size_t p = at + static_cast<size_t>(lo), count = static_cast<size_t>(hi - lo + 1);
      __builtin_prefetch(t.depth + p + 2 * W, 1);  // the row after next, as the vector kernels
      __builtin_prefetch(rgb + 3 * (p + 2 * W), 1);
      if (one_colour) row(p, count, c, nullptr);
      else if (in_range) row(p, count, c, shifted);
      else row(p, count, c, clamped);
    }
    for (size_t k = 0; k < 4; ++k) left[k] += dy[k];
  }
  passed += pass_count;
  return covered;
}
template <bool kTags>
uint64_t colourSpansFrac(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb, uint64_t& passed) {
  // The renderer's colour codes (kColourFrac) with constant shifts.
  if (frac == kColourFrac) return colourSpansPlain<kTags>(s, W, std::integral_constant<int, kColourFrac>{}, t, rgb, passed);
  return colourSpansPlain<kTags>(s, W, frac, t, rgb, passed);
}
}  // namespace

uint64_t colourSpansScalar(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb, uint64_t& passed) {
  return t.tri != nullptr ? colourSpansFrac<true>(s, W, frac, t, rgb, passed)
                          : colourSpansFrac<false>(s, W, frac, t, rgb, passed);
}

// Each kernel's choice: the AVX-512 one where available(), else the AVX2 one where
// availableAvx2(), else the plain C++ one where there is one, else null (the run loop; always
// without SHD_X86_KERNELS).
namespace {
template <class Kernel>
Kernel byCpu(Kernel avx512, Kernel avx2, Kernel scalar = nullptr) {
  return available() ? avx512 : availableAvx2() ? avx2 : scalar;
}
}  // namespace
ColourKernel colourKernel() { return byCpu<ColourKernel>(colourRunsAvx512, colourRunsAvx2); }
ColourSpansKernel colourSpansKernel() {
  return byCpu<ColourSpansKernel>(colourSpansAvx512, colourSpansAvx2, colourSpansScalar);
}
NhKernel nhKernel() { return byCpu<NhKernel>(shadeNh, shadeNhAvx2, shadeNhScalar); }
BufferKernel bufferKernel() { return byCpu<BufferKernel>(bufferRun, bufferRunAvx2, bufferRunScalar); }
SpansBufferKernel spansBufferKernel() {
  return byCpu<SpansBufferKernel>(bufferSpans, bufferSpansAvx2, bufferSpansScalar);
}

}  // namespace shd::fixed_simd
