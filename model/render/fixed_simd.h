// phong-fixed's datapath for fragments 8 at a time, in AVX-512 (F, DQ, CD) where
// the CPU has it: the same integer operations as FixedPointShader::shade() (fixed_shading.h,
// normalize.h), lane by lane, so the same colours. It covers the common case, one directional
// light and a lobe of N.H from a table (blinn, pow, normalized-blinn, schlick); everything
// else, and lanes it cannot take (a squared norm below 2^8, see CosineScale), stays scalar.
//
// The 128-bit products of the scalar path become 64-bit lane operations:
//   m r0^2 >> 32   r0^2 < 2^34 split at 2^32: mq a + (mq b >> 32), each product below 2^64;
//   scaleCosine    the high word of the signed 64 x 64 product d r64 from four 32 x 32
//                  products, plus the carry of adding 2^63 to the low word;
//   idx            ((mq - 2^30) << 10) / (3 2^30) = ((mq - 2^30) >> 20) / 3, the quotient by 3 of
//                  a number below 3072 as a multiply and shift (exact below 2^15).
// Test FixedSimd.* compares the lanes with shade() on random and extreme inputs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

namespace shd::fixed_simd {

// The CPU runs the vector kernel (AVX-512 F, DQ and CD), and SHD_SCALAR is not set in the
// environment (which forces the scalar path, for comparisons).
bool available();

// The constants of the one light and the lobe table.
struct NhParams {
  const uint32_t* table = nullptr;  // lobeTable's entries
  uint32_t zero_below = 0;          // and its LobeTable::zero_below
  std::array<int64_t, 3> ambient{}, diffuse{}, specular{};
};

// Fragments i < n (n <= kMaxBatch) in groups of 8 (fragments 8g .. 8g + 7): squared norm sq[i]
// (56 fraction bits) and the raw dot products N.L = l[i] and N.H = h[i] (58 fraction bits,
// two's complement) give the output colour rgb[k][i] of channel k and, where codes is not
// null, the 12-fraction-bit code before the output rounding (FixedShade::code) in codes[k][i].
// Returns the groups it declines (bit g: a fragment of group g needs the scalar path); their
// outputs are untouched. The inputs hold n rounded up to a multiple of 8 readable entries
// (those past n are read and ignored), the outputs as many writable ones.
constexpr size_t kMaxBatch = 512;
uint64_t shadeNh(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                 uint8_t* const rgb[3], int64_t* const codes[3] = nullptr);
// Every group of n fragments: what shadeNh returns when it takes none.
inline uint64_t allGroups(size_t n) { return n == 0 ? 0 : ~uint64_t{0} >> (64 - (n + 7) / 8); }

}  // namespace shd::fixed_simd
