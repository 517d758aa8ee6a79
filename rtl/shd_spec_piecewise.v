// shd_spec_piecewise: the piecewise polynomial datapath of the specular unit (Kind 4 of
// shd_spec_unit): f = a polynomial of degree d in the cosine, one per segment of [B_0, 1], from the
// cycle-1 registers (c, the PROM word of the segments' first codes) to f.
// Why:      one polynomial over the whole of [0, 1] fits c^n poorly for large n (the lobe is narrow
//           and flat elsewhere); S = Segments pieces of degree d = Degree, each a polynomial in its
//           own local coordinate u = (c - B_s) 2^e / 2^Wc in [0, 1], fit it with coefficients that
//           stay small (sQCi.Kf), so d Horner steps of one multiply-add each are the whole
//           datapath. Below the cut B_0 the lobe is 0 to Wf bits: f = 0.
// Latency:  PipeStages cycles (1..d+1) after the cycle-1 registers; one result per cycle, no
//           stalls. Cycle 1: cut, the segment s, x = c - B_s, from the unit's cycle-1 registers
//           and the shininess code registered here (shin_q1), which with s addresses the
//           segment ROM. Ranks, enabled in this order as PipeStages grows: S (always: the segment
//           ROM's read register, with x, cut), then rank r = 1..PipeStages-1 right after Horner
//           step r (step 1 produces the acc that adds K_{d-1}); PipeStages = d+1 gives every
//           multiply-add its own cycle. The rounding and clamp of f follow the last step, before
//           the unit's stage D. light_i travels beside the data unchanged.
// Formats:  c_i uQ1.Wc, at most 1.0 (shd_spec_unit saturates it); bounds_i, the PROM word: field
//           j = 0..S-1 is B_j = bounds_i[j*CW +: CW], unsigned cos codes, B_0 the cut (c < B_0
//           gives f = 0); a well-formed word has B_0 <= .. <= B_{S-1} (unused segments may start
//           above 1.0, where no c reaches them). Segment ROM (file RomFile + ".seg"), address
//           {shin, s} ({shin} for S = 1), word {K_d, .., K_1, K_0, e}: e = word[EB-1:0] unsigned
//           in 0..Wc, K_j = word[EB + j*KW +: KW] sQCi.Kf (two's complement). f_o uQ1.Wf, in
//           [0, 1].
// Widths:   CW = Wc + 1, KW = Ci + Kf, EB = clog2(Wc + 1) (e <= Wc), SB = log2 S. s counts the
//           S - 1 comparisons c >= B_j, j >= 1: at most S - 1 = 2^SB - 1, SB bits.
//           x = c - B_s in CW bits, modulo 2^CW (exact, in [0, 2^Wc], when c >= B_s; when cut it
//           is meaningless and f is forced to 0). u = (x << e) mod 2^CW: the PROM generator picks
//           e so that x 2^e <= 2^Wc for every c of segment s, so u = x 2^e <= 2^Wc exactly.
//           |K_j| <= 2^(KW-1) = 2^(Ci-1+Kf). With 0 <= u <= 2^Wc, |floor(acc u / 2^Wc)| <=
//           |acc| + 1, so after step k |acc| <= (k+1) 2^(Ci-1+Kf) + k, at most
//           (d+1) 2^(Ci-1+Kf) + d <= 2^(Ci+Kf+1) + 3 < 2^(Ci+Kf+2) (d <= 3): AW = KW + 3 signed
//           bits hold every acc. A step is one multiply-add, m = acc u + K 2^Wc (u extended with a
//           0 sign bit): |acc u| < 2^(AW-1) 2^CW for any u < 2^CW and |K 2^Wc| <= 2^(KW-1+Wc), so
//           m is exact in AW + CW + 1 bits, the product's natural width. Bits [AW+Wc-1:Wc] of m
//           are floor(acc u / 2^Wc) + K (a two's complement shift is a floor, and adding a
//           multiple of 2^Wc commutes with it), in AW bits as above. (Adding K after the shift is
//           the same function, but yosys 0.23's xilinx_dsp then packs that add into the next
//           step's DSP48E1 pre-adder with zero-extended operands, a wrong xc7 netlist; the
//           multiply-add maps to the post-adder instead.) Rounding: acc + 2^(sh-1) <=
//           2^(KW+1) + 3 + 2^(Kf-1) < 2^(AW-1) (sh = Kf - Wf <= Kf), still AW bits; r = that >>> sh
//           has AW - sh = Ci + Wf + 3 >= Wf + 2 bits, enough to compare with 2^Wf; f <= 2^Wf:
//           FW = Wf + 1 bits.
//           A malformed word (B out of order, e too large) still gives a defined result: x and u
//           wrap modulo 2^CW, acc and its rounding modulo 2^AW (the model refuses such PROMs).
// Rounding: Trunc (floor) of each Horner product acc u to Kf fraction bits (Wc bits dropped);
//           RoundHalfUp of the last acc to Wf bits (none when Kf = Wf); f saturated to [0, 1], and
//           0 below the cut.
// Model:    model/device/spec_unit.h SpecUnitModel (approx/piecewise.h PiecewiseCodes::eval),
//           bit-exact (the cycle behaviour is shd_spec_unit's).
module shd_spec_piecewise #(
  parameter integer Degree       = 2,
  parameter integer Segments     = 4,
  parameter integer CosFracBits  = 15,
  parameter integer ShinBits     = 10,
  parameter integer CoefIntBits  = 2,
  parameter integer CoefFracBits = 18,
  parameter integer SpecFracBits = 16,
  parameter integer LightBits    = 8,
  parameter integer PipeStages   = 1,
  parameter         RomFile      = ""
) (
  input  wire                                 clk_i,
  input  wire                                 rst_ni,
  input  wire [ShinBits-1:0]                  shin_i,    // cycle 0: registered here
  input  wire                                 valid_q1,  // cycle 1
  input  wire [CosFracBits:0]                 c_i,       // cycle 1, saturated
  input  wire [Segments*(CosFracBits+1)-1:0]  bounds_i,  // cycle 1, the PROM word {B_S-1..B_0}
  input  wire [3*LightBits-1:0]               light_i,   // cycle 1
  output wire                                 valid_o,
  output wire [SpecFracBits:0]                f_o,
  output wire [3*LightBits-1:0]               light_o
);

  localparam integer D    = (Degree > 1) ? Degree : 1;         // < 1: see the unit's Checks
  localparam integer S    = Segments;
  localparam integer SB   = (S == 4) ? 2 : (S == 2) ? 1 : 0;   // segment index bits
  localparam integer SBX  = (SB > 0) ? SB : 1;                  // s as carried (0 when S = 1)
  localparam integer WC   = CosFracBits;
  localparam integer CW   = WC + 1;                             // c, x, u: uQ1.Wc
  localparam integer KW   = CoefIntBits + CoefFracBits;          // K_j, sQCi.Kf
  localparam integer WF   = SpecFracBits;
  localparam integer FW   = WF + 1;                             // f, uQ1.Wf
  localparam integer LW   = 3 * LightBits;
  localparam integer EB   = $clog2(WC + 1);                     // e in 0..Wc
  localparam integer SEGW = EB + (D + 1) * KW;                  // segment ROM word
  localparam integer SAB  = ShinBits + SB;                      // segment ROM address
  localparam integer AW   = KW + 3;                             // acc, signed
  localparam integer SH   = CoefFracBits - SpecFracBits;         // bits rounded away, >= 0
  localparam integer RW   = AW - SH;                            // r, signed: Ci + Wf + 3
  localparam [31:0]     ONE32    = 1;
  localparam [SBX-1:0]  S_ONE    = ONE32[SBX-1:0];
  localparam [RW-1:0]   SPEC_ONE = {{(RW-FW){1'b0}}, 1'b1, {WF{1'b0}}};

  // ---------------------------------------------------------------- cycle 1: cut, s, x
  reg [ShinBits-1:0] shin_q1;
  always @(posedge clk_i) begin
    shin_q1 <= shin_i;
  end

  wire          cut_1 = (c_i < bounds_i[CW-1:0]);
  reg [SBX-1:0] s_1;                     // #{j in 1..S-1 : c >= B_j}
  reg [CW-1:0]  bs_1;                    // B_s
  integer j;
  always @* begin
    s_1 = {SBX{1'b0}};
    for (j = 1; j < S; j = j + 1) begin
      if (c_i >= bounds_i[j*CW +: CW]) s_1 = s_1 + S_ONE;
    end
    bs_1 = bounds_i[CW-1:0];
    for (j = 1; j < S; j = j + 1) begin
      if (s_1 == j[SBX-1:0]) bs_1 = bounds_i[j*CW +: CW];
    end
  end
  wire [CW-1:0] x_1 = c_i - bs_1;        // modulo 2^CW

  wire [SAB-1:0] seg_addr;
  generate
    if (SB > 0) begin : g_seg_addr
      assign seg_addr = {shin_q1, s_1[SB-1:0]};
    end else begin : g_shin_addr
      assign seg_addr = shin_q1;
      wire unused_s = s_1[0];            // always 0: one segment
    end
  endgenerate

  // ---------------------------------------------------------------- rank S (always)
  // The segment ROM's read register, with x, cut, light.
  wire [SEGW-1:0] seg_s;
  shd_coef_rom #(
    .AddrBits(SAB),
    .WordBits(SEGW),
    .RomFile (RomFile),
    .Suffix  (".seg")
  ) u_seg_rom (
    .clk_i (clk_i),
    .addr_i(seg_addr),
    .word_o(seg_s)
  );

  wire          valid_s;
  wire [CW-1:0] x_s;
  wire          cut_s;
  wire [LW-1:0] light_s;
  shd_pipe_reg #(.Width(CW + 1 + LW), .Enable(1)) u_pipe_s (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_q1),
    .data_i ({x_1, cut_1, light_i}),
    .valid_o(valid_s),
    .data_o ({x_s, cut_s, light_s})
  );

  // ---------------------------------------------------------------- Horner steps 1..d
  // g_step[k], k = 1..d: acc = floor(acc u / 2^Wc) + K_{d-k} from the state after step k-1 (after
  // rank S for k = 1, with acc = K_d), then the optional rank k (k <= PipeStages - 1). The
  // state: valid, cut, light, acc and, while steps remain (k < d), u and the coefficients still
  // to add, ks = {K_{d-k-1}, .., K_0}.
  wire [EB-1:0] e_s   = seg_s[EB-1:0];
  wire [CW-1:0] u_s   = x_s << e_s;                              // modulo 2^CW
  wire [KW-1:0] kd_s  = seg_s[EB + D*KW +: KW];                  // K_d
  wire [AW-1:0] acc_s = {{(AW-KW){kd_s[KW-1]}}, kd_s};
  genvar k;
  generate
    for (k = 1; k <= D; k = k + 1) begin : g_step
      localparam integer NK = D - k;                             // coefficients left after it
      // The state before the step.
      wire                 valid_p;
      wire                 cut_p;
      wire [LW-1:0]        light_p;
      wire [AW-1:0]        acc_p;
      wire [CW-1:0]        u_p;
      wire [(NK+1)*KW-1:0] ks_p;
      if (k == 1) begin : g_first
        assign valid_p = valid_s;
        assign cut_p   = cut_s;
        assign light_p = light_s;
        assign acc_p   = acc_s;
        assign u_p     = u_s;
        assign ks_p    = seg_s[EB +: D*KW];
      end else begin : g_next
        assign valid_p = g_step[k-1].valid;
        assign cut_p   = g_step[k-1].cut;
        assign light_p = g_step[k-1].light;
        assign acc_p   = g_step[k-1].acc;
        assign u_p     = g_step[k-1].g_more.u;
        assign ks_p    = g_step[k-1].g_more.ks;
      end

      // One multiply-add: m = acc u + K 2^Wc, exact in AW + CW + 1 bits; its bits
      // [AW+Wc-1:Wc] are floor(acc u / 2^Wc) + K (K 2^Wc, a multiple of 2^Wc, commutes with the
      // floor), which AW bits hold (see Widths).
      wire        [KW-1:0]  k_p   = ks_p[NK*KW +: KW];              // K_{d-k}
      wire signed [AW+CW:0] prod  = $signed(acc_p) * $signed({1'b0, u_p});
      wire        [AW+CW:0] m     = prod + {{(AW+CW+1-KW-WC){k_p[KW-1]}}, k_p, {WC{1'b0}}};
      wire        [AW-1:0]  acc_n = m[AW+WC-1:WC];
      wire unused_m = ^{m[AW+CW:AW+WC], m[WC-1:0]};

      // Optional rank k.
      localparam integer RK = (k <= PipeStages - 1) ? 1 : 0;
      wire          valid;
      wire          cut;
      wire [LW-1:0] light;
      wire [AW-1:0] acc;
      shd_pipe_reg #(.Width(AW + 1 + LW), .Enable(RK)) u_pipe_h (
        .clk_i  (clk_i),
        .rst_ni (rst_ni),
        .valid_i(valid_p),
        .data_i ({acc_n, cut_p, light_p}),
        .valid_o(valid),
        .data_o ({acc, cut, light})
      );
      if (NK > 0) begin : g_more
        wire [CW-1:0]    u;
        wire [NK*KW-1:0] ks;
        wire             unused_v;
        shd_pipe_reg #(.Width(CW + NK*KW), .Enable(RK)) u_pipe_u (
          .clk_i  (clk_i),
          .rst_ni (rst_ni),
          .valid_i(valid_p),
          .data_i ({u_p, ks_p[NK*KW-1:0]}),
          .valid_o(unused_v),                                   // = valid
          .data_o ({u, ks})
        );
      end
    end
  endgenerate

  wire          valid_f = g_step[D].valid;
  wire          cut_f   = g_step[D].cut;
  wire [LW-1:0] light_f = g_step[D].light;
  wire [AW-1:0] acc_f   = g_step[D].acc;

  // ---------------------------------------------------------------- round, clamp
  wire [RW-1:0] r_f;                     // signed, Wf fraction bits
  generate
    if (SH > 0) begin : g_round
      // RoundHalfUp: add half an output LSB, then drop SH bits (floor); cannot overflow AW bits.
      wire [AW-1:0] half    = {{(AW-1){1'b0}}, 1'b1} << (SH - 1);
      wire [AW-1:0] acc_rnd = acc_f + half;
      assign r_f = acc_rnd[AW-1:SH];
      wire unused_rnd = ^acc_rnd[SH-1:0];
    end else begin : g_exact
      assign r_f = acc_f;
    end
  endgenerate

  reg [FW-1:0] f_f;
  always @* begin
    if (cut_f || r_f[RW-1])  f_f = {FW{1'b0}};              // below the cut, or negative
    else if (r_f > SPEC_ONE) f_f = SPEC_ONE[FW-1:0];
    else                     f_f = r_f[FW-1:0];
  end

  assign valid_o = valid_f;
  assign f_o     = f_f;
  assign light_o = light_f;

endmodule
