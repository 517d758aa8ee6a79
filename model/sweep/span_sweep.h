// One point of a span-unit sweep, evaluated by the model: the base configuration's RTL
// parameters and triangle setup's raster widths (raster/setup.h) with the grid's values, and
//   - the error of the interpolated attributes: the codes the unit hands out (walkSpanUnit, bit-
//     and cycle-exact to SpanUnitModel, test_span_unit) against the exact plane of the snapped
//     vertex codes (exactPlane), at every covered pixel of every triangle of a stated set (the
//     TriangleGenerator stream of the base's seed and count, 10^5 triangles by default), exactly:
//     each error is an integer over the triangle's determinant, and a run of a row (RowRun) is
//     reduced in closed form (its error is affine along the run), so nothing is sampled;
//   - the cycles the unit takes on that set, and on each named scene (vectors/scenes/<name>.json
//     rendered with the gouraud method, as scripts/regress.py and `shadesim render` count them);
//   - its lanes.
//
// Errors are in output LSBs, the units setup.h's fraction rule aims at: colour channels (the
// generator's 0..255, the renderer's colour in LSBs) come out as integer codes, so one LSB is
// 1/255 of full scale and the error is the code error / 2^ColourFracBits; depth (0..1) comes out
// with kSpanDepthOutFrac = 16 fraction bits, so one LSB is 2^-16 and the error is the code error
// / 2^(DepthFracBits - 16). With setup's default widths (defaultAttrFracBits) every error is
// at most 1/4 LSB; setup.h's bound at a pixel is 0.5 (1 + |px - xref| + |py - yref|) codes.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "config/registry.h"
#include "raster/trigen.h"
#include "sweep/grid.h"
#include "sweep/sweep_unit.h"

namespace shd {

constexpr uint64_t kSpanSweepTriangles = 100'000;  // the set's size unless --triangles says otherwise
constexpr uint64_t kMaxSpanSweepTriangles = 100'000'000;
constexpr uint64_t kSpanSweepSeed = 1;  // the set's seed unless --seed says otherwise
constexpr int kSpanColourOutFrac = 0;  // colour output: integer codes 0..255
constexpr int kSpanDepthOutFrac = 16;  // depth output: 16 fraction bits (setup.h)
constexpr int kSpanEvalAttrs = 4;      // attributes evaluated: colour 0..2, depth 3

// A point: the unit's RTL parameters and setup's raster widths. The record holds them as one
// object ("params"), every name of spanParamNames().
struct SpanPoint {
  SpanParams rtl;
  int SubpixelBits = 4;     // vertex snapping (RasterConfig::subpixel_bits)
  int ColourFracBits = 12;  // fraction bits of the colour attribute codes (F of attributes 0..2)
  int DepthFracBits = 28;   // fraction bits of the depth code (F of attribute 3)

  nlohmann::json toJson() const;
};

// The names a span sweep may vary: SpanParams's (NumTri ... TagBits) and SubpixelBits,
// ColourFracBits, DepthFracBits.
std::vector<std::string> spanParamNames();

// The base of a span sweep as its plan records it:
//   {"unit": "span", "config": what --config names, "rtl": the configuration's parameters,
//    "raster": {"SubpixelBits", "ColourFracBits", "DepthFracBits"}: setup's defaults for the
//    viewport (RasterConfig, defaultAttrFracBits), "viewport": {"width", "height"}: the scenes'
//    (one viewport for all), "triangles", "seed", "scenes": the names}
// Everything a point's evaluation depends on (sweep-merge rebuilds the unit from it). Loads the
// scenes for their viewport: std::invalid_argument for no scene, a malformed or repeated name, a
// scene missing from vectors/scenes, scenes of different viewports, or a count outside
// 1..kMaxSpanSweepTriangles.
nlohmann::json spanSweepBase(const SpanUnitConfig& cfg, uint64_t triangles, uint64_t seed,
                             const std::vector<std::string>& scenes);

// The base's point with `values` set, every derivation its evaluation rests on checked:
// std::invalid_argument naming the point and the derivation it breaks (SpanParams::validate, the
// viewport in PixBits, the guard band in CoordBits, RemBits for the edge divisor, the colour
// and depth codes in AttrBits, NumAttr holding the attributes evaluated).
SpanPoint spanPointParams(const nlohmann::json& base, const PointValues& values);

// The generator of the base's triangle set (seed and count apart): the viewport, the base's
// SubpixelBits as the grid of the snapped shapes, 4 attributes (colour 0..255, depth 0..1), the
// other options TriGenOptions's defaults.
TriGenOptions spanSweepTriangleOptions(const nlohmann::json& base);

// The span unit as a sweep sees it. A record:
//   {"index", "hash" (textHash of "params"), "params",
//    "error": {"max_lsb" (the front error: the worse of colour and depth, each in its output
//              LSBs), "colour_max_lsb", "colour_rms_lsb", "colour_worst_triangle",
//              "colour_worst_x", "colour_worst_y", "colour_worst_attr", "colour_bound_ratio",
//              and the same for depth (its attribute is 3), "plane_mismatches"},
//    "triangles" (of the set), "drawn", "dropped" (setup's stated drops: zero area, no pixel
//    centre), "rejected" (setup refused: a width too narrow for that triangle), "fragments",
//    "cycles" (over the set), "lanes", "cycles_<scene>", "fragments_<scene>"}
// The worst pixel's ties go to the least (triangle, y, x, attribute), so the record does not
// depend on the order the lanes emit in. <kind>_bound_ratio: the largest |error| over setup.h's
// bound at that pixel (at most 1 by design); plane_mismatches: fragments whose code differs from
// setup's integer plane iref + didx (px - xref) + didy (py - yref) (none by design).
// The fronts weigh max_lsb against cycles and lanes; the area is synthesised from the "rtl"
// parameters alone (the raster widths are setup's, not the unit's: points that differ only in
// them share a synthesis). No config(): --target-lsb, which writes a minimal configuration and
// replays it under Icarus, is the specular unit's. Scenes are loaded once per unit, when first
// needed (validate() loads them).
// Cost: one point of the default set (10^5 triangles, 5.6 x 10^6 fragments) with sphere and
// still_life takes about 0.17 s on one core of the 2-core VM, sierpinski (no runs: every
// fragment on its own) 0.36 s.
SweepUnit spanSweepUnit(const nlohmann::json& base);

}  // namespace shd
