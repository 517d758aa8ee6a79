// Triangle setup: screen-space vertices in, a span-unit descriptor (raster/span_unit.h) out.
//
// Fixed point and the pixel grid
//   Vertices snap to S = subpixel_bits fraction bits (round-half-even): X = round(x * 2^S).
//   Pixel (px, py) covers [px, px+1) x [py, py+1) and is sampled at its centre (px+0.5, py+0.5).
//   Internally positions are in units u = 2^-(S+1) pixel (a vertex is U = 2X, a pixel centre
//   (2px+1)*2^S), so that the edge midpoints of the 4-way split are exact integers too.
//   Vertices must lie in the guard band |x|, |y| <= 2^(CoordBits-3) pixels (8192 for the default
//   CoordBits 16): clip larger triangles first. NaN or infinite coordinates are rejected.
//
// Edge functions and the fill rule
//   With det = (X1-X0)(Y2-Y0) - (X2-X0)(Y1-Y0) > 0 (setup swaps two vertices otherwise) the
//   edge P->Q has E(px, py) = A px + B py + C with A = -(Qy-Py) 2^(S+1), B = (Qx-Px) 2^(S+1),
//   C = E at pixel (0, 0), all integers (u^2 units), and the inside is E >= 0. Top-left rule
//   (y down): an edge is "left" if A > 0 and "top" if A == 0 and B > 0; a pixel centre exactly on
//   an edge belongs to the triangle only for top and left edges. Setup folds this into a bias:
//   C' = C - 1 for the other edges, so the per-pixel test is the sign bit of A px + B py + C'.
//   A pixel shared by two triangles of a mesh (a shared edge is the same line with opposite
//   direction, so exactly one of the two is top/left) is drawn exactly once.
//
// Degenerate triangles (the stated rule): det == 0 (zero area: repeated or collinear vertices)
//   covers no pixel and is dropped at setup without a division; so is a triangle whose bounding
//   box holds no pixel centre of the viewport (wholly above, below, left or right of it, or too
//   small to reach a centre row or column). setupTriangle() then returns no descriptor and says
//   why. Each lane-triangle's rows are trimmed to the first and the last that hold a pixel (a
//   sliver's tip can pass between the centres of a row), so the unit spends no cycle on a row
//   without a pixel at either end; a triangle whose box holds centres but that covers none (a
//   sliver passing between them) is dropped as well ("no pixel centre inside it").
//
// Lane-triangles (NumTri 4): the triangle split at its edge midpoints (raster/span_unit.h). With
//   Interleave 1 setup also builds the row interleave (lane-triangle j: the whole triangle on
//   the screen rows 4 w + j) and keeps the one the unit takes fewer cycles for, alone (the
//   split on a tie): the interleave wins where the split leaves lanes idle (a sub-triangle off
//   screen or without pixels) or walks the widest sub-triangle's rows for all four.
//
// Attribute planes (the corrected 4.1 of docs/paper-corrections.md: the plane gradient with det as denominator)
//   Vertex attribute k is quantised to a code a_i = round(value * 2^F_k) (F_k = attr_frac_bits).
//   The gradients per pixel are the exact rationals
//     dI/dx = 2^S ((a1-a0)(Y2-Y0) - (a2-a0)(Y1-Y0)) / det,
//     dI/dy = 2^S ((X1-X0)(a2-a0) - (X2-X0)(a1-a0)) / det,
//   rounded half-even to integer codes didx, didy, and iref is the exact plane at the reference
//   pixel (xref, yref) rounded the same way. The plane every mode uses is then
//     I(px, py) = iref + didx (px - xref) + didy (py - yref)      (exact integer arithmetic)
//   so stepping by didx along a span, by didy down rows, or jumping by a multiple (the lanes,
//   the segments, the 4-way split) gives, at every pixel, exactly the value of evaluating this
//   plane there: bit-identical, no drift, whatever the span width or triangle height.
//   Against the exact plane of the vertex values the error at a pixel is at most
//     0.5 * (1 + |px - xref| + |py - yref|) codes <= 0.5 * (1 + W + H) * 2^-F_k
//   in the attribute's own units (each of the three rounded quantities errs by <= half a code).
//   For it to stay below a quarter of an output LSB 2^-O_k anywhere in a W x H viewport:
//     F_k >= O_k + 1 + ceil(log2(1 + W + H)).
//   512 x 512, colour out as integer codes (O = 0): F = 12 (bound 0.125 LSB); depth out with
//   16 fraction bits: F = 28 (codes up to 2^28, so AttrBits 32 holds them with sign and margin).
//   defaultAttrFracBits() applies this rule.
//   Only the values at covered pixels must fit AttrBits: the unit computes modulo 2^AttrBits,
//   so wrapped gradients and intermediate sums still give the exact value where it fits.
//   Setup checks the covered values' bound and reports an attribute that cannot fit.
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "raster/span_unit.h"

namespace shd {

struct RasterConfig {
  int width = 512, height = 512;
  int subpixel_bits = 4;
  std::vector<int> attr_frac_bits;  // per attribute; empty: defaultAttrFracBits
  SpanParams unit;

  void validate() const;  // std::invalid_argument naming the field
  int attrFracBits(int k) const;
};

// F_k for output fraction bits out_frac (see the header comment).
int defaultAttrFracBits(int width, int height, int out_frac);
// Colour channels (attributes 0..2, integer output codes) and depth (attribute 3, 16 output
// fraction bits); further attributes as colour.
std::vector<int> defaultAttrFracBitsFor(int width, int height, int num_attr);

struct SetupVertex {
  double x = 0, y = 0;        // pixels, y down
  InlineVec<double, kMaxAttr> attr;  // NumAttr values in the attribute's units
};

// The fixed-point triangle after snapping: kept for references and diagnostics.
struct SnappedTriangle {
  std::array<int64_t, 3> X{}, Y{};                 // subpixel units, det > 0 order
  InlineVec<std::array<int64_t, 3>, kMaxAttr> a;   // attribute codes per attribute
  bool swapped = false;                            // vertices 1 and 2 were swapped
  int64_t det = 0;
};

struct EdgeFunction {
  int64_t A = 0, B = 0, C = 0;  // C includes the top-left bias; inside iff A px + B py + C >= 0
  bool topLeft = false;
  int64_t eval(int64_t px, int64_t py) const { return A * px + B * py + C; }
};

struct AttributePlane {
  int64_t xref = 0, yref = 0;
  AttrVec iref, didx, didy;  // codes (not wrapped)
  // In 128 bits: with wide attributes (AttrBits up to 62) a product can leave int64 at a covered
  // pixel of a sliver although the sum fits (setup checks that the values it hands on fit).
  int64_t at(int k, int64_t px, int64_t py) const {
    const size_t i = static_cast<size_t>(k);
    using i128 = __int128;
    return static_cast<int64_t>(static_cast<i128>(iref[i]) + static_cast<i128>(didx[i]) * (px - xref) +
                                static_cast<i128>(didy[i]) * (py - yref));
  }
};

struct SetupResult {
  std::optional<SpanDesc> desc;  // empty: nothing to draw, see `dropped`
  // "zero area", "no pixel centre of its bounding box in the viewport", "no pixel centre inside
  // it in the viewport" (its box has one: a sliver between pixel centres)
  std::string dropped;
  SnappedTriangle tri;
  std::array<EdgeFunction, 3> edges;  // of the whole triangle, screen pixel coordinates
  AttributePlane plane;               // screen pixel coordinates
};

// std::invalid_argument (a clear message naming the vertex or attribute) for NaN/infinite
// coordinates, vertices outside the guard band, or attributes that cannot fit AttrBits.
SetupResult setupTriangle(const std::array<SetupVertex, 3>& v, uint32_t tag, const RasterConfig& cfg);
// The same into res, whatever it held (a result reused in place: the renderer's two-thread
// frame sets up each triangle in the slot its other thread draws it from, without a copy).
void setupTriangle(const std::array<SetupVertex, 3>& v, uint32_t tag, const RasterConfig& cfg, SetupResult& res);

// The reference the span unit is tested against: every pixel of the viewport whose centre
// passes the three biased edge functions (direct evaluation, no DDA), with the plane's value,
// in row-major order.
std::vector<SpanFragment> rasterizeReference(const SetupResult& s, const RasterConfig& cfg);

// The exact (rational) plane of the snapped vertex codes at a pixel centre, in codes.
double exactPlane(const SetupResult& s, const RasterConfig& cfg, int k, int64_t px, int64_t py);

}  // namespace shd
