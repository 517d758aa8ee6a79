// The span unit (paper 4.1-4.2): fragments of a triangle along raster lines, with the constant
// attribute increment dI/dx, in lanes. SpanUnitModel is the bit-exact, cycle-accurate twin of
// rtl/shd_span_unit.v; SpanDesc is the triangle descriptor that triangle setup
// (raster/setup.h) produces and both consume.
//
// ---------------------------------------------------------------------------------------------
// Frames and lanes
//   The unit walks a *walker frame*: rows w (integers) and columns x (integers), signed.
//   It holds NumTri *lane-triangles*, each a triangle given in the walker frame by up to three
//   edges in solved (DDA) form, with its own row range and clip box, and an output map from the
//   walker frame to screen pixels. Each lane-triangle drives LanesPerTri lanes. The lane modes
//   are the span configurations (vectors/config/span_<mode>.json); those of the registry:
//     serial      NumTri 1, LanesPerTri 1
//     evenodd     NumTri 1, LanesPerTri 2, AlignLanes 1: lane i takes the pixels x = i (mod 2),
//                 as a framebuffer interleaved in two banks by x parity would
//     seg2/4/8    NumTri 1, LanesPerTri 2^k, AlignLanes 0: lane i takes x = xs + i + t*2^k of a
//                 span starting at xs (segments of the span, the last one masked)
//     sierpinski  NumTri 4, LanesPerTri 1: the triangle split at its edge midpoints; the walker
//                 frame is the corner sub-triangle at vertex 0; sub-triangles 1 and 2 are
//                 translated copies (integer pixel offset, rounded), sub-triangle 3 (the middle
//                 one) is point-reflected, so its pixels are walked in the opposite direction.
//                 Each lane-triangle carries its own exact edges, so when an edge delta is odd
//                 (the paper's "cut points") every lane still covers exactly its own pixels.
//   Any product of the two works (NumTri 4 with LanesPerTri 2: each sub-triangle in segments
//   of two): setup splits by NumTri, the walker shows LanesPerTri columns per lane-triangle.
//   Interleave = 1 (NumTri 4): a descriptor may instead interleave rows (its `interleave` bit):
//   lane-triangle j is the whole triangle on the screen rows NumTri*w + j, so four adjacent
//   rows leave together; the walker frame is the screen squeezed NumTri times vertically, and
//   each lane-triangle's edges are exact in it (E = A x + NumTri B w + C + B j). Setup chooses,
//   per triangle, the assignment with fewer cycles (raster/setup.h).
//   Every lane reads the same walker attribute plane: I_w(x, w) = iref + didx*(x - xref)
//   + didy*(w - row_first), exact integer (two's complement) arithmetic on attribute codes. A
//   lane's fragment at walker (x, w) has, with y = NumTri*w for a descriptor that interleaves
//   rows and y = w otherwise,
//       flip = 0:  pixel (x + ox, y + oy),  attribute I_w(x, w) + aoff
//       flip = 1:  pixel (ox - x, oy - y),  attribute aoff - I_w(x, w)
//   Because all of it is exact integer arithmetic on one plane, every mode produces, pixel by
//   pixel, the code the plane equation gives there: bit-identical across modes by construction
//   (and test_span_unit checks it).
//
// Edges in solved form (one DDA per edge)
//   A lane-triangle's edge is a linear function E = A x + B w + C' (C' includes the top-left
//   bias, raster/setup.h) and the pixel (x, w) is inside the edge iff E >= 0. With D = |A| > 0
//   and N = -(B w + C'):
//     left edge  (A > 0):  x >= N/D,   i.e. x >= ceil(N/D)
//     right edge (A < 0):  x <= -N/D,  i.e. x <= floor(-N/D) = -ceil(N/D)
//   so every edge keeps q = ceil(N/D) and r = q*D - N in [0, D), and the bound is q (left) or
//   -q (right). From row w to w+1, N grows by -B = k*D + m with 0 <= m < D:
//       r' = r - m;  if r' < 0 { r' += D; q' = q + k + 1 } else { q' = q + k }
//   exactly (no division per row). An edge bounds the span only in its active rows
//   [row_first, row_last] (the rows whose pixel centre lies within the edge's vertical extent,
//   within its lane-triangle's rows: setup trims those to the first and last with a pixel);
//   a lane-triangle's horizontal edge has no DDA: setup folds it into the lane-triangle's row
//   range. Unused edge slots have row_first > row_last.
//
// ---------------------------------------------------------------------------------------------
// Cycle behaviour (identical in the RTL). One clock; synchronous state, reset to IDLE.
//   Outputs are functions of the registers only (valid/ready without combinational paths from
//   inputs to outputs):
//     desc_ready = (state == IDLE)
//     in SPAN, for lane-triangle j and lane i (lane index j*LanesPerTri + i), at x = xg + i:
//       lane_valid = ne_j && lo_j <= x && x <= hi_j
//       fragment: pixel and attribute by the map above, attribute = map(icur + i*didx)
//     out_valid = OR of lane_valid (0 outside SPAN); tag = the descriptor's tag
//   At the rising edge:
//     IDLE: if desc_valid: latch the descriptor; w <- row_first; every edge (q, r) <- (q0, r0);
//           irow <- iref; state <- ROW.
//     ROW:  for each lane-triangle j:
//             in_j = row_first_j <= w <= row_last_j
//             lo_j = max(clip_x0_j, q_e of the left edges e active at w)
//             hi_j = min(clip_x1_j, -q_e of the right edges e active at w)
//             ne_j = in_j && lo_j <= hi_j                       (latched with lo_j, hi_j)
//           if some ne_j:  xs = min of lo_j, xe = max of hi_j over the ne_j (xe latched);
//                          xg <- AlignLanes ? xs - (xs mod LanesPerTri) : xs;
//                          icur <- irow + didx*(xg - xref);  wspan <- w;  state <- SPAN
//           else:          state <- (w == row_last) ? IDLE : ROW
//           in both cases: every edge active at w with w < its row_last steps its DDA;
//                          irow <- irow + didy;  w <- w + 1
//     SPAN: if !out_valid || out_ready:
//             if xg + LanesPerTri > xe: state <- (wspan == row_last) ? IDLE : ROW
//             else:                     xg <- xg + LanesPerTri; icur <- icur + LanesPerTri*didx
//   Cycles per triangle without stalls: 1 (IDLE, accepting) + sum over walker rows of
//   (1 + the SPAN cycles of the row), SPAN cycles = floor((xe - xg0)/LanesPerTri) + 1.
//
// The full-rate unit (RowAhead = 1): the same rows, fragments and order per descriptor, without
//   the ROW cycle between rows and the IDLE cycle between descriptors. Three stages:
//     F, the former: the walker (w, irow, the edges' DDAs) and its descriptor; in each busy
//       cycle it forms row w exactly as ROW above (lo_j, hi_j, ne_j, xe, xg0 = the row's first
//       xg, icur0 = irow + didx*(xg0 - xref)), and moves on (the DDA steps, irow, w + 1) unless
//       the row has pixels and B stays full. After its descriptor's row_last it takes the next
//       descriptor in the same edge: Q's, else the one accepted in this cycle; else it idles.
//     Q, one descriptor register: desc_ready = !Q.valid. An accepted descriptor goes straight
//       to F when F takes one in the same edge (F idle or finishing) and Q is empty, else to Q.
//     B, one row register: the row F formed with pixels, with its descriptor's output map.
//     E, the emitter: shows its row's lane groups as SPAN above (xg from xg0, icur from icur0,
//       the same lanes and outputs). When its row's last group leaves (or E is empty) it takes
//       B's row in the same edge, or with B empty the row F forms in that cycle (as the paper's
//       SPAN follows its ROW cycle); so a row's first group follows the last group of the row
//       before with no cycle between, while F keeps ahead.
//   At the rising edge, in this order of dependence: E's group leaves (!out_valid || out_ready);
//   E takes B's row if E is free, or F's row if E is free and B empty; B takes F's row if E did
//   not and B is empty or taken in this edge; F moves on or stalls; F takes the next descriptor;
//   Q accepts.
//   Cycles, out_ready always 1, descriptors back to back (SpanStream, which the walker uses):
//   F forms walker row after walker row, one per cycle, from cycle 1 (cycle 0 accepts the first
//   descriptor), stalled only while B holds a row E has not taken; a row with pixels formed in
//   cycle f enters E after the later of cycle f and the previous row's last group, and stays
//   for its lane groups. The unit is idle after E's last group and F's last row. A descriptor
//   alone takes the paper's cycles less its ROW cycles after the first row, at most.
//   desc_ready = !Q.valid and the outputs are still functions of registers only.
//   Register widths: w, q, xg, xe, lo, hi: CoordBits signed; r, D, m: RemBits unsigned;
//   attributes: AttrBits signed, wrapping (two's complement) like the RTL. Setup guarantees that
//   every value a valid lane shows fits, so wrapping only ever touches masked lanes.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "raster/inline_vec.h"

namespace shd {

constexpr size_t kMaxAttr = 16;    // NumAttr <= 16
constexpr size_t kMaxLaneTri = 4;  // NumTri is 1 or 4
using AttrVec = InlineVec<int64_t, kMaxAttr>;  // attribute codes, held in place (no heap)

// Parameters of shd_span_unit, named as in the Verilog: the "rtl" object of a span-unit
// configuration (config/registry.h), whose name is its lane mode's.
struct SpanParams {
  int NumTri = 1;       // lane-triangles: 1, or 4 (sierpinski)
  int LanesPerTri = 1;  // 1, 2, 4 or 8
  int AlignLanes = 0;   // 1: lane i takes x = i (mod LanesPerTri)
  int NumAttr = 4;      // attributes per fragment
  int AttrBits = 32;    // signed attribute codes
  int CoordBits = 16;   // signed walker-frame coordinates (rows, columns, DDA quotients, k)
  int RemBits = 27;     // unsigned DDA divisor, remainder and m
  int PixBits = 12;     // unsigned screen pixel coordinates on the fragment ports
  int TagBits = 32;     // triangle tag carried to the fragments
  // 0: the paper's unit (a ROW cycle per walker row, an IDLE cycle per descriptor); 1: the
  // full-rate unit (rows formed ahead into a row register, the next descriptor queued). May be
  // left out of a configuration's "rtl" object: 0, the Verilog default.
  int RowAhead = 0;
  // 0: every descriptor's lane-triangles share the walker's rows (the split); 1 (NumTri 4): a
  // descriptor may interleave rows (SpanDesc::interleave). May be left out: 0.
  int Interleave = 0;

  int lanes() const { return NumTri * LanesPerTri; }
  void validate() const;  // std::invalid_argument naming the parameter

  // Reads the "rtl" object: every member required; unknown or non-integer members and values
  // validate() refuses are std::invalid_argument naming `where`.
  static SpanParams fromJson(const nlohmann::json& rtl, const std::string& where);
  nlohmann::json toJson() const;
};

struct SpanEdge {
  int32_t row_first = 1, row_last = 0;  // active walker rows; row_first > row_last: unused slot
  bool right = false;                   // bound is -q (right) or q (left)
  int32_t q = 0;                        // at row_first
  int64_t r = 0;                        // at row_first, 0 <= r < div
  int64_t div = 1;                      // D = |A| > 0
  int32_t k = 0;                        // per row: -B = k*D + m
  int64_t m = 0;                        // 0 <= m < D
};

struct SpanLaneTri {
  // User-provided, as SpanDesc's: value-initialisation (InlineVec::emplace_back()) then runs the
  // member initialisers alone, instead of first zeroing aoff's storage.
  SpanLaneTri() {}
  int32_t row_first = 1, row_last = 0;  // walker rows (scissored); empty if first > last
  int32_t clip_x0 = 0, clip_x1 = -1;    // walker columns whose pixels lie in the viewport
  SpanEdge edge[3];
  bool flip = false;
  int32_t ox = 0, oy = 0;
  AttrVec aoff;  // NumAttr
};

struct SpanDesc {
  // User-provided: value-initialisation (std::optional::emplace()) then runs the member
  // initialisers alone, instead of first zeroing the 1.7 KB of the lane-triangles' storage.
  SpanDesc() {}
  uint32_t tag = 0;
  // Walker rows: the union of the lane-triangles' rows; never empty (row_first <= row_last):
  // setup drops a triangle without rows, and the unit, which stops at w == row_last, would
  // otherwise walk until w wraps.
  int32_t row_first = 0, row_last = -1;
  int32_t xref = 0;                      // iref is the plane at (xref, row_first)
  bool interleave = false;               // walker row w is screen row NumTri*w + oy (Interleave 1)
  AttrVec iref, didx, didy;                  // NumAttr each
  InlineVec<SpanLaneTri, kMaxLaneTri> tri;  // NumTri
};

struct SpanFragment {
  uint32_t tag = 0;
  int32_t x = 0, y = 0;
  AttrVec attr;
};

struct SpanLaneOut {
  bool valid = false;
  int32_t x = 0, y = 0;
  AttrVec attr;
};

struct SpanIn {
  bool desc_valid = false;
  const SpanDesc* desc = nullptr;  // read when desc_valid
  bool out_ready = true;
};

struct SpanOut {
  bool desc_ready = false;
  bool out_valid = false;
  uint32_t tag = 0;
  std::vector<SpanLaneOut> lane;  // lanes(); data meaningful where valid
};

// An edge's DDA registers: the quotient q and remainder r of the current row.
// Trivial (no member initialisers): the walk's registers are left uninitialised beyond the edges
// a descriptor uses (zeroing all twelve cost a `rep stos` per triangle); `{}` zeroes.
struct SpanDdaState {
  int64_t q, r;
};

// The full-rate unit's cycles (RowAhead = 1) over a stream of descriptors presented back to back
// (each from the cycle the unit can take it) with out_ready always 1: the recurrence of the
// cycle behaviour above, fed walker row by walker row. end() is the cycle count until the unit is
// idle if no descriptor followed; a later descriptor never moves an earlier row, so end() only
// grows, and its growth over a descriptor is that descriptor's share of the stream's cycles.
class SpanStream {
 public:
  // A walker row of the current descriptor (the first row of the stream starts it): the lane
  // groups E shows for it, 0 for a row without pixels.
  void row(uint64_t groups) {
    ++walker_rows_;
    if (groups == 0) {
      f_last_ = f_;
      ++f_;
      return;
    }
    // B is free for this row once E has taken the row before (at the edge before its start).
    const uint64_t f = rows_ > 0 ? std::max(f_, e_start_ - 1) : f_;
    e_start_ = std::max(rows_ > 0 ? e_end_ : 0, f) + 1;
    e_end_ = e_start_ + groups - 1;
    f_last_ = f;
    f_ = f + 1;
    ++rows_;
  }
  uint64_t end() const { return walker_rows_ == 0 ? 0 : std::max(rows_ > 0 ? e_end_ : 0, f_last_) + 1; }

 private:
  uint64_t f_ = 1;        // the cycle F forms its next walker row (cycle 0 accepts the first)
  uint64_t f_last_ = 0;   // the cycle of F's last row
  uint64_t e_start_ = 0, e_end_ = 0;  // the cycles of E's last row: its first and last group
  uint64_t rows_ = 0;     // rows with pixels so far
  uint64_t walker_rows_ = 0;
};

class SpanUnitModel {
 public:
  explicit SpanUnitModel(SpanParams p);
  const SpanParams& params() const { return p_; }

  void reset();
  // The outputs during this cycle (functions of the registers), then the rising edge with
  // the inputs `in`. Returns the outputs seen before the edge. The second form reuses `out`'s
  // storage (the co-simulation's hot path).
  SpanOut tick(const SpanIn& in);
  void tick(const SpanIn& in, SpanOut& out);
  uint64_t cycle() const { return cycle_; }
  bool idle() const {
    return p_.RowAhead ? !f_busy_ && !q_valid_ && !b_valid_ && !e_valid_ : state_ == State::Idle;
  }
  // Cycles spent in ROW and in SPAN since reset (for utilisation figures); the full-rate unit:
  // the rows F formed (stalls not counted) and the cycles E showed a lane group.
  uint64_t rowCycles() const { return row_cycles_; }
  uint64_t spanCycles() const { return span_cycles_; }

 private:
  enum class State { Idle, Row, Span };
  // A row formed (ROW, or F): the lane-triangles' bounds, the span's end and first group, the
  // plane there, its walker row and the slot of its descriptor.
  struct RowRec {
    std::array<int64_t, kMaxLaneTri> lo{}, hi{};
    std::array<bool, kMaxLaneTri> ne{};
    int64_t xe = 0, xg0 = 0, wspan = 0;
    std::array<int64_t, kMaxAttr> icur0{};
    size_t slot = 0;
  };
  void outputs(SpanOut& o) const;
  int64_t wrapAttr(uint64_t v) const;
  int64_t wrapCoord(int64_t v) const;
  bool formRow(RowRec& r) const;          // row w_ of slot f_slot_'s descriptor; false: no pixels
  void stepRow();                         // the walker to the next row
  void startDescriptor(size_t slot);      // the walker at the first row of slot's descriptor
  size_t freeSlot() const;                // a slot no stage holds
  void tickPaper(const SpanIn& in, const SpanOut& out);
  void tickRowAhead(const SpanIn& in, const SpanOut& out);

  SpanParams p_;
  // The descriptors held: the paper's unit uses slot 0; the full-rate unit one per stage that
  // holds one (E's row, B's row, F, Q), so a stage refers to its slot instead of a copy.
  std::array<SpanDesc, 4> slot_;
  size_t f_slot_ = 0, q_slot_ = 0;
  // The paper's unit: its state (E shows er_ in Span). The full-rate unit: F busy, Q, B and E.
  State state_ = State::Idle;
  bool f_busy_ = false, q_valid_ = false, b_valid_ = false, e_valid_ = false;
  bool f_held_ = false;  // F stalled in the last cycle on row f_row_ (the RTL's f_held_q)
  RowRec b_, er_, f_row_;
  int64_t w_ = 0, xg_ = 0;
  // Registers held in place, sized for the largest unit; the first NumTri*3 and NumAttr are used.
  std::array<SpanDdaState, kMaxLaneTri * 3> e_{};
  std::array<int64_t, kMaxAttr> irow_{}, icur_{};
  uint64_t cycle_ = 0, row_cycles_ = 0, span_cycles_ = 0;
};

// Runs one descriptor through the model with out_ready always 1, from IDLE to IDLE: the
// fragments in output order and the cycles spent (including the accepting IDLE cycle).
struct SpanRun {
  std::vector<SpanFragment> fragments;
  uint64_t cycles = 0;
  uint64_t valid_lanes = 0;  // sum over SPAN cycles of the valid lanes (= fragments)
  uint64_t span_cycles = 0;  // SPAN cycles
  uint64_t row_cycles = 0;   // ROW cycles
};
SpanRun runSpanUnit(SpanUnitModel& m, const SpanDesc& d);
// The same into `run`, reusing its fragments' memory (a long stream of triangles allocates once).
void runSpanUnit(SpanUnitModel& m, const SpanDesc& d, SpanRun& run);

// A row's fragments as one run (walkSpanUnit's run consumer): count fragments, fragment i at
// pixel (x0 + i dx, y) with attribute a equal to a0[a] + i da[a] exactly (nothing wraps in
// the run; da is 0 for a run of one). a0 and da: NumAttr values, valid during the call.
struct RowRun {
  int32_t x0 = 0, y = 0, dx = 1;  // dx: +1 or -1
  int64_t count = 0;
  const int64_t* a0 = nullptr;
  const int64_t* da = nullptr;
};

// The same unit without the cycle-by-cycle machinery: the fragments of one descriptor in the
// order SpanUnitModel hands them over with out_ready always 1 (cycle by cycle, lane by lane
// within a cycle), appended to `out`, and the cycles it takes, counted as runSpanUnit counts
// them. It shares the ROW logic with SpanUnitModel and is bit- and cycle-exact to it
// (test_span_unit compares them on the generator's streams in every mode): the renderer's
// fast path, with no allocation beyond the growth of `out`.
struct SpanWalk {
  uint64_t cycles = 0, row_cycles = 0, span_cycles = 0, fragments = 0;
};
// stream: as for the template form (raster/span_walk.h), the full-rate unit's stream.
SpanWalk walkSpanUnit(const SpanParams& p, const SpanDesc& d, std::vector<SpanFragment>& out,
                      SpanStream* stream = nullptr);

}  // namespace shd
