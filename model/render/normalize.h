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

// The recurrence along one span: start() at its first pixel returns F_0 = A, each next() the
// following pixel's F_i (two additions).
class SquaredNormRecurrence {
 public:
  uint64_t start(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn) {
    uint64_t A = 0, B = 0, C = 0;
    for (size_t k = 0; k < 3; ++k) {
      const uint64_t a = static_cast<uint64_t>(n0[k]), d = static_cast<uint64_t>(dn[k]);
      A += a * a;
      B += a * d;
      C += d * d;
    }
    F_ = A;
    two_b_ = 2 * B;
    two_c_ = 2 * C;
    ci_ = C;  // C_1 = C
    return F_;
  }
  uint64_t next() {
    F_ += two_b_ + ci_;  // F_i = F_{i-1} + 2B + C_i
    ci_ += two_c_;       // C_{i+1} = C_i + 2C
    return F_;
  }

 private:
  uint64_t F_ = 0, two_b_ = 0, two_c_ = 0, ci_ = 0;
};

std::vector<uint64_t> squaredNormsAlongSpan(const std::array<int64_t, 3>& n0, const std::array<int64_t, 3>& dn,
                                            size_t count);

// 1/sqrt(v * 2^-frac_bits) for v > 0 (0 for v == 0), 16 significant fraction bits.
double rsqrtFixed(uint64_t v, int frac_bits);

}  // namespace shd
