#include "image/metrics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

namespace shd {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Ref is ImageF (LSB values) or Image (codes, exact as doubles); mask nullptr selects all.
template <typename Ref>
ImageMetrics measure(const Image& test, const Ref& ref, const PixelMask* mask) {
  requireSameSize(test.width, test.height, ref.width, ref.height, "imageMetrics: test vs reference");
  if (mask) requireSameSize(test.width, test.height, mask->width, mask->height, "imageMetrics: test vs mask");

  ImageMetrics m;
  m.max_abs_lsb = -1;  // below any error, so the first selected pixel becomes the worst
  double sum_sq = 0;
  uint64_t over = 0;
  for (int y = 0; y < test.height; ++y) {
    for (int x = 0; x < test.width; ++x) {
      if (mask && !mask->test(x, y)) continue;
      const uint8_t* t = test.at(x, y);
      const auto* r = ref.at(x, y);
      double e = 0;
      for (int c = 0; c < 3; ++c) {
        const double rc = static_cast<double>(r[c]);
        if (!std::isfinite(rc))
          throw std::invalid_argument(
              fmt::format("imageMetrics: reference sample at ({}, {}) channel {} is {}", x, y, c, rc));
        const double d = std::fabs(static_cast<double>(t[c]) - rc);
        e = std::max(e, d);
        sum_sq += d * d;
      }
      ++m.pixels;
      if (e > 1.0) ++over;
      if (e > m.max_abs_lsb) {
        m.max_abs_lsb = e;
        m.worst_x = x;
        m.worst_y = y;
      }
    }
  }

  // Nothing selected: nothing measured (see the header).
  if (m.pixels == 0) {
    m.max_abs_lsb = 0;
    m.psnr_db = kInf;
    return m;
  }
  const double samples = 3.0 * static_cast<double>(m.pixels);
  m.rmse_lsb = std::sqrt(sum_sq / samples);
  m.psnr_db = m.rmse_lsb == 0 ? kInf : 20.0 * std::log10(255.0 / m.rmse_lsb);
  m.share_over_1lsb = static_cast<double>(over) / static_cast<double>(m.pixels);
  return m;
}

Image heatmap(const Image& test, const ImageF& ref, double full_scale_lsb, const PixelMask* mask) {
  requireSameSize(test.width, test.height, ref.width, ref.height, "errorHeatmap: test vs reference");
  if (mask) requireSameSize(test.width, test.height, mask->width, mask->height, "errorHeatmap: test vs mask");
  (void)heatColour(0, full_scale_lsb);  // validates the full scale even for an empty image

  Image out(test.width, test.height);
  for (int y = 0; y < test.height; ++y) {
    for (int x = 0; x < test.width; ++x) {
      Rgb8 c = kHeatUnselected;
      if (!mask || mask->test(x, y)) {
        const uint8_t* t = test.at(x, y);
        const double* r = ref.at(x, y);
        double e = 0;
        // NaN propagates into e through the comparison below being false, so test it apart.
        bool nan = false;
        for (int ch = 0; ch < 3; ++ch) {
          const double d = std::fabs(static_cast<double>(t[ch]) - r[ch]);
          nan = nan || std::isnan(d);
          e = std::max(e, d);
        }
        c = heatColour(nan ? std::numeric_limits<double>::quiet_NaN() : e, full_scale_lsb);
      }
      uint8_t* o = out.at(x, y);
      o[0] = c.r;
      o[1] = c.g;
      o[2] = c.b;
    }
  }
  return out;
}

Rgb8 pixel(const Image& img, int x, int y) {
  const uint8_t* p = img.at(x, y);
  return {p[0], p[1], p[2]};
}

}  // namespace

ImageMetrics imageMetrics(const Image& test, const ImageF& ref) { return measure(test, ref, nullptr); }
ImageMetrics imageMetrics(const Image& test, const ImageF& ref, const PixelMask& mask) {
  return measure(test, ref, &mask);
}
ImageMetrics imageMetrics(const Image& test, const Image& ref) { return measure(test, ref, nullptr); }
ImageMetrics imageMetrics(const Image& test, const Image& ref, const PixelMask& mask) {
  return measure(test, ref, &mask);
}

nlohmann::json toJson(const ImageMetrics& m) {
  return {
      {"max_abs_lsb", m.max_abs_lsb},
      {"worst_x", m.worst_x},
      {"worst_y", m.worst_y},
      {"rmse_lsb", m.rmse_lsb},
      {"psnr_db", std::isinf(m.psnr_db) ? nlohmann::json(nullptr) : nlohmann::json(m.psnr_db)},
      {"share_over_1lsb", m.share_over_1lsb},
      {"pixels", m.pixels},
  };
}

Rgb8 heatColour(double error_lsb, double full_scale_lsb) {
  if (!(full_scale_lsb > 0) || !std::isfinite(full_scale_lsb))
    throw std::invalid_argument(fmt::format("heat map full scale {} LSB is not a positive number", full_scale_lsb));
  if (error_lsb <= 0) return {0, 0, 0};
  if (!(error_lsb < full_scale_lsb)) return {255, 255, 255};  // clipped, or NaN

  // Stops at 0, 1/4, 1/2, 3/4, 1 of full scale (exact binary fractions, so half scale is
  // exactly green).
  static constexpr Rgb8 kStops[5] = {{0, 0, 0}, {0, 0, 255}, {0, 255, 0}, {255, 255, 0}, {255, 0, 0}};
  const double s = 4.0 * error_lsb / full_scale_lsb;  // in (0, 4)
  const int seg = std::min(3, static_cast<int>(s));
  const double u = s - seg;
  const Rgb8 a = kStops[seg], b = kStops[seg + 1];
  auto mix = [u](uint8_t p, uint8_t q) {
    return static_cast<uint8_t>(std::floor(p + (static_cast<double>(q) - p) * u + 0.5));
  };
  return {mix(a.r, b.r), mix(a.g, b.g), mix(a.b, b.b)};
}

Image errorHeatmap(const Image& test, const ImageF& ref, double full_scale_lsb) {
  return heatmap(test, ref, full_scale_lsb, nullptr);
}
Image errorHeatmap(const Image& test, const ImageF& ref, double full_scale_lsb, const PixelMask& covered) {
  return heatmap(test, ref, full_scale_lsb, &covered);
}

PixelMask differingPixels(const Image& a, const Image& b) {
  requireSameSize(a.width, a.height, b.width, b.height, "differingPixels");
  PixelMask out(a.width, a.height);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) out.set(x, y, pixel(a, x, y) != pixel(b, x, y));
  return out;
}

std::optional<PixelDiff> firstDifference(const Image& a, const Image& b) {
  requireSameSize(a.width, a.height, b.width, b.height, "firstDifference");
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x)
      if (pixel(a, x, y) != pixel(b, x, y)) return PixelDiff{x, y, pixel(a, x, y), pixel(b, x, y)};
  return std::nullopt;
}

Image diffMask(const Image& a, const Image& b) {
  requireSameSize(a.width, a.height, b.width, b.height, "diffMask");
  Image out(a.width, a.height);
  for (int y = 0; y < a.height; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const Rgb8 pa = pixel(a, x, y);
      uint8_t* o = out.at(x, y);
      if (pa != pixel(b, x, y)) {
        o[0] = 255;
        o[1] = 0;
        o[2] = 0;
        continue;
      }
      const unsigned luma = (77u * pa.r + 150u * pa.g + 29u * pa.b) >> 8;  // 0..255
      o[0] = o[1] = o[2] = static_cast<uint8_t>(luma / 4);
    }
  }
  return out;
}

}  // namespace shd
