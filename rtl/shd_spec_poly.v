// shd_spec_poly: the polynomial datapath of the specular unit (Kind 0 of shd_spec_unit): stages
// A, B and C of paper Fig. 11, from the cycle-1 registers (c, the PROM word) to f.
// Why:      f(c) = a*(c^2 - c) + c = a c^2 + (1-a) c needs two multipliers and no pow; a(n) comes
//           from the PROM word. Degree 3 is the same structure with a Horner step:
//           f = c + (c^2 - c)*(u*c + v), u = a1, v = a1 + b1, and a cut-off code.
// Latency:  PipeStages cycles (0..3) valid_i -> valid_o, combinational for 0. Optional registers,
//           enabled in this order as PipeStages grows: B after MUL2+rounding, A after Sm1 (and
//           Horner), C after Sm2+clamp. light_i travels beside the data unchanged.
// Formats:  c_i uQ1.Wc, at most 1.0 (shd_spec_unit saturates it); word_i the PROM word: a in
//           uQCi.Cf (degree 2) or {cut-off code uQ1.Wc, v sQCi.Cf, u sQCi.Cf} (degree 3);
//           f_o in uQ1.Wf, in [0, 1].
// Widths:   c^2 <= 1 and c^2 - c lies in [-1/4, 0], so bits [2Wc-2:0] of Sm1 hold it exactly as
//           a signed number; after dropping 2Wc-Df LSBs (floor) dt lies in [-2^(Df-2), 0] and
//           needs Df-1 bits. Degree 2: |a*dt| <= (2^KW - 1)*2^(Df-2) < 2^(KW+Df-2), so the
//           product needs KW+Df-1 = KW+DTW bits signed. Degree 3: |u*c| <= 2^(KW-1+Wc) and
//           |v*2^Wc| < 2^(KW-1+Wc), so g needs KW+Wc+1 bits, exactly Ci+1+Hf after the shift;
//           |dt*gt| <= 2^(Df-2) * 2^(GTW-1) needs DTW+GTW bits signed (the product can be
//           positive). Each width is the derivation above, not a guess; the model asserts them
//           (Overflow::Error) at every conversion.
// Rounding: Trunc (floor) of c^2 - c to Df bits and of g to Hf bits; RoundHalfUp of the MUL2
//           product to Wf bits. Sm2 saturates f to [0, 1]; for degree 2 only the lower clamp can
//           act (a >= 0 and c^2 - c <= 0 give f <= c <= 1).
// Model:    model/device/spec_unit.h SpecUnitModel, bit-exact and cycle-accurate.
module shd_spec_poly #(
  parameter integer Degree         = 2,
  parameter integer CosFracBits    = 15,
  parameter integer CoefIntBits    = 10,
  parameter integer CoefFracBits   = 14,
  parameter integer DiffFracBits   = 28,
  parameter integer HornerFracBits = 14,
  parameter integer SpecFracBits   = 16,
  parameter integer LightBits      = 8,
  parameter integer PipeStages     = 1
) (
  input  wire                     clk_i,
  input  wire                     rst_ni,
  input  wire                     valid_i,
  input  wire [CosFracBits:0]     c_i,
  // The PROM word: KW bits (degree 2) or 2*KW + CW bits (degree 3), KW = Ci + Cf, CW = Wc + 1.
  input  wire [((Degree == 2) ? 1 : 2) * (CoefIntBits + CoefFracBits)
               + ((Degree == 2) ? 0 : CosFracBits + 1) - 1:0] word_i,
  input  wire [3*LightBits-1:0]   light_i,
  output wire                     valid_o,
  output wire [SpecFracBits:0]    f_o,
  output wire [3*LightBits-1:0]   light_o
);

  localparam integer WC    = CosFracBits;
  localparam integer CW    = WC + 1;                        // c, uQ1.Wc
  localparam integer KW    = CoefIntBits + CoefFracBits;     // one coefficient
  localparam integer LW    = 3 * LightBits;
  localparam integer DTW   = DiffFracBits - 1;              // dt, sQ(-1).Df
  localparam integer GTW   = CoefIntBits + 1 + HornerFracBits;  // gt, sQ(Ci+1).Hf
  localparam integer MW    = (Degree == 2) ? KW : GTW;        // MUL2 operand beside dt
  localparam integer PW    = MW + DTW;                        // MUL2 product
  localparam integer PFRAC = DiffFracBits + ((Degree == 2) ? CoefFracBits : HornerFracBits);
  localparam integer SH    = PFRAC - SpecFracBits;           // LSBs rounded away, >= 0
  localparam integer PRW   = PW - SH;                        // rounded product
  localparam integer WF    = SpecFracBits;
  localparam integer FW    = WF + 1;                         // f, uQ1.Wf
  localparam integer FSW   = ((PRW > WF + 2) ? PRW : WF + 2) + 1;  // Sm2 sum, signed
  localparam [FW-1:0] SPEC_ONE = {1'b1, {WF{1'b0}}};

  // ---------------------------------------------------------------- A: MUL1, BI, Sm1, Horner
  wire [2*CW-1:0] sq     = {{CW{1'b0}}, c_i} * {{CW{1'b0}}, c_i};     // MUL1, <= 2^(2Wc)
  wire [2*CW-1:0] c_al   = {1'b0, c_i, {WC{1'b0}}};                   // c at 2Wc fraction bits
  wire [2*CW-1:0] d_full = sq + ~c_al + {{(2*CW-1){1'b0}}, 1'b1};    // BI + Sm1: c^2 - c
  // d in [-2^(2Wc-2), 0]: bits [2Wc-2:0] hold it; bits above are copies of its sign.
  wire signed [2*WC-2:0] d_s     = d_full[2*WC-2:0];
  wire signed [2*WC-2:0] d_shift = d_s >>> (2 * WC - DiffFracBits);  // Trunc to Df bits
  wire signed [DTW-1:0]  dt_a    = d_shift[DTW-1:0];
  wire unused_d = ^{d_full[2*CW-1:2*WC-1], d_shift};

  wire [MW-1:0] m_a;   // MUL2 operand: a (degree 2) or gt (degree 3)
  wire [CW-1:0] cut_a; // degree 3 cut-off code (0 for degree 2)
  generate
    if (Degree == 2) begin : g_quad
      assign m_a   = word_i;
      assign cut_a = {CW{1'b0}};
    end else begin : g_cubic
      localparam integer UCW = KW + CW + 1;              // u * {0,c}, natural width
      localparam integer GW  = KW + WC + 1;              // g = u*c + v*2^Wc
      localparam integer GSH = CoefFracBits + WC - HornerFracBits;
      wire signed [KW-1:0]  u_a = word_i[KW-1:0];
      wire signed [KW-1:0]  v_a = word_i[2*KW-1:KW];
      wire signed [UCW-1:0] uc  = u_a * $signed({1'b0, c_i});    // signed x signed: no wasted DSP tile
      // |u*c| <= 2^(KW-1+Wc): bits [GW-2:0] hold it.
      wire signed [GW-1:0]  g_full = {uc[GW-2], uc[GW-2:0]} + {v_a[KW-1], v_a, {WC{1'b0}}};
      wire signed [GW-1:0]  g_shift = g_full >>> GSH;    // Trunc to Hf bits
      assign m_a   = g_shift[GTW-1:0];                   // GW - GSH = GTW: nothing else dropped
      assign cut_a = word_i[2*KW+CW-1:2*KW];
      wire unused_g = ^{uc[UCW-1:GW-1], g_shift};
    end
  endgenerate

  // Optional register A (PipeStages >= 2).
  localparam integer AW = CW + DTW + MW + CW + LW;
  wire          valid_a;
  wire [CW-1:0] c_a;
  wire [DTW-1:0] dt_ar;
  wire [MW-1:0] m_ar;
  wire [CW-1:0] cut_ar;
  wire [LW-1:0] light_a;
  shd_pipe_reg #(.Width(AW), .Enable((PipeStages >= 2) ? 1 : 0)) u_pipe_a (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_i),
    .data_i ({c_i, dt_a, m_a, cut_a, light_i}),
    .valid_o(valid_a),
    .data_o ({c_a, dt_ar, m_ar, cut_ar, light_a})
  );

  // ---------------------------------------------------------------- B: MUL2, round
  wire signed [PW-1:0] m_ext  = (Degree == 2) ? {{DTW{1'b0}}, m_ar}
                                              : {{DTW{m_ar[MW-1]}}, m_ar};
  wire signed [PW-1:0] dt_ext = {{MW{dt_ar[DTW-1]}}, dt_ar};
  wire signed [PW-1:0] prod   = m_ext * dt_ext;          // MUL2, fits PW bits (see header)
  wire signed [PRW-1:0] pr_b;
  generate
    if (SH > 0) begin : g_round
      // RoundHalfUp: add half an output LSB, then drop SH bits (floor). Cannot overflow:
      // |prod| <= 2^(PW-2) and 2^(SH-1) < 2^(PW-2).
      wire signed [PW-1:0] half     = {{(PW-1){1'b0}}, 1'b1} << (SH - 1);
      wire signed [PW-1:0] prod_rnd = prod + half;
      assign pr_b = prod_rnd[PW-1:SH];
      wire unused_rnd = ^prod_rnd[SH-1:0];
    end else begin : g_exact
      assign pr_b = prod;
    end
  endgenerate

  // Optional register B (PipeStages >= 1). The cut-off code sits above c in it: yosys (0.23)
  // orders the operands of c < cut by a hash of their bits, and with this order the comparison
  // maps to a carry chain alone on iCE40, as it did before the datapath moved into this module.
  localparam integer BW = CW + PRW + CW + LW;
  wire           valid_b;
  wire [CW-1:0]  c_b;
  wire [PRW-1:0] pr_br;
  wire [CW-1:0]  cut_b;
  wire [LW-1:0]  light_b;
  shd_pipe_reg #(.Width(BW), .Enable((PipeStages >= 1) ? 1 : 0)) u_pipe_b (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_a),
    .data_i ({cut_ar, pr_b, c_a, light_a}),
    .valid_o(valid_b),
    .data_o ({cut_b, pr_br, c_b, light_b})
  );

  // ---------------------------------------------------------------- C: Sm2, clamp, cut-off
  wire signed [FSW-1:0] c_f   = {{(FSW-CW){1'b0}}, c_b} << (WF - WC);  // c at Wf bits
  wire signed [FSW-1:0] pr_f  = {{(FSW-PRW){pr_br[PRW-1]}}, pr_br};
  wire signed [FSW-1:0] f_sum = c_f + pr_f;              // Sm2
  wire signed [FSW-1:0] f_one = {{(FSW-FW){1'b0}}, SPEC_ONE};
  wire                  cut_c = (Degree == 3) && (c_b < cut_b);
  reg  [FW-1:0]         f_c;
  always @* begin
    if (f_sum[FSW-1] || cut_c) f_c = {FW{1'b0}};          // negative lobe cut to 0
    else if (f_sum > f_one)    f_c = SPEC_ONE;            // degree 3 only, see header
    else                       f_c = f_sum[FW-1:0];
  end

  // Optional register C (PipeStages >= 3).
  localparam integer CRW = FW + LW;
  shd_pipe_reg #(.Width(CRW), .Enable((PipeStages >= 3) ? 1 : 0)) u_pipe_c (
    .clk_i  (clk_i),
    .rst_ni (rst_ni),
    .valid_i(valid_b),
    .data_i ({f_c, light_b}),
    .valid_o(valid_o),
    .data_o ({f_o, light_o})
  );

endmodule
