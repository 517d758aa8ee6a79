// shd_span_unit: fragments of a triangle along raster lines with the constant step dI/dx, in
// lanes (paper 4.1-4.2; modes serial, even/odd, segments of 2^k lanes, 4-way Sierpinski split).
// What:     walks the walker rows w of one descriptor. Per row each of NumTri lane-triangles j
//           bounds it by its clip box and its active edges in solved (DDA) form (left edge
//           x >= q, right edge x <= -q): [lo_j, hi_j], ne_j; the union [xs, xe] of the non-empty
//           ones is then shown LanesPerTri columns per cycle. Lane l = j*LanesPerTri + i shows
//           column x = xg + i, valid iff ne_j && lo_j <= x <= hi_j, its pixel and attribute
//           mapped by j's (flip, ox, oy, aoff).
//           Interleave 1 (NumTri 4): a descriptor with desc_interleave_i set maps walker row w to
//           screen row NumTri*w (+ oy, or oy - when flipped): its lane-triangles take interleaved
//           rows of the triangle instead of the 4-way split (setup chooses per triangle). With
//           Interleave 0 the input is ignored.
// Why:      all lanes read one walker plane I = irow + didx*(x - xref): one multiply per
//           attribute at a row start, then steps of LanesPerTri*didx, and lane i adds i*didx
//           (shifts and adds, i < 8), so every mode gives at each pixel exactly the plane's value.
//           Each edge is a DDA (q, r): no division and no multiply per row.
// Latency:  IDLE -> ROW -> (SPAN ...) -> ROW ... -> IDLE. 1 cycle accepting a descriptor
//           (desc_ready_o = IDLE), 1 ROW cycle per walker row, floor((xe - xg0)/LanesPerTri) + 1
//           SPAN cycles per row with pixels, more only while out_ready_i stalls a valid output.
//           Outputs are functions of registers only (no path from desc_valid_i, out_ready_i).
// Formats:  w, q, k, xg, xe, lo, hi, clip, ox, oy, xref, row ranges: CoordBits signed.
//           r, div, m: RemBits unsigned. Attributes: AttrBits signed, two's complement, wrapping.
//           out_x_o, out_y_o: the low PixBits of the screen pixel.
// Widths:   x = xg + i and xg + LanesPerTri: CoordBits+1 bits, no wrap, for the comparisons.
//           The right-edge bound -q: CoordBits+1 bits, exact (-(-2^(C-1)) = 2^(C-1)); then
//           hi = min(clip_x1, -q ...) lies in [min(clip_x1, -(2^(C-1)-1)), clip_x1] and lo =
//           max(clip_x0, q ...) is one of its CoordBits operands: both fit CoordBits, the dropped
//           MSBs are sign copies. xg - xref: CoordBits+1 bits signed, exact. icur <- irow +
//           didx*(xg - xref): the low AttrBits of the exact product sum (signed AttrBits x
//           (CoordBits+1) multiply). r - m: RemBits+1 bits signed, exact for r, m < 2^RemBits;
//           when negative div is added back, and 0 <= r' < div < 2^RemBits drops a 0 MSB (setup
//           guarantees 0 <= r, m < div). q + k (+ 1) and w + 1 wrap at CoordBits. In SPAN
//           xg + LanesPerTri is only stored when <= xe, so it fits. Pixels: exact sums of
//           max(CoordBits+2, PixBits+1) bits, the low PixBits kept.
// Rounding: none: integer arithmetic, modulo 2^AttrBits for the attributes.
// Choices where model/raster/span_unit.h leaves room (the model must make the same ones):
//           - lo_q, hi_q, ne_q load in every ROW cycle; xg_q, xe_q, icur_q, wspan_q only in a
//             ROW cycle that goes to SPAN (xg_q and icur_q also when SPAN advances in a row).
//           - The descriptor registers (tag, row_last, xref, didx, didy, lane-triangles, edges)
//             load only on accepting; out_tag_o shows that register in every state.
//           - out_lane_valid_o and out_valid_o are 0 outside SPAN. out_x_o, out_y_o, out_attr_o
//             are driven from the registers in every state and mean something only on a valid
//             lane (data registers have no reset): compare them there only. Likewise out_tag_o
//             only while out_valid_o.
//           - An edge is active at w iff row_first_e <= w <= row_last_e (signed); it steps in a
//             ROW cycle iff row_first_e <= w < row_last_e. Every slot's (q, r) loads from e_q_i,
//             e_r_i on accepting, used or not.
//           - The row loop ends only on w == row_last (a ROW cycle without pixels) or wspan ==
//             row_last (the end of a span): a descriptor with row_first > row_last walks until w
//             wraps around to row_last (up to 2^CoordBits rows). Setup must not send one.
//           - Parameters are not checked: LanesPerTri must be 1, 2, 4 or 8 (lane i adds i*didx
//             as at most three shifted copies of didx, i < 8).
// RowAhead: 0 is the paper's unit above. 1 is the full-rate unit (model/raster/span_unit.h
//           gives its cycle behaviour): a row former F (the walker and the ROW logic above, one
//           walker row per cycle), a row register B, an emitter E (the SPAN lanes above) and a
//           one-descriptor queue Q; desc_ready_o = !Q.valid. F's descriptor registers are the
//           ones above, loaded when F takes a descriptor (from Q, else from the inputs); a row
//           F forms carries its output map (tag, didx, the lane-triangles' ox, oy, flip, aoff)
//           to B and E, so E shows a row of one descriptor while F walks the next. lo_q, hi_q,
//           ne_q, xe_q, wspan_q, xg_q, icur_q are E's and load when E takes a row. Q, B and E
//           hold data registers without reset; their valid bits and F's busy bit reset to 0.
// Model:    model/raster/span_unit.h SpanUnitModel, bit-exact and cycle-accurate.
module shd_span_unit #(
  parameter integer NumTri      = 1,
  parameter integer LanesPerTri = 1,
  parameter integer AlignLanes  = 0,
  parameter integer NumAttr     = 4,
  parameter integer AttrBits    = 32,
  parameter integer CoordBits   = 16,
  parameter integer RemBits     = 27,
  parameter integer PixBits     = 12,
  parameter integer TagBits     = 32,
  parameter integer RowAhead    = 0,
  parameter integer Interleave  = 0
) (
  input  wire                                  clk_i,
  input  wire                                  rst_ni,

  input  wire                                  desc_valid_i,
  output wire                                  desc_ready_o,
  input  wire [TagBits-1:0]                    desc_tag_i,
  input  wire [CoordBits-1:0]                  desc_row_first_i,
  input  wire [CoordBits-1:0]                  desc_row_last_i,
  input  wire [CoordBits-1:0]                  desc_xref_i,
  input  wire [NumAttr*AttrBits-1:0]           desc_iref_i,
  input  wire [NumAttr*AttrBits-1:0]           desc_didx_i,
  input  wire [NumAttr*AttrBits-1:0]           desc_didy_i,
  input  wire                                  desc_interleave_i,
  input  wire [NumTri*CoordBits-1:0]           lt_row_first_i,
  input  wire [NumTri*CoordBits-1:0]           lt_row_last_i,
  input  wire [NumTri*CoordBits-1:0]           lt_clip_x0_i,
  input  wire [NumTri*CoordBits-1:0]           lt_clip_x1_i,
  input  wire [NumTri*CoordBits-1:0]           lt_ox_i,
  input  wire [NumTri*CoordBits-1:0]           lt_oy_i,
  input  wire [NumTri-1:0]                     lt_flip_i,
  input  wire [NumTri*NumAttr*AttrBits-1:0]    lt_aoff_i,
  input  wire [NumTri*3-1:0]                   e_right_i,
  input  wire [NumTri*3*CoordBits-1:0]         e_row_first_i,
  input  wire [NumTri*3*CoordBits-1:0]         e_row_last_i,
  input  wire [NumTri*3*CoordBits-1:0]         e_q_i,
  input  wire [NumTri*3*CoordBits-1:0]         e_k_i,
  input  wire [NumTri*3*RemBits-1:0]           e_r_i,
  input  wire [NumTri*3*RemBits-1:0]           e_div_i,
  input  wire [NumTri*3*RemBits-1:0]           e_m_i,

  output wire                                  out_valid_o,
  input  wire                                  out_ready_i,
  output wire [TagBits-1:0]                    out_tag_o,
  output wire [NumTri*LanesPerTri-1:0]         out_lane_valid_o,
  output wire [NumTri*LanesPerTri*PixBits-1:0] out_x_o,
  output wire [NumTri*LanesPerTri*PixBits-1:0] out_y_o,
  output wire [NumTri*LanesPerTri*NumAttr*AttrBits-1:0] out_attr_o
);

  localparam integer C     = CoordBits;
  localparam integer R     = RemBits;
  localparam integer A     = AttrBits;
  localparam integer L     = LanesPerTri;
  localparam integer NE    = NumTri * 3;                 // edge slots, e = j*3 + s
  localparam integer AV    = NumAttr * AttrBits;         // one attribute vector
  localparam integer LOG2L = (L >= 8) ? 3 : (L >= 4) ? 2 : (L >= 2) ? 1 : 0;
  // Pixel sums, exact: C+2 bits, and at least one bit above the PixBits kept.
  localparam integer PXW   = (PixBits >= C + 2) ? PixBits + 1 : C + 2;
  localparam integer MW    = A + C + 1;                  // didx*(xg - xref), natural width
  // A descriptor as one word, in the order the walker loads it (the full-rate unit's queue).
  localparam integer DW    = TagBits + 3*C + 3*AV + 1 + NumTri*(6*C + 1 + AV) + NE*(1 + 4*C + 3*R);
  // Interleaving descriptors: walker row w is screen row NumTri*w + oy, a shift by LOG2T.
  localparam integer LOG2T = (NumTri >= 4) ? 2 : 0;

  // The most negative / positive C+1-bit and C-bit values: empty min/max reductions give them.
  localparam [C:0]   EXT_MIN    = {1'b1, {C{1'b0}}};
  localparam [C:0]   EXT_MAX    = {1'b0, {C{1'b1}}};
  localparam [C-1:0] COORD_MIN  = {1'b1, {(C-1){1'b0}}};
  localparam [C-1:0] COORD_MAX  = {1'b0, {(C-1){1'b1}}};
  localparam [C-1:0] ALIGN_MASK = {C{1'b1}} << ((AlignLanes != 0) ? LOG2L : 0);

  // ---------------------------------------------------------------- registers
  // The walker's descriptor (F's in the full-rate unit): loaded when the walker takes one.
  reg  [TagBits-1:0]     tag_q;
  reg  [C-1:0]           row_last_q;
  reg  [C-1:0]           xref_q;
  reg  [AV-1:0]          didx_q;
  reg  [AV-1:0]          didy_q;
  reg                    ilv_q;     // the descriptor interleaves rows (0 unless Interleave)
  reg  [NumTri*C-1:0]    lt_row_first_q;
  reg  [NumTri*C-1:0]    lt_row_last_q;
  reg  [NumTri*C-1:0]    lt_clip_x0_q;
  reg  [NumTri*C-1:0]    lt_clip_x1_q;
  reg  [NumTri*C-1:0]    lt_ox_q;
  reg  [NumTri*C-1:0]    lt_oy_q;
  reg  [NumTri-1:0]      lt_flip_q;
  reg  [NumTri*AV-1:0]   lt_aoff_q;
  reg  [NE-1:0]          e_right_q;
  reg  [NE*C-1:0]        e_row_first_q;
  reg  [NE*C-1:0]        e_row_last_q;
  reg  [NE*C-1:0]        e_k_q;
  reg  [NE*R-1:0]        e_div_q;
  reg  [NE*R-1:0]        e_m_q;

  // Walker: the row, the plane at (xref, w), every edge's DDA state (q, r).
  reg  [C-1:0]           w_q;
  reg  [AV-1:0]          irow_q;
  reg  [NE*C-1:0]        quo_q;
  reg  [NE*R-1:0]        rem_q;
  wire [C-1:0]           w_d;
  wire [AV-1:0]          irow_d;
  wire [NE*C-1:0]        quo_d;
  wire [NE*R-1:0]        rem_d;

  // The row formed at w (ROW; F): each lane-triangle's bounds.
  wire [NumTri*C-1:0]    lo_d;
  wire [NumTri*C-1:0]    hi_d;
  wire [NumTri-1:0]      ne_d;

  // The row shown (SPAN; E): each lane-triangle's bounds, the span end, its row, the lane
  // group's first column and the plane there.
  reg  [NumTri*C-1:0]    lo_q;
  reg  [NumTri*C-1:0]    hi_q;
  reg  [NumTri-1:0]      ne_q;
  reg  [C-1:0]           xg_q;
  reg  [C-1:0]           xe_q;
  reg  [C-1:0]           wspan_q;
  reg  [AV-1:0]          icur_q;
  // Its output map: the walker's descriptor registers (paper), E's copy (full rate).
  wire [TagBits-1:0]     em_tag;
  wire [AV-1:0]          em_didx;
  wire [NumTri*C-1:0]    em_ox;
  wire [NumTri*C-1:0]    em_oy;
  wire [NumTri-1:0]      em_flip;
  wire                   em_ilv;
  wire [NumTri*AV-1:0]   em_aoff;

  // ---------------------------------------------------------------- control, shared
  // Each mode's section at the end of the module drives these.
  wire          f_load;     // the walker takes a descriptor: Q's if f_from_q, else the ports'
  wire          f_from_q;   // (0 in the paper's unit)
  wire [DW-1:0] q_word;     // Q's descriptor, in the walker's load order (0 in the paper's unit)
  wire          f_step;     // the walker steps to the next row
  wire          form_en;    // the ROW logic's result is used (ROW; F busy)
  wire          show;       // the lanes show a row (SPAN; E holds one)
  wire          any_ne;     // row w has pixels in some lane-triangle
  wire          span_done;  // the lane group shown is its row's last
  wire          span_adv = !out_valid_o || out_ready_i;  // the lane group shown leaves (or is empty)

  // The interleave bit counts only in a unit built for it: 0 otherwise (synthesis drops it).
  wire ilv_in = (Interleave != 0) && desc_interleave_i;

  // Taking a descriptor loads the descriptor registers and starts the walker at row_first with
  // iref and every edge's (q0, r0); f_step steps the walker. The ports are concatenated here,
  // in the clocked block, and not in a wire: a simulator then reads them only when a descriptor
  // is taken, not on every input change (Verilator's input logic runs on every eval); the
  // hardware is the same two-input mux. q_word holds the same fields in the same order
  // (g_ahead's Q load).
  always @(posedge clk_i) begin
    if (f_load) begin
      if (f_from_q)
        {tag_q, row_last_q, xref_q, didx_q, didy_q, ilv_q, lt_row_first_q, lt_row_last_q, lt_clip_x0_q,
         lt_clip_x1_q, lt_ox_q, lt_oy_q, lt_flip_q, lt_aoff_q, e_right_q, e_row_first_q,
         e_row_last_q, e_k_q, e_div_q, e_m_q, w_q, irow_q, quo_q, rem_q} <= q_word;
      else
        {tag_q, row_last_q, xref_q, didx_q, didy_q, ilv_q, lt_row_first_q, lt_row_last_q, lt_clip_x0_q,
         lt_clip_x1_q, lt_ox_q, lt_oy_q, lt_flip_q, lt_aoff_q, e_right_q, e_row_first_q,
         e_row_last_q, e_k_q, e_div_q, e_m_q, w_q, irow_q, quo_q, rem_q} <=
        {desc_tag_i, desc_row_last_i, desc_xref_i, desc_didx_i, desc_didy_i, ilv_in, lt_row_first_i,
         lt_row_last_i, lt_clip_x0_i, lt_clip_x1_i, lt_ox_i, lt_oy_i, lt_flip_i, lt_aoff_i,
         e_right_i, e_row_first_i, e_row_last_i, e_k_i, e_div_i, e_m_i, desc_row_first_i,
         desc_iref_i, e_q_i, e_r_i};
    end else if (f_step) begin
      w_q    <= w_d;
      irow_q <= irow_d;
      quo_q  <= quo_d;
      rem_q  <= rem_d;
    end
  end

  // ---------------------------------------------------------------- ROW datapath
  // The logic of this section feeds only the walker's step, the row's registers (lo, hi, ne,
  // xg, xe, icur, wspan; the full-rate unit's B and E) and the control (any_ne). It is written
  // as combinational blocks that compute it under `if (form_en)` and leave it don't-care ('x)
  // otherwise: a simulator that evaluates every block on every clock (Verilator) then skips it
  // in the paper's SPAN and IDLE cycles, and synthesis may simplify with the don't-care (the
  // registers load these values only when form_en is 1). The functions carry
  // `verilator no_inline_task`: Verilator then makes them C++ functions with local variables
  // instead of copying every argument and local into a member of the model at each call site,
  // which is faster; other tools ignore the comment.

  // One edge slot in row w: the DDA state of row w+1, stepped iff row_first <= w < row_last
  // (active at w and w < row_last): r' = r - m; if r' < 0 { r' += D; q' = q + k + 1 } else
  // { q' = q + k }. Returns {q', r'}.
  function automatic [C+R-1:0] dda_row(input [C-1:0] w, input [C-1:0] rf, input [C-1:0] rl,
                                       input [C-1:0] q, input [R-1:0] r, input [C-1:0] k,
                                       input [R-1:0] m, input [R-1:0] div);
    /*verilator no_inline_task*/
    reg [R:0] r_sub;  // exact: |r - m| < 2^R
    begin
      r_sub = {1'b0, r} - {1'b0, m};
      if ($signed(rf) <= $signed(w) && $signed(w) < $signed(rl))
        // 0 <= r' < div < 2^R when 0 <= r, m < div: its low R bits are all of it. q' wraps at
        // CoordBits.
        dda_row = {q + k + {{(C-1){1'b0}}, r_sub[R]}, r_sub[R-1:0] + (r_sub[R] ? div : {R{1'b0}})};
      else
        dda_row = {q, r};
    end
  endfunction

  // An edge slot is active at w iff row_first_e <= w <= row_last_e (signed).
  function automatic edge_act(input [C-1:0] w, input [C-1:0] rf, input [C-1:0] rl);
    /*verilator no_inline_task*/
    edge_act = ($signed(rf) <= $signed(w)) && ($signed(w) <= $signed(rl));
  endfunction

  // An edge slot's bound: q (left) or -q (right), CoordBits+1 bits (exact).
  function automatic [C:0] edge_bound(input right, input [C-1:0] q);
    /*verilator no_inline_task*/
    edge_bound = right ? (~{q[C-1], q} + {{C{1'b0}}, 1'b1}) : {q[C-1], q};
  endfunction

  // One lane-triangle in row w: {ne, lo, hi}, lo and hi in CoordBits+1 bits. lo = max(clip_x0,
  // q of the active left edges), hi = min(clip_x1, -q of the active right edges), compared with
  // CoordBits+1 bits; ne = row_first <= w <= row_last && lo <= hi.
  function automatic [2*C+2:0] tri_row(input [C-1:0] w, input [C-1:0] rf, input [C-1:0] rl,
                                       input [C-1:0] x0, input [C-1:0] x1, input [3*C-1:0] erf,
                                       input [3*C-1:0] erl, input [2:0] right, input [3*C-1:0] q);
    /*verilator no_inline_task*/
    reg [2:0]        act;
    reg signed [C:0] b_0, b_1, b_2;
    reg signed [C:0] cl_0, cl_1, cl_2, cr_0, cr_1, cr_2;   // candidates per edge slot
    reg signed [C:0] lo_x0, hi_x1, lo_a, lo_b, lo, hi_a, hi_b, hi;
    begin
      act  = {edge_act(w, erf[2*C +: C], erl[2*C +: C]), edge_act(w, erf[C +: C], erl[C +: C]),
              edge_act(w, erf[0 +: C], erl[0 +: C])};
      b_0  = edge_bound(right[0], q[0 +: C]);
      b_1  = edge_bound(right[1], q[C +: C]);
      b_2  = edge_bound(right[2], q[2*C +: C]);
      cl_0 = (act[0] && !right[0]) ? b_0 : EXT_MIN;
      cl_1 = (act[1] && !right[1]) ? b_1 : EXT_MIN;
      cl_2 = (act[2] && !right[2]) ? b_2 : EXT_MIN;
      cr_0 = (act[0] && right[0]) ? b_0 : EXT_MAX;
      cr_1 = (act[1] && right[1]) ? b_1 : EXT_MAX;
      cr_2 = (act[2] && right[2]) ? b_2 : EXT_MAX;
      lo_x0 = {x0[C-1], x0};
      hi_x1 = {x1[C-1], x1};
      lo_a = (cl_0 > lo_x0) ? cl_0 : lo_x0;
      lo_b = (cl_2 > cl_1) ? cl_2 : cl_1;
      lo   = (lo_b > lo_a) ? lo_b : lo_a;
      hi_a = (cr_0 < hi_x1) ? cr_0 : hi_x1;
      hi_b = (cr_2 < cr_1) ? cr_2 : cr_1;
      hi   = (hi_b < hi_a) ? hi_b : hi_a;
      tri_row = {edge_act(w, rf, rl) && (lo <= hi), lo, hi};
    end
  endfunction


  // Taking a descriptor loads row_first, iref and every edge's (q0, r0); f_step steps them.
  assign w_d = w_q + {{(C-1){1'b0}}, 1'b1};  // next row, wraps at CoordBits

  genvar e;
  generate
    for (e = 0; e < NE; e = e + 1) begin : g_edge
      reg [C+R-1:0] qr_d;
      always @* begin
        qr_d = {(C+R){1'bx}};
        if (form_en)
          qr_d = dda_row(w_q, e_row_first_q[e*C +: C], e_row_last_q[e*C +: C], quo_q[e*C +: C],
                         rem_q[e*R +: R], e_k_q[e*C +: C], e_m_q[e*R +: R], e_div_q[e*R +: R]);
      end
      assign quo_d[e*C +: C] = qr_d[R +: C];
      assign rem_d[e*R +: R] = qr_d[0 +: R];
    end
  endgenerate

  // ---------------------------------------------------------------- ROW: lane-triangle bounds
  genvar j;
  generate
    for (j = 0; j < NumTri; j = j + 1) begin : g_tri
      reg [2*C+2:0] b_d;   // {ne, lo, hi}, lo and hi in CoordBits+1 bits
      always @* begin
        b_d = {(2*C+3){1'bx}};
        if (form_en)
          b_d = tri_row(w_q, lt_row_first_q[j*C +: C], lt_row_last_q[j*C +: C],
                        lt_clip_x0_q[j*C +: C], lt_clip_x1_q[j*C +: C],
                        e_row_first_q[j*3*C +: 3*C], e_row_last_q[j*3*C +: 3*C],
                        e_right_q[j*3 +: 3], quo_q[j*3*C +: 3*C]);
      end
      // lo is a CoordBits value (clip_x0 or some q); hi <= clip_x1 and hi >= -(2^(C-1)-1)
      // unless it is clip_x1 (see header): both fit CoordBits, the MSBs are sign copies.
      assign ne_d[j] = b_d[2*C+2];
      assign lo_d[j*C +: C] = b_d[C+1 +: C];
      assign hi_d[j*C +: C] = b_d[0 +: C];
      wire unused_lohi_msb = b_d[2*C+1] ^ b_d[C];
    end
  endgenerate

  // xs = min lo_j, xe = max hi_j over the lane-triangles with ne_j (NumTri <= 4 terms).
  reg signed [C-1:0] xs_r;
  reg signed [C-1:0] xe_r;
  integer t;
  always @* begin
    t    = 0;  // the loop variable too is assigned on every path (no latch)
    xs_r = {C{1'bx}};
    xe_r = {C{1'bx}};
    if (form_en) begin
      xs_r = COORD_MAX;
      xe_r = COORD_MIN;
      for (t = 0; t < NumTri; t = t + 1) begin
        if (ne_d[t]) begin
          if ($signed(lo_d[t*C +: C]) < xs_r) xs_r = lo_d[t*C +: C];
          if ($signed(hi_d[t*C +: C]) > xe_r) xe_r = hi_d[t*C +: C];
        end
      end
    end
  end
  assign any_ne = |ne_d;

  // AlignLanes: xg = xs - (xs mod LanesPerTri), floor modulo (two's complement AND).
  wire [C-1:0] xg_row = xs_r & ALIGN_MASK;
  wire [C:0]   dx_row = {xg_row[C-1], xg_row} - {xref_q[C-1], xref_q};  // exact, C+1 signed

  // ---------------------------------------------------------------- SPAN: lane group
  // Done when xg + LanesPerTri > xe (CoordBits+1 bits: xg + L may pass the largest coordinate).
  // Otherwise xg + L <= xe fits CoordBits.
  wire signed [C:0] xg_next = $signed({xg_q[C-1], xg_q}) + $signed(L[C:0]);
  assign span_done = xg_next > $signed({xe_q[C-1], xe_q});
  wire unused_xg_next_msb = xg_next[C];

  // ---------------------------------------------------------------- attributes (per a)
  wire [AV-1:0] icur_row;    // irow + didx*(xg - xref)
  wire [AV-1:0] icur_step;   // icur + LanesPerTri*didx
  genvar a;
  generate
    for (a = 0; a < NumAttr; a = a + 1) begin : g_attr
      wire signed [A-1:0]  didx_a = didx_q[a*A +: A];
      // Signed A x (C+1) product (the sign copies are removed by synthesis); only its low
      // AttrBits are needed: the plane is computed modulo 2^AttrBits. form_en only.
      reg signed [MW-1:0] prod_a;
      always @* begin
        prod_a = {MW{1'bx}};
        if (form_en)
          prod_a = $signed({{(C+1){didx_a[A-1]}}, didx_a}) * $signed({{A{dx_row[C]}}, dx_row});
      end
      wire unused_prod_msbs = ^prod_a[MW-1:A];
      assign icur_row[a*A +: A]  = irow_q[a*A +: A] + prod_a[A-1:0];
      assign icur_step[a*A +: A] = icur_q[a*A +: A] + (em_didx[a*A +: A] << LOG2L);
      assign irow_d[a*A +: A]    = irow_q[a*A +: A] + didy_q[a*A +: A];
    end
  endgenerate

  // ---------------------------------------------------------------- lanes
  // Lane i of every lane-triangle shows column x = xg + i and the plane value icur + i*didx
  // (i*didx as at most three shifted copies, i < 8); lane-triangle j maps them to its pixel and
  // attribute.
  wire [NumTri*L-1:0] lane_valid;
  genvar i;
  generate
    for (i = 0; i < L; i = i + 1) begin : g_lane
      localparam [C:0] LANE_OFF = i;
      wire signed [C:0] x_i = $signed({xg_q[C-1], xg_q}) + $signed(LANE_OFF);
      wire [AV-1:0]     v_i;
      for (a = 0; a < NumAttr; a = a + 1) begin : g_attr
        wire [A-1:0] d_a  = em_didx[a*A +: A];
        wire [A-1:0] s0_a = ((i & 1) != 0) ? d_a        : {A{1'b0}};
        wire [A-1:0] s1_a = ((i & 2) != 0) ? (d_a << 1) : {A{1'b0}};
        wire [A-1:0] s2_a = ((i & 4) != 0) ? (d_a << 2) : {A{1'b0}};
        assign v_i[a*A +: A] = icur_q[a*A +: A] + s0_a + s1_a + s2_a;   // wraps at AttrBits
      end

      for (j = 0; j < NumTri; j = j + 1) begin : g_tri
        localparam integer LN = j * L + i;
        wire signed [C-1:0] lo_l = lo_q[j*C +: C];
        wire signed [C-1:0] hi_l = hi_q[j*C +: C];
        wire [C-1:0]        ox_l = em_ox[j*C +: C];
        wire [C-1:0]        oy_l = em_oy[j*C +: C];
        wire                flip = em_flip[j];
        assign lane_valid[LN] = show && ne_q[j]
                                && ($signed({lo_l[C-1], lo_l}) <= x_i)
                                && (x_i <= $signed({hi_l[C-1], hi_l}));

        // flip: (ox - x, oy - y); else (x + ox, y + oy), y = wspan, or NumTri*wspan for an
        // interleaving descriptor; the low PixBits kept (exact below them).
        wire [PXW-1:0] x_p  = {{(PXW-C-1){x_i[C]}}, x_i};
        wire [PXW-1:0] ox_p = {{(PXW-C){ox_l[C-1]}}, ox_l};
        wire [PXW-1:0] oy_p = {{(PXW-C){oy_l[C-1]}}, oy_l};
        wire [PXW-1:0] w_p  = {{(PXW-C){wspan_q[C-1]}}, wspan_q} << (em_ilv ? LOG2T : 0);
        wire [PXW-1:0] px   = flip ? ox_p - x_p : x_p + ox_p;
        wire [PXW-1:0] py   = flip ? oy_p - w_p : w_p + oy_p;
        assign out_x_o[LN*PixBits +: PixBits] = px[PixBits-1:0];
        assign out_y_o[LN*PixBits +: PixBits] = py[PixBits-1:0];
        wire unused_pix_msbs = ^{px[PXW-1:PixBits], py[PXW-1:PixBits]};

        for (a = 0; a < NumAttr; a = a + 1) begin : g_attr
          wire [A-1:0] v_a    = v_i[a*A +: A];
          wire [A-1:0] aoff_a = em_aoff[(j*NumAttr+a)*A +: A];
          assign out_attr_o[(LN*NumAttr+a)*A +: A] = flip ? aoff_a - v_a : v_a + aoff_a;
        end
      end
    end
  endgenerate

  // ---------------------------------------------------------------- outputs
  assign out_valid_o      = |lane_valid;
  assign out_tag_o        = em_tag;
  assign out_lane_valid_o = lane_valid;

  // ---------------------------------------------------------------- control, per mode
  generate
    if (RowAhead == 0) begin : g_paper
      // The paper's unit: IDLE -> ROW -> (SPAN ...) -> ROW ... -> IDLE.
      localparam [1:0] ST_IDLE = 2'd0;
      localparam [1:0] ST_ROW  = 2'd1;
      localparam [1:0] ST_SPAN = 2'd2;
      reg  [1:0] state_q;
      reg  [1:0] state_d;
      wire in_idle   = (state_q == ST_IDLE);
      wire in_row    = (state_q == ST_ROW);
      wire in_span   = (state_q == ST_SPAN);
      wire span_load = in_row && any_ne;
      wire span_step = in_span && span_adv && !span_done;

      always @* begin
        state_d = state_q;
        case (state_q)
          ST_IDLE: if (desc_valid_i) state_d = ST_ROW;
          ST_ROW: begin
            if (any_ne)                 state_d = ST_SPAN;
            else if (w_q == row_last_q) state_d = ST_IDLE;
          end
          ST_SPAN: begin
            if (span_adv && span_done) state_d = (wspan_q == row_last_q) ? ST_IDLE : ST_ROW;
          end
          default: state_d = ST_IDLE;
        endcase
      end

      always @(posedge clk_i or negedge rst_ni) begin
        if (!rst_ni) state_q <= ST_IDLE;
        else         state_q <= state_d;
      end

      always @(posedge clk_i) begin
        if (in_row) begin
          lo_q <= lo_d;
          hi_q <= hi_d;
          ne_q <= ne_d;
        end
      end

      // xg, icur load the row's start (span_load) or step (span_step), xe and wspan the row's
      // span. The muxes sit in the clocked block, like the walker's, so that Verilator's input
      // logic (span_step depends on out_ready_i) does not re-evaluate the row-start multiply.
      always @(posedge clk_i) begin
        if (span_load) begin
          xg_q   <= xg_row;
          icur_q <= icur_row;
        end else if (span_step) begin
          xg_q   <= xg_next[C-1:0];
          icur_q <= icur_step;
        end
      end

      always @(posedge clk_i) begin
        if (span_load) begin
          xe_q    <= xe_r;
          wspan_q <= w_q;
        end
      end

      assign f_from_q     = 1'b0;
      assign q_word       = {DW{1'b0}};
      assign f_load       = in_idle && desc_valid_i;
      assign f_step       = in_row;
      assign form_en      = in_row;
      assign show         = in_span;
      assign desc_ready_o = in_idle;
      assign em_tag       = tag_q;
      assign em_didx      = didx_q;
      assign em_ox        = lt_ox_q;
      assign em_oy        = lt_oy_q;
      assign em_flip      = lt_flip_q;
      assign em_ilv       = ilv_q;
      assign em_aoff      = lt_aoff_q;
    end else begin : g_ahead
      // The full-rate unit: F (the walker) forms a row per busy cycle into B or straight into
      // E; E shows its row's lane groups; Q holds the next descriptor.
      // A row: {ne, lo, hi, xe, xg0, wspan, icur0, map}, map = {tag, didx, ilv, ox, oy, flip, aoff}.
      localparam integer MAPW = TagBits + AV + 1 + NumTri*(2*C + 1 + AV);
      localparam integer RW   = NumTri*(1 + 2*C) + 3*C + AV + MAPW;
      reg             f_busy_q, q_valid_q, b_valid_q, e_valid_q;
      reg             f_held_q;  // F stalled in the last cycle: its row has pixels, B is full
      reg  [DW-1:0]   qd_q;   // Q
      reg  [RW-1:0]   b_q;    // B
      reg  [MAPW-1:0] em_q;   // E's row's map

      // F holding a row while E shows a group other than its row's last: B cannot be taken in this
      // cycle, so F stalls again whatever the row logic gives; it is not computed (form_en 0) and
      // the row counts as one with pixels (f_any).
      wire f_skip  = f_held_q && e_valid_q && !span_done;
      wire f_any   = f_skip || any_ne;
      wire e_done  = e_valid_q && span_adv && span_done;   // E's row's last group leaves
      wire e_step  = e_valid_q && span_adv && !span_done;  // E's next group
      wire e_free  = !e_valid_q || e_done;
      wire take_b  = b_valid_q && e_free;                  // E takes B's row
      wire b_free  = !b_valid_q || take_b;
      wire bypass  = f_busy_q && f_any && e_free && !b_valid_q;  // E takes F's row
      wire f_puts  = f_busy_q && f_any && b_free && !bypass;     // B takes F's row
      wire f_moves = f_busy_q && (!f_any || b_free);
      wire f_takes = !f_busy_q || (f_moves && w_q == row_last_q); // F is free for a descriptor
      wire accept  = desc_valid_i && !q_valid_q;
      wire e_load  = take_b || bypass;

      always @(posedge clk_i or negedge rst_ni) begin
        if (!rst_ni) begin
          f_busy_q  <= 1'b0;
          f_held_q  <= 1'b0;
          q_valid_q <= 1'b0;
          b_valid_q <= 1'b0;
          e_valid_q <= 1'b0;
        end else begin
          if (f_takes) f_busy_q <= q_valid_q || accept;
          f_held_q <= f_busy_q && !f_moves;
          // Q empties when F takes its descriptor; it fills with one F does not take.
          q_valid_q <= q_valid_q ? !f_takes : (accept && !f_takes);
          if (f_puts)      b_valid_q <= 1'b1;
          else if (take_b) b_valid_q <= 1'b0;
          if (e_load)      e_valid_q <= 1'b1;
          else if (e_done) e_valid_q <= 1'b0;
        end
      end

      always @(posedge clk_i) begin
        if (accept && !f_takes)
          qd_q <= {desc_tag_i, desc_row_last_i, desc_xref_i, desc_didx_i, desc_didy_i, ilv_in,
                   lt_row_first_i, lt_row_last_i, lt_clip_x0_i, lt_clip_x1_i, lt_ox_i, lt_oy_i,
                   lt_flip_i, lt_aoff_i, e_right_i, e_row_first_i, e_row_last_i, e_k_i, e_div_i,
                   e_m_i, desc_row_first_i, desc_iref_i, e_q_i, e_r_i};
      end

      always @(posedge clk_i) begin
        // F's row, concatenated here and not in a wire (a simulator then builds it only when
        // it is loaded; the hardware is the same).
        if (f_puts)
          b_q <= {ne_d, lo_d, hi_d, xe_r, xg_row, w_q, icur_row, tag_q, didx_q, ilv_q, lt_ox_q, lt_oy_q,
                  lt_flip_q, lt_aoff_q};
      end

      always @(posedge clk_i) begin
        if (e_load) begin
          if (take_b) {ne_q, lo_q, hi_q, xe_q, xg_q, wspan_q, icur_q, em_q} <= b_q;
          else        {ne_q, lo_q, hi_q, xe_q, xg_q, wspan_q, icur_q, em_q} <=
                      {ne_d, lo_d, hi_d, xe_r, xg_row, w_q, icur_row, tag_q, didx_q, ilv_q, lt_ox_q,
                       lt_oy_q, lt_flip_q, lt_aoff_q};
        end else if (e_step) begin
          xg_q   <= xg_next[C-1:0];
          icur_q <= icur_step;
        end
      end

      assign f_from_q     = q_valid_q;
      assign q_word       = qd_q;
      assign f_load       = f_takes && (q_valid_q || accept);
      assign f_step       = f_moves;
      assign form_en      = f_busy_q && !f_skip;
      assign show         = e_valid_q;
      assign desc_ready_o = !q_valid_q;
      assign {em_tag, em_didx, em_ilv, em_ox, em_oy, em_flip, em_aoff} = em_q;
    end
  endgenerate

endmodule
