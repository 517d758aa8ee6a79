// Small pictures of several images on one canvas: a box-filtered reduction and a grid of tiles,
// for the contact sheet of `shadesim report`. No text: whoever composes a sheet labels its
// cells by position (row, column) elsewhere.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "image/image.h"

namespace shd {

using Rgb = std::array<uint8_t, 3>;

// The image reduced by `factor` in each direction: each output pixel the mean of a factor x
// factor block, rounded half up (a block cut by the right or bottom edge averages the pixels it
// holds), ceil(width / factor) x ceil(height / factor) pixels. factor 1 returns a copy.
// std::invalid_argument if factor < 1 or the image is empty.
Image downscaleBox(const Image& img, int factor);

// a above b, `gap` rows of `background` between them, as wide as the wider (the narrower left
// aligned, the rest background).
Image stackVertical(const Image& a, const Image& b, int gap, Rgb background);

// Tiles in a grid of `columns` columns, row-major (tiles.size() / columns rows, rounded up),
// every cell tile_width x tile_height with `gap` pixels of background between cells and around
// the grid. A null tile leaves its cell `empty`; a tile is placed at its cell's top left and
// must fit in it. std::invalid_argument for columns < 1, no tiles, a tile larger than a cell or
// a negative gap.
Image tileGrid(const std::vector<const Image*>& tiles, int columns, int tile_width, int tile_height, int gap,
               Rgb background, Rgb empty);

}  // namespace shd
