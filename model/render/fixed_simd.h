// Fixed-point fragment work 8 fragments at a time, in AVX-512 (F, DQ, CD, VL, BW) where the
// CPU has it, else in AVX2 where it has that: the z-test and writes of the runs of a row (flat
// and Gouraud colours; phong-fixed's inputs into a batch), and phong-fixed's datapath, the same
// integer operations as FixedPointShader::shade() (fixed_shading.h, normalize.h), lane by lane,
// so the same colours. Where neither runs, phong-fixed's batch is kept in plain C++ kernels
// (shadeNhScalar, bufferRunScalar, bufferSpansScalar).
// The datapath covers the common case, one directional light and a lobe of N.H from a table
// (blinn, pow, normalized-blinn, schlick); everything else, and lanes it does not take (a squared
// norm outside [kVectorSqFrom, kVectorSqBelow), see shadeNh), stays scalar.
//
// The 128-bit products of the scalar path become 64-bit lane operations:
//   m r0^2 >> 32   r0^2 < 2^34 split at 2^32: mq a + (mq b >> 32), each product below 2^64;
//   scaleCosine    the high word of the signed 64 x 64 product d r64 from four 32 x 32
//                  products, plus the carry of adding 2^63 to the low word;
//   idx            ((mq - 2^30) << 10) / (3 2^30) = ((mq - 2^30) >> 20) / 3, the quotient by 3 of
//                  a number below 3072 as a multiply and shift (exact below 2^15).
// AVX2 lacks AVX-512's 64-bit multiply, arithmetic shift, minimum and maximum, count of
// leading zeros and compress: there the low 64 bits of a product come from three 32 x 32
// products (fewer where an operand is known to be below 2^32), the shifts and clamps from
// compares, the bit length from a double's exponent, the packing from a permutation table.
// Test FixedSimd.* compares the lanes with shade() on random and extreme inputs.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>

#include "raster/row_spans.h"

namespace shd::fixed_simd {

// The CPU runs the vector kernel (AVX-512 F, DQ, CD, VL and BW), and neither SHD_SCALAR (which
// forces the scalar paths) nor SHD_NO_AVX512 (the AVX2 paths where the CPU has AVX2) is set in
// the environment: both are for comparisons and tests.
bool available();
// The CPU runs the AVX2 colour-run kernel (colourRunsAvx2, without AVX-512), and SHD_SCALAR is not set.
bool availableAvx2();
// The CPU alone (SHD_SCALAR not consulted): what the kernels below need.
bool cpuHasAvx512();
bool cpuHasAvx2();

// The constants of the one light and the lobe table.
struct NhParams {
  const uint32_t* table = nullptr;  // lobeTable's entries
  uint32_t zero_below = 0;          // and its LobeTable::zero_below
  std::array<int64_t, 3> ambient{}, diffuse{}, specular{};
};

// A pixel's colour bytes in one word: r | g << 8 | b << 16.
constexpr uint32_t packedRgb(const std::array<uint8_t, 3>& c) {
  return uint32_t{c[0]} | uint32_t{c[1]} << 8 | uint32_t{c[2]} << 16;
}

// Fragments i < n (n <= kMaxBatch) in groups of 8 (fragments 8g .. 8g + 7): squared norm sq[i]
// (56 fraction bits) and the raw dot products N.L = l[i] and N.H = h[i] (58 fraction bits,
// two's complement) give the output colour rgb[i] (packedRgb) and, where codes is not null, the
// 12-fraction-bit code of channel k before the output rounding (FixedShade::code) in codes[k][i].
// Returns the groups it declines (bit g: a fragment of group g needs the scalar path: a squared
// norm outside [kVectorSqFrom, kVectorSqBelow) in the vector kernels, below 2^8 in the plain C++
// one); their outputs are untouched.
// The inputs hold n rounded up to a multiple of 8 readable entries (those past n are read and
// ignored), the outputs as many writable ones.
// Two kernels, each for a CPU with its instructions: AVX-512 (8 64-bit lanes) and AVX2 (4 lanes,
// two per group; the 64-bit products, shifts and the bit length that AVX2 lacks made of its
// 32 x 32 products, shifts, compares and double subtraction); and one in plain C++ for any CPU
// (shadeNhScalar: the scalar datapath's functions, fragment by fragment, in the same passes).
constexpr size_t kMaxBatch = 512;
// The squared norms the vector kernels take, [kVectorSqFrom, kVectorSqBelow) (|N| from 2^-12 to
// 8); a group with any other goes to the scalar path.
constexpr uint64_t kVectorSqFrom = uint64_t{1} << 32, kVectorSqBelow = uint64_t{1} << 62;
uint64_t shadeNh(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                 uint32_t* rgb, int64_t* const codes[3] = nullptr);
uint64_t shadeNhAvx2(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                     uint32_t* rgb, int64_t* const codes[3] = nullptr);
uint64_t shadeNhScalar(const NhParams& p, const uint64_t* sq, const uint64_t* l, const uint64_t* h, size_t n,
                       uint32_t* rgb, int64_t* const codes[3] = nullptr);
// The kernel to use: AVX-512 where available(), else AVX2 where availableAvx2(), else
// shadeNhScalar.
using NhKernel = uint64_t (*)(const NhParams&, const uint64_t*, const uint64_t*, const uint64_t*, size_t,
                              uint32_t*, int64_t* const[3]);
NhKernel nhKernel();
// Every group of n fragments: what shadeNh returns when it takes none.
inline uint64_t allGroups(size_t n) { return n == 0 ? 0 : ~uint64_t{0} >> (64 - (n + 7) / 8); }

// Fragments waiting for shadeNh: their inputs, the framebuffer pixel each colours, and the
// colours. Padded by 8: a group reads and writes 8 entries.
struct Batch {
  static constexpr size_t kCap = 256;
  static_assert(kCap <= kMaxBatch && kCap % 8 == 0, "one shadeNh call shades a batch");
  std::array<uint64_t, kCap + 8> sq{}, l{}, h{};
  std::array<uint32_t, kCap + 8> pixel{};
  std::array<uint32_t, kCap + 8> rgb{};  // packedRgb
  size_t n = 0;
};

// The pixels of a run of a row, left to right: framebuffer pixels p .. p + count - 1, fragment
// k with the depth code z + k dz (mod 2^32).
struct RunPixels {
  size_t p = 0, count = 0;
  uint32_t z = 0, dz = 0;
};

// A phong-fixed run: fragment k of px with the squared norm a + k two_b + k^2 c
// (SquaredNormRecurrence::Terms) and the raw dot products l + k dl, h + k dh (mod 2^64).
struct Run {
  RunPixels px;
  uint64_t a = 0, two_b = 0, c = 0;
  uint64_t l = 0, dl = 0, h = 0, dh = 0;
  size_t room = 0;  // pixels from the run's first to the end of its row (bufferRunAvx2's blends)
};

// The depth and triangle buffers the run's fragments are tested against and written to. The
// depth codes are compared as int32_t: right when every code of the run fits int32_t (the
// span unit's AttrBits <= 32), as the caller checks.
struct Target {
  int32_t* depth = nullptr;
  int32_t* tri = nullptr;  // null: no triangle buffer to write (RenderOptions::tags)
  int32_t tag = 0;
  size_t width = 0;  // pixels per row: the row after next is prefetched
};

// Runs of flat or Gouraud fragments, each left to right, with the same steps (a triangle's
// rows, drawn with one call): fragment k of run i at pixel rows[i].p + k, with the depth code
// rows[i].z + k dz (mod 2^32) and the colour codes rows[i].c[ch] + k dc[ch] (frac fraction bits,
// 1 <= frac <= 23; a run's codes fit int32_t, as the span unit's do for AttrBits <= 32).
struct ColourRuns {
  static constexpr size_t kCap = 64;
  struct Row {
    size_t p = 0, count = 0;
    size_t room = 0;  // pixels from the run's first to the end of its row (the AVX2 kernel's blends)
    uint32_t z = 0;
    std::array<int32_t, 3> c{};
  };
  std::array<int32_t, 3> dc{};
  uint32_t dz = 0;
  int frac = 12;
  size_t n = 0;  // rows[0 .. n - 1]
  std::array<Row, kCap> rows;
};

// The runs' z-test, 8 pixels at a time, and where it passes the depth code and the tag written,
// and the colour: unorm8FromCode of each code (shading.h) at rgb[3 pixel + ch], run after run.
// Returns the passing pixels whose depth was 0 (not covered before); adds the passing pixels to
// passed. Two kernels, each for a CPU with its instructions: AVX-512 and AVX2, the same
// operations on 8 lanes. AVX2 has no byte-masked store, and its masked 32-bit store is slow on
// AMD: a group's colour bytes, depth codes and tags are blended into the 32 bytes there (those
// of other pixels written back as read) where those lie within the run's row (room), else
// written pixel by pixel (colour) or by masked stores, so no pixel of another row is touched.
uint64_t colourRunsAvx512(const ColourRuns& r, const Target& t, uint8_t* rgb, uint64_t& passed);
uint64_t colourRunsAvx2(const ColourRuns& r, const Target& t, uint8_t* rgb, uint64_t& passed);
// The kernel to use: AVX-512 where available(), else AVX2 where availableAvx2(), else null.
using ColourKernel = uint64_t (*)(const ColourRuns&, const Target&, uint8_t*, uint64_t&);
ColourKernel colourKernel();

// colourRunsAvx2 straight from a triangle's rows' spans (raster/row_spans.h): its rows z-tested
// and coloured row by row, each row a run from its first pixel with the codes there (RowSpans::at
// mod 2^32, in 32-bit lanes: the same bits) and the triangle's gradients as its steps, without a
// list of runs in between (frac: the colour codes' fraction bits, as ColourRuns::frac; W: pixels
// per framebuffer row). Returns and adds to passed as the colour kernels.
uint64_t colourSpansAvx2(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb, uint64_t& passed);
// The same with colourRunsAvx512's operations.
uint64_t colourSpansAvx512(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb, uint64_t& passed);
// The same pixel by pixel in plain C++: the colour kernel of the scalar paths.
uint64_t colourSpansScalar(const RowSpans& s, size_t W, int frac, const Target& t, uint8_t* rgb, uint64_t& passed);
// The one of colourKernel()'s instructions (Frame::colour_spans), colourSpansScalar where that is
// null.
using ColourSpansKernel = uint64_t (*)(const RowSpans&, size_t, int, const Target&, uint8_t*, uint64_t&);
ColourSpansKernel colourSpansKernel();

// Fragments first, first + 1, ... of run r, 8 at a time while the batch has room for 8 more:
// the z-test (the fragment's code above the buffer's), and where it passes the code and the
// tag written to the buffers and the fragment appended to b. Adds to fresh the passing pixels
// whose depth was 0 (not covered before). Returns the first fragment it did not take (r.count
// when it took all); the caller shades the batch and calls again for the rest. AVX-512 (where
// available()).
size_t bufferRun(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh);
// The same in AVX2 (the kernel of a CPU without AVX-512, with shadeNhAvx2), and in plain C++ (with
// shadeNhScalar).
size_t bufferRunAvx2(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh);
size_t bufferRunScalar(const Run& r, size_t first, const Target& t, Batch& b, uint64_t& fresh);
// The one that goes with nhKernel().
using BufferKernel = size_t (*)(const Run&, size_t, const Target&, Batch&, uint64_t&);
BufferKernel bufferKernel();

// A phong-fixed triangle's rows' spans (raster/row_spans.h) as runs, without the walk: each row
// of s whose bit is set in `rows` (bit i: row y0 + i) a run from its first pixel, with the
// normal codes and depth code there (RowSpans::at) and the triangle's gradients along x as its
// steps, its dot products with the light's l and h (Q1.30, dot58's operands) and its
// squared-norm terms: the Run that phong-fixed's batchRun makes of the walk's RowRun of the row.
struct NhSpans {
  const RowSpans* s = nullptr;
  uint64_t rows = ~uint64_t{0};
  std::array<int32_t, 3> l{}, h{};
  size_t W = 0;  // pixels per framebuffer row
};
// Where the buffering of an NhSpans stands: fragment k of row `row` (of s).
struct SpanCursor {
  int32_t row = 0;
  size_t k = 0;
};
// The runs of r buffered as bufferRun buffers each, from `at` on, while the batch has room for
// 8 more: returns true when every run is in, else false with `at` at the first fragment not
// taken (the caller shades the batch and calls again). Adds to fresh as bufferRun.
bool bufferSpans(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh);
// The same with bufferRunAvx2, and with bufferRunScalar.
bool bufferSpansAvx2(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh);
bool bufferSpansScalar(const NhSpans& r, SpanCursor& at, const Target& t, Batch& b, uint64_t& fresh);
// The one that goes with bufferKernel().
using SpansBufferKernel = bool (*)(const NhSpans&, SpanCursor&, const Target&, Batch&, uint64_t&);
SpansBufferKernel spansBufferKernel();

}  // namespace shd::fixed_simd
