// The explog kind of the specular unit: c^n = 2^(-n (-log2 c)) from a logarithm table and an
// exponent table, both linearly interpolated; rtl/shd_spec_explog.v is its RTL and proves the
// widths (SpecUnitParams::expLogWidths).
//
// The tables are fixed (not per shininess). Both sides compute them with the same integer
// algorithm in 60-bit fixed point (the RTL in constant functions at elaboration), so no
// floating-point library takes part and the words are equal by construction:
//   g(i) = -log2(1 - D) / D at D = i / 2^(T+1), i = 0..2^T: the series sum_k D^k / (k+1) (62
//          terms, each floor-divided), times floor(log2(e) 2^60), rounded half up to GF bits;
//   e(j) = 2^-x at x = j / 2^T, j = 0..2^T: sum_k (-x ln 2)^k / k! (30 terms, z = floor(x
//          floor(ln(2) 2^60)), terms floor-divided), rounded half up to EF bits.
// Word i of the log ROM is {g(i+1) - g(i), g(i)}, word j of the exp ROM {e(j) - e(j+1), e(j)}.
#pragma once

#include <cstdint>
#include <vector>

#include "device/spec_params.h"

namespace shd {

struct ExpLogTables {
  ExpLogWidths w{};        // the parameters' widths, derived once
  std::vector<int64_t> g;  // 2^T + 1 codes, GF fraction bits
  std::vector<int64_t> e;  // 2^T + 1 codes, EF fraction bits
};

// std::logic_error if a step between neighbours does not fit its ROM field (the widths'
// proof in rtl/shd_spec_explog.v would be wrong).
ExpLogTables makeExpLogTables(const SpecUnitParams& p);

// f (uQ1.Wf code) for the saturated cosine code c (0..2^Wc) and the PROM's n code (uQCi.Cf),
// the integer datapath of rtl/shd_spec_explog.v step by step.
int64_t expLogSpec(const SpecUnitParams& p, const ExpLogTables& t, int64_t n_code, int64_t c);

}  // namespace shd
