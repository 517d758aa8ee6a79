// tb_spec_unit: replays a shadesim vector file (format: sim/vectors/vector_file.h, unit spec) on
// rtl/shd_spec_unit.v under Icarus Verilog, and compares every output on every cycle.
// Why:      the vector files hold the golden model's outputs cycle by cycle; the same files pass
//           under Verilator (`shadesim replay`), so the RTL means the same in both simulators.
// Run:      testbench/icarus/run_icarus.sh FILE does all of it; by hand:
//             iverilog -g2012 -Wall -I testbench/icarus -s tb_spec_unit -Ptb_spec_unit.<Name>=<value>... -o tb.vvp \
//               testbench/icarus/tb_spec_unit.v rtl/shd_spec_unit.v rtl/shd_spec_poly.v rtl/shd_spec_schlick.v \
//               rtl/shd_spec_explog.v rtl/shd_spec_piecewise.v \
//               rtl/shd_coef_rom.v rtl/shd_pipe_reg.v
//             vvp -n tb.vvp +vec=/abs/file.vec +prom=/abs/prom.hex [+dump=/abs/wave.fst -fst]
//           (Kind 4, piecewise: its segment ROM loads from /abs/prom.hex.seg beside the PROM)
//           Paths must be absolute: $readmemh (and $fopen) resolve a relative path against the
//           simulator's current directory, not the vector file's, and a PROM file $readmemh cannot
//           find is only a warning.
//           Parameters: those of the configuration, which the file's "# params" line must repeat
//           (a file for another configuration fails).
// Checks:   every PROM word loaded (no X: $readmemh only warns on a missing or short file);
//           per cycle valid_o, spec_o, spec_r_o, spec_g_o, spec_b_o with !== (an X is a
//           mismatch). Prints the first 10 mismatches (cycle, signal, both values), ends with
//           $fatal (exit status 1) on any mismatch or malformed input, else prints the counts.
// Timing:   rst_ni low for two cycles with valid_i low; then per line: inputs set while clk_i is
//           low, rising edge, outputs compared 1 time unit later (sim/harness/spec_dut.h does the same).
module tb_spec_unit #(
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
  parameter integer Segments       = 1
) ();

  // The PROM's depth: 2^ShinBits words, 2^(ShinBits+TableBits) for the table (Kind 1); the
  // segment ROM's (Kind 4): 2^ShinBits words per segment.
  localparam integer DEPTH     = 1 << (ShinBits + ((Kind == 1) ? TableBits : 0));
  localparam integer SEG_DEPTH = (Kind == 4) ? (1 << ShinBits) * Segments : 0;
  localparam integer MAX_SHOWN = 10;

  reg                   clk_i   = 1'b0;
  reg                   rst_ni  = 1'b1;
  reg                   valid_i = 1'b0;
  reg  [ShinBits-1:0]   shin_i  = {ShinBits{1'b0}};
  reg  [CosFracBits:0]  cos_i   = {(CosFracBits+1){1'b0}};
  reg  [LightBits-1:0]  light_r_i = {LightBits{1'b0}};
  reg  [LightBits-1:0]  light_g_i = {LightBits{1'b0}};
  reg  [LightBits-1:0]  light_b_i = {LightBits{1'b0}};
  wire                  valid_o;
  wire [SpecFracBits:0] spec_o;
  wire [LightBits-1:0]  spec_r_o;
  wire [LightBits-1:0]  spec_g_o;
  wire [LightBits-1:0]  spec_b_o;

  shd_spec_unit #(
    .Degree(Degree), .CosFracBits(CosFracBits), .ShinBits(ShinBits), .CoefIntBits(CoefIntBits),
    .CoefFracBits(CoefFracBits), .DiffFracBits(DiffFracBits), .HornerFracBits(HornerFracBits),
    .SpecFracBits(SpecFracBits), .LightBits(LightBits), .PipeStages(PipeStages), .Kind(Kind),
    .TableBits(TableBits), .Segments(Segments)
  ) dut (
    .clk_i(clk_i), .rst_ni(rst_ni), .valid_i(valid_i), .shin_i(shin_i), .cos_i(cos_i),
    .light_r_i(light_r_i), .light_g_i(light_g_i), .light_b_i(light_b_i), .valid_o(valid_o),
    .spec_o(spec_o), .spec_r_o(spec_r_o), .spec_g_o(spec_g_o), .spec_b_o(spec_b_o)
  );

  reg [8*1024-1:0] path;
  reg [8*1024-1:0] dump;
  // A line: 1024 characters, as tb_span_unit.v (the longest the writers make is the "# config"
  // line, about 220). Every $fgets and $sscanf reads the whole register bit by bit, so its width
  // is the simulation's cost: at 4096 characters a 20,000-cycle file took 4.6-5.5 s, at 1024
  // 2.4 s, at 512 no less.
  reg [8*1024-1:0] line;
  integer fd, n, i, lineno, cycle, results, compared, mismatches, bad_cycles;
  reg     cycle_bad;
  reg     params_seen;
  reg     dumping;
  integer hp [0:13];   // one more than the 13 parameters: a 14th number makes the line differ
  reg [63:0] f [0:11];   // one more than the 11 columns: a 12th field makes the line malformed

  task automatic clock;
    begin
      #5 clk_i = 1'b1;
      #5 clk_i = 1'b0;
    end
  endtask

  localparam TB_NAME = "tb_spec_unit";
`include "tb_vectors.vh"

  // The segment ROM (Kind 4), during reset: $readmemh of <prom>.seg ran at time 0.
  generate
    if (Kind == 4) begin : g_seg_rom_check
      integer k;
      initial begin
        #2;
        for (k = 0; k < SEG_DEPTH; k = k + 1)
          if (^dut.g_piecewise.u_piecewise.u_seg_rom.rom[k] === 1'bx) begin
            $display("tb_spec_unit: error: segment ROM word %0d is X after $readmemh: the +prom file's .seg is missing, short or corrupt", k);
            $fatal(1);
          end
      end
    end
  endgenerate

  // A column of `width` bits: hex without X or Z digits, no bit at or above the width.
  task automatic field(input integer k, input integer width, input [8*16-1:0] name);
    begin
      if ((^f[k] === 1'bx) || (width < 64 && (f[k] >> width) != 0)) begin
        $display("tb_spec_unit: error: %0s, line %0d: column %0s = %0h is not a %0d-bit hex value", path, lineno,
                 name, f[k], width);
        $fatal(1);
      end
    end
  endtask

  initial begin
    open_vectors(dumping);
    if (dumping) $dumpvars(0, tb_spec_unit);
    lineno = 0; cycle = 0; results = 0; compared = 0; mismatches = 0; bad_cycles = 0;
    params_seen = 1'b0;

    // Reset: rst_ni low for two cycles, valid_i low.
    #1 rst_ni = 1'b0;
    clock;
    clock;
    rst_ni = 1'b1;

    // The PROM: $readmemh ran at time 0; a missing, short or corrupt file leaves X words.
    for (i = 0; i < DEPTH; i = i + 1)
      if (^dut.u_rom.rom[i] === 1'bx) begin
        $display("tb_spec_unit: error: PROM word %0d is X after $readmemh: the +prom file is missing, short or corrupt", i);
        $fatal(1);
      end

    while (!$feof(fd)) begin
      line = 0;
      n = $fgets(line, fd);
      if (n > 0) begin
        lineno = lineno + 1;
        if (line[7:0] != "\n" && !$feof(fd)) malformed("line longer than 1024 characters");
        if (line[8*n-1 -: 8] == "#") begin
          for (i = 0; i < 14; i = i + 1) hp[i] = 32'bx;
          if ($sscanf(line, "# params %d %d %d %d %d %d %d %d %d %d %d %d %d %d", hp[0], hp[1], hp[2], hp[3], hp[4],
                      hp[5], hp[6], hp[7], hp[8], hp[9], hp[10], hp[11], hp[12], hp[13]) >= 1) begin
            if (hp[0] !== Degree || hp[1] !== CosFracBits || hp[2] !== ShinBits || hp[3] !== CoefIntBits ||
                hp[4] !== CoefFracBits || hp[5] !== DiffFracBits || hp[6] !== HornerFracBits ||
                hp[7] !== SpecFracBits || hp[8] !== LightBits || hp[9] !== PipeStages || hp[10] !== Kind ||
                hp[11] !== TableBits || hp[12] !== Segments || hp[13] !== 32'bx) begin
              if (line[7:0] == "\n") line = line >> 8;
              $display("tb_spec_unit: error: %0s, line %0d: '%0s' differs from the parameters compiled in:", path, lineno, line);
              $display("  # params %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d %0d (%0s)",
                       Degree, CosFracBits, ShinBits, CoefIntBits, CoefFracBits, DiffFracBits, HornerFracBits,
                       SpecFracBits, LightBits, PipeStages, Kind, TableBits, Segments,
                       {"Degree CosFracBits ShinBits CoefIntBits CoefFracBits DiffFracBits HornerFracBits ",
                        "SpecFracBits LightBits PipeStages Kind TableBits Segments"});
              $fatal(1);
            end
            params_seen = 1'b1;
          end
        end else if (line[8*n-1 -: 8] != "\n" && line[8*n-1 -: 8] != "\r") begin
          if (!params_seen) malformed("a cycle line before the '# params' header line");
          for (i = 0; i < 12; i = i + 1) f[i] = 64'bx;
          if ($sscanf(line, "%h %h %h %h %h %h %h %h %h %h %h %h", f[0], f[1], f[2], f[3], f[4], f[5], f[6], f[7],
                      f[8], f[9], f[10], f[11]) != 11)
            malformed("not 11 hex columns (valid shin cos light_r light_g light_b exp_valid exp_spec exp_r exp_g exp_b)");
          field(0, 1, "valid");
          field(1, ShinBits, "shin");
          field(2, CosFracBits + 1, "cos");
          field(3, LightBits, "light_r");
          field(4, LightBits, "light_g");
          field(5, LightBits, "light_b");
          field(6, 1, "exp_valid");
          field(7, SpecFracBits + 1, "exp_spec");
          field(8, LightBits, "exp_r");
          field(9, LightBits, "exp_g");
          field(10, LightBits, "exp_b");
          cycle = cycle + 1;
          cycle_bad = 1'b0;
          valid_i   = f[0][0];
          shin_i    = f[1][ShinBits-1:0];
          cos_i     = f[2][CosFracBits:0];
          light_r_i = f[3][LightBits-1:0];
          light_g_i = f[4][LightBits-1:0];
          light_b_i = f[5][LightBits-1:0];
          #5 clk_i = 1'b1;
          #1;
          check("valid_o", f[6], {63'd0, valid_o});
          check("spec_o", f[7], {{(63-SpecFracBits){1'b0}}, spec_o});
          check("spec_r_o", f[8], {{(64-LightBits){1'b0}}, spec_r_o});
          check("spec_g_o", f[9], {{(64-LightBits){1'b0}}, spec_g_o});
          check("spec_b_o", f[10], {{(64-LightBits){1'b0}}, spec_b_o});
          if (f[6][0]) results = results + 1;
          #4 clk_i = 1'b0;
        end
      end
    end
    fail_on_mismatches("no cycle lines");
    $display("tb_spec_unit: PASS %0s: %0d cycles, %0d valid results, %0d output values compared, 0 mismatches",
             path, cycle, results, compared);
    $finish;
  end

endmodule
