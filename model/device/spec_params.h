// Parameters of shd_spec_unit, named exactly as the Verilog parameters: the "rtl" object of a
// specular-unit configuration (config/registry.h). Missing members take the defaults below;
// unknown members are errors.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "fixed/fixed.h"

namespace shd {

// The kinds of specular unit (the parameter Kind), one list: the paper's polynomial device and the
// alternatives a designer would weigh against it (rtl/shd_spec_unit.v describes each datapath).
enum class SpecKind { Poly = 0, Table = 1, Schlick = 2, ExpLog = 3, Piecewise = 4 };
struct SpecKindInfo {
  SpecKind kind;
  const char* name;   // "poly", "table", "schlick", "explog", "piecewise"
  const char* what;   // one line for tables and --help
};
const std::vector<SpecKindInfo>& specKinds();
const SpecKindInfo& specKindInfo(SpecKind k);

// The widths the explog kind derives from the parameters (rtl/shd_spec_explog.v proves each):
// fraction bits of the log table's g = -log2(1 - D) / D, of L = -log2 c, of the exp table's
// e = 2^-x, and of y = n L as the exp table and its interpolation use it; LI the integer bits of
// L <= CosFracBits.
struct ExpLogWidths {
  int GF, LF, EF, EX, LI;
  int gBits() const { return GF + 2; }             // g <= 2
  int gStepBits(int T) const { return GF - T + 1; }
  int eBits() const { return EF + 1; }             // e <= 1
  int eStepBits(int T) const { return EF - T + 1; }
};

struct SpecUnitParams {
  int Degree = 2;           // poly: 2 a c^2 + (1-a) c, 3 cubic in Horner form with cut-off;
                            // piecewise: each segment's degree, 1..3
  int CosFracBits = 15;     // Wc: cos_i is uQ1.Wc; codes above 1.0 saturate to 1.0
  int ShinBits = 10;        // PROM address width: 2^ShinBits shininess codes
  int CoefIntBits = 10;     // Ci: coefficient uQCi.Cf (degree 2) or sQCi.Cf (degree 3)
  int CoefFracBits = 14;    // Cf
  int DiffFracBits = 28;    // Df: c^2 - c truncated to sQ1.Df before MUL2 (2*Wc = exact)
  int HornerFracBits = 14;  // Hf: degree 3 only, g = u*c + v truncated to Hf fraction bits
  int SpecFracBits = 16;    // Wf: the specular value f leaves Sm2 as uQ1.Wf
  int LightBits = 8;        // light channels (k_s * L) and colour out: unorm LightBits
  int PipeStages = 1;       // internal pipeline registers (poly 0..3, table 0..1, schlick 0..Wf+1,
                            // explog 1..3, piecewise 1..Degree+1); latency = 2 + PipeStages
  int Kind = 0;             // SpecKind: 0 poly (Degree 2 or 3), 1 table, 2 schlick, 3 explog,
                            // 4 piecewise
  int TableBits = 8;        // table: cosine address bits T, 1..CosFracBits; explog: the log and
                            // exp tables have 2^T intervals each, 1..min(CosFracBits, Wf+3)
  int Segments = 1;         // piecewise: cosine segments per n, 1, 2 or 4

  SpecKind kind() const { return static_cast<SpecKind>(Kind); }

  // Derived formats (see rtl/shd_spec_unit.v for the width derivations).
  FixedFormat cosFormat() const { return FixedFormat::u(1, CosFracBits); }
  FixedFormat coefFormat() const {
    return {(kind() == SpecKind::Poly && Degree == 3) || kind() == SpecKind::Piecewise, CoefIntBits, CoefFracBits};
  }
  FixedFormat diffFormat() const { return FixedFormat::s(1, DiffFracBits); }
  FixedFormat hornerFormat() const { return FixedFormat::s(CoefIntBits + 1, HornerFracBits); }
  FixedFormat specFormat() const { return FixedFormat::u(1, SpecFracBits); }
  FixedFormat lightFormat() const { return FixedFormat::u(LightBits, 0); }
  int latency() const { return 2 + PipeStages; }
  int shinCodes() const { return 1 << ShinBits; }  // shin_i values
  // PROM address bits and depth: shin_i, and for the table the cosine index below it.
  int promAddrBits() const { return ShinBits + (kind() == SpecKind::Table ? TableBits : 0); }
  int promDepth() const { return 1 << promAddrBits(); }
  // PROM word: poly degree 2 {a}; poly degree 3 {cut[Wc:0], v, u} (u in the LSBs); table {f}
  // (uQ1.Wf); schlick {m = n - 1} (uQCi.Cf, unsigned); explog {n} (uQCi.Cf, unsigned);
  // piecewise {B_S-1, ..., B_1, B_0}, the segments' first cosine codes (uQ1.Wc; B_0 the cut).
  int promWordBits() const;
  // The piecewise kind's segment ROM (file <RomFile>.seg), address {shin, s}: word
  // {K_Degree, ..., K_0, e} with e the scale (segScaleBits() bits) and K_j sQCi.Cf. Depth 0 for
  // the other kinds, which have no segment ROM.
  int segAddrBits() const;  // ShinBits + log2(Segments)
  int segDepth() const { return kind() == SpecKind::Piecewise ? 1 << segAddrBits() : 0; }
  int segScaleBits() const;  // clog2(CosFracBits + 1)
  int segWordBits() const;
  ExpLogWidths expLogWidths() const;
  // Bits of the fixed ROMs beside the PROM: the explog kind's log and exp tables, 0 otherwise.
  int64_t fixedRomBits() const;
  // Bits of the memories that hold per-n contents: the PROM and the piecewise kind's segment ROM.
  int64_t promBits() const {
    return int64_t{promDepth()} * promWordBits() + (segDepth() > 0 ? int64_t{segDepth()} * segWordBits() : 0);
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
