// PROM files: the coefficient table of the specular unit written for simulators and FPGA tools,
// read back strictly, and written atomically.
//
// Formats (PromFormat), each holding exactly unit.promDepth() words, address 0 first:
//   hex  Verilog $readmemh (what rtl/shd_coef_rom.v loads in Verilator, Icarus and yosys):
//        `//` provenance lines, then one word per line, ceil(bits/4) lowercase hex digits,
//        zero-padded. IEEE 1364 allows // and /* */ comments and whitespace between words.
//   mem  Lattice Diamond/Radiant Memory Generator initialisation file, Hex format. The header
//        may not carry comments, so it comes first, exactly:
//          #Format=Hex  #Depth=<depth>  #Width=<bits>  #AddrRadix=3  #DataRadix=3  #Data
//        (one per line; radix index 3 = hexadecimal; Depth 1..65536, Width 1..256), then `//`
//        provenance lines (comments are allowed anywhere after the header, with # or //), then
//        one word per line from address 0. Source: Lattice's .mem syntax as documented in
//        srecord's srec_mem(5).
//   coe  Xilinx: `;` provenance lines, memory_initialization_radix=16; then
//        memory_initialization_vector= and the words separated by `,`, the last ending in `;`.
//   mif  Intel/Altera: `--` provenance lines, WIDTH=, DEPTH=, ADDRESS_RADIX=UNS, DATA_RADIX=HEX,
//        CONTENT BEGIN, `  <addr> : <word>;` per address, END;
//   csv  one row per entry (not the padding) with the real coefficients and their codes:
//          degree 2: n,address,a_real,a_code
//          degree 3: n,address,a1_real,a1_code,v_real,v_code,cut_real,cut_code
//          schlick:  n,address,m_real,m_code                (m = n - 1)
//          table:    n,address,bucket,value_real,value_code (one row per word of the n's row)
//          piecewise: n,address,segment,segment_address,first_code,scale,K0_code..Kd_code,a_real,b_real
//                    (one row per segment of the fit, [a_real, b_real] its real interval)
//        v = a1 + b1 is the second word field (the Horner form p = c - c(1-c)(a1 c + v)); cut is
//        the cut-off cosine and cut_code = ceil(cut * 2^Wc) the stored uQ1.Wc code. Reals carry
//        17 significant digits (they round-trip to the same double), codes are signed decimal.
//        CSV has no comment syntax, so its provenance is the JSON sidecar
//        (renderProvenanceJson), which the other formats' comments restate.
// The piecewise kind has a second memory, the segment ROM (RomPart::Segments), written beside the
// PROM as <file>.seg in the same format (hex, mem, coe, mif; the csv table holds both); the
// RTL loads it from the PROM's path with that suffix (rtl/shd_coef_rom.v Suffix).
// Provenance: tool and version, fit, degree, level, n spec and count, coefficient format and
// rounding, cos format, word width and layout, depth, and which addresses are unused padding
// (they hold the all-zero word). No timestamps or paths: the output is a pure function of the
// table, so checked-in files can be compared byte for byte with a fresh regeneration.
#pragma once

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "device/prom.h"
#include "device/spec_unit.h"

namespace shd {

enum class PromFormat { Hex, Mem, Coe, Mif, Csv };
enum class RomPart { Prom, Segments };
constexpr const char* kSegRomSuffix = ".seg";

// "hex", "mem", "coe", "mif", "csv"; std::invalid_argument("unknown PROM format 'x' (expected
// hex, mem, coe, mif or csv)") otherwise.
PromFormat parsePromFormat(std::string_view s);
const char* toString(PromFormat f);

// w as exactly ceil(bits/4) lowercase hex digits, zero-padded. std::invalid_argument unless
// 1 <= bits <= 128 and w has no bit at or above `bits`.
std::string hexWord(PromWord w, int bits);

// The whole file text in format f. std::invalid_argument if t.words does not hold
// unit.promDepth() words of unit.promWordBits() bits, or (mem) the depth or width exceeds what
// the Lattice format allows.
// RomPart::Segments: the piecewise kind's segment ROM (std::invalid_argument for the other kinds
// and for csv).
std::string renderProm(const PromTable& t, PromFormat f, RomPart part = RomPart::Prom);

// Every file of a table in format f as {suffix of the PROM's path, text}: the PROM ("") and, for
// the piecewise kind, its segment ROM (kSegRomSuffix; not for csv).
using PromFiles = std::vector<std::pair<std::string, std::string>>;
PromFiles renderPromFiles(const PromTable& t, PromFormat f);

// The hex files the RTL loads from `path` (renderPromFiles), written together or not at all.
void writePromHexFiles(const std::string& path, const PromTable& t);

// CSV "address,n", one row per entry (n with 17 significant digits): the address map of an
// n list, written beside the PROM as <file>.map.csv.
std::string renderAddressMap(const PromTable& t);

// The provenance as a JSON object text (pretty-printed, keys in a fixed order, trailing
// newline): the sidecar of a csv table, or of any PROM file.
std::string renderProvenanceJson(const PromTable& t);

// Strict reader of a hex ($readmemh) PROM file as renderProm writes it: `//` comments and blank
// lines are skipped; every other whitespace-separated token must be hex digits only (no x/z,
// no underscores, no @address directives) and fit word_bits; the file must hold exactly `depth`
// words. std::runtime_error with the path, the line number and what is wrong otherwise.
std::vector<PromWord> readPromHex(const std::string& path, int word_bits, int depth);

// The contents of a unit's memories: the PROM and, for the piecewise kind, the segment ROM
// (empty for the other kinds).
struct RomImage {
  std::vector<PromWord> prom, seg;
  static RomImage of(const PromTable& t) { return {t.words, t.seg_words}; }
};
// readPromHex of path and, when the unit has a segment ROM, of path + kSegRomSuffix.
RomImage readPromHexFiles(const std::string& path, const SpecUnitParams& p);
// "" when equal, else the first difference: "PROM word 7 is 0x..., expected 0x..." (or
// "segment ROM ..."; or the depths).
std::string romImageDiff(const RomImage& got, const RomImage& want, const SpecUnitParams& p);

}  // namespace shd
