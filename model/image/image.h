// Images of the renderer: unorm8 RGB framebuffers (what the hardware writes and a person looks
// at), double-precision references in output LSB units, pixel masks, and PNG files.
//
// Layout: row-major, top row first, 3 samples per pixel (R, G, B); pixel (x, y) starts at sample
// 3 * (y * width + x). x grows to the right, y downwards, as on screen and in PNG.
//
// Units: Image holds the unorm8 codes 0..255 (colour = code / 255). ImageF holds the same
// quantity before rounding, value * 255, as a double ("LSB units"), so |Image - ImageF| is an
// error in output LSBs directly and the final rounding alone costs up to 0.5 LSB.
//
// PNG: 8-bit RGB, no alpha, with an sRGB chunk (libpng's simplified API, png_image_*, which
// handles libpng's errors internally with its own setjmp, so no longjmp crosses C++ frames).
// The encoded bytes are a pure function of the pixels (no time chunk), and the file is written
// atomically through writeFileAtomic (io/files.h): a reader sees the old file or the whole
// new one, never a partial PNG.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace shd {

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // 3 bytes per pixel, row-major, top row first

  Image() = default;
  // width x height black pixels. std::invalid_argument if a size is negative or the sample
  // count overflows size_t.
  Image(int width, int height);

  size_t pixelCount() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
  // The 3 samples of pixel (x, y); no bounds check (callers iterate inside the image).
  uint8_t* at(int x, int y) { return rgb.data() + index(x, y); }
  const uint8_t* at(int x, int y) const { return rgb.data() + index(x, y); }

 private:
  size_t index(int x, int y) const {
    return 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
  }
};

bool operator==(const Image& a, const Image& b);
inline bool operator!=(const Image& a, const Image& b) { return !(a == b); }

// A reference image: the unrounded colour times 255 per channel (output LSB units, nominally
// 0..255; values outside are kept, so an overshooting method shows its overshoot).
struct ImageF {
  int width = 0, height = 0;
  std::vector<double> rgb;  // 3 samples per pixel, row-major, top row first

  ImageF() = default;
  ImageF(int width, int height);  // all 0.0; std::invalid_argument as Image(w, h)
  // The samples given (taken over, not cleared and copied); std::invalid_argument unless there are
  // 3 per pixel.
  ImageF(int width, int height, std::vector<double> samples);

  size_t pixelCount() const { return static_cast<size_t>(width) * static_cast<size_t>(height); }
  double* at(int x, int y) { return rgb.data() + index(x, y); }
  const double* at(int x, int y) const { return rgb.data() + index(x, y); }

 private:
  size_t index(int x, int y) const {
    return 3 * (static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x));
  }
};

// The codes as LSB values (exact).
ImageF toImageF(const Image& img);

// Each sample clamped to [0, 255] and rounded half up (floor(v + 0.5)): how a reference is
// shown as a PNG. std::invalid_argument naming the pixel if a sample is NaN.
Image roundToUnorm8(const ImageF& ref);

// One flag per pixel, row-major, top row first: which pixels a metric or a heat map counts
// (covered pixels; the highlight region). The renderer builds it; this file only combines.
struct PixelMask {
  int width = 0, height = 0;
  std::vector<bool> bits;

  PixelMask() = default;
  PixelMask(int width, int height, bool value = false);  // std::invalid_argument as Image(w, h)

  bool test(int x, int y) const { return bits[index(x, y)]; }
  void set(int x, int y, bool value = true) { bits[index(x, y)] = value; }
  uint64_t count() const;  // pixels set

 private:
  size_t index(int x, int y) const {
    return static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x);
  }
};

// Pixels set in both. std::invalid_argument if the sizes differ.
PixelMask intersect(const PixelMask& a, const PixelMask& b);

// std::invalid_argument "<what>: sizes differ (w0xh0 vs w1xh1)" unless the sizes are equal.
void requireSameSize(int w0, int h0, int w1, int h1, const char* what);

// Pixels whose largest channel exceeds threshold (strictly): e.g. the highlight region, from an
// image of the reference specular term alone in LSB units.
PixelMask thresholdMask(const ImageF& img, double threshold);

// Writes img as an 8-bit RGB PNG, atomically (see the file comment).
// std::invalid_argument naming the path if the image is empty (PNG needs 1x1 at least), its
// buffer does not hold 3 * width * height bytes, or a row is too wide for libpng's stride.
// std::runtime_error naming the path if libpng fails to encode, or from writeFileAtomic (missing
// directory, disk full, ...: the temporary file is removed, the old file left as it was).
void writePng(const std::string& path, const Image& img);
// The PNG bytes writePng writes (path only names the file in errors): for an OutputFiles set.
std::string encodePng(const std::string& path, const Image& img);

// The PNG at path as 8-bit RGB. libpng's simplified reader converts any PNG: grey is expanded,
// 16-bit samples are reduced to 8-bit sRGB (16-bit data without gAMA/sRGB is taken as linear,
// libpng's default), alpha is composited onto black. Strict: std::runtime_error naming the path
// if the file cannot be opened, is not a PNG, is truncated anywhere (the file must end with the
// IEND chunk, which libpng's simplified reader alone would not check), carries bytes after IEND,
// is corrupt (CRC of a critical chunk, zlib), or holds more than 2^28 pixels (a guard against a
// corrupt header asking for terabytes).
Image readPng(const std::string& path);

}  // namespace shd
