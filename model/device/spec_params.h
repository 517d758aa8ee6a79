// Parameters of shd_spec_unit, named exactly as the Verilog parameters: the "rtl" object of a
// specular-unit configuration (config/registry.h). Missing members take the defaults below;
// unknown members are errors.
#pragma once

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "fixed/fixed.h"

namespace shd {

struct SpecUnitParams {
  int Degree = 2;           // 2: a c^2 + (1-a) c ; 3: cubic, Horner form, with cut-off
  int CosFracBits = 15;     // Wc: cos_i is uQ1.Wc; codes above 1.0 saturate to 1.0
  int ShinBits = 10;        // PROM address width: 2^ShinBits shininess codes
  int CoefIntBits = 10;     // Ci: coefficient uQCi.Cf (degree 2) or sQCi.Cf (degree 3)
  int CoefFracBits = 14;    // Cf
  int DiffFracBits = 28;    // Df: c^2 - c truncated to sQ1.Df before MUL2 (2*Wc = exact)
  int HornerFracBits = 14;  // Hf: degree 3 only, g = u*c + v truncated to Hf fraction bits
  int SpecFracBits = 16;    // Wf: the specular value f leaves Sm2 as uQ1.Wf
  int LightBits = 8;        // light channels (k_s * L) and colour out: unorm LightBits
  int PipeStages = 1;       // internal pipeline registers, 0..3; latency = 2 + PipeStages

  // Derived formats (see rtl/shd_spec_unit.v for the width derivations).
  FixedFormat cosFormat() const { return FixedFormat::u(1, CosFracBits); }
  FixedFormat coefFormat() const { return {Degree == 3, CoefIntBits, CoefFracBits}; }
  FixedFormat diffFormat() const { return FixedFormat::s(1, DiffFracBits); }
  FixedFormat hornerFormat() const { return FixedFormat::s(CoefIntBits + 1, HornerFracBits); }
  FixedFormat specFormat() const { return FixedFormat::u(1, SpecFracBits); }
  FixedFormat lightFormat() const { return FixedFormat::u(LightBits, 0); }
  int latency() const { return 2 + PipeStages; }
  int promDepth() const { return 1 << ShinBits; }
  // PROM word: degree 2 {a}; degree 3 {cut[Wc:0], v, u} (u in the LSBs).
  int promWordBits() const {
    return Degree == 2 ? coefFormat().width() : 2 * coefFormat().width() + CosFracBits + 1;
  }
  int64_t cosOne() const { return int64_t{1} << CosFracBits; }
  int64_t lightMax() const { return (int64_t{1} << LightBits) - 1; }

  // Throws std::invalid_argument naming the parameter and the limit it breaks, including
  // widths the model or the RTL ports cannot hold.
  void validate() const;

  // Reads the "rtl" object; unknown or non-integer members are errors naming `where`.
  static SpecUnitParams fromJson(const nlohmann::json& rtl, const std::string& where);
  nlohmann::json toJson() const;
};

// Which coefficients the PROM holds.
struct PromContent {
  std::string fit = "inflection";  // inflection | level | shortcut | minimax
  double level = 0.5;              // q (degree 2 level fit) or Q (degree 3)
  std::string n = "1:1000";        // "lo:hi[:step]" range or, with is_list, "8,32,200"
  bool is_list = false;
};

}  // namespace shd
