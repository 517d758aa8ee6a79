// shd_spec_unit: specular term ks*L * f(N.H), f from a PROM indexed by the shininess code (paper
// Fig. 11), by one of five datapaths chosen by the parameter Kind; ports and back end are common.
// Why:      Kind 0, poly (rtl/shd_spec_poly.v, the paper's device): f(c) = a*(c^2 - c) + c =
//           a c^2 + (1-a) c needs two multipliers and no pow; a(n) comes from the PROM. Degree 3 is
//           the same structure with a Horner step: f = c + (c^2 - c)*(u*c + v), u = a1,
//           v = a1 + b1, and a cut-off code.
//           Kind 1, table: f = c^n read from the PROM at {shininess code, top T = TableBits bits of
//           c}: no arithmetic before MUL3..MUL5, but 2^T PROM words per shininess code.
//           Kind 2, schlick (rtl/shd_spec_schlick.v): Schlick's rational c / (n - n c + c) =
//           c / ((n-1)(1-c) + 1), m = n - 1 from the PROM, one multiplier and a restoring divider.
//           Kind 3, explog (rtl/shd_spec_explog.v): the exact power c^n = 2^(-n L), L = -log2 c,
//           n from the PROM, by two fixed interpolated tables (log and exp, 2^T words each, in
//           block RAM) and three multipliers: no fit and no per-n table.
//           Kind 4, piecewise (rtl/shd_spec_piecewise.v): S = Segments polynomials of degree
//           d = Degree in u = (c - B_s) 2^e / 2^Wc, the PROM word holding the segments' first
//           codes B_j (B_0 the cut), a segment ROM (<RomFile>.seg) each segment's scale e and
//           coefficients: d Horner multiply-adds, small coefficients even for large n.
//           Every kind ends in the same stage D (MUL3..MUL5) and output registers.
// Latency:  2 + PipeStages cycles valid_i -> valid_o; one result per cycle, no stalls.
//           Cycle 1: RG1..RG5 (the PROM's address register is RG1; Kind 3 adds its own cycle-1
//           registers and the log ROM's read register in shd_spec_explog). Optional registers:
//           Kind 0 (PipeStages 0..3): enabled in this order as PipeStages grows: B after
//             MUL2+rounding, A after Sm1 (and Horner), C after Sm2+clamp.
//           Kind 1 (PipeStages 0..1): T between the PROM output and stage D.
//           Kind 2 (PipeStages 0..Wf+1): that many ranks spread evenly over the Wf+1 divider steps
//             (rank j after step floor(j*(Wf+1)/(PipeStages+1)), step 0 being the den multiply).
//           Kind 3 (PipeStages 1..3): X, the exp ROM's read register, always; then A after
//             P = DN*G (PipeStages >= 2), C after the rounding of f (PipeStages = 3).
//           Kind 4 (PipeStages 1..d+1): S, the segment ROM's read register, always (addressed
//             in cycle 1 by {shin, s}, shin registered in shd_spec_piecewise); then rank r after
//             Horner step r, r = 1..PipeStages-1.
//           Output registers load only while their stage is valid, so the outputs hold the last
//           result; valid and outputs reset to 0 (rst_ni, asynchronous).
// Formats:  cos_i uQ1.Wc (codes above 1.0 saturate to 1.0: an upstream N.H may overshoot);
//           PROM word: Kind 0 the coefficient uQCi.Cf (degree 2) or {cut-off uQ1.Wc, v, u} in
//           sQCi.Cf (degree 3); Kind 1 f itself, uQ1.Wf; Kind 2 m = n - 1, uQCi.Cf (unsigned; the
//           padding words are 0, giving f = c); Kind 3 n itself, uQCi.Cf (unsigned; the padding
//           words are 0, giving f = 1 for c > 0); Kind 4 {B_S-1, .., B_0}, uQ1.Wc codes (the
//           segment ROM word {K_d, .., K_0, e}: K_j sQCi.Cf, e unsigned). spec_o = f in uQ1.Wf,
//           in [0, 1]; light_*_i and spec_*_o unorm LightBits (code/(2^LightBits-1)),
//           spec_x = round(f*L_x).
// Widths:   PROM address: ShinBits; Kind 1 ShinBits + T, {shin_i, idx} with
//           idx = min(c >> (Wc - T), 2^T - 1) (c >> (Wc - T) <= 2^T, equal only for c = 1.0), formed
//           from the input ports so that the PROM's address register is the cycle-1 register.
//           PROM word: Kind 0 KW = Ci + Cf (degree 2) or 2*KW + Wc + 1 (degree 3); Kind 1 Wf + 1;
//           Kind 2 and 3 KW; Kind 4 S*(Wc + 1) (its segment ROM: address ShinBits + log2 S,
//           word clog2(Wc + 1) + (d+1)*KW). The datapaths' widths are derived in their files
//           (Kind 0: c^2 - c in [-1/4, 0] gives dt Df-1 bits, MUL2 KW+DTW or DTW+GTW bits signed,
//           g KW+Wc+1 bits; Kind 2: den KW+Wc+1 bits, f <= 1; Kind 3: the table words, L <= Wc,
//           y, f <= 1; Kind 4: acc KW+3 bits signed, its products (KW+3) x (Wc+2) signed).
//           Kind 3 takes c from c_d (cycle 0): its log ROM's address register is a cycle-1
//           register, as the table kind's PROM address is. Stage D: f <= 1, so
//           f*L_x <= L_x * 2^Wf and the rounded result fits LightBits (see there).
// Rounding: Kind 0: Trunc (floor) of c^2 - c to Df bits and of g to Hf bits; RoundHalfUp of the
//           MUL2 product to Wf bits; Sm2 saturates f to [0, 1] (degree 2: only the lower clamp can
//           act). Kind 1: none in the unit (the table words are f as `shadesim prom` rounded them).
//           Kind 2: Trunc (floor) of the quotient to Wf bits. Kind 3: table words rounded half
//           up; Trunc (floor) of both interpolations, of L and of y's fraction; RoundHalfUp of f
//           to Wf bits. Kind 4: Trunc (floor) of each Horner product to Cf fraction bits;
//           RoundHalfUp of f to Wf bits, saturated to [0, 1]. All: RoundHalfUp of MUL3..MUL5 to
//           integers.
// Checks:   a Kind outside 0..4, a Degree other than 2 or 3 (Kind 0) or outside 1..3 (Kind 4),
//           PipeStages outside its kind's range, TableBits outside 1..Wc (Kind 1) or
//           1..min(Wc, Wf+3) (Kind 3), Kind 3's log-table fraction bits GF = Wf + 6 +
//           max(0, Ci - Wc - 4) above 56 (its tables are 60-bit fixed point), or for Kind 4
//           Segments not 1, 2 or 4, Cf < Wf, or a PROM word (S*(Wc+1)) or segment ROM word
//           (clog2(Wc+1) + (d+1)*KW) above 128 bits instantiate the module
//           shd_spec_unit_bad_parameter, which does not exist: every tool stops at elaboration.
// Model:    model/device/spec_unit.h SpecUnitModel, bit-exact and cycle-accurate.
module shd_spec_unit #(
  parameter integer Degree         = 2,
  parameter integer CosFracBits    = 15,
  parameter integer ShinBits       = 10,
  parameter integer CoefIntBits    = 10,
  parameter integer CoefFracBits   = 14,
  parameter integer DiffFracBits   = 28,
  parameter integer HornerFracBits = 14,
  parameter integer SpecFracBits   = 16,
  parameter integer LightBits      = 8,
  parameter integer PipeStages     = 1,
  parameter integer Kind           = 0,
  parameter integer TableBits      = 8,
  parameter integer Segments       = 1,
  parameter         RomFile        = ""
) (
  input  wire                 clk_i,
  input  wire                 rst_ni,
  input  wire                 valid_i,
  input  wire [ShinBits-1:0]  shin_i,
  input  wire [CosFracBits:0] cos_i,
  input  wire [LightBits-1:0] light_r_i,
  input  wire [LightBits-1:0] light_g_i,
  input  wire [LightBits-1:0] light_b_i,
  output wire                 valid_o,
  output wire [SpecFracBits:0] spec_o,
  output wire [LightBits-1:0] spec_r_o,
  output wire [LightBits-1:0] spec_g_o,
  output wire [LightBits-1:0] spec_b_o
);

  localparam integer WC    = CosFracBits;
  localparam integer CW    = WC + 1;                        // c, uQ1.Wc
  localparam integer KW    = CoefIntBits + CoefFracBits;     // one coefficient
  localparam integer WF    = SpecFracBits;
  localparam integer FW    = WF + 1;                         // f, uQ1.Wf
  localparam integer LW    = 3 * LightBits;
  localparam integer AB    = (Kind == 1) ? ShinBits + TableBits : ShinBits;  // PROM address
  localparam integer WORD  = (Kind == 1) ? FW                                // PROM word
                           : (Kind == 2 || Kind == 3) ? KW
                           : (Kind == 4) ? Segments * CW
                           : (Degree == 2) ? KW : 2 * KW + CW;
  localparam integer PMIN  = (Kind == 3 || Kind == 4) ? 1 : 0;              // PipeStages range
  localparam integer PMAX  = (Kind == 1) ? 1 : (Kind == 2) ? WF + 1
                           : (Kind == 4) ? Degree + 1 : 3;
  localparam integer XGF   = WF + 6 + ((CoefIntBits > WC + 4) ? CoefIntBits - WC - 4 : 0);
  localparam integer PSEGW = $clog2(WC + 1) + (Degree + 1) * KW;          // Kind 4 segment ROM
  localparam [CW-1:0] COS_ONE = {1'b1, {WC{1'b0}}};

  generate
    if (Kind < 0 || Kind > 4 || PipeStages < PMIN || PipeStages > PMAX ||
        (Kind == 0 && Degree != 2 && Degree != 3) ||
        (Kind == 1 && (TableBits < 1 || TableBits > CosFracBits)) ||
        (Kind == 3 && (TableBits < 1 || TableBits > CosFracBits || TableBits > WF + 3 ||
                       XGF > 56)) ||
        (Kind == 4 && (Degree < 1 || Degree > 3 ||
                       (Segments != 1 && Segments != 2 && Segments != 4) ||
                       CoefFracBits < SpecFracBits || Segments * CW > 128 || PSEGW > 128)))
    begin : g_bad_parameter
      shd_spec_unit_bad_parameter u_bad ();   // no such module: see Checks in the header
    end
  endgenerate

  // ---------------------------------------------------------------- cycle 1: RG1..RG5, PROM
  wire [CW-1:0]   c_d = (cos_i > COS_ONE) ? COS_ONE : cos_i;
  reg  [CW-1:0]   c_q1;
  reg  [LW-1:0]   light_q1;
  reg             valid_q1;
  wire [AB-1:0]   rom_addr;
  wire [WORD-1:0] word_q1;

  generate
    if (Kind == 1) begin : g_table_addr
      localparam integer TB = TableBits;
      localparam [CW-1:0] IDX_MAX = {{(CW-TB){1'b0}}, {TB{1'b1}}};  // 2^T - 1
      wire [CW-1:0] c_sh = c_d >> (WC - TB);                       // <= 2^T (c = 1.0 only)
      wire [CW-1:0] idx  = (c_sh > IDX_MAX) ? IDX_MAX : c_sh;
      assign rom_addr = {shin_i, idx[TB-1:0]};
      wire unused_idx = ^idx[CW-1:TB];
    end else begin : g_shin_addr
      assign rom_addr = shin_i;
    end
  endgenerate

  shd_coef_rom #(
    .AddrBits(AB),
    .WordBits(WORD),
    .RomFile (RomFile)
  ) u_rom (
    .clk_i (clk_i),
    .addr_i(rom_addr),
    .word_o(word_q1)
  );

  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) valid_q1 <= 1'b0;
    else         valid_q1 <= valid_i;
  end
  always @(posedge clk_i) begin
    c_q1     <= c_d;
    light_q1 <= {light_b_i, light_g_i, light_r_i};
  end

  // ---------------------------------------------------------------- the datapath of the kind
  // From the cycle-1 registers to f (uQ1.Wf) with its valid and the light side-band.
  wire          valid_c;
  wire [FW-1:0] f_cr;
  wire [LW-1:0] light_c;
  generate
    if (Kind == 1) begin : g_table
      // Optional register T (PipeStages = 1).
      shd_pipe_reg #(.Width(FW + LW), .Enable((PipeStages >= 1) ? 1 : 0)) u_pipe_t (
        .clk_i  (clk_i),
        .rst_ni (rst_ni),
        .valid_i(valid_q1),
        .data_i ({word_q1, light_q1}),
        .valid_o(valid_c),
        .data_o ({f_cr, light_c})
      );
      wire unused_c = ^c_q1;                 // the table was addressed with c already
    end else if (Kind == 4) begin : g_piecewise
      shd_spec_piecewise #(
        .Degree      (Degree),
        .Segments    (Segments),
        .CosFracBits (CosFracBits),
        .ShinBits    (ShinBits),
        .CoefIntBits (CoefIntBits),
        .CoefFracBits(CoefFracBits),
        .SpecFracBits(SpecFracBits),
        .LightBits   (LightBits),
        .PipeStages  (PipeStages),
        .RomFile     (RomFile)
      ) u_piecewise (
        .clk_i   (clk_i),
        .rst_ni  (rst_ni),
        .shin_i  (shin_i),
        .valid_q1(valid_q1),
        .c_i     (c_q1),
        .bounds_i(word_q1),
        .light_i (light_q1),
        .valid_o (valid_c),
        .f_o     (f_cr),
        .light_o (light_c)
      );
    end else if (Kind == 3) begin : g_explog
      shd_spec_explog #(
        .CosFracBits (CosFracBits),
        .CoefIntBits (CoefIntBits),
        .CoefFracBits(CoefFracBits),
        .SpecFracBits(SpecFracBits),
        .LightBits   (LightBits),
        .TableBits   (TableBits),
        .PipeStages  (PipeStages)
      ) u_explog (
        .clk_i   (clk_i),
        .rst_ni  (rst_ni),
        .c_i     (c_d),
        .valid_q1(valid_q1),
        .n_i     (word_q1),
        .light_i (light_q1),
        .valid_o (valid_c),
        .f_o     (f_cr),
        .light_o (light_c)
      );
      wire unused_c = ^c_q1;                 // the log ROM was addressed with c already
    end else if (Kind == 2) begin : g_schlick
      shd_spec_schlick #(
        .CosFracBits (CosFracBits),
        .CoefIntBits (CoefIntBits),
        .CoefFracBits(CoefFracBits),
        .SpecFracBits(SpecFracBits),
        .LightBits   (LightBits),
        .PipeStages  (PipeStages)
      ) u_schlick (
        .clk_i  (clk_i),
        .rst_ni (rst_ni),
        .valid_i(valid_q1),
        .c_i    (c_q1),
        .m_i    (word_q1),
        .light_i(light_q1),
        .valid_o(valid_c),
        .f_o    (f_cr),
        .light_o(light_c)
      );
    end else begin : g_poly
      shd_spec_poly #(
        .Degree        (Degree),
        .CosFracBits   (CosFracBits),
        .CoefIntBits   (CoefIntBits),
        .CoefFracBits  (CoefFracBits),
        .DiffFracBits  (DiffFracBits),
        .HornerFracBits(HornerFracBits),
        .SpecFracBits  (SpecFracBits),
        .LightBits     (LightBits),
        .PipeStages    (PipeStages)
      ) u_poly (
        .clk_i  (clk_i),
        .rst_ni (rst_ni),
        .valid_i(valid_q1),
        .c_i    (c_q1),
        .word_i (word_q1),
        .light_i(light_q1),
        .valid_o(valid_c),
        .f_o    (f_cr),
        .light_o(light_c)
      );
    end
  endgenerate

  // ---------------------------------------------------------------- D: MUL3..MUL5, round
  // spec_x = round_half_up(f * L_x / 2^Wf); f <= 1 gives a result <= L_x, so LightBits hold
  // it and bit Wf+LightBits of the sum is always 0.
  localparam integer XW = FW + LightBits;
  wire [LW-1:0] rgb_d;
  genvar k;
  generate
    for (k = 0; k < 3; k = k + 1) begin : g_chan
      wire [LightBits-1:0] l_k   = light_c[k*LightBits +: LightBits];
      wire [XW-1:0]        x_k   = {{LightBits{1'b0}}, f_cr} * {{FW{1'b0}}, l_k};  // MUL3..5
      wire [XW-1:0]        x_rnd = x_k + ({{(XW-1){1'b0}}, 1'b1} << (WF - 1));
      assign rgb_d[k*LightBits +: LightBits] = x_rnd[WF +: LightBits];
      wire unused_x = ^{x_rnd[XW-1], x_rnd[WF-1:0]};
    end
  endgenerate

  // ---------------------------------------------------------------- output registers
  reg          valid_q;
  reg [FW-1:0] spec_q;
  reg [LW-1:0] rgb_q;
  always @(posedge clk_i or negedge rst_ni) begin
    if (!rst_ni) begin
      valid_q <= 1'b0;
      spec_q  <= {FW{1'b0}};
      rgb_q   <= {LW{1'b0}};
    end else begin
      valid_q <= valid_c;
      if (valid_c) begin
        spec_q <= f_cr;
        rgb_q  <= rgb_d;
      end
    end
  end

  assign valid_o  = valid_q;
  assign spec_o   = spec_q;
  assign spec_r_o = rgb_q[0*LightBits +: LightBits];
  assign spec_g_o = rgb_q[1*LightBits +: LightBits];
  assign spec_b_o = rgb_q[2*LightBits +: LightBits];

endmodule
