#include "image/compose.h"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace shd {

namespace {

void fill(Image& img, Rgb c) {
  for (size_t i = 0; i < img.pixelCount(); ++i) std::copy(c.begin(), c.end(), img.rgb.begin() + 3 * i);
}

// src copied into dst with its top left at (x0, y0); src lies inside dst.
void blit(Image& dst, const Image& src, int x0, int y0) {
  for (int y = 0; y < src.height; ++y) std::copy_n(src.at(0, y), 3 * static_cast<size_t>(src.width), dst.at(x0, y0 + y));
}

}  // namespace

Image downscaleBox(const Image& img, int factor) {
  if (factor < 1) throw std::invalid_argument(fmt::format("downscaleBox: factor {} (must be at least 1)", factor));
  if (img.width < 1 || img.height < 1) throw std::invalid_argument("downscaleBox: an empty image");
  Image out((img.width + factor - 1) / factor, (img.height + factor - 1) / factor);
  for (int oy = 0; oy < out.height; ++oy)
    for (int ox = 0; ox < out.width; ++ox) {
      const int x1 = std::min(img.width, (ox + 1) * factor), y1 = std::min(img.height, (oy + 1) * factor);
      uint64_t sum[3] = {0, 0, 0}, n = 0;
      for (int y = oy * factor; y < y1; ++y)
        for (int x = ox * factor; x < x1; ++x, ++n)
          for (int k = 0; k < 3; ++k) sum[k] += img.at(x, y)[k];
      for (int k = 0; k < 3; ++k) out.at(ox, oy)[k] = static_cast<uint8_t>((2 * sum[k] + n) / (2 * n));
    }
  return out;
}

Image stackVertical(const Image& a, const Image& b, int gap, Rgb background) {
  if (gap < 0) throw std::invalid_argument("stackVertical: a negative gap");
  Image out(std::max(a.width, b.width), a.height + gap + b.height);
  fill(out, background);
  blit(out, a, 0, 0);
  blit(out, b, 0, a.height + gap);
  return out;
}

Image tileGrid(const std::vector<const Image*>& tiles, int columns, int tile_width, int tile_height, int gap,
               Rgb background, Rgb empty) {
  if (columns < 1 || tiles.empty() || gap < 0 || tile_width < 1 || tile_height < 1)
    throw std::invalid_argument(fmt::format("tileGrid: {} tiles in {} columns of {}x{} with gap {}", tiles.size(),
                                            columns, tile_width, tile_height, gap));
  const int rows = static_cast<int>((tiles.size() + static_cast<size_t>(columns) - 1) / static_cast<size_t>(columns));
  Image out(gap + columns * (tile_width + gap), gap + rows * (tile_height + gap));
  fill(out, background);
  Image blank(tile_width, tile_height);
  fill(blank, empty);
  for (size_t i = 0; i < tiles.size(); ++i) {
    const Image& t = tiles[i] != nullptr ? *tiles[i] : blank;
    if (t.width > tile_width || t.height > tile_height)
      throw std::invalid_argument(
          fmt::format("tileGrid: tile {} is {}x{}, larger than a cell {}x{}", i, t.width, t.height, tile_width, tile_height));
    const int c = static_cast<int>(i % static_cast<size_t>(columns)), r = static_cast<int>(i / static_cast<size_t>(columns));
    blit(out, t, gap + c * (tile_width + gap), gap + r * (tile_height + gap));
  }
  return out;
}

}  // namespace shd
