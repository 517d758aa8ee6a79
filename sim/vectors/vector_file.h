// Vector files: a unit's inputs and expected outputs, cycle by cycle from reset, as plain text
// that the Verilator replay (sim/cosim/replay.h, `shadesim replay`), the Icarus testbenches
// (testbench/icarus/tb_*_unit.v) and a person read alike. `shadesim vectors` writes them from the
// golden model (checked in under vectors/cycles/), and a failing co-simulation saves its failing
// case in the same format, so that the case replays alone.
//
// Format 1. Lines starting with '#' are the header and comments; a header line is
// "# <key> <value>" with one of these keys (every other '#' line is a comment):
//   unit     spec | span
//   config   the configuration name (vectors/config/<unit>_<name>.json, the verilated model),
//            a space, and its "rtl" parameters as one-line JSON: the replay refuses a file whose
//            parameters differ from the verilated configuration's
//   params   the same parameters as decimal integers in a fixed order (below), which the Icarus
//            testbench compares with its own
//   prom     spec only: the PROM $readmemh file, relative to the vector file's directory
//   latency  spec only: 2 + PipeStages (informative; the readers check it)
//   source   how the file was made (informative)
// The spec header keeps the lines of the failing-window files sim/cosim/spec_cosim.cpp wrote before
// this format ("# config <name> <json>", "# latency", "# prom"), so readers of those still work.
// Every value is hex, lowercase, without 0x, in the width of its port; a signed value is its
// two's complement in that width (the port's bits). Reset, before the first cycle: rst_ni low
// for two clock cycles with the valid inputs low (span: out_ready_i high), then high.
//
// spec (rtl/shd_spec_unit.v): params = Degree CosFracBits ShinBits CoefIntBits CoefFracBits
//   DiffFracBits HornerFracBits SpecFracBits LightBits PipeStages Kind TableBits Segments. One
//   line per clock cycle:
//     valid shin cos light_r light_g light_b  exp_valid exp_spec exp_r exp_g exp_b
//   the inputs applied before the cycle's rising edge and every output as expected right after
//   that edge (the outputs hold their last valid result, so all of them are compared on every
//   cycle; inputs of cycles without valid are driven too: the unit must ignore them).
//
// span (rtl/shd_span_unit.v): params = NumTri LanesPerTri AlignLanes NumAttr AttrBits CoordBits
//   RemBits PixBits TagBits RowAhead Interleave. Two records, each one line starting with its
//   letter:
//     D tag row_first row_last xref  {iref didx didy} per attribute  interleave
//       {row_first row_last clip_x0 clip_x1 ox oy flip  {aoff} per attribute
//        {right row_first row_last q r div k m} per edge (3)} per lane-triangle
//       the descriptor ports (desc_*, lt_*, e_*) from the next C record on. A D record comes
//       before the first C record that offers it and never while an offer is pending (the
//       valid/ready rule: an offered descriptor does not change until accepted).
//     C desc_valid out_ready  exp_desc_ready exp_out_valid exp_tag exp_lane_valid
//       {x y {attr} per attribute} per expected-valid lane, lowest lane first
//       one clock cycle: the inputs during it and the outputs expected during it, before its
//       rising edge (the outputs are functions of the registers). exp_lane_valid is a bit mask
//       (bit l = lane l); exp_tag is compared only when exp_out_valid is 1, pixel and attributes
//       only on expected-valid lanes (elsewhere the unit's data outputs mean nothing).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "device/spec_unit.h"
#include "raster/span_unit.h"

namespace shd {

constexpr int kVectorFormat = 1;

struct SpecVectors {
  std::string config;
  SpecUnitParams params;
  std::string prom;    // as written in the file: relative to the file's directory, or absolute
  std::string source;  // informative
  std::vector<std::string> notes;  // comment lines of the header (without "# ")
  std::vector<SpecIn> in;
  std::vector<SpecOut> expected;  // one per cycle, after the cycle's rising edge
};

struct SpanVectorCycle {
  bool desc_valid = false;
  bool out_ready = true;
  int desc = -1;     // index into SpanVectors::descs of the descriptor on the ports, -1: none yet
  SpanOut expected;  // lanes() entries; data meaningful where valid (out_tag where out_valid)
};

struct SpanVectors {
  std::string config;
  SpanParams params;
  std::string source;
  std::vector<std::string> notes;  // comment lines of the header (without "# ")
  std::vector<SpanDesc> descs;
  std::vector<SpanVectorCycle> cycles;
};

// The unit a vector file is for ("spec" or "span"), from its header. std::runtime_error naming
// the path when the file cannot be read or has no "# unit" line.
std::string vectorFileUnit(const std::string& path);

// Text of the file. std::invalid_argument if the data does not fit the parameters (a cycle
// count mismatch, an expected lane mask wider than the unit, a C record before any D record).
// Values are written as the ports see them: the low bits of each field.
std::string renderSpecVectors(const SpecVectors& v);
std::string renderSpanVectors(const SpanVectors& v);
// Renders and writes atomically.
void writeSpecVectors(const std::string& path, const SpecVectors& v);
void writeSpanVectors(const std::string& path, const SpanVectors& v);

// Strict readers: std::runtime_error "<path>:<line>: <what is wrong>" for a missing header
// field, parameters that contradict each other, a wrong number of fields, a token that is not
// hex, a value wider than its port, a D record while an offer is pending, or a C record
// offering no descriptor.
SpecVectors loadSpecVectors(const std::string& path);
SpanVectors loadSpanVectors(const std::string& path);

}  // namespace shd
