// The error report of the specular unit, split in two (error against run time is only useful
// when one knows which part of it the hardware adds):
//   (a) approximation: the ideal device (the fit's real coefficients, clamp and cut-off, in
//       double precision) against cos^n, over continuous c, exact maxima (lobe_error.h):
//       whole lobe [0, 1]; peak50 (c^n >= 0.5); inflection (c from 1 down to the inflection
//       point). Absolute, and relative in the two peak regions.
//   (b) datapath: the bit-exact unit (SpecUnitModel: stored coefficient codes, truncations,
//       roundings) against the ideal device at every cos code 0..2^Wc, in output LSBs. The
//       output is a colour channel, unorm LightBits, at full light (L = 2^LightBits - 1), so one
//       LSB is 1/(2^LightBits - 1) of full scale and the final rounding alone costs 0.5 LSB.
//       Also in LSBs of the internal f (spec_o, uQ1.Wf).
//   (c) total: the unit against cos^n at every cos code, in output LSBs.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "approx/lobe_error.h"
#include "device/prom.h"

namespace shd {

struct SpecErrorRow {
  double n = 0;
  uint32_t address = 0;
  RegionError lobe, peak50, inflection;  // (a)
  double datapath_max_lsb = 0, datapath_worst_c = 0, datapath_max_f_lsb = 0;  // (b)
  double total_max_lsb = 0, total_worst_c = 0;                                 // (c)
  double total_peak_max_lsb = 0;  // (c) restricted to c^n >= 0.5
};

// Worst of each quantity over all rows, with the n where it first occurs.
struct SpecErrorWorst {
  double value = 0;
  double n = 0;
};
struct SpecErrorSummary {
  SpecErrorWorst approx_lobe_max_abs, approx_peak_max_abs, approx_peak_max_rel,
      approx_inflection_max_abs, approx_inflection_max_rel, datapath_max_lsb, datapath_max_f_lsb,
      total_max_lsb, total_peak_max_lsb;
};

struct SpecErrorReport {
  std::string config;
  PromTable table;
  std::vector<SpecErrorRow> rows;
  SpecErrorSummary summary;
  double seconds = 0;
};

// One row per PROM entry; `progress(done, total)` is called after each row when given. `codes`:
// the cosine codes evaluated (ascending, each in 0..2^CosFracBits); empty: every one.
SpecErrorReport computeSpecError(const std::string& config, const PromTable& table,
                                 const std::function<void(size_t, size_t)>& progress = {},
                                 const std::vector<int64_t>& codes = {});

nlohmann::json toJson(const SpecErrorReport& r);

// A table a person can read: for the selected n, the primary fit's errors beside the
// comparison fit's (if any), then the summaries over all n.
std::string renderSpecErrorTable(const SpecErrorReport& primary, const SpecErrorReport* compare,
                                 const std::vector<double>& show_n);

// n values worth showing from a long list: 1, 2, 3, 5, 8, 16, ... up to the largest (those
// present in the table), or all of them when there are at most 24.
std::vector<double> representativeN(const PromTable& t);

}  // namespace shd
