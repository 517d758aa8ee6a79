// Two software scanline rasterisers that differ only in how the colour advances along a raster
// line, to time the paper's claim (section 4.1, "1.7 times") in software as well as in cycles:
//
//   classical          per raster line: interpolate the attribute along the left AND the right
//                      edge, then divide by the span length (one division per line) for the
//                      step dI = (I_R - I_L) / (x_R - x_L); the idx3d-style loop of the
//                      paper's listings.
//   constant increment dI/dx is computed once per triangle (the plane gradient, docs/paper-corrections.md 4.1);
//                      per line only the left-edge value is needed; no division per line.
//
// Both walk the same spans (edges interpolated in float, pixel centres, the same rounding of
// the span ends), write attribute 0 rounded to an integer per pixel, and work in float as the
// Java code did. They are timing subjects, not references: their images may differ from each
// other (and from the fixed-point unit) by the float rounding of the step, which
// test_soft_raster bounds.
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace shd {

struct SoftVertex {
  float x, y, a;  // pixels (y down) and one attribute
};

struct SoftFramebuffer {
  int width = 0, height = 0;
  std::vector<int32_t> px;  // width * height, -1 where nothing was drawn
  SoftFramebuffer(int w, int h) : width(w), height(h), px(static_cast<std::size_t>(w) * static_cast<std::size_t>(h), -1) {}
};

// Counts of the work done, for the report.
struct SoftStats {
  uint64_t lines = 0, pixels = 0, divisions = 0;
};

void rasterClassical(const std::array<SoftVertex, 3>& v, SoftFramebuffer& fb, SoftStats& st);
void rasterConstantIncrement(const std::array<SoftVertex, 3>& v, SoftFramebuffer& fb, SoftStats& st);

}  // namespace shd
