// shd_spec_schlick: the Schlick datapath of the specular unit (Kind 2 of shd_spec_unit):
// f = c / (n - n c + c) = c / ((n-1)(1-c) + 1), from the cycle-1 registers (c, m = n - 1) to f.
// Why:      Schlick's rational replaces pow by one multiply and one divide; the PROM holds only
//           m = n - 1 per shininess code, and a restoring divider of Wf+1 steps gives f truncated
//           to Wf fraction bits with no table of c and no polynomial fit.
// Latency:  PipeStages cycles (0..Wf+1) valid_i -> valid_o, combinational for 0; one result per
//           cycle, no stalls. The divider has steps 1..Wf+1 (step 0 is the den multiply); rank
//           j = 1..PipeStages of registers follows step floor(j*(Wf+1)/(PipeStages+1)), so the
//           ranks are spread evenly, never two after one step and never one after the last step
//           (the output register of shd_spec_unit follows it). den, the remainder, the bits of
//           the dividend not yet used with the quotient bits so far (one shift register qn), and
//           light_i travel through the same ranks.
// Formats:  c_i uQ1.Wc, at most 1.0 (shd_spec_unit saturates it); m_i = n - 1 uQCi.Cf (unsigned;
//           m = 0 gives f = c, the padding words of the PROM); f_o uQ1.Wf, in [0, 1].
// Widths:   KW = Ci + Cf, CW = Wc + 1. omc = 2^Wc - c is in [0, 2^Wc]: CW bits.
//           m*omc <= (2^KW - 1)*2^Wc < 2^(KW+Wc), exact in KW + CW bits; den = m*omc + 2^(Cf+Wc)
//           <= 2^(KW+Wc) - 2^Wc + 2^(Cf+Wc) < 2^(KW+Wc+1) since Cf <= KW: DW = KW + Wc + 1 bits,
//           and den >= 2^(Cf+Wc) > 0. NUM = c * 2^(Cf+Wf) has CW + Cf + Wf bits. Because
//           c <= 2^Wc, den >= 2^(Cf+Wc) >= c*2^Cf, so f = floor(NUM/den) <= 2^Wf: Wf+1 bits.
//           The first remainder r = NUM >> (Wf+1) <= c*2^(Cf-1) < den (Wc+Cf bits, < DW), so the
//           quotient's bits above Wf are 0 and Wf+1 steps give all of it. In a step r < den, so
//           t = 2r + NUM[i] < 2 den < 2^(DW+1): DW+1 bits; the new r (t - den or t) is < den again,
//           DW bits. The subtraction t - den is DW+2 bits wide; its sign is the borrow (t < den).
// Rounding: Trunc (floor) of the quotient to Wf fraction bits, exact otherwise.
// Model:    model/device/spec_unit.h SpecUnitModel::altSpec, bit-exact (the cycle behaviour is
//           shd_spec_unit's).
module shd_spec_schlick #(
  parameter integer CosFracBits  = 15,
  parameter integer CoefIntBits  = 10,
  parameter integer CoefFracBits = 14,
  parameter integer SpecFracBits = 16,
  parameter integer LightBits    = 8,
  parameter integer PipeStages   = 1
) (
  input  wire                                clk_i,
  input  wire                                rst_ni,
  input  wire                                valid_i,
  input  wire [CosFracBits:0]                c_i,
  input  wire [CoefIntBits+CoefFracBits-1:0] m_i,
  input  wire [3*LightBits-1:0]              light_i,
  output wire                                valid_o,
  output wire [SpecFracBits:0]               f_o,
  output wire [3*LightBits-1:0]              light_o
);

  localparam integer WC = CosFracBits;
  localparam integer CW = WC + 1;                           // c, uQ1.Wc
  localparam integer KW = CoefIntBits + CoefFracBits;        // m, uQCi.Cf
  localparam integer WF = SpecFracBits;
  localparam integer FW = WF + 1;                            // f, uQ1.Wf
  localparam integer LW = 3 * LightBits;
  localparam integer DW = KW + WC + 1;                       // den, remainder
  localparam integer NW = CW + CoefFracBits + WF;            // NUM = c << (Cf + Wf)
  localparam integer R0 = NW - FW;                           // NUM >> (Wf+1): Wc + Cf bits
  localparam integer STEPS = FW;                             // divider steps, one per f bit
  localparam integer SW = DW + DW + FW + LW;                 // {den, r, qn, light} at a rank
  localparam [CW-1:0] COS_ONE = {1'b1, {WC{1'b0}}};
  localparam [DW-1:0] DEN_ONE = {{(DW-1){1'b0}}, 1'b1} << (CoefFracBits + WC);  // 1.0 of den

  // 1 when a register rank follows step b (0 = the den multiply): rank j = 1..PipeStages follows
  // step floor(j*STEPS/(PipeStages+1)), distinct for distinct j while PipeStages <= STEPS.
  function integer rank_after(input integer b);
    integer j;
    begin
      rank_after = 0;
      for (j = 1; j <= PipeStages; j = j + 1)
        if ((j * STEPS) / (PipeStages + 1) == b) rank_after = 1;
    end
  endfunction

  // ---------------------------------------------------------------- step 0: den = m*(1-c) + 1
  wire [CW-1:0] omc  = COS_ONE - c_i;                        // 1 - c, in [0, 2^Wc]
  wire [DW-1:0] mo   = {{(DW-KW){1'b0}}, m_i} * {{(DW-CW){1'b0}}, omc};  // exact (see header)
  wire [DW-1:0] den0 = mo + DEN_ONE;
  wire [NW-1:0] num  = {c_i, {(CoefFracBits+WF){1'b0}}};
  wire [DW-1:0] r0   = {{(DW-R0){1'b0}}, num[NW-1:FW]};      // < den0
  wire [FW-1:0] qn0  = num[FW-1:0];                          // the dividend bits still to use

  // ---------------------------------------------------------------- the divider
  // g_step[s].*_d: the state after step s; g_step[s].*_q: the same after its optional rank.
  // qn holds {dividend bits not yet used, quotient bits so far}: a step shifts its MSB out
  // (NUM[i]) and the quotient bit q[i] in; after step Wf+1 it is the quotient f.
  genvar s;
  generate
    for (s = 0; s <= STEPS; s = s + 1) begin : g_step
      wire          valid_d;
      wire [DW-1:0] den_d;
      wire [DW-1:0] r_d;
      wire [FW-1:0] qn_d;
      wire [LW-1:0] light_d;
      wire          valid_q;
      wire [DW-1:0] den_q;
      wire [DW-1:0] r_q;
      wire [FW-1:0] qn_q;
      wire [LW-1:0] light_q;
      if (s == 0) begin : g_den
        assign valid_d = valid_i;
        assign den_d   = den0;
        assign r_d     = r0;
        assign qn_d    = qn0;
        assign light_d = light_i;
      end else begin : g_div
        // t = 2r + NUM[i]; q[i] = (t >= den): one DW+2-bit subtraction, its sign the borrow.
        wire [DW:0]   t    = {g_step[s-1].r_q, g_step[s-1].qn_q[FW-1]};
        wire [DW+1:0] diff = {1'b0, t} - {2'b00, g_step[s-1].den_q};
        wire          q    = ~diff[DW+1];
        assign valid_d = g_step[s-1].valid_q;
        assign den_d   = g_step[s-1].den_q;
        assign r_d     = q ? diff[DW-1:0] : t[DW-1:0];       // < den either way: DW bits
        assign qn_d    = {g_step[s-1].qn_q[FW-2:0], q};
        assign light_d = g_step[s-1].light_q;
        wire unused_top = ^{t[DW], diff[DW]};                // 0 whenever selected (header)
      end
      shd_pipe_reg #(.Width(SW), .Enable(rank_after(s))) u_rank (
        .clk_i  (clk_i),
        .rst_ni (rst_ni),
        .valid_i(valid_d),
        .data_i ({den_d, r_d, qn_d, light_d}),
        .valid_o(valid_q),
        .data_o ({den_q, r_q, qn_q, light_q})
      );
    end
  endgenerate

  assign valid_o = g_step[STEPS].valid_q;
  assign f_o     = g_step[STEPS].qn_q;
  assign light_o = g_step[STEPS].light_q;
  wire unused_last = ^{g_step[STEPS].den_q, g_step[STEPS].r_q};  // after the last step

endmodule
