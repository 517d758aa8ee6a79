// SpecUnitModel: the bit-exact, cycle-accurate twin of rtl/shd_spec_unit.v.
//
// Datapath of the poly kind (paper Fig. 11, with the corrections of docs/paper-corrections.md
// 4.3), formats from SpecUnitParams, rounding named where the RTL rounds:
//   c   = min(cos_i, 1.0)                              uQ1.Wc   (RG2; N.H may overshoot 1)
//   sq  = c * c                                        MUL1, exact
//   d   = sq + ~c + 1 = c^2 - c  in [-1/4, 0]           BI + Sm1 with carry-in, exact
//   dt  = d -> sQ1.Df                                  Trunc (floor)
//   degree 2:  P = a * dt                              MUL2, exact
//   degree 3:  g = u*c + v -> sQ(Ci+1).Hf (Trunc);  P = dt * g    (Horner; u = a1, v = a1 + b1)
//   Pr  = P -> Wf fraction bits                        RoundHalfUp
//   f   = c + Pr, saturated to [0, 1] (degree 3: 0 when c < cut)   Sm2 + clamp, uQ1.Wf
//   out = f * L_k -> integer                           MUL3..MUL5, RoundHalfUp, unorm LightBits
// The table kind:   f = PROM[{shin, min(c >> (Wc - T), 2^T - 1)}]      (one registered read)
// The schlick kind: f = floor(c 2^(Cf+Wf) / (m (2^Wc - c) + 2^(Cf+Wc)))  with m = n - 1 from
//                   PROM[shin]: c / (n - n c + c) truncated to uQ1.Wf (a restoring divider)
// The explog kind:  f = 2^(-n L), L = -log2 c, n from PROM[shin], both by interpolated tables
//                   (device/spec_explog.h)
// The piecewise kind: PROM[shin] holds the segments' first codes B_0 (the cut) .. B_S-1; the
//                   segment s = #{j >= 1 : c >= B_j} selects the segment ROM's word {K, e} at
//                   {shin, s}; f = Horner's scheme in u = (c - B_s) 2^e / 2^Wc with floors,
//                   rounded half up to Wf bits and clamped to [0, 1]; 0 below B_0
//                   (approx/piecewise.h PiecewiseCodes::eval, rtl/shd_spec_piecewise.v)
// Every kind ends in the same MUL3..MUL5.
// Pipeline: registered inputs and PROM read (cycle 1), PipeStages optional registers, registered
// outputs; latency 2 + PipeStages, one result per cycle. The output registers load only when
// their stage is valid, so outputs hold the last valid result; they reset to zero.
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "approx/piecewise.h"
#include "device/spec_explog.h"
#include "device/spec_params.h"
#include "fixed/fixed.h"

namespace shd {

using PromWord = unsigned __int128;

// The fields of one PROM word as raw codes. Degree 2: u = a (uQCi.Cf), v = cut = 0.
// Degree 3: u = a1, v = a1 + b1 (sQCi.Cf), cut = cos code below which f = 0. Table: u = f
// (uQ1.Wf). Schlick: u = m = n - 1 (uQCi.Cf). Explog: u = n (uQCi.Cf).
struct SpecCoef {
  int64_t u = 0;
  int64_t v = 0;
  int64_t cut = 0;
};
PromWord encodePromWord(const SpecCoef& coef, const SpecUnitParams& p);
SpecCoef decodePromWord(PromWord word, const SpecUnitParams& p);

// The piecewise kind's words for one shininess code: the PROM word of the first codes (unused
// segments above the fit's get B = 2^Wc + 1, which no cosine reaches) and the Segments words of
// the segment ROM (unused: 0). std::out_of_range if a code does not fit its field.
PromWord encodePiecewiseBounds(const PiecewiseCodes& q, const SpecUnitParams& p);
std::vector<PromWord> encodePiecewiseSegments(const PiecewiseCodes& q, const SpecUnitParams& p);
// The codes of one shininess code back from its PROM word and its Segments segment ROM words;
// std::invalid_argument if the words are not well formed (see SpecUnitModel).
PiecewiseCodes decodePiecewise(PromWord bounds, const PromWord* segs, const SpecUnitParams& p);

struct SpecIn {
  bool valid = false;
  uint32_t shin = 0;                // RG1, shininess code (PROM address)
  uint32_t cos = 0;                 // RG2, uQ1.Wc code
  std::array<uint32_t, 3> light{};  // RG3..RG5, k_s * light R, G, B as unorm codes
};

struct SpecOut {
  bool valid = false;
  uint32_t spec = 0;              // f, uQ1.Wf code
  std::array<uint32_t, 3> rgb{};  // specular colour, unorm LightBits
  friend bool operator==(const SpecOut& a, const SpecOut& b) {
    return a.valid == b.valid && a.spec == b.spec && a.rgb == b.rgb;
  }
  friend bool operator!=(const SpecOut& a, const SpecOut& b) { return !(a == b); }
};

// Intermediate values of one evaluation, for reports and mismatch diagnostics (the table and
// other kinds fill c and f only).
struct SpecTrace {
  Fixed c, sq, d, dt, g, p, pr, f;
  bool cut = false;
};

class SpecUnitModel {
 public:
  // prom holds promDepth() words and seg (the piecewise kind's segment ROM) segDepth() words;
  // std::invalid_argument if not, or if a word has bits above its width (the table kind: a
  // word above 1.0; the piecewise kind: first codes that decrease, a scale above CosFracBits or
  // one that would carry u past 1.0 in its segment).
  SpecUnitModel(SpecUnitParams params, std::vector<PromWord> prom, std::vector<PromWord> seg = {});

  const SpecUnitParams& params() const { return p_; }
  const std::vector<PromWord>& prom() const { return prom_; }
  const std::vector<PromWord>& segRom() const { return seg_; }

  // The combinational function the pipeline delivers latency() cycles later, on raw integers
  // (the fast path the co-simulation runs). Inputs must fit their ports (std::out_of_range).
  SpecOut evaluate(uint32_t shin, uint32_t cos, const std::array<uint32_t, 3>& light) const;
  // The same datapath written with Fixed values in their formats, with every intermediate:
  // the readable formulation, for diagnostics and reports; trace().f equals evaluate().spec.
  SpecTrace trace(uint32_t shin, uint32_t cos) const;
  // The largest cosine code up to which f is 0 at every code for shininess code shin (the
  // polynomial's zero, the cubic's cut-off, a table's or a segment's zeros), or -1 when f(0) > 0:
  // there the output is 0 whatever the light. Found by evaluating codes 0, 1, ... in turn.
  int64_t zeroCode(uint32_t shin) const;

  // Cycle-accurate: state after reset, and the outputs after one rising clock edge with `in`
  // on the input ports.
  void reset();
  SpecOut tick(const SpecIn& in);
  uint64_t cycle() const { return cycle_; }

  // The least cosine code per shininess code (PROM address) a configuration was sized for
  // (shadesim prune: the least the scene reached): checkCosine() then refuses a cosine below it
  // with std::invalid_argument naming the code, the address and `origin`. Empty: every code.
  // The renderer's paths to the model check (render.h ModelSpecEngine, the memo, phong's direct
  // requests); evaluate() itself does not, so the co-simulation's fast path stays as it is.
  void limitCosines(std::vector<uint32_t> least, std::string origin);
  void checkCosine(uint32_t shin, uint32_t cos) const {
    if (!cos_least_.empty() && (shin >= cos_least_.size() || cos < cos_least_[shin])) refuseCosine(shin, cos);
  }

 private:
  void checkInputs(uint32_t shin, uint32_t cos) const;  // std::out_of_range naming the port
  void refuseCosine(uint32_t shin, uint32_t cos) const;  // below cos_least_: std::invalid_argument
  int64_t tableIndex(int64_t c) const;                   // table: the cosine address
  int64_t altSpec(uint32_t shin, int64_t c) const;       // f of the kinds other than poly
  SpecOut backEnd(int64_t f, const std::array<uint32_t, 3>& light) const;  // MUL3..MUL5
  struct Stage {
    bool valid = false;
    SpecOut value;
  };
  SpecUnitParams p_;
  std::vector<PromWord> prom_;
  std::vector<SpecCoef> coef_;  // decoded prom_
  ExpLogTables explog_;         // the explog kind's fixed tables
  std::vector<PromWord> seg_;   // the piecewise kind's segment ROM
  std::vector<uint32_t> cos_least_;  // limitCosines()
  std::string cos_origin_;
  std::vector<PiecewiseCodes> pieces_;  // decoded per shininess code
  std::vector<Stage> pipe_;     // ring buffer, latency() entries
  size_t head_ = 0;
  SpecOut out_;
  uint64_t cycle_ = 0;
};

}  // namespace shd
