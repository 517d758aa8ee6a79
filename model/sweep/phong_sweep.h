// A sweep of phong-fixed's datapath widths (render/phong_widths.h): each point renders the
// base's scenes (vectors/scenes/<name>.json, sweepSceneFile in sweep_unit.h) with
// phong-fixed at the point's widths (RenderOptions::phong_widths: the scalar datapath of
// render/fixed_widths.h, the span unit interpolating the normal at NormalFracBits), each
// material with its own brdf, the device lobes (if a scene has any) on the model of the base's
// specular configurations, the serial lane mode (the image does not depend on it) and the
// default subpixel bits.
//
// A point's record: {"index", "hash" (textHash of the "widths" object's dump), "widths",
// "error": {...}, "rom_bits", "mul_bits"}. No timings, no paths: the same widths give the
// same bytes on every run and machine.
//
// "error", per scene under "scenes": {"<name>": {...}}, over the pixels both images cover:
//   max_abs_lsb, worst_x, worst_y, rmse_lsb   the image against the reference method's exact
//              colour (Framebuffer::lsb, clamped to 0..255, as `shadesim render` compares):
//              the total error, the lobe's and the interpolation's own included
//   datapath_max_lsb, datapath_worst_x, datapath_worst_y, datapath_rmse_lsb
//              the image against the `phong` method's: the same algorithm (the span unit's
//              normal, normalised per pixel, the exact lobe, the same output rounding) in
//              double precision, so the error the fixed-point datapath and its widths add.
//              This is the honest datapath error: it is measured against the ideal arithmetic,
//              not against today's widths, so a wider point than the defaults shows how much of
//              the defaults' own error it removes (against the defaults' image it could only
//              grow). Both images are unorm8, so it counts whole LSBs: at the defaults about 1
//              (an output rounding that falls the other way), the rmse resolves below that.
//   default_max_lsb   the image against phong-fixed without widths (today's datapath): 0 at
//              the defaults, for the record
// and over the scenes: datapath_max_lsb (the front's error), datapath_rmse_lsb, max_abs_lsb
// (each the largest of the scenes').
//
// Costs (functions of the widths alone, no scene in them):
//   rom_bits   the 1/sqrt seed table, 2^RsqrtSeedBits words of the bit length of its largest
//              entry (RsqrtSeedFracBits + 1 unless an entry rounds up to 2.0), plus one lobe
//              table, 2^LobeCosBits + 1 words of LobeCodeBits + LobeIntBits bits (the
//              interpolation's right neighbour at c = 1 is the last word read again; a scene
//              holds one table per material of a table lobe, loaded per object)
//   mul_bits   the sum of a x b over the multipliers with inputs of a and b bits that one pixel
//              passes through, for one directional light and a lobe of N.H (blinn: the
//              sphere's), as the scalar datapath forms them; signed values take their format's
//              bits plus a sign (N sQ2.NormalFracBits, |N| <= 1: NormalFracBits + 2; L, H:
//              UnitFracBits + 2; N.u: NormalFracBits + UnitFracBits + 2):
//                dot products N.L, N.H        6 x (NormalFracBits + 2)(UnitFracBits + 2)
//                each Newton step             r r, m (r^2), r (3 - m r^2): w^2 + Nf 2w + w (Nf + 2),
//                                             Nf = NewtonFracBits, w = the seed word (first step)
//                                             or Nf + 2 (later steps)
//                the cosines N.L, N.H         2 x (NormalFracBits + UnitFracBits + 2)(Nf + 2)
//                lobe interpolation           (LobeCodeBits + LobeIntBits + 1)(CosFracBits - LobeCosBits)
//                diffuse D_k (N.L)            3 x (FactorIntBits + ColourFracBits)(CosFracBits + 1)
//                specular S_k f_code          3 x (FactorIntBits + ColourFracBits)(LobeCodeBits + LobeIntBits)
//              (|N|^2 costs two additions per pixel by the recurrence; its products are per span).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "render/phong_widths.h"
#include "sweep/grid.h"
#include "sweep/sweep_unit.h"

namespace shd {

// The base of a phong-fixed sweep as its plan records it: {"unit": "phong", "scenes": the
// names, "scene_hashes": {name: textHash of the scene file and the mesh files it reads},
// "widths": PhongWidths{}, "lobe_configs": {"quadratic", "cubic"}: the specular configurations
// of device lobes}. std::invalid_argument for no scene, a repeated one, a name that is not a
// bundled scene's ([a-z0-9_]+), or a scene that is not there or does not load.
nlohmann::json phongSweepBase(const std::vector<std::string>& scenes);

// The unit: params PhongWidths::names(), params_member "widths", front datapath_max_lsb
// against rom_bits and mul_bits, no area, no configuration. validate() checks every point's
// widths (PhongWidths::validate), naming the point and the derivation; evaluate() loads the
// scenes on first use (std::invalid_argument if a scene file changed since the plan: its hash)
// and renders the reference, phong and fixed images once per unit.
SweepUnit phongSweepUnit(const nlohmann::json& base);

// The base widths with `values` set: std::invalid_argument naming the point and the derivation.
PhongWidths phongPointWidths(const PhongWidths& base, const PointValues& values);

// The costs of the file comment.
int64_t phongRomBits(const PhongWidths& w);
int64_t phongMulBits(const PhongWidths& w);

}  // namespace shd
