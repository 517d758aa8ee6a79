// tb_span_unit: replays a shadesim vector file (format: sim/vectors/vector_file.h, unit span) on
// rtl/shd_span_unit.v under Icarus Verilog, and compares every output on every cycle.
// Why:      the vector files hold the golden model's outputs cycle by cycle; the same files pass
//           under Verilator (`shadesim replay`), so the RTL means the same in both simulators.
// Run:      testbench/icarus/run_icarus.sh FILE does all of it; by hand:
//             iverilog -g2012 -Wall -I testbench/icarus -s tb_span_unit -Ptb_span_unit.<Name>=<value>... -o tb.vvp \
//               testbench/icarus/tb_span_unit.v rtl/shd_span_unit.v
//             vvp -n tb.vvp +vec=/abs/file.vec [+dump=/abs/wave.fst -fst]
//           The parameters are those of the configuration; the file's "# params" line must
//           repeat them (a file for another configuration fails).
// Records:  D (the descriptor ports, held until the next D) and C (one clock cycle); each line is
//           split into hex fields here, character by character, so a short or long record, a
//           non-hex token or a value wider than its port is reported as malformed input, never
//           read into the next record.
// Checks:   per cycle desc_ready_o, out_valid_o, out_lane_valid_o; out_tag_o when out_valid is
//           expected; out_x_o, out_y_o, out_attr_o of every lane expected valid (elsewhere they
//           mean nothing). !== compares, so an X is a mismatch. Prints the first 10 mismatches
//           (cycle, signal, both values) and ends with $fatal (exit status 1) on any mismatch or
//           malformed input, else prints the counts.
// Timing:   rst_ni low for two cycles (desc_valid_i 0, out_ready_i 1); then per C record: inputs
//           set while clk_i is low, outputs compared 1 time unit later (they are functions of
//           the registers), then the rising edge (sim/harness/span_dut.h does the same).
module tb_span_unit #(
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
) ();

  localparam integer L         = NumTri * LanesPerTri;
  localparam integer C         = CoordBits;
  localparam integer R         = RemBits;
  localparam integer A         = AttrBits;
  localparam integer K         = NumAttr;
  localparam integer NE        = NumTri * 3;
  localparam integer MAX_SHOWN = 10;

  reg                        clk_i        = 1'b0;
  reg                        rst_ni       = 1'b1;
  reg                        desc_valid_i = 1'b0;
  reg                        out_ready_i  = 1'b1;
  reg  [TagBits-1:0]         desc_tag_i       = {TagBits{1'b0}};
  reg  [C-1:0]               desc_row_first_i = {C{1'b0}};
  reg  [C-1:0]               desc_row_last_i  = {C{1'b0}};
  reg  [C-1:0]               desc_xref_i      = {C{1'b0}};
  reg  [K*A-1:0]             desc_iref_i      = {(K*A){1'b0}};
  reg  [K*A-1:0]             desc_didx_i      = {(K*A){1'b0}};
  reg  [K*A-1:0]             desc_didy_i      = {(K*A){1'b0}};
  reg                        desc_interleave_i = 1'b0;
  reg  [NumTri*C-1:0]        lt_row_first_i   = {(NumTri*C){1'b0}};
  reg  [NumTri*C-1:0]        lt_row_last_i    = {(NumTri*C){1'b0}};
  reg  [NumTri*C-1:0]        lt_clip_x0_i     = {(NumTri*C){1'b0}};
  reg  [NumTri*C-1:0]        lt_clip_x1_i     = {(NumTri*C){1'b0}};
  reg  [NumTri*C-1:0]        lt_ox_i          = {(NumTri*C){1'b0}};
  reg  [NumTri*C-1:0]        lt_oy_i          = {(NumTri*C){1'b0}};
  reg  [NumTri-1:0]          lt_flip_i        = {NumTri{1'b0}};
  reg  [NumTri*K*A-1:0]      lt_aoff_i        = {(NumTri*K*A){1'b0}};
  reg  [NE-1:0]              e_right_i        = {NE{1'b0}};
  reg  [NE*C-1:0]            e_row_first_i    = {(NE*C){1'b0}};
  reg  [NE*C-1:0]            e_row_last_i     = {(NE*C){1'b0}};
  reg  [NE*C-1:0]            e_q_i            = {(NE*C){1'b0}};
  reg  [NE*C-1:0]            e_k_i            = {(NE*C){1'b0}};
  reg  [NE*R-1:0]            e_r_i            = {(NE*R){1'b0}};
  reg  [NE*R-1:0]            e_div_i          = {(NE*R){1'b0}};
  reg  [NE*R-1:0]            e_m_i            = {(NE*R){1'b0}};
  wire                       desc_ready_o;
  wire                       out_valid_o;
  wire [TagBits-1:0]         out_tag_o;
  wire [L-1:0]               out_lane_valid_o;
  wire [L*PixBits-1:0]       out_x_o;
  wire [L*PixBits-1:0]       out_y_o;
  wire [L*K*A-1:0]           out_attr_o;

  shd_span_unit #(
    .NumTri(NumTri), .LanesPerTri(LanesPerTri), .AlignLanes(AlignLanes), .NumAttr(NumAttr),
    .AttrBits(AttrBits), .CoordBits(CoordBits), .RemBits(RemBits), .PixBits(PixBits), .TagBits(TagBits),
    .RowAhead(RowAhead), .Interleave(Interleave)
  ) dut (
    .clk_i(clk_i), .rst_ni(rst_ni),
    .desc_valid_i(desc_valid_i), .desc_ready_o(desc_ready_o), .desc_tag_i(desc_tag_i),
    .desc_row_first_i(desc_row_first_i), .desc_row_last_i(desc_row_last_i), .desc_xref_i(desc_xref_i),
    .desc_iref_i(desc_iref_i), .desc_didx_i(desc_didx_i), .desc_didy_i(desc_didy_i),
    .desc_interleave_i(desc_interleave_i),
    .lt_row_first_i(lt_row_first_i), .lt_row_last_i(lt_row_last_i), .lt_clip_x0_i(lt_clip_x0_i),
    .lt_clip_x1_i(lt_clip_x1_i), .lt_ox_i(lt_ox_i), .lt_oy_i(lt_oy_i), .lt_flip_i(lt_flip_i),
    .lt_aoff_i(lt_aoff_i), .e_right_i(e_right_i), .e_row_first_i(e_row_first_i),
    .e_row_last_i(e_row_last_i), .e_q_i(e_q_i), .e_k_i(e_k_i), .e_r_i(e_r_i), .e_div_i(e_div_i),
    .e_m_i(e_m_i),
    .out_valid_o(out_valid_o), .out_ready_i(out_ready_i), .out_tag_o(out_tag_o),
    .out_lane_valid_o(out_lane_valid_o), .out_x_o(out_x_o), .out_y_o(out_y_o), .out_attr_o(out_attr_o)
  );

  reg [8*1024-1:0] path;
  reg [8*1024-1:0] dump;
  reg [8*1024-1:0] line;
  integer fd, n, ch, lineno, cycle, descs, fragments, compared, mismatches, bad_cycles;
  integer j, s, a, l, e, digits;
  reg     cycle_bad, params_seen, pending, have_desc, done, dumping;
  reg [63:0] v, exp_mask, exp_tag, exp_dr, exp_ov;
  reg [8*40-1:0] signal;
  integer hp [0:11];

  // The file is read character by character ($fgetc): ch is the next unread one (-1 at the end),
  // so a record's fields are taken from its own line only.
  localparam integer EOF = -1;

  localparam TB_NAME = "tb_span_unit";
`include "tb_vectors.vh"

  function automatic is_blank(input integer c);
    is_blank = (c == " ") || (c == "\t") || (c == "\r");
  endfunction

  function automatic is_eol(input integer c);
    is_eol = (c == "\n") || (c == EOF);
  endfunction

  task automatic advance;
    ch = $fgetc(fd);
  endtask

  // The next whitespace-separated hex field of the record into v; it must fit `width` bits.
  task automatic next_field(input integer width, input [8*48-1:0] name);
    begin
      while (is_blank(ch)) advance;
      if (is_eol(ch)) begin
        $display("tb_span_unit: error: %0s, line %0d: the record ends before field %0s", path, lineno, name);
        $fatal(1);
      end
      v = 64'd0;
      digits = 0;
      while (!is_blank(ch) && !is_eol(ch)) begin
        if (ch >= "0" && ch <= "9")      v = {v[59:0], ch[3:0]};
        else if (ch >= "a" && ch <= "f") v = {v[59:0], ch[3:0] + 4'd9};
        else if (ch >= "A" && ch <= "F") v = {v[59:0], ch[3:0] + 4'd9};
        else begin
          $display("tb_span_unit: error: %0s, line %0d: field %0s: '%c' is not a hex digit", path, lineno, name,
                   ch[7:0]);
          $fatal(1);
        end
        digits = digits + 1;
        advance;
      end
      if (digits > 16 || (width < 64 && (v >> width) != 0)) begin
        $display("tb_span_unit: error: %0s, line %0d: field %0s does not fit its %0d-bit port", path, lineno, name,
                 width);
        $fatal(1);
      end
    end
  endtask

  // The rest of the record's line must be blank; consumes the line end.
  task automatic end_of_record;
    begin
      while (is_blank(ch)) advance;
      if (!is_eol(ch)) malformed("more fields than the record has");
      if (ch == "\n") begin
        lineno = lineno + 1;
        advance;
      end
    end
  endtask

  task automatic read_descriptor;
    begin
      next_field(TagBits, "tag");          desc_tag_i       = v[TagBits-1:0];
      next_field(C, "row_first");          desc_row_first_i = v[C-1:0];
      next_field(C, "row_last");           desc_row_last_i  = v[C-1:0];
      next_field(C, "xref");               desc_xref_i      = v[C-1:0];
      for (a = 0; a < K; a = a + 1) begin
        next_field(A, "iref");             desc_iref_i[a*A +: A] = v[A-1:0];
        next_field(A, "didx");             desc_didx_i[a*A +: A] = v[A-1:0];
        next_field(A, "didy");             desc_didy_i[a*A +: A] = v[A-1:0];
      end
      next_field(1, "interleave");         desc_interleave_i = v[0];
      for (j = 0; j < NumTri; j = j + 1) begin
        next_field(C, "lt row_first");     lt_row_first_i[j*C +: C] = v[C-1:0];
        next_field(C, "lt row_last");      lt_row_last_i[j*C +: C]  = v[C-1:0];
        next_field(C, "lt clip_x0");       lt_clip_x0_i[j*C +: C]   = v[C-1:0];
        next_field(C, "lt clip_x1");       lt_clip_x1_i[j*C +: C]   = v[C-1:0];
        next_field(C, "lt ox");            lt_ox_i[j*C +: C]        = v[C-1:0];
        next_field(C, "lt oy");            lt_oy_i[j*C +: C]        = v[C-1:0];
        next_field(1, "lt flip");          lt_flip_i[j]             = v[0];
        for (a = 0; a < K; a = a + 1) begin
          next_field(A, "lt aoff");        lt_aoff_i[(j*K+a)*A +: A] = v[A-1:0];
        end
        for (s = 0; s < 3; s = s + 1) begin
          e = j*3 + s;
          next_field(1, "edge right");     e_right_i[e]             = v[0];
          next_field(C, "edge row_first"); e_row_first_i[e*C +: C]  = v[C-1:0];
          next_field(C, "edge row_last");  e_row_last_i[e*C +: C]   = v[C-1:0];
          next_field(C, "edge q");         e_q_i[e*C +: C]          = v[C-1:0];
          next_field(R, "edge r");         e_r_i[e*R +: R]          = v[R-1:0];
          next_field(R, "edge div");       e_div_i[e*R +: R]        = v[R-1:0];
          next_field(C, "edge k");         e_k_i[e*C +: C]          = v[C-1:0];
          next_field(R, "edge m");         e_m_i[e*R +: R]          = v[R-1:0];
        end
      end
      end_of_record;
    end
  endtask

  task automatic run_cycle;
    begin
      next_field(1, "desc_valid");         desc_valid_i = v[0];
      next_field(1, "out_ready");          out_ready_i  = v[0];
      next_field(1, "exp_desc_ready");     exp_dr   = v;
      next_field(1, "exp_out_valid");      exp_ov   = v;
      next_field(TagBits, "exp_tag");      exp_tag  = v;
      next_field(L, "exp_lane_valid");     exp_mask = v;
      if ((exp_mask != 0) != exp_ov[0]) malformed("exp_out_valid is not the OR of exp_lane_valid");
      if (desc_valid_i && !have_desc) malformed("desc_valid is 1 before any D record");
      cycle = cycle + 1;
      cycle_bad = 1'b0;
      #1;
      check("desc_ready_o", exp_dr, {63'd0, desc_ready_o});
      check("out_valid_o", exp_ov, {63'd0, out_valid_o});
      if (exp_ov[0]) check("out_tag_o", exp_tag, {{(64-TagBits){1'b0}}, out_tag_o});
      check("out_lane_valid_o", exp_mask, {{(64-L){1'b0}}, out_lane_valid_o});
      for (l = 0; l < L; l = l + 1)
        if (exp_mask[l]) begin
          fragments = fragments + 1;
          next_field(PixBits, "x");
          $sformat(signal, "out_x_o[lane %0d]", l);
          check(signal, v, {{(64-PixBits){1'b0}}, out_x_o[l*PixBits +: PixBits]});
          next_field(PixBits, "y");
          $sformat(signal, "out_y_o[lane %0d]", l);
          check(signal, v, {{(64-PixBits){1'b0}}, out_y_o[l*PixBits +: PixBits]});
          for (a = 0; a < K; a = a + 1) begin
            next_field(A, "attr");
            $sformat(signal, "out_attr_o[lane %0d attr %0d]", l, a);
            check(signal, v, {{(64-A){1'b0}}, out_attr_o[(l*K+a)*A +: A]});
          end
        end
      end_of_record;
      pending = desc_valid_i && !exp_dr[0];
      #4 clk_i = 1'b1;
      #5 clk_i = 1'b0;
    end
  endtask

  initial begin
    open_vectors(dumping);
    if (dumping) $dumpvars(0, tb_span_unit);
    lineno = 0; cycle = 0; descs = 0; fragments = 0; compared = 0; mismatches = 0; bad_cycles = 0;
    params_seen = 1'b0; pending = 1'b0; have_desc = 1'b0;

    // Reset: rst_ni low for two cycles, desc_valid_i 0, out_ready_i 1.
    #1 rst_ni = 1'b0;
    #4 clk_i = 1'b1;
    #5 clk_i = 1'b0;
    #5 clk_i = 1'b1;
    #5 clk_i = 1'b0;
    rst_ni = 1'b1;

    lineno = 1;
    done = 1'b0;
    advance;
    while (!done) begin
      if (ch == EOF) begin
        done = 1'b1;
      end else if (ch == "#") begin
        // A header or comment line: the rest of it at once.
        line = 0;
        n = $fgets(line, fd);
        for (a = 0; a < 12; a = a + 1) hp[a] = 32'bx;
        if ($sscanf(line, " params %d %d %d %d %d %d %d %d %d %d %d %d", hp[0], hp[1], hp[2], hp[3], hp[4], hp[5],
                    hp[6], hp[7], hp[8], hp[9], hp[10], hp[11]) >= 1) begin
          if (hp[0] !== NumTri || hp[1] !== LanesPerTri || hp[2] !== AlignLanes || hp[3] !== NumAttr ||
              hp[4] !== AttrBits || hp[5] !== CoordBits || hp[6] !== RemBits || hp[7] !== PixBits ||
              hp[8] !== TagBits || hp[9] !== RowAhead || hp[10] !== Interleave ||
              hp[11] !== 32'bx) begin
            if (line[7:0] == "\n") line = line >> 8;
            $display("tb_span_unit: error: %0s, line %0d: '#%0s' differs from the parameters compiled in:", path, lineno, line);
            $display("  # params %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d (NumTri LanesPerTri AlignLanes NumAttr AttrBits CoordBits RemBits PixBits TagBits RowAhead Interleave)",
                     NumTri, LanesPerTri, AlignLanes, NumAttr, AttrBits, CoordBits, RemBits, PixBits, TagBits, RowAhead, Interleave);
            $fatal(1);
          end
          params_seen = 1'b1;
        end
        if (n > 0 && line[7:0] != "\n" && !$feof(fd)) malformed("comment line longer than 1024 characters");
        lineno = lineno + 1;
        advance;
      end else if (ch == "D" || ch == "C") begin
        if (!params_seen) malformed("a record before the '# params' header line");
        if (ch == "D") begin
          advance;
          if (!is_blank(ch)) malformed("a record letter not followed by a space");
          if (pending) malformed("a D record while the previous descriptor is offered and not accepted");
          read_descriptor;
          have_desc = 1'b1;
          descs = descs + 1;
        end else begin
          advance;
          if (!is_blank(ch)) malformed("a record letter not followed by a space");
          run_cycle;
        end
      end else if (is_blank(ch) || ch == "\n") begin
        // A blank line (or trailing blanks).
        if (ch == "\n") lineno = lineno + 1;
        advance;
      end else begin
        malformed("unknown record (D, C or a # comment expected)");
      end
    end
    fail_on_mismatches("no C records (cycles)");
    $display("tb_span_unit: PASS %0s: %0d cycles, %0d descriptors, %0d valid lane outputs, %0d output values compared, 0 mismatches",
             path, cycle, descs, fragments, compared);
    $finish;
  end

endmodule
