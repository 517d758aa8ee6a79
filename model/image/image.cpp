#include "image/image.h"

#include <png.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "device/prom_io.h"
#include "io/files.h"

namespace shd {

namespace {

// width * height * channels, checked: sizes come from callers and from PNG headers.
size_t checkedSamples(int width, int height, size_t channels, const char* what) {
  if (width < 0 || height < 0)
    throw std::invalid_argument(fmt::format("{}: negative size {}x{}", what, width, height));
  const size_t w = static_cast<size_t>(width), h = static_cast<size_t>(height);
  const size_t max = std::numeric_limits<size_t>::max();
  if (w != 0 && h > max / w / channels)
    throw std::invalid_argument(fmt::format("{}: size {}x{} overflows", what, width, height));
  return w * h * channels;
}

// A png_image ready for the simplified API (the header asks for a zeroed struct with version).
png_image blankPngImage() {
  png_image img;
  std::memset(&img, 0, sizeof img);
  img.version = PNG_IMAGE_VERSION;
  return img;
}

// 2^28 pixels (16384 x 16384): far above any framebuffer here, far below what a corrupt header
// (libpng accepts up to 10^6 x 10^6 by default) would make us allocate.
constexpr uint64_t kMaxReadPixels = uint64_t{1} << 28;

}  // namespace

void requireSameSize(int w0, int h0, int w1, int h1, const char* what) {
  if (w0 != w1 || h0 != h1)
    throw std::invalid_argument(fmt::format("{}: sizes differ ({}x{} vs {}x{})", what, w0, h0, w1, h1));
}

Image::Image(int w, int h) : width(w), height(h), rgb(checkedSamples(w, h, 3, "Image"), 0) {}

ImageF::ImageF(int w, int h) : width(w), height(h), rgb(checkedSamples(w, h, 3, "ImageF"), 0.0) {}

ImageF::ImageF(int w, int h, std::vector<double> samples) : width(w), height(h), rgb(std::move(samples)) {
  if (rgb.size() != checkedSamples(w, h, 3, "ImageF"))
    throw std::invalid_argument(fmt::format("ImageF: {} samples for {}x{} pixels", rgb.size(), w, h));
}

PixelMask::PixelMask(int w, int h, bool value)
    : width(w), height(h), bits(checkedSamples(w, h, 1, "PixelMask"), value) {}

bool operator==(const Image& a, const Image& b) {
  return a.width == b.width && a.height == b.height && a.rgb == b.rgb;
}

uint64_t PixelMask::count() const {
  return static_cast<uint64_t>(std::count(bits.begin(), bits.end(), true));
}

ImageF toImageF(const Image& img) {
  ImageF out(img.width, img.height);
  std::copy(img.rgb.begin(), img.rgb.end(), out.rgb.begin());
  return out;
}

Image roundToUnorm8(const ImageF& ref) {
  Image out(ref.width, ref.height);
  for (size_t i = 0; i < ref.rgb.size(); ++i) {
    const double v = ref.rgb[i];
    if (std::isnan(v)) {
      const size_t p = i / 3;
      throw std::invalid_argument(fmt::format("roundToUnorm8: NaN at pixel ({}, {}) channel {}",
                                              p % static_cast<size_t>(ref.width),
                                              p / static_cast<size_t>(ref.width), i % 3));
    }
    out.rgb[i] = static_cast<uint8_t>(std::floor(std::clamp(v, 0.0, 255.0) + 0.5));
  }
  return out;
}

PixelMask intersect(const PixelMask& a, const PixelMask& b) {
  requireSameSize(a.width, a.height, b.width, b.height, "intersect");
  PixelMask out(a.width, a.height);
  for (size_t i = 0; i < a.bits.size(); ++i) out.bits[i] = a.bits[i] && b.bits[i];
  return out;
}

PixelMask thresholdMask(const ImageF& img, double threshold) {
  PixelMask out(img.width, img.height);
  for (size_t p = 0; p < out.bits.size(); ++p) {
    const double* s = img.rgb.data() + 3 * p;
    out.bits[p] = s[0] > threshold || s[1] > threshold || s[2] > threshold;
  }
  return out;
}

std::string encodePng(const std::string& path, const Image& img) {
  // Degenerate images first: PNG has no 0-pixel image, and libpng's stride is a png_int_32.
  if (img.width < 1 || img.height < 1)
    throw std::invalid_argument(fmt::format("cannot write PNG '{}': empty image {}x{}", path, img.width, img.height));
  if (img.rgb.size() != checkedSamples(img.width, img.height, 3, "writePng"))
    throw std::invalid_argument(fmt::format("cannot write PNG '{}': {}x{} image holds {} bytes, expected {}",
                                            path, img.width, img.height, img.rgb.size(), 3 * img.pixelCount()));
  if (img.width > std::numeric_limits<png_int_32>::max() / 3)
    throw std::invalid_argument(fmt::format("cannot write PNG '{}': width {} too large", path, img.width));

  png_image png = blankPngImage();
  png.width = static_cast<png_uint_32>(img.width);
  png.height = static_cast<png_uint_32>(img.height);
  png.format = PNG_FORMAT_RGB;
  // Fast: no row filters, zlib level 3 (libpng's simplified API). A report writes hundreds of
  // images, and libpng's default (adaptive filters, level 6) made zlib and libpng 37 % of
  // `shadesim report` on builtin:plane (perf); with this flag the report took 0.69-0.76 of the
  // time (2 interleaved rounds), its output 25.2 MB instead of 18.3. Still lossless: the pixels
  // read back are the same.
  png.flags = PNG_IMAGE_FLAG_FAST;

  // One pass into a buffer of the documented worst-case size (uncompressed data plus zlib and
  // chunk overhead), then trimmed to what was written.
  png_alloc_size_t size = PNG_IMAGE_PNG_SIZE_MAX(png);
  std::string bytes(size, '\0');
  const int ok = png_image_write_to_memory(&png, bytes.data(), &size, /*convert_to_8_bit=*/0, img.rgb.data(),
                                           /*row_stride=*/3 * img.width, /*colormap=*/nullptr);
  if (!ok || PNG_IMAGE_FAILED(png)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw std::runtime_error(fmt::format("cannot write PNG '{}': libpng: {}", path, message));
  }
  png_image_free(&png);
  bytes.resize(size);
  return bytes;
}

void writePng(const std::string& path, const Image& img) { writeFileAtomic(path, encodePng(path, img)); }

Image readPng(const std::string& path) {
  // The whole file first (PNGs here are a few MB at most): errno names an open failure, and the
  // tail can be checked, which libpng's simplified reader does not do (it stops after IDAT).
  if (const std::string why = inputFileProblem(path, uint64_t{256} << 20); !why.empty())
    throw std::runtime_error(fmt::format("cannot read PNG '{}': {}", path, why));
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read PNG '{}': open: {}", path, std::strerror(errno)));
  noteInput(path);
  std::ostringstream buf;
  buf << in.rdbuf();
  if (in.bad()) throw std::runtime_error(fmt::format("cannot read PNG '{}': read failed", path));
  const std::string bytes = buf.str();
  if (bytes.empty()) {
    std::error_code ec;
    const bool dir = std::filesystem::is_directory(path, ec);
    throw std::runtime_error(fmt::format("cannot read PNG '{}': {}", path, dir ? "is a directory" : "empty file"));
  }

  // IEND, the last chunk: length 0, type "IEND", CRC ae426082.
  static const std::string kIend("\0\0\0\0IEND\xae\x42\x60\x82", 12);
  if (bytes.size() < kIend.size() || bytes.compare(bytes.size() - kIend.size(), kIend.size(), kIend) != 0) {
    // Let libpng name a bad signature or header first; blame the tail only if those are fine.
    png_image probe = blankPngImage();
    const bool header_ok = png_image_begin_read_from_memory(&probe, bytes.data(), bytes.size()) != 0;
    const std::string message = header_ok ? "truncated or trailing data (the file does not end with IEND)"
                                          : std::string("header: ") + probe.message;
    png_image_free(&probe);
    throw std::runtime_error(fmt::format("cannot read PNG '{}': {}", path, message));
  }

  png_image png = blankPngImage();
  auto fail = [&](const char* step) -> std::runtime_error {
    const std::string message = png.message;
    png_image_free(&png);  // idempotent: libpng may already have freed it on error
    return std::runtime_error(fmt::format("cannot read PNG '{}': {}: {}", path, step, message));
  };

  if (!png_image_begin_read_from_memory(&png, bytes.data(), bytes.size())) throw fail("header");
  if (uint64_t{png.width} * png.height > kMaxReadPixels) {
    png_image_free(&png);
    throw std::runtime_error(fmt::format("cannot read PNG '{}': {}x{} is more than the {} pixels readPng accepts",
                                         path, png.width, png.height, kMaxReadPixels));
  }
  png.format = PNG_FORMAT_RGB;
  Image out(static_cast<int>(png.width), static_cast<int>(png.height));
  // background nullptr: alpha, if any, is composited onto the buffer, which is black.
  if (!png_image_finish_read(&png, /*background=*/nullptr, out.rgb.data(),
                             /*row_stride=*/static_cast<png_int_32>(3 * png.width), /*colormap=*/nullptr))
    throw fail("image data");
  png_image_free(&png);
  return out;
}

}  // namespace shd
