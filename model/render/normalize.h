// Normalising interpolated normals in hardware terms (phong-incremental).
//
// Squared norm along a span (paper 4.1, as corrected by the errata): with N_i = N_0 + i dN,
//   F_i = |N_i|^2 = A + 2 i B + i^2 C,  A = |N_0|^2, B = N_0 . dN, C = |dN|^2,
// and by finite differences F_{i+1} = F_i + 2B + C_{i+1}, C_{i+1} = C_i + 2C, with F_0 = A and
// C_1 = C (the paper's seed "C_0 = 1" is wrong). After the three products of A, B and C once per
// span, each pixel costs two additions. On integer attribute codes the recurrence is exact;
// it runs in uint64_t, i.e. modulo 2^64, so large increments (slivers) wrap in the partial sums
// but every F_i, which fits, comes out exact.
//
// Reciprocal square root in fixed point: a 256-entry table of 1/sqrt(m) (uQ2.16) for the
// mantissa m in [1/4, 1) and one Newton step, all in integers.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace shd {

// out(i, F_i) for i = 0 .. count-1.
template <class Out>
void squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn, size_t count, Out out) {
  if (count == 0) return;
  uint64_t A = 0, B = 0, C = 0;
  for (size_t k = 0; k < 3; ++k) {
    const uint64_t a = static_cast<uint64_t>(n0[k]), d = static_cast<uint64_t>(dn[k]);
    A += a * a;
    B += a * d;
    C += d * d;
  }
  uint64_t F = A, Ci = C;  // F_0 = A, C_1 = C
  out(size_t{0}, F);
  for (size_t i = 1; i < count; ++i) {
    F += 2 * B + Ci;  // F_i = F_{i-1} + 2B + C_i
    Ci += 2 * C;      // C_{i+1} = C_i + 2C
    out(i, F);
  }
}
std::vector<uint64_t> squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn,
                                            size_t count);

// 1/sqrt(v * 2^-frac_bits) for v > 0 (0 for v == 0), 16 significant fraction bits.
double rsqrtFixed(uint64_t v, int frac_bits);

}  // namespace shd
