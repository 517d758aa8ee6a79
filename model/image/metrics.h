// Image error metrics in output LSBs, the error heat map, and the exact-equality tools for
// RTL-vs-model framebuffers.
//
// Definitions (test: unorm8 codes; ref: LSB units, ImageF, or another Image as exact codes):
//   channel error  d = |test - ref| per channel sample, in LSBs.
//   pixel error    e = max(d_R, d_G, d_B).
//   max_abs_lsb    max of e over the selected pixels; worst_x, worst_y the first pixel in
//                  row-major order (top row first) that reaches it.
//   rmse_lsb       sqrt(sum of d^2 over all 3N channel samples / 3N).
//   psnr_db        20 log10(255 / rmse_lsb); +infinity when rmse_lsb == 0 (identical images).
//                  In JSON (toJson) an infinite PSNR is null: JSON has no infinity, and a large
//                  finite sentinel could be mistaken for (and averaged as) a measurement.
//   share_over_1lsb  fraction of selected pixels with e > 1 (strictly), 0 when N == 0.
//   pixels         N, the number of selected pixels.
// Selection: every pixel, or the pixels set in a PixelMask (covered pixels; the highlight
// region). With no pixels selected nothing is measured: every error is 0, PSNR +infinity,
// worst -1, -1, pixels 0; check pixels before reading the rest.
// Against a double reference, d is rarely 0: a perfect unorm8 renderer still shows d <= 0.5.
//
// Heat map ramp (heatColour): e <= 0 black; 0 < e < full scale interpolated linearly in sRGB
// codes through black (0) -> blue (1/4) -> green (1/2) -> yellow (3/4) -> red (1) of full scale;
// e >= full scale (or NaN) white, a deliberate jump so clipped errors stand out from the ramp.
// Each channel is rounded half up, so errors below full scale / 2040 show as black.
// Pixels outside the mask are dark grey (48, 48, 48), a colour the ramp never produces.
#pragma once

#include <cstdint>
#include <optional>

#include <nlohmann/json_fwd.hpp>

#include "image/image.h"

namespace shd {

struct ImageMetrics {
  double max_abs_lsb = 0;
  int worst_x = -1, worst_y = -1;
  double rmse_lsb = 0;
  double psnr_db = 0;  // +infinity when rmse_lsb == 0
  double share_over_1lsb = 0;
  uint64_t pixels = 0;
};

// std::invalid_argument if the sizes of test, ref and mask differ, or a selected reference
// sample is not finite (a NaN reference is a bug in the reference, not an error to average).
ImageMetrics imageMetrics(const Image& test, const ImageF& ref);
ImageMetrics imageMetrics(const Image& test, const ImageF& ref, const PixelMask& mask);
ImageMetrics imageMetrics(const Image& test, const Image& ref);
ImageMetrics imageMetrics(const Image& test, const Image& ref, const PixelMask& mask);

// {"max_abs_lsb", "worst_x", "worst_y", "rmse_lsb", "psnr_db" (null when infinite),
//  "share_over_1lsb", "pixels"}.
nlohmann::json toJson(const ImageMetrics& m);

struct Rgb8 {
  uint8_t r = 0, g = 0, b = 0;
};
inline bool operator==(Rgb8 a, Rgb8 b) { return a.r == b.r && a.g == b.g && a.b == b.b; }
inline bool operator!=(Rgb8 a, Rgb8 b) { return !(a == b); }

inline constexpr Rgb8 kHeatUnselected{48, 48, 48};

// The ramp of the file comment. std::invalid_argument unless full_scale_lsb > 0 and finite.
Rgb8 heatColour(double error_lsb, double full_scale_lsb);

// Per-pixel e (max channel error) as heatColour; without a mask every pixel is coloured, with
// one the unset pixels are kHeatUnselected. std::invalid_argument on size mismatch or a bad
// full scale.
Image errorHeatmap(const Image& test, const ImageF& ref, double full_scale_lsb);
Image errorHeatmap(const Image& test, const ImageF& ref, double full_scale_lsb, const PixelMask& covered);

// RTL vs model, which must be identical.
// The pixels where a and b differ in any channel. std::invalid_argument if the sizes differ.
PixelMask differingPixels(const Image& a, const Image& b);

// The first differing pixel in row-major order, with both values; nullopt if identical.
struct PixelDiff {
  int x = 0, y = 0;
  Rgb8 a, b;
};
std::optional<PixelDiff> firstDifference(const Image& a, const Image& b);

// A picture of where a and b differ: differing pixels pure red (255, 0, 0); identical pixels
// show a's luma (Rec. 601, (77 R + 150 G + 29 B) >> 8) at a quarter brightness as grey (0..63),
// so the scene stays recognisable and no grey can be mistaken for a mark.
Image diffMask(const Image& a, const Image& b);

}  // namespace shd
