// shd_spec_explog: the exp/log datapath of the specular unit (Kind 3 of shd_spec_unit):
// f = c^n = 2^(-n L), L = -log2 c, from the cycle-0 saturated cos code and the PROM word N = n
// to f, by a logarithm table and an exponent table, both linearly interpolated.
// Why:      the exact power c^n for every n the PROM holds (n itself, uQCi.Cf: no fit, no
//           approximation of the lobe's shape), with two small fixed tables that do not depend on
//           n and three multipliers. c = 2^(1-z) (1 - D) with z the leading zeros of C and
//           D = DN/2^CW in (0, 1/2], so L = (z - 1) + D g(D), g(D) = -log2(1 - D)/D in [1/ln 2, 2]:
//           g is smooth and D g(D) keeps its relative accuracy as c -> 1, where n L is
//           amplified most. Then y = n L, f = 2^-floor(y) 2^-frac(y), the second factor
//           (in (1/2, 1]) from the exponent table, the first a shift.
// Latency:  PipeStages cycles (1..3) after the cycle-1 registers; one result per cycle, no
//           stalls. The cycle-1 registers (zero, one, z, DN, r and the log ROM's read register,
//           addressed from c_i in cycle 0) are in this module; valid_q1, n_i and light_i are
//           the unit's cycle-1 registers. Ranks, enabled in this order as PipeStages grows:
//           X (always: the exp ROM's read register, with r2, ys, zero), A after P = DN*G
//           (PipeStages >= 2), C after the rounding of f (PipeStages = 3). light travels beside
//           the data unchanged.
// Formats:  c_i uQ1.Wc, at most 1.0 (shd_spec_unit saturates it); n_i = n uQCi.Cf (unsigned;
//           n = 0, the padding words of the PROM, gives f = 1 for c > 0); f_o uQ1.Wf, in
//           [0, 1]. Internal (Q = 60-bit fixed point for the tables only): g GF fraction bits,
//           L LF, e EF, y EX fraction bits (see the localparams).
//           Log ROM word i = {g(i+1) - g(i), g(i)}, exp ROM word j = {e(j) - e(j+1), e(j)},
//           i, j = 0..2^T - 1; g(i) at D = i/2^(T+1), e(j) = 2^-x at x = j/2^T. Both are computed
//           by the constant functions below with 128-bit integer arithmetic (every division and
//           shift a floor), identical to the model's, and read through a registered read so
//           that they map to block RAM.
// Widths:   CW = Wc + 1; z in 1..Wc for 0 < C < 2^Wc (0 for C = 1.0): ZW = clog2(Wc+1) bits,
//           enough for the normaliser's shifts 2^(ZW-1) .. 1 (sum 2^ZW - 1 >= Wc).
//           M = C << z in [2^Wc, 2^CW), DN = 2^CW - M in [1, 2^Wc]: CW bits. DN >> (Wc - T) <=
//           2^T (equal for DN = 2^Wc, C a power of two), so i = min(., 2^T - 1) has T bits and
//           r = DN - (i << (Wc - T)) in [0, 2^(Wc-T)] has Wc - T + 1 bits.
//           g is increasing and convex with g(1/2) = 2; the floors of the series keep
//           gq <= 2^(Q+1), so g(i) <= 2^(GF+1) = g(2^T) after rounding: GW = GF + 2 bits; the step
//           g(i+1) - g(i) >= 0 is at most g'(1/2) 2^(GF-T-1) + 1 = 0.886 2^(GF-T) + 1 <
//           2^(GF-T+1) (GF - T >= 3): DGW = GF - T + 1 bits. e is decreasing with e(0) = 2^EF
//           exactly and e(2^T) = 2^(EF-1), its step at most ln2 2^(EF-T) + 1 < 2^(EF-T+1)
//           (EF - T >= 1): EW = EF + 1, DEW = EF - T + 1 bits. (The model, and this file in
//           simulation, check every word's fields for every table built.)
//           G = g + ((dg r) >> (Wc-T)) <= g + dg = g(i+1) <= 2^(GF+1): GW bits; dg r has DGW+RW
//           bits. P = DN G <= 2^Wc 2^(GF+1) = 2^(CW+GF) (the value D g(D) <= 1): PW = CW + GF + 1
//           bits, the product computed in PW bits is exact. CW + GF >= LF (GF has the term
//           max(0, Ci - Wc - 4) for this), so Lf = P >> (CW+GF-LF) <= 2^LF: LF + 1 bits.
//           L = (z - 1) 2^LF + Lf <= (Wc - 1 + 1) 2^LF < 2^(ZW+LF): LLW = ZW + LF bits (L <= Wc,
//           c >= 2^-Wc); for C = 1.0 (z = 0, z - 1 would be -1) L is forced to 0. Y = N L:
//           KW + LLW bits, Cf + LF fraction bits, so its integer part has Ci + ZW bits;
//           ys = min(that, Wf + 2): YSW = clog2(Wf+3) bits. yfx = bits
//           [Cf+LF-1 : Cf+LF-EX] of Y (LF >= EX), j its top T bits (T <= Wf + 3 = EX), r2 its
//           low EX - T bits (none when T = EX: then E = e).
//           E = e - ((de r2) >> (EX-T)) with (de r2) >> (EX-T) <= de: E in [e(j+1), e(j)], so
//           2^(EF-1) <= E <= 2^EF: EW bits. With s = EF - Wf + ys = 4 + ys in [4, Wf+6]:
//           E + 2^(s-1) <= 2^(Wf+4) + 2^(Wf+5) < 2^(Wf+6) = 2^(EF+2): SSW = EF + 2 bits;
//           f = (E + 2^(s-1)) >> s <= (2^(Wf+4) + 8) >> 4 = 2^Wf: Wf + 1 bits, and ys = Wf + 2
//           gives 0 (E < 2^(Wf+5)).
//           Tables: every intermediate of the series stays below 2^122 (term <= 2^60,
//           d, x, zz <= 2^60, sum and pos < 1.4 2^60, LOG2E_Q < 1.45 2^60), so reg [127:0] is
//           exact.
// Rounding: tables: floors inside the series, RoundHalfUp to GF and EF bits. Datapath: Trunc
//           (floor) of both interpolations, of Lf (P to LF bits) and of y to EX fraction bits;
//           ys saturates at Wf + 2 (any y >= Wf + 2 gives f = 0 anyway); RoundHalfUp of f to
//           Wf bits (f = 0 for c = 0, forced).
// Error:    |f - c^n 2^Wf| is at most 1/2 (the final rounding) plus the interpolations' terms
//           (each falls by 4 per extra table bit) and the truncations of L and y (2^-(Wf+3) in y
//           each, moving f by ln 2 times that): testbench/test_spec_kinds.cpp derives the bound
//           and checks the model at every input against it. vectors/config/spec_explog.json
//           (T = 8): at most 0.733 f-LSB over every cos code and n = 1..1000.
// Model:    model/device/spec_unit.h SpecUnitModel::altSpec, bit-exact (the cycle behaviour is
//           shd_spec_unit's).
module shd_spec_explog #(
  parameter integer CosFracBits  = 15,
  parameter integer CoefIntBits  = 10,
  parameter integer CoefFracBits = 0,
  parameter integer SpecFracBits = 16,
  parameter integer LightBits    = 8,
  parameter integer TableBits    = 8,
  parameter integer PipeStages   = 1
) (
  input  wire                                clk_i,
  input  wire                                rst_ni,
  input  wire [CosFracBits:0]                c_i,      // cycle 0, saturated
  input  wire                                valid_q1, // cycle 1
  input  wire [CoefIntBits+CoefFracBits-1:0] n_i,      // cycle 1, the PROM word N
  input  wire [3*LightBits-1:0]              light_i,  // cycle 1
  output wire                                valid_o,
  output wire [SpecFracBits:0]               f_o,
  output wire [3*LightBits-1:0]              light_o
);

  localparam integer WC   = CosFracBits;
  localparam integer CW   = WC + 1;                          // c, uQ1.Wc
  localparam integer CI   = CoefIntBits;
  localparam integer CF   = CoefFracBits;
  localparam integer KW   = CI + CF;                         // N, uQCi.Cf
  localparam integer WF   = SpecFracBits;
  localparam integer FW   = WF + 1;                          // f, uQ1.Wf
  localparam integer LW   = 3 * LightBits;
  localparam integer T    = TableBits;
  localparam integer DEPTH = 1 << T;                         // words of each ROM
  localparam integer GF   = WF + 6 + ((CI > WC + 4) ? CI - WC - 4 : 0);  // g fraction bits
  localparam integer LF   = WF + CI + 3;                     // L fraction bits
  localparam integer EF   = WF + 4;                          // e fraction bits
  localparam integer EX   = WF + 3;                          // y fraction bits
  localparam integer GW   = GF + 2;                          // g
  localparam integer DGW  = GF - T + 1;                      // g(i+1) - g(i)
  localparam integer LOGW = DGW + GW;                        // log ROM word
  localparam integer EW   = EF + 1;                          // e
  localparam integer DEW  = EF - T + 1;                      // e(j) - e(j+1)
  localparam integer EXPW = DEW + EW;                        // exp ROM word
  localparam integer ZW   = $clog2(WC + 1);                  // z
  localparam integer SHR  = WC - T;                          // log interpolation shift
  localparam integer RW   = SHR + 1;                         // r
  localparam integer PW   = CW + GF + 1;                     // P = DN * G
  localparam integer LLW  = ZW + LF;                         // L
  localparam integer YW   = KW + LLW;                        // Y = N * L
  localparam integer YIW  = YW - CF - LF;                    // integer part of Y: Ci + ZW
  localparam integer YSW  = $clog2(WF + 3);                  // ys in 0..Wf+2
  localparam integer CMPW = ((YIW > YSW) ? YIW : YSW) + 1;   // the clamp of ys
  localparam integer R2W  = EX - T;                          // r2 (may be 0)
  localparam integer R2X  = (R2W > 0) ? R2W : 1;             // r2 as carried (0 when R2W = 0)
  localparam integer SSW  = EF + 2;                          // E + 2^(s-1)
  localparam [31:0]      YS_MAX32 = WF + 2;
  localparam [YSW-1:0]   YS_MAX   = YS_MAX32[YSW-1:0];       // the clamp of ys, Wf + 2
  localparam [31:0]      ONE32    = 1;
  localparam [ZW-1:0]    Z_ONE    = ONE32[ZW-1:0];

  // ---------------------------------------------------------------- the tables
  localparam integer Q = 60;
  localparam [127:0] ONE_Q   = 128'd1 << Q;
  localparam [127:0] LOG2E_Q = 128'd1663314137230540311;    // floor(log2(e) 2^60)
  localparam [127:0] LN2_Q   = 128'd799144290325165978;     // floor(ln(2) 2^60)

  // g(i) = -log2(1 - D)/D at D = i/2^(T+1): sum_k D^k/(k+1) times log2(e), GF fraction bits.
  function [127:0] g_code(input integer i);
    reg [127:0] d, sum, term, kq, gq;
    integer k;
    begin
      d    = {96'd0, i[31:0]} << (Q - T - 1);
      sum  = 128'd0;
      term = ONE_Q;
      kq   = 128'd1;
      for (k = 0; k < 62; k = k + 1) begin
        sum  = sum + term / kq;
        term = (term * d) >> Q;
        kq   = kq + 128'd1;
      end
      gq     = (sum * LOG2E_Q) >> Q;
      g_code = (gq + (128'd1 << (Q - GF - 1))) >> (Q - GF);
    end
  endfunction

  // e(j) = 2^-x at x = j/2^T: sum_k (-x ln 2)^k/k!, EF fraction bits.
  function [127:0] e_code(input integer j);
    reg [127:0] x, zz, pos, neg, term, kq, eq;
    integer k;
    begin
      x    = {96'd0, j[31:0]} << (Q - T);
      zz   = (x * LN2_Q) >> Q;
      pos  = 128'd0;
      neg  = 128'd0;
      term = ONE_Q;
      kq   = 128'd1;
      for (k = 0; k < 30; k = k + 1) begin
        if (k[0] == 1'b0) pos = pos + term;
        else              neg = neg + term;
        term = ((term * zz) >> Q) / kq;
        kq   = kq + 128'd1;
      end
      eq     = pos - neg;
      e_code = (eq + (128'd1 << (Q - EF - 1))) >> (Q - EF);
    end
  endfunction

  // Word k of the log table (which = 0) or the exp table (1): {step to entry k+1, entry k}, in
  // the low LOGW or EXPW bits. In simulation a field that does not hold its value (a wrong width
  // proof, see the header; a negative step wraps to a huge one) stops the run, as the model's
  // check does.
  function [127:0] table_word(input integer which, input integer k);
    reg [127:0] v0, v1, step;
    integer vb, sb;
    begin
      if (which == 0) begin                            // g increases
        v0   = g_code(k);
        v1   = g_code(k + 1);
        step = v1 - v0;
        vb   = GW;
        sb   = DGW;
      end else begin                                   // e decreases
        v0   = e_code(k);
        v1   = e_code(k + 1);
        step = v0 - v1;
        vb   = EW;
        sb   = DEW;
      end
      table_word = (step << vb) | v0;
`ifndef SYNTHESIS
      if ((v0 >> vb) != 0 || (step >> sb) != 0) begin
        $display("shd_spec_explog: %0s table word %0d does not fit its fields", (which == 0) ? "log" : "exp", k);
        $fatal(1);
      end
`endif
    end
  endfunction

  (* rom_style = "block" *)
  reg [LOGW-1:0] log_rom [0:DEPTH-1];
  (* rom_style = "block" *)
  reg [EXPW-1:0] exp_rom [0:DEPTH-1];
  integer w;
  reg [127:0] log_w, exp_w;
  initial begin
    for (w = 0; w < DEPTH; w = w + 1) begin
      log_w = table_word(0, w);
      exp_w = table_word(1, w);
      log_rom[w[T-1:0]] = log_w[LOGW-1:0];
      exp_rom[w[T-1:0]] = exp_w[EXPW-1:0];
    end
  end
  wire unused_words = ^{log_w[127:LOGW], exp_w[127:EXPW]};   // zero: checked above

  // ---------------------------------------------------------------- cycle 0: normalise c
  // g_norm[k], k = 1..ZW, shifts left by 2^(ZW-k) when the top 2^(ZW-k) bits are 0; the shifts
  // taken are the bits of z (C != 0: at most Wc leading zeros <= 2^ZW - 1).
  genvar k;
  generate
    for (k = 0; k <= ZW; k = k + 1) begin : g_norm
      wire [CW-1:0] m;
      wire          hit;
      if (k == 0) begin : g_src
        assign m   = c_i;
        assign hit = 1'b0;
      end else begin : g_shift
        localparam integer S = 1 << (ZW - k);                 // <= Wc < CW
        assign hit = ~|g_norm[k-1].m[CW-1 -: S];
        assign m   = hit ? {g_norm[k-1].m[CW-1-S:0], {S{1'b0}}} : g_norm[k-1].m;
      end
    end
  endgenerate

  wire [ZW-1:0] z_d;
  generate
    for (k = 1; k <= ZW; k = k + 1) begin : g_zbit
      assign z_d[ZW-k] = g_norm[k].hit;
    end
  endgenerate
  wire unused_hit0 = g_norm[0].hit;

  localparam [CW-1:0] COS_ONE = {1'b1, {WC{1'b0}}};
  localparam [T:0]    IDX_MAX = {1'b0, {T{1'b1}}};                // 2^T - 1
  wire          zero_d = (c_i == {CW{1'b0}});
  wire          one_d  = (c_i == COS_ONE);
  wire [CW-1:0] dn_d   = ~g_norm[ZW].m + {{(CW-1){1'b0}}, 1'b1};  // 2^CW - M, in [1, 2^Wc]
  wire [T:0]    i_sh   = dn_d[CW-1:SHR];                          // <= 2^T
  wire [T:0]    i_min  = i_sh[T] ? IDX_MAX : i_sh;
  wire [T-1:0]  i_d    = i_min[T-1:0];
  wire unused_i = i_min[T];                                        // 0
  wire [CW-1:0] r_full = dn_d - ({{(CW-T){1'b0}}, i_d} << SHR);    // in [0, 2^(Wc-T)]
  wire [RW-1:0] r_d    = r_full[RW-1:0];
  wire unused_r = ^r_full[CW-1:RW];

  // ---------------------------------------------------------------- cycle 1 registers, log ROM
  reg            zero_q1;
  reg            one_q1;
  reg [ZW-1:0]   z_q1;
  reg [CW-1:0]   dn_q1;
  reg [RW-1:0]   r_q1;
  reg [LOGW-1:0] logw_q1;
  always @(posedge clk_i) begin
    logw_q1 <= log_rom[i_d];
  end
  always @(posedge clk_i) begin
    zero_q1 <= zero_d;
    one_q1  <= one_d;
    z_q1    <= z_d;
    dn_q1   <= dn_d;
    r_q1    <= r_d;
  end

  // ---------------------------------------------------------------- A: G, P = DN * G
  wire [GW-1:0]      g_a   = logw_q1[GW-1:0];
  wire [DGW-1:0]     dg_a  = logw_q1[LOGW-1:GW];
  // dg r < 2^(DGW+RW) <= 2^(GW+SHR): exact in GW + SHR bits; (dg r) >> SHR <= dg.
  wire [GW+SHR-1:0]  dgr   = {{(GW+SHR-DGW){1'b0}}, dg_a} * {{(GW-1){1'b0}}, r_q1};
  wire [GW-1:0]      gi_a  = g_a + dgr[GW+SHR-1:SHR];
  wire [PW-1:0]      p_a   = {{(PW-CW){1'b0}}, dn_q1} * {{(PW-GW){1'b0}}, gi_a};  // exact
  generate
    if (SHR > 0) begin : g_dgr_low
      wire unused_dgr = ^dgr[SHR-1:0];
    end
  endgenerate

  // Optional rank A (PipeStages >= 2).
  localparam integer AW = PW + ZW + 2 + KW + LW;
  wire          valid_a;
  wire [PW-1:0] p_ar;
  wire [ZW-1:0] z_a;
  wire          one_a;
  wire          zero_a;
  wire [KW-1:0] n_a;
  wire [LW-1:0] light_a;
  shd_pipe_reg #(.Width(AW), .Enable((PipeStages >= 2) ? 1 : 0)) u_pipe_a (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_q1),
    .data_i ({p_a, z_q1, one_q1, zero_q1, n_i, light_i}),
    .valid_o(valid_a),
    .data_o ({p_ar, z_a, one_a, zero_a, n_a, light_a})
  );

  // ---------------------------------------------------------------- B: L, Y = N * L, split y
  wire [LF:0]      lf_b  = p_ar[PW-1:CW+GF-LF];              // <= 2^LF
  wire [ZW-1:0]    zm1_b = z_a - Z_ONE;
  wire [LLW:0]     l_sum = {1'b0, zm1_b, {LF{1'b0}}} + {{ZW{1'b0}}, lf_b};
  wire [LLW-1:0]   l_b   = one_a ? {LLW{1'b0}} : l_sum[LLW-1:0];  // -log2 c, <= Wc
  wire [YW-1:0]    y_b   = {{LLW{1'b0}}, n_a} * {{KW{1'b0}}, l_b};
  wire [YIW-1:0]   yi_b  = y_b[YW-1:CF+LF];
  wire [EX-1:0]    yfx_b = y_b[CF+LF-1:CF+LF-EX];            // CF + LF - EX = KW
  wire [CMPW-1:0]  yi_e  = {{(CMPW-YIW){1'b0}}, yi_b};     // both extended to CMPW bits
  wire [CMPW-1:0]  ysm_e = {{(CMPW-YSW){1'b0}}, YS_MAX};
  wire [CMPW-1:0]  ys_e  = (yi_e > ysm_e) ? ysm_e : yi_e;   // min(integer part, Wf + 2)
  wire [YSW-1:0]   ys_b  = ys_e[YSW-1:0];
  wire [T-1:0]     j_b   = yfx_b[EX-1:EX-T];
  wire [R2X-1:0]   r2_b;
  generate
    if (CW + GF - LF > 0) begin : g_p_low
      wire unused_p = ^p_ar[CW+GF-LF-1:0];
    end
    if (CF + LF - EX > 0) begin : g_y_low
      wire unused_y = ^y_b[CF+LF-EX-1:0];                  // below y's EX fraction bits
    end
    if (R2W > 0) begin : g_r2
      assign r2_b = yfx_b[R2W-1:0];
    end else begin : g_no_r2
      assign r2_b = 1'b0;
    end
  endgenerate
  wire unused_b = ^{l_sum[LLW], ys_e[CMPW-1:YSW]};

  // Rank X (always): the exp ROM's read register, with r2, ys, zero, light.
  localparam integer XW = R2X + YSW + 1 + LW;
  reg  [EXPW-1:0] expw_x;
  wire            valid_x;
  wire [R2X-1:0]  r2_x;
  wire [YSW-1:0]  ys_x;
  wire            zero_x;
  wire [LW-1:0]   light_x;
  always @(posedge clk_i) begin
    expw_x <= exp_rom[j_b];
  end
  shd_pipe_reg #(.Width(XW), .Enable(1)) u_pipe_x (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_a),
    .data_i ({r2_b, ys_b, zero_a, light_a}),
    .valid_o(valid_x),
    .data_o ({r2_x, ys_x, zero_x, light_x})
  );

  // ---------------------------------------------------------------- C: E, shift, round
  wire [EW-1:0]  e_x  = expw_x[EW-1:0];
  wire [DEW-1:0] de_x = expw_x[EXPW-1:EW];
  wire [EW-1:0]  e_c;
  generate
    if (R2W > 0) begin : g_interp
      // de r2 < 2^(DEW+R2W) <= 2^(EW+R2W): exact; (de r2) >> R2W <= de, so E >= e(j+1).
      wire [EW+R2W-1:0] der = {{(EW+R2W-DEW){1'b0}}, de_x} * {{EW{1'b0}}, r2_x};
      assign e_c = e_x - der[EW+R2W-1:R2W];
      wire unused_der = ^der[R2W-1:0];
    end else begin : g_node
      assign e_c = e_x;                                        // T = EX: no fraction left
      wire unused_de = ^{de_x, r2_x};
    end
  endgenerate
  // f = (E + 2^(s-1)) >> s, s = 4 + ys: RoundHalfUp to Wf bits.
  wire [SSW-1:0] half_c = {{(SSW-4){1'b0}}, 4'b1000} << ys_x;
  wire [SSW-1:0] sum_c  = {1'b0, e_c} + half_c;
  wire [SSW-1:0] sh_c   = sum_c >> ys_x;
  wire [FW-1:0]  f_c    = zero_x ? {FW{1'b0}} : sh_c[FW+3:4];
  wire unused_c = ^{sh_c[SSW-1], sh_c[3:0]};                 // SSW - 1 = FW + 4

  // Optional rank C (PipeStages = 3).
  shd_pipe_reg #(.Width(FW + LW), .Enable((PipeStages >= 3) ? 1 : 0)) u_pipe_c (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_x),
    .data_i ({f_c, light_x}),
    .valid_o(valid_o),
    .data_o ({f_o, light_o})
  );

endmodule
