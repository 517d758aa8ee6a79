// The parts of the Icarus vector-file testbenches (tb_spec_unit.v, tb_span_unit.v) that do not
// depend on the unit, `include-d inside each module. The module declares TB_NAME (its name, for
// messages) and the variables used here: fd, path, dump, lineno, cycle, compared, mismatches,
// bad_cycles, cycle_bad, and MAX_SHOWN. TB_NAME must be an untyped localparam: Icarus 11 prints a
// sized string parameter ([8*16-1:0]) as an empty string.

  // Malformed input: the file and line, then $fatal (exit status 1).
  task automatic malformed(input [8*200-1:0] what);
    begin
      $display("%0s: error: %0s, line %0d: %0s", TB_NAME, path, lineno, what);
      $fatal(1);
    end
  endtask

  // One output against the file's expectation (!==: an X is a mismatch); the first MAX_SHOWN
  // mismatches are printed with the cycle and both values.
  task automatic check(input [8*40-1:0] name, input [63:0] expected, input [63:0] got);
    begin
      compared = compared + 1;
      if (got !== expected) begin
        mismatches = mismatches + 1;
        if (!cycle_bad) bad_cycles = bad_cycles + 1;
        cycle_bad = 1'b1;
        if (mismatches <= MAX_SHOWN)
          $display("MISMATCH cycle %0d: %0s: expected 0x%0h, rtl 0x%0h", cycle, name, expected, got);
      end
    end
  endtask

  // +vec=<absolute path> opened into fd; +dump=<path> names the waveform file (the module then
  // calls $dumpvars on itself). Returns 1 when a dump was asked for.
  task automatic open_vectors(output reg dumping);
    begin
      if (!$value$plusargs("vec=%s", path)) begin
        $display("%0s: error: no vector file: pass +vec=<absolute path>", TB_NAME);
        $fatal(1);
      end
      fd = $fopen(path, "r");
      if (fd == 0) begin
        $display("%0s: error: cannot open vector file %0s", TB_NAME, path);
        $fatal(1);
      end
      dumping = $value$plusargs("dump=%s", dump);
      if (dumping) $dumpfile(dump);
    end
  endtask

  // After the last record: no cycles is malformed input (no_cycles says so); any mismatch prints
  // the counts and ends with $fatal (exit status 1).
  task automatic fail_on_mismatches(input [8*40-1:0] no_cycles);
    begin
      $fclose(fd);
      if (cycle == 0) malformed(no_cycles);
      if (mismatches != 0) begin
        if (mismatches > MAX_SHOWN) $display("(%0d more mismatches not shown)", mismatches - MAX_SHOWN);
        $display("%0s: FAIL %0s: %0d of %0d output values differ, in %0d of %0d cycles", TB_NAME, path, mismatches,
                 compared, bad_cycles, cycle);
        $fatal(1);
      end
    end
  endtask
