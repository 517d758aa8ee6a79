// Images: PNG files round-trip byte-exact, are written atomically and read strictly; the
// metrics follow their definitions (metrics.h) on hand-made cases; the heat map's ramp and the
// masks are respected; the RTL-vs-model diff tools find every differing pixel; the contact
// sheet's composition (compose.h) averages, stacks and tiles as stated.
#include "image/compose.h"
#include "image/image.h"
#include "image/metrics.h"

#include <gtest/gtest.h>

#include "test_util.h"
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using shd::Image;
using shd::ImageF;
using shd::ImageMetrics;
using shd::PixelMask;
using shd::Rgb8;
using shd::testutil::errorOf;

namespace {

constexpr uint32_t kSeed = 20261122;

std::string readAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeAll(const fs::path& p, const std::string& bytes) {
  std::ofstream(p, std::ios::binary) << bytes;
}

Image randomImage(int w, int h, std::mt19937& rng) {
  Image img(w, h);
  std::uniform_int_distribution<int> byte(0, 255);
  for (uint8_t& s : img.rgb) s = static_cast<uint8_t>(byte(rng));
  return img;
}

Image filled(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
  Image img(w, h);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      img.at(x, y)[0] = r;
      img.at(x, y)[1] = g;
      img.at(x, y)[2] = b;
    }
  return img;
}

Rgb8 px(const Image& img, int x, int y) { return {img.at(x, y)[0], img.at(x, y)[1], img.at(x, y)[2]}; }

std::string str(Rgb8 c) {
  return "(" + std::to_string(c.r) + ", " + std::to_string(c.g) + ", " + std::to_string(c.b) + ")";
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Image, ImageF, PixelMask

TEST(Image, LayoutIsRowMajorTopRowFirst) {
  Image img(3, 2);
  EXPECT_EQ(img.rgb.size(), 18u);
  EXPECT_EQ(img.pixelCount(), 6u);
  img.at(2, 1)[1] = 7;
  EXPECT_EQ(img.rgb[3 * (1 * 3 + 2) + 1], 7);
  EXPECT_THROW(Image(-1, 2), std::invalid_argument);
  EXPECT_THROW(ImageF(2, -1), std::invalid_argument);
  EXPECT_THROW(PixelMask(-3, 1), std::invalid_argument);
}

TEST(Image, RoundToUnorm8ClampsAndRoundsHalfUp) {
  ImageF f(6, 1);
  const double in[6] = {-3.0, 0.49, 0.5, 127.5, 254.6, 300.0};
  const uint8_t want[6] = {0, 0, 1, 128, 255, 255};
  for (int x = 0; x < 6; ++x) f.at(x, 0)[0] = f.at(x, 0)[1] = f.at(x, 0)[2] = in[x];
  const Image q = shd::roundToUnorm8(f);
  for (int x = 0; x < 6; ++x) EXPECT_EQ(q.at(x, 0)[2], want[x]) << "input " << in[x];
  EXPECT_EQ(shd::toImageF(q).rgb[3 * 3], 128.0);
  f.at(4, 0)[1] = std::numeric_limits<double>::quiet_NaN();
  const std::string e = errorOf<std::invalid_argument>([&] { shd::roundToUnorm8(f); });
  EXPECT_NE(e.find("(4, 0) channel 1"), std::string::npos) << e;
}

TEST(PixelMask, ThresholdIsStrictOnTheLargestChannelAndIntersectIsAnd) {
  ImageF spec(3, 1);
  spec.at(0, 0)[0] = 2.0;  // not above 2
  spec.at(1, 0)[2] = 2.5;  // above, in blue only
  const PixelMask hi = shd::thresholdMask(spec, 2.0);
  EXPECT_FALSE(hi.test(0, 0));
  EXPECT_TRUE(hi.test(1, 0));
  EXPECT_FALSE(hi.test(2, 0));
  EXPECT_EQ(hi.count(), 1u);
  PixelMask covered(3, 1, true);
  covered.set(1, 0, false);
  EXPECT_EQ(shd::intersect(hi, covered).count(), 0u);
  EXPECT_THROW(shd::intersect(hi, PixelMask(2, 1)), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// PNG

TEST(Png, RoundTripIsByteExactForRandomImages) {
  std::cout << "seed " << kSeed << "\n";
  std::mt19937 rng(kSeed);
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const int sizes[][2] = {{1, 1}, {3, 7}, {7, 3}, {1, 300}, {300, 1}, {512, 512}};
  for (const auto& s : sizes) {
    const Image img = randomImage(s[0], s[1], rng);
    const fs::path p = dir / ("img_" + std::to_string(s[0]) + "x" + std::to_string(s[1]) + ".png");
    shd::writePng(p.string(), img);
    const Image back = shd::readPng(p.string());
    ASSERT_EQ(back.width, img.width);
    ASSERT_EQ(back.height, img.height);
    EXPECT_TRUE(back == img) << s[0] << "x" << s[1] << " differs after the round trip";
  }
  EXPECT_EQ(shd::testutil::dirEntries(dir).size(), std::size(sizes));  // no temporaries left
}

TEST(Png, EncodingIsAPureFunctionOfThePixels) {
  std::mt19937 rng(kSeed + 1);
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const Image img = randomImage(33, 17, rng);
  shd::writePng((dir / "a.png").string(), img);
  shd::writePng((dir / "b.png").string(), img);
  const std::string a = readAll(dir / "a.png");
  EXPECT_EQ(a, readAll(dir / "b.png"));
  EXPECT_EQ(a.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8));
}

TEST(Png, MissingDirectoryThrowsAndLeavesNothing) {
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const fs::path p = dir / "no_such_dir" / "out.png";
  const std::string e = errorOf<std::runtime_error>([&] { shd::writePng(p.string(), filled(2, 2, 1, 2, 3)); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_FALSE(fs::exists(dir / "no_such_dir"));
  EXPECT_TRUE(shd::testutil::dirEntries(dir).empty());
}

TEST(Png, OverwriteReplacesTheFileWithNoTemporaryLeft) {
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const fs::path p = dir / "frame.png";
  shd::writePng(p.string(), filled(4, 4, 10, 20, 30));
  const Image second = filled(9, 5, 200, 100, 0);
  shd::writePng(p.string(), second);
  EXPECT_TRUE(shd::readPng(p.string()) == second);
  EXPECT_EQ(shd::testutil::dirEntries(dir), std::vector<std::string>{"frame.png"});
}

TEST(Png, WriteOverADirectoryThrowsAndLeavesItAlone) {
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const fs::path target = dir / "frame.png";
  fs::create_directory(target);
  const std::string e = errorOf<std::runtime_error>([&] { shd::writePng(target.string(), filled(1, 1, 0, 0, 0)); });
  EXPECT_NE(e.find(target.string()), std::string::npos) << e;
  EXPECT_EQ(shd::testutil::dirEntries(dir), std::vector<std::string>{"frame.png"});
  EXPECT_TRUE(fs::is_directory(target));
}

TEST(Png, WriteRejectsEmptyAndMisSizedImages) {
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const std::string p = (dir / "x.png").string();
  std::string e = errorOf<std::invalid_argument>([&] { shd::writePng(p, Image()); });
  EXPECT_NE(e.find(p), std::string::npos) << e;
  Image bad(2, 2);
  bad.rgb.pop_back();
  e = errorOf<std::invalid_argument>([&] { shd::writePng(p, bad); });
  EXPECT_NE(e.find("11 bytes, expected 12"), std::string::npos) << e;
  EXPECT_TRUE(shd::testutil::dirEntries(dir).empty());
}

TEST(Png, ReadRejectsMissingTruncatedAndCorruptFilesNamingThem) {
  std::mt19937 rng(kSeed + 2);
  const fs::path dir = shd::testutil::freshTestDir("test_image");
  const fs::path good = dir / "good.png";
  shd::writePng(good.string(), randomImage(64, 48, rng));  // random: incompressible, a long IDAT
  const std::string bytes = readAll(good);
  ASSERT_GT(bytes.size(), 64u * 48u * 3u);

  const auto expectRejected = [&](const fs::path& p, const std::string& why) {
    const std::string e = errorOf<std::runtime_error>([&] { shd::readPng(p.string()); });
    EXPECT_NE(e.find("cannot read PNG '" + p.string() + "'"), std::string::npos) << why << ": '" << e << "'";
  };
  EXPECT_EQ(shd::readPng(good.string()).width, 64);
  expectRejected(dir / "missing.png", "missing file");
  writeAll(dir / "empty.png", "");
  expectRejected(dir / "empty.png", "empty file");
  fs::create_directory(dir / "dir.png");
  expectRejected(dir / "dir.png", "a directory");
  writeAll(dir / "text.png", "this is not a PNG file at all, just some text\n");
  expectRejected(dir / "text.png", "not a PNG");

  // Truncated: inside the signature, inside IHDR, inside IDAT (several places), and inside or
  // before IEND (the last 12 bytes; all pixel data is there, libpng alone would accept it).
  for (size_t len : {size_t{4}, size_t{8}, size_t{20}, size_t{40}, bytes.size() / 4, bytes.size() / 2,
                     bytes.size() - 40, bytes.size() - 13, bytes.size() - 12, bytes.size() - 4,
                     bytes.size() - 1}) {
    const fs::path p = dir / ("trunc_" + std::to_string(len) + ".png");
    writeAll(p, bytes.substr(0, len));
    expectRejected(p, "truncated to " + std::to_string(len) + " of " + std::to_string(bytes.size()) + " bytes");
  }

  // Trailing bytes after IEND.
  writeAll(dir / "trailing.png", bytes + "junk");
  expectRejected(dir / "trailing.png", "bytes after IEND");

  // Corrupt: one flipped bit in the signature, in IHDR (CRC), and in the middle of the IDAT
  // data (CRC).
  for (size_t at : {size_t{1}, size_t{18}, bytes.size() / 2}) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    const fs::path p = dir / ("flip_" + std::to_string(at) + ".png");
    writeAll(p, bad);
    expectRejected(p, "bit flipped at byte " + std::to_string(at));
  }
}

TEST(Png, ReadRefusesAHeaderAskingForTooManyPixels) {
  // A valid 100000 x 100000 RGB PNG header (CRCs correct, within libpng's 10^6 limit) with an
  // empty IDAT: refused from the header, before allocating 30 GB.
  const std::string huge(
      "\x89\x50\x4e\x47\x0d\x0a\x1a\x0a\x00\x00\x00\x0d\x49\x48\x44\x52\x00\x01\x86\xa0\x00\x01"
      "\x86\xa0\x08\x02\x00\x00\x00\x27\x30\x9c\x9f\x00\x00\x00\x08\x49\x44\x41\x54\x78\x9c\x03\x00"
      "\x00\x00\x00\x01\x48\x06\x89\xd2\x00\x00\x00\x00\x49\x45\x4e\x44\xae\x42\x60\x82",
      65);
  const fs::path p = shd::testutil::freshTestDir("test_image") / "huge.png";
  writeAll(p, huge);
  const std::string e = errorOf<std::runtime_error>([&] { shd::readPng(p.string()); });
  EXPECT_NE(e.find(p.string()), std::string::npos) << e;
  EXPECT_NE(e.find("100000x100000"), std::string::npos) << e;
}

// ---------------------------------------------------------------------------------------------
// Metrics

TEST(ImageMetrics, IdenticalImagesHaveZeroErrorAndInfinitePsnr) {
  std::mt19937 rng(kSeed + 3);
  const Image img = randomImage(13, 11, rng);
  for (const ImageMetrics& m : {shd::imageMetrics(img, shd::toImageF(img)), shd::imageMetrics(img, img)}) {
    EXPECT_EQ(m.max_abs_lsb, 0.0);
    EXPECT_EQ(m.rmse_lsb, 0.0);
    EXPECT_TRUE(std::isinf(m.psnr_db) && m.psnr_db > 0);
    EXPECT_EQ(m.share_over_1lsb, 0.0);
    EXPECT_EQ(m.pixels, 13u * 11u);
    EXPECT_EQ(m.worst_x, 0);  // every pixel ties at 0: the first one is the worst
    EXPECT_EQ(m.worst_y, 0);
    const nlohmann::json j = shd::toJson(m);
    EXPECT_TRUE(j.at("psnr_db").is_null()) << j.dump();
    EXPECT_EQ(j.at("pixels"), 143);
  }
}

TEST(ImageMetrics, OnePixelOffByThreeInOneChannel) {
  const int w = 10, h = 7;
  const double n = w * h;
  const Image ref = filled(w, h, 100, 150, 200);
  Image test = ref;
  test.at(6, 4)[1] = 147;
  for (const ImageMetrics& m : {shd::imageMetrics(test, shd::toImageF(ref)), shd::imageMetrics(test, ref)}) {
    EXPECT_EQ(m.max_abs_lsb, 3.0);
    EXPECT_EQ(m.worst_x, 6);
    EXPECT_EQ(m.worst_y, 4);
    EXPECT_DOUBLE_EQ(m.share_over_1lsb, 1.0 / n);
    EXPECT_DOUBLE_EQ(m.rmse_lsb, std::sqrt(9.0 / (3.0 * n)));
    EXPECT_DOUBLE_EQ(m.psnr_db, 20.0 * std::log10(255.0 / std::sqrt(9.0 / (3.0 * n))));
    EXPECT_EQ(m.pixels, static_cast<uint64_t>(n));
    EXPECT_DOUBLE_EQ(shd::toJson(m).at("psnr_db").get<double>(), m.psnr_db);
  }
}

TEST(ImageMetrics, FractionalReferenceAndTheStrictOneLsbThreshold) {
  // Reference half an LSB off everywhere: the rounding error of a perfect renderer.
  const Image test = filled(4, 1, 10, 10, 10);
  ImageF ref = shd::toImageF(test);
  for (double& s : ref.rgb) s += 0.5;
  ImageMetrics m = shd::imageMetrics(test, ref);
  EXPECT_EQ(m.max_abs_lsb, 0.5);
  EXPECT_EQ(m.rmse_lsb, 0.5);
  EXPECT_EQ(m.share_over_1lsb, 0.0);
  // Exactly 1 LSB is not over 1; 1.25 is. Pixel error is the max over channels.
  ref.at(1, 0)[0] = 11.0;   // error 1
  ref.at(2, 0)[2] = 8.75;   // error 1.25
  ref.at(3, 0)[1] = 11.25;  // error 1.25, a tie: the first one (2, 0) is the worst
  m = shd::imageMetrics(test, ref);
  EXPECT_EQ(m.max_abs_lsb, 1.25);
  EXPECT_EQ(m.worst_x, 2);
  EXPECT_EQ(m.share_over_1lsb, 0.5);
  const double sum_sq = 9 * 0.25 + 1.0 + 2 * 1.5625;  // nine samples still 0.5 off
  EXPECT_DOUBLE_EQ(m.rmse_lsb, std::sqrt(sum_sq / 12.0));
}

TEST(ImageMetrics, MaskSelectsPixels) {
  const Image ref = filled(5, 4, 50, 50, 50);
  Image test = ref;
  test.at(0, 0)[0] = 90;  // huge error, outside the mask
  test.at(3, 2)[2] = 52;  // inside
  PixelMask mask(5, 4);
  mask.set(3, 2);
  mask.set(4, 3);
  const ImageMetrics m = shd::imageMetrics(test, shd::toImageF(ref), mask);
  EXPECT_EQ(m.pixels, 2u);
  EXPECT_EQ(m.max_abs_lsb, 2.0);
  EXPECT_EQ(m.worst_x, 3);
  EXPECT_EQ(m.worst_y, 2);
  EXPECT_EQ(m.share_over_1lsb, 0.5);
  EXPECT_DOUBLE_EQ(m.rmse_lsb, std::sqrt(4.0 / 6.0));

  // Nothing selected: nothing measured.
  const ImageMetrics none = shd::imageMetrics(test, ref, PixelMask(5, 4));
  EXPECT_EQ(none.pixels, 0u);
  EXPECT_EQ(none.max_abs_lsb, 0.0);
  EXPECT_EQ(none.rmse_lsb, 0.0);
  EXPECT_TRUE(std::isinf(none.psnr_db));
  EXPECT_EQ(none.worst_x, -1);
  EXPECT_EQ(none.worst_y, -1);
  EXPECT_EQ(none.share_over_1lsb, 0.0);
}

TEST(ImageMetrics, RejectsSizeMismatchAndNonFiniteReference) {
  const Image test(4, 4);
  EXPECT_THROW(shd::imageMetrics(test, ImageF(4, 5)), std::invalid_argument);
  EXPECT_THROW(shd::imageMetrics(test, Image(3, 4)), std::invalid_argument);
  EXPECT_THROW(shd::imageMetrics(test, ImageF(4, 4), PixelMask(4, 3)), std::invalid_argument);
  ImageF ref(4, 4);
  ref.at(1, 2)[0] = std::numeric_limits<double>::quiet_NaN();
  const std::string e = errorOf<std::invalid_argument>([&] { shd::imageMetrics(test, ref); });
  EXPECT_NE(e.find("(1, 2)"), std::string::npos) << e;
  PixelMask skip(4, 4, true);
  skip.set(1, 2, false);
  EXPECT_NO_THROW(shd::imageMetrics(test, ref, skip));  // only selected samples must be finite
}

// ---------------------------------------------------------------------------------------------
// Heat map

TEST(HeatColour, RampStopsAndClipping) {
  const double fs = 8.0;
  EXPECT_EQ(shd::heatColour(0.0, fs), (Rgb8{0, 0, 0}));
  EXPECT_EQ(shd::heatColour(1.0, fs), (Rgb8{0, 0, 128}));     // 1/8: half way black -> blue
  EXPECT_EQ(shd::heatColour(2.0, fs), (Rgb8{0, 0, 255}));     // 1/4 blue
  EXPECT_EQ(shd::heatColour(4.0, fs), (Rgb8{0, 255, 0}));     // 1/2 green
  EXPECT_EQ(shd::heatColour(6.0, fs), (Rgb8{255, 255, 0}));   // 3/4 yellow
  EXPECT_EQ(shd::heatColour(7.999, fs), (Rgb8{255, 0, 0}));   // just below full scale: red
  EXPECT_EQ(shd::heatColour(8.0, fs), (Rgb8{255, 255, 255}));  // full scale: white
  EXPECT_EQ(shd::heatColour(1e9, fs), (Rgb8{255, 255, 255}));
  EXPECT_EQ(shd::heatColour(std::numeric_limits<double>::quiet_NaN(), fs), (Rgb8{255, 255, 255}));
  EXPECT_THROW(shd::heatColour(1.0, 0.0), std::invalid_argument);
  EXPECT_THROW(shd::heatColour(1.0, -2.0), std::invalid_argument);
  EXPECT_THROW(shd::heatColour(1.0, std::numeric_limits<double>::infinity()), std::invalid_argument);
  // Below full scale the ramp gives no grey but black (errors under fs/2040 round to black), so
  // never the grey of unselected pixels.
  for (int i = 1; i < 8000; ++i) {
    const Rgb8 c = shd::heatColour(i / 1000.0, fs);
    if (c == Rgb8{0, 0, 0}) continue;
    EXPECT_FALSE(c.r == c.g && c.g == c.b) << "error " << i / 1000.0 << " gives grey " << str(c);
  }
  EXPECT_EQ(shd::heatColour(fs / 2040 * 0.99, fs), (Rgb8{0, 0, 0}));
  EXPECT_EQ(shd::heatColour(fs / 2040 * 1.01, fs), (Rgb8{0, 0, 1}));
}

TEST(ErrorHeatmap, ColoursFollowTheMaxChannelErrorAndTheMask) {
  const double fs = 6.0;
  const Image test = filled(4, 2, 100, 100, 100);
  ImageF ref = shd::toImageF(test);
  ref.at(1, 0)[2] = 103.0;  // half scale, in blue
  ref.at(2, 0)[0] = 94.0;   // full scale
  ref.at(2, 0)[1] = 99.0;   // smaller error in another channel: the max counts
  ref.at(3, 0)[0] = 101.5;  // 1/4 scale
  ref.at(0, 1)[0] = 160.0;  // huge, but unselected below

  const Image all = shd::errorHeatmap(test, ref, fs);
  EXPECT_EQ(px(all, 0, 0), (Rgb8{0, 0, 0}));
  EXPECT_EQ(px(all, 1, 0), (Rgb8{0, 255, 0}));
  EXPECT_EQ(px(all, 2, 0), (Rgb8{255, 255, 255}));
  EXPECT_EQ(px(all, 3, 0), (Rgb8{0, 0, 255}));
  EXPECT_EQ(px(all, 0, 1), (Rgb8{255, 255, 255}));

  PixelMask covered(4, 2, true);
  covered.set(0, 1, false);
  covered.set(1, 1, false);
  const Image masked = shd::errorHeatmap(test, ref, fs, covered);
  EXPECT_EQ(px(masked, 0, 1), shd::kHeatUnselected);
  EXPECT_EQ(px(masked, 1, 1), shd::kHeatUnselected);
  EXPECT_EQ(px(masked, 2, 1), (Rgb8{0, 0, 0}));
  EXPECT_EQ(px(masked, 1, 0), (Rgb8{0, 255, 0}));
  EXPECT_EQ(shd::kHeatUnselected, (Rgb8{48, 48, 48}));

  EXPECT_THROW(shd::errorHeatmap(test, ImageF(4, 3), fs), std::invalid_argument);
  EXPECT_THROW(shd::errorHeatmap(test, ref, fs, PixelMask(3, 2)), std::invalid_argument);
  EXPECT_THROW(shd::errorHeatmap(test, ref, 0.0), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// RTL vs model

TEST(ImageDiff, FindsEveryDifferingPixelAndTheFirst) {
  std::cout << "seed " << kSeed + 4 << "\n";
  std::mt19937 rng(kSeed + 4);
  const Image a = randomImage(17, 9, rng);
  EXPECT_EQ(shd::differingPixels(a, a).count(), 0u);
  EXPECT_FALSE(shd::firstDifference(a, a).has_value());

  Image b = a;
  b.at(5, 3)[2] ^= 1;  // lowest bit of one channel
  b.at(16, 8)[0] ^= 0x80;
  b.at(2, 6)[1] ^= 4;
  const PixelMask d = shd::differingPixels(a, b);
  EXPECT_EQ(d.count(), 3u);
  EXPECT_TRUE(d.test(5, 3) && d.test(16, 8) && d.test(2, 6));
  const auto first = shd::firstDifference(a, b);
  ASSERT_TRUE(first.has_value());
  EXPECT_EQ(first->x, 5);
  EXPECT_EQ(first->y, 3);
  EXPECT_EQ(first->a, px(a, 5, 3));
  EXPECT_EQ(first->b, px(b, 5, 3));

  const Image m = shd::diffMask(a, b);
  for (int y = 0; y < a.height; ++y)
    for (int x = 0; x < a.width; ++x) {
      const Rgb8 c = px(m, x, y);
      if (d.test(x, y)) {
        EXPECT_EQ(c, (Rgb8{255, 0, 0})) << x << ", " << y;
      } else {
        EXPECT_TRUE(c.r == c.g && c.g == c.b && c.r <= 63) << x << ", " << y << ": " << str(c);
      }
    }
  EXPECT_EQ(px(shd::diffMask(filled(1, 1, 255, 255, 255), filled(1, 1, 255, 255, 255)), 0, 0), (Rgb8{63, 63, 63}));
  EXPECT_THROW(shd::diffMask(a, Image(17, 8)), std::invalid_argument);
  EXPECT_THROW(shd::firstDifference(a, Image(1, 9)), std::invalid_argument);
}

TEST(Compose, DownscaleAveragesBlocksAndCutBlocksAtTheEdges) {
  Image img(5, 3);  // value of a pixel: 10 x + y (every channel)
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x)
      for (int k = 0; k < 3; ++k) img.at(x, y)[k] = static_cast<uint8_t>(10 * x + y);
  const Image d = shd::downscaleBox(img, 2);
  ASSERT_EQ(d.width, 3);
  ASSERT_EQ(d.height, 2);
  EXPECT_EQ(d.at(0, 0)[0], 6);   // (0 + 1 + 10 + 11) / 4 = 5.5, rounded half up
  EXPECT_EQ(d.at(2, 0)[1], 41);  // the cut column x = 4: (40 + 41) / 2 = 40.5
  EXPECT_EQ(d.at(2, 1)[2], 42);  // the corner pixel alone
  EXPECT_EQ(shd::downscaleBox(img, 1), img);
  EXPECT_THROW(shd::downscaleBox(img, 0), std::invalid_argument);
  EXPECT_THROW(shd::downscaleBox(Image(), 2), std::invalid_argument);
}

TEST(Compose, StackAndGridPlaceTilesAtTheirCells) {
  Image a(2, 1), b(3, 2);
  a.at(0, 0)[0] = 200;
  b.at(2, 1)[1] = 100;
  const Image s = shd::stackVertical(a, b, 1, {7, 7, 7});
  ASSERT_EQ(s.width, 3);
  ASSERT_EQ(s.height, 4);
  EXPECT_EQ(s.at(0, 0)[0], 200);
  EXPECT_EQ(s.at(2, 0)[0], 7);  // beside the narrower image: background
  EXPECT_EQ(s.at(1, 1)[0], 7);  // the gap
  EXPECT_EQ(s.at(2, 3)[1], 100);
  // 3 tiles in 2 columns of 3 x 4 cells with a gap of 1: 9 x 11 pixels; the null tile is `empty`.
  const Image g = shd::tileGrid({&s, nullptr, &a}, 2, 3, 4, 1, {255, 255, 255}, {9, 9, 9});
  ASSERT_EQ(g.width, 1 + 2 * (3 + 1));
  ASSERT_EQ(g.height, 1 + 2 * (4 + 1));
  EXPECT_EQ(g.at(0, 0)[0], 255);
  EXPECT_EQ(g.at(1, 1)[0], 200);  // s at cell (0, 0)
  EXPECT_EQ(g.at(5, 1)[0], 9);    // the empty cell (1, 0)
  EXPECT_EQ(g.at(1, 6)[0], 200);  // a at cell (0, 1)
  EXPECT_EQ(g.at(5, 6)[0], 255);  // no tile: background
  EXPECT_THROW(shd::tileGrid({&b}, 1, 2, 2, 0, {0, 0, 0}, {0, 0, 0}), std::invalid_argument);  // too large
  EXPECT_THROW(shd::tileGrid({}, 1, 2, 2, 0, {0, 0, 0}, {0, 0, 0}), std::invalid_argument);
}
