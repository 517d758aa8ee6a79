// phong-fixed's datapath (render/fixed_shading.h): against the double-precision shader it
// replaces, its lobe tables against the lobes, and the specular unit's memo against the unit.
#include "config/registry.h"
#include "render/fixed_shading.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "approx/brdf.h"
#include "device/prom.h"
#include "device/spec_params.h"
#include "render/fixed_simd.h"
#include "render/normalize.h"
#include "scene/scene.h"

using namespace shd;

namespace {

// The sphere's light and a coloured point light beside it.
ShadeContext twoLights() {
  Scene s = loadScene("builtin:sphere");
  Light p;
  p.kind = Light::Kind::Point;
  p.position = {2, 3, -4};
  p.colour = {1, 0.9, 0.6};
  s.lights.push_back(p);
  return makeShadeContext(s);
}

// A normal as the span unit interpolates it (28 fraction bits per component) and its exact
// squared norm (56 fraction bits), the shader's inputs.
struct NormalCode {
  std::array<int64_t, 3> n{};
  uint64_t sq = 0;
  explicit NormalCode(Vec3 v) : n{std::llround(std::ldexp(v.x, 28)), std::llround(std::ldexp(v.y, 28)),
                                  std::llround(std::ldexp(v.z, 28))} {
    for (int64_t x : n) sq += static_cast<uint64_t>(x * x);
  }
  Vec3 unit() const { return normalize(Vec3{double(n[0]), double(n[1]), double(n[2])}); }
};

}  // namespace

// Every pixel's colour within 1 LSB (a rounding boundary) of the double-precision shader's
// for the exact unit normal of the same codes, for every lobe phong-fixed tables or evaluates
// itself, n from 1 to 1000, normals of length 0.3 to 1.2 (half of them near the highlight),
// directional and point lights. A coarser datapath fails it: with L, H, V in Q1.16 (the first
// version) the phong lobe at n = 1000 was 11 LSB off, with the 8-bit 1/sqrt seed 5 LSB.
TEST(FixedShading, WithinOneLsbOfTheDoubleShader) {
  const ShadeContext ctx = twoLights();
  const Material base = loadScene("builtin:sphere").materials.at(0);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01;
  for (double n : {1.0, 32.0, 300.0, 1000.0})
    for (Lobe lobe : {Lobe::Blinn, Lobe::Pow, Lobe::Phong, Lobe::NormalizedBlinn, Lobe::Schlick, Lobe::CookTorrance}) {
      Material m = base;
      m.shininess = n;
      m.roughness = beckmannRoughnessForBlinn(n);
      const PointShader ref(ctx, m, lobe, nullptr);
      FixedPointShader fixed(ctx, m, lobe, nullptr, nullptr);
      int worst = 0;
      for (int t = 0; t < 40000; ++t) {
        Vec3 v{g(rng), g(rng), g(rng)};
        if (t % 2 != 0) v = normalize(normalize(v) + 3.0 * ctx.lights[0].half);
        v = ((0.3 + 0.9 * u01(rng)) / length(v)) * v;
        const NormalCode c(v);
        const Vec3 p{u01(rng) - 0.5, u01(rng) - 0.5, 2 + u01(rng)};  // on the sphere's side of the camera
        const auto want = combine(ref.shade(c.unit(), p, nullptr).lsb, nullptr, 0);
        const auto got = fixedColour(fixed.shade(c.n.data(), c.sq, p, nullptr));
        for (size_t k = 0; k < 3; ++k) worst = std::max(worst, std::abs(int{want[k]} - int{got[k]}));
      }
      EXPECT_LE(worst, 1) << toString(lobe) << " n = " << n;
    }
}

// The lobe tables hold round(f 2^24) of the exact lobe at every 16-bit cosine code, are built
// once per (lobe, n) and shared, and exist only for lobes of one cosine.
TEST(FixedShading, LobeTablesHoldTheLobeAtEveryCode) {
  for (double n : {1.0, 32.0, 1000.0}) {
    const auto blinn = lobeTable(Lobe::Blinn, n), phong = lobeTable(Lobe::Phong, n);
    const auto nb = lobeTable(Lobe::NormalizedBlinn, n), schlick = lobeTable(Lobe::Schlick, n);
    ASSERT_EQ(blinn->code.size(), (size_t{1} << kFixedCosFrac) + 2);
    for (uint32_t c = 0; c <= (1u << kFixedCosFrac); ++c) {
      const double x = std::ldexp(c, -kFixedCosFrac);
      ASSERT_EQ(blinn->code[c], std::llround(std::ldexp(blinnLobe(x, n), 24))) << c;
      ASSERT_EQ(phong->code[c], std::llround(std::ldexp(phongLobe(x, n), 24))) << c;
      ASSERT_EQ(nb->code[c], std::llround(std::ldexp(normalizedBlinn(x, n), 24))) << c;
      ASSERT_EQ(schlick->code[c], std::llround(std::ldexp(schlickLobe(x, n), 24))) << c;
    }
    EXPECT_EQ(blinn->code.back(), blinn->code[1u << kFixedCosFrac]);  // the interpolation's neighbour at 1
    // zero_below: the first entry pair that is not all zero (n = 1000: most of the table).
    for (const auto& t : {blinn, phong, nb, schlick}) {
      const uint32_t z = t->zero_below;
      for (uint32_t c = 0; c <= z; ++c) ASSERT_EQ(t->code[c], 0u) << "n " << n << " entry " << c << " of " << z;
      ASSERT_TRUE(t->code[z] != 0 || t->code[z + 1] != 0) << n;
    }
    if (n == 1000.0) {
      EXPECT_GT(blinn->zero_below, 1u << 15);
    }
    EXPECT_EQ(lobeTable(Lobe::Pow, n), blinn);  // the same function: one table
    EXPECT_EQ(lobeTable(Lobe::Blinn, n), blinn);
  }
  // More exponents than the cache keeps (64): it starts over, and tables in use live on.
  const auto held = lobeTable(Lobe::Schlick, 7);
  for (int n = 1; n <= 70; ++n) ASSERT_EQ(lobeTable(Lobe::Schlick, n)->code[1u << 15], std::llround(std::ldexp(schlickLobe(0.5, n), 24)));
  EXPECT_EQ(held->code[1u << 15], std::llround(std::ldexp(schlickLobe(0.5, 7), 24)));
  EXPECT_THROW(lobeTable(Lobe::CookTorrance, 32), std::logic_error);
  EXPECT_THROW(lobeTable(Lobe::Quadratic, 32), std::logic_error);
}

// The memo gives the unit's model's result for every cos code of a row, and rows of other
// requests leave it in place.
TEST(FixedShading, SpecResultMemoEqualsTheUnitsModel) {
  const SpecUnitConfig cfg = specConfig("default");
  const PromTable t = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
  const SpecUnitModel unit(t.unit, t.words, t.seg_words);
  SpecResultMemo memo(unit);
  const uint32_t shin = static_cast<uint32_t>(t.addressOf(32));
  const std::array<uint32_t, 3> light{255, 200, 17};
  uint64_t* row = memo.row(shin, light);
  memo.row(shin, {1, 2, 3});  // another row
  EXPECT_EQ(memo.row(shin, light), row);
  for (uint32_t cos = 0; cos <= static_cast<uint32_t>(unit.params().cosOne()); ++cos) {
    ASSERT_EQ(row[cos], 0u);
    const uint64_t e = memo.result(row, shin, cos, light);
    ASSERT_EQ(row[cos], e);
    const SpecOut want = unit.evaluate(shin, cos, light);
    ASSERT_NE(e & SpecResultMemo::kValid, 0u);
    for (size_t k = 0; k < 3; ++k) ASSERT_EQ((e >> (20 * k)) & 0xFFFFF, want.rgb[k]) << "cos " << cos;
  }
  // A unit too wide for rows (CosFracBits 21: 16 MB a row) gets none; evaluate() still works.
  SpecUnitParams wide = cfg.rtl;
  wide.CosFracBits = SpecResultMemo::kMaxCosFracBits + 1;
  wide.SpecFracBits = std::max(wide.SpecFracBits, wide.CosFracBits);
  const PromTable wt = buildPromTable(PromRequest::fromContent(cfg.prom), wide);
  const SpecUnitModel wunit(wt.unit, wt.words, wt.seg_words);
  SpecResultMemo wmemo(wunit);
  EXPECT_EQ(wmemo.row(shin, light), nullptr);
  const uint32_t cos = 1u << 20;  // 0.5
  const SpecOut want = wunit.evaluate(shin, cos, light);
  EXPECT_EQ(wmemo.evaluate(shin, cos, light),
            SpecResultMemo::kValid | want.rgb[0] | uint64_t{want.rgb[1]} << 20 | uint64_t{want.rgb[2]} << 40);
  // and a shader on that unit adds what the unit gives for the request it would send
  const Scene s = loadScene("builtin:sphere");
  const ShadeContext ctx = makeShadeContext(s);
  DeviceCoding coding;
  coding.cos_frac_bits = wide.CosFracBits;
  coding.shin = shin;
  FixedPointShader direct(ctx, s.materials.at(0), Lobe::Quadratic, &coding, &wmemo);
  FixedPointShader requesting(ctx, s.materials.at(0), Lobe::Quadratic, &coding, nullptr);
  const NormalCode c(normalize(ctx.lights.at(0).half + Vec3{0.05, 0.02, 0}));
  std::vector<SpecRequest> req;
  requesting.shade(c.n.data(), c.sq, Vec3{}, &req);
  ASSERT_EQ(req.size(), 1u);
  const SpecOut unit_out = wunit.evaluate(req[0].shin, req[0].cos, req[0].light);
  const FixedShade got = direct.shade(c.n.data(), c.sq, Vec3{}, nullptr);
  EXPECT_EQ(got.device, unit_out.rgb);
  EXPECT_GT(unit_out.rgb[0], 0u);
}

// A device lobe's request: N.H rounded to the unit's cos_frac_bits, one per lit light, with
// the material's shininess code and light codes; nothing for a light behind the surface.
TEST(FixedShading, DeviceRequestsCarryTheRoundedCosine) {
  const Scene s = loadScene("builtin:sphere");
  const ShadeContext ctx = makeShadeContext(s);
  DeviceCoding coding;
  coding.cos_frac_bits = 15;
  coding.shin = 7;
  FixedPointShader fixed(ctx, s.materials.at(0), Lobe::Quadratic, &coding, nullptr);
  const Vec3 h = ctx.lights.at(0).half;
  for (const Vec3 n : {h, normalize(h + Vec3{0.3, 0, 0}), -1.0 * ctx.lights.at(0).dir}) {
    const NormalCode c(n);
    std::vector<SpecRequest> req;
    const FixedShade sh = fixed.shade(c.n.data(), c.sq, Vec3{}, &req);
    if (dot(n, ctx.lights.at(0).dir) <= 0) {
      EXPECT_TRUE(req.empty());
      continue;
    }
    ASSERT_EQ(req.size(), 1u);
    EXPECT_EQ(sh.device_requests, 1u);
    EXPECT_EQ(req[0].shin, 7u);
    EXPECT_NEAR(req[0].cos, std::ldexp(std::min(1.0, dot(n, h)), 15), 1.0);
    EXPECT_EQ(req[0].light, (std::array<uint32_t, 3>{255, 255, 255}));
  }
  EXPECT_THROW(FixedPointShader(ctx, s.materials.at(0), Lobe::Quadratic, nullptr, nullptr), std::logic_error);
}

// The batch kernels (render/fixed_simd.h: shadeNh, shadeNhAvx2, shadeNhScalar) against shade(),
// lane by lane: runs of 1 to 8 fragments with normals from 2^-27 to 11.2 in length (squared norms
// of every bit length up to 63), facing the light or away, for each lobe they take,
// with factor codes up to saturation. A group must be declined exactly where a lane's squared norm
// is outside the kernel's domain: [kVectorSqFrom, kVectorSqBelow) for the vector kernels, from 2^8
// on (a zero normal is below) for the plain C++ one. Each vector kernel where the CPU has its
// instructions, and the plain C++ one everywhere.
static void checkNhKernel(const char* name, fixed_simd::NhKernel nh, uint64_t from = uint64_t{1} << 8,
                          uint64_t below = ~uint64_t{0}) {
  SCOPED_TRACE(name);
  std::mt19937_64 rng(12);
  std::normal_distribution<double> g;
  std::uniform_real_distribution<double> u01;
  uint64_t lanes = 0, declined = 0;
  for (int scene = 0; scene < 3; ++scene) {
    Scene s = loadScene("builtin:sphere");
    if (scene == 1) s.lights[0].colour = {3, 0.5, 2};
    if (scene == 2) s.lights[0].colour = {2000, 1, 0};  // saturates the factor codes
    const ShadeContext ctx = makeShadeContext(s);
    for (double n : {1.0, 7.5, 32.0, 300.0, 1000.0})
      for (Lobe lobe : {Lobe::Blinn, Lobe::Pow, Lobe::NormalizedBlinn, Lobe::Schlick}) {
        Material m = s.materials.at(0);
        m.shininess = n;
        FixedPointShader fixed(ctx, m, lobe, nullptr, nullptr);
        fixed.withRunKernel([&](auto kernel) {
          if constexpr (decltype(kernel)::kGroups) {
            for (int t = 0; t < 3000; ++t) {
              // A run: N_j = n0 + j dn, as the span unit interpolates it.
              // 2^-27 to 11.2 in length: codes from a few units (squared norms below 2^8) to
              // 2^31.5 (squared norms of 63 bits, their squares within int64_t); two runs in
              // three from 2^-12 to 4 (the vector kernels' domain).
              const int e = t % 3 == 0 ? -27 + static_cast<int>(rng() % 31) : -12 + static_cast<int>(rng() % 14);
              const double len = std::ldexp(1.0, e) * (1 + (e == 3 ? 0.4 : 1.0) * u01(rng));
              Vec3 v{g(rng), g(rng), g(rng)};
              if (t % 2 != 0) v = normalize(normalize(v) + 3.0 * ctx.lights[0].half);
              if (t % 10 == 1) v = ctx.lights[0].half;  // N.H at 1 and a hair either side (the clamp at 2^32)
              // N.L at 1 and a hair either side: a scaled N.L of 2^32 and more has a high word, which
              // the diffuse products multiply by each channel's diffuse factor.
              if (t % 10 == 3) v = ctx.lights[0].dir;
              v = (len / length(v)) * v;
              const NormalCode c(v);
              std::array<int64_t, 3> dn{};
              for (int64_t& d : dn) d = static_cast<int64_t>(rng() % (uint64_t{1} << (5 + rng() % 20))) - (int64_t{1} << 4);
              const int count = 1 + static_cast<int>(rng() % 8);
              std::array<uint64_t, 8> sq{}, l{}, h{};
              std::array<std::array<int64_t, 3>, 8> nj{};
              kernel.start(c.n.data(), dn.data());
              bool outside = false;
              for (int j = 0; j < count; ++j) {
                for (size_t k = 0; k < 3; ++k) nj[j][k] = c.n[k] + j * dn[k];
                for (size_t k = 0; k < 3; ++k) sq[j] += static_cast<uint64_t>(nj[j][k] * nj[j][k]);
                outside = outside || sq[j] < from || sq[j] >= below;
                l[j] = kernel.dotL();
                h[j] = kernel.dotH();
                kernel.step();
              }
              uint32_t rgb[8];
              int64_t codes[3][8];
              int64_t* const codes_out[3] = {codes[0], codes[1], codes[2]};
              const bool vec =
                  nh(kernel.nhParams(), sq.data(), l.data(), h.data(), static_cast<size_t>(count), rgb, codes_out) == 0;
              ASSERT_EQ(vec, !outside) << "n " << n << " " << toString(lobe);
              if (!vec) {
                ++declined;
                continue;
              }
              for (int j = 0; j < count; ++j) {
                const FixedShade want = fixed.shade(nj[j].data(), sq[j], Vec3{}, nullptr);
                const auto colour = fixedColour(want);
                for (size_t k = 0; k < 3; ++k) {
                  // The codes (12 fraction bits) before the output rounding: a cosine or lobe
                  // value one unit off shows here, where the 8-bit colour would rarely change.
                  ASSERT_EQ(codes[k][j], want.code[k]) << toString(lobe) << " n " << n << " lane " << j << " of "
                                                       << count << " sqnorm " << sq[j] << " channel " << k;
                  ASSERT_EQ((rgb[j] >> (8 * k)) & 0xFF, colour[k]) << toString(lobe) << " n " << n << " lane " << j;
                }
                ++lanes;
              }
            }
          } else {
            FAIL() << "one directional light and a lobe of N.H: the vector case";
          }
        });
      }
  }
  EXPECT_GT(lanes, 500000u);
  EXPECT_GT(declined, 0u);
  testing::Test::RecordProperty(std::string("lanes_") + name, std::to_string(lanes));
}

TEST(FixedSimd, LanesEqualTheScalarDatapath) {
  using fixed_simd::kVectorSqBelow, fixed_simd::kVectorSqFrom;
  if (fixed_simd::cpuHasAvx512()) checkNhKernel("avx512", fixed_simd::shadeNh, kVectorSqFrom, kVectorSqBelow);
  if (fixed_simd::cpuHasAvx2()) checkNhKernel("avx2", fixed_simd::shadeNhAvx2, kVectorSqFrom, kVectorSqBelow);
  checkNhKernel("scalar", fixed_simd::shadeNhScalar);
}

// What a renderer's run kernel shades its batches with: the vector kernel where the CPU has one
// (and SHD_SCALAR is not set), the plain C++ one where it has not, and the buffer kernels that
// go with each.
TEST(FixedSimd, RunKernelTakesTheCpusKernel) {
  const Scene s = loadScene("builtin:sphere");
  const ShadeContext ctx = makeShadeContext(s);
  FixedPointShader fixed(ctx, s.materials.at(0), Lobe::Blinn, nullptr, nullptr);
  fixed.withRunKernel([&](auto kernel) {
    if constexpr (decltype(kernel)::kGroups) {
      const bool avx512 = fixed_simd::available(), avx2 = fixed_simd::availableAvx2();
      EXPECT_EQ(fixed_simd::nhKernel(),
                avx512 ? fixed_simd::shadeNh : avx2 ? fixed_simd::shadeNhAvx2 : fixed_simd::shadeNhScalar);
      EXPECT_EQ(fixed_simd::bufferKernel(),
                avx512 ? fixed_simd::bufferRun : avx2 ? fixed_simd::bufferRunAvx2 : fixed_simd::bufferRunScalar);
      EXPECT_EQ(fixed_simd::spansBufferKernel(), avx512 ? fixed_simd::bufferSpans
                                                 : avx2 ? fixed_simd::bufferSpansAvx2
                                                        : fixed_simd::bufferSpansScalar);
      // The batch's shades equal the scalar datapath's (what shadeBatch gives, LanesEqualTheScalarDatapath).
      uint64_t sq[8] = {uint64_t{1} << 56}, l[8] = {uint64_t{1} << 57}, h[8] = {uint64_t{1} << 57};
      uint32_t rgb[8] = {};
      EXPECT_EQ(kernel.shadeBatch(sq, l, h, 1, rgb), 0u);
      EXPECT_EQ(rgb[0], fixed_simd::packedRgb(fixedColour(kernel.shadeRaw(sq[0], l[0], h[0]))));
    } else {
      FAIL() << "one directional light and blinn: the vector case";
    }
  });
}

namespace {

// The run tests' framebuffer: a run lies within the first kRunPixels pixels; rows of
// kRunWidth, and room for the prefetches of the row after next.
constexpr size_t kRunPixels = 64, kRunWidth = 16, kRunBuffer = kRunPixels + 2 * kRunWidth + 8;

// A random run of 1 to 40 pixels from any start offset, its depth codes wrapping mod 2^32
// (every third run with any step).
fixed_simd::RunPixels randomRunPixels(std::mt19937_64& rng, int t) {
  fixed_simd::RunPixels px;
  px.count = 1 + rng() % 40;
  px.p = rng() % (kRunPixels - px.count + 1);
  px.z = static_cast<uint32_t>(rng());
  px.dz = t % 3 == 0 ? static_cast<uint32_t>(rng()) : static_cast<uint32_t>(static_cast<int64_t>(rng() % 2001) - 1000);
  return px;
}

// Fragment k's depth code, as the kernel compares it.
int32_t depthCode(const fixed_simd::RunPixels& px, size_t k) {
  return static_cast<int32_t>(px.z + static_cast<uint32_t>(k) * px.dz);
}

// A depth buffer around the run's codes: each pixel below (passes), equal or above (fails), or
// 0 (not covered).
std::vector<int32_t> depthAround(std::mt19937_64& rng, const fixed_simd::RunPixels& px) {
  std::vector<int32_t> depth(kRunBuffer);
  for (size_t k = 0; k < px.count; ++k) {
    const int32_t zk = depthCode(px, k);
    const int pick = static_cast<int>(rng() % 4);
    depth[px.p + k] = pick == 0 ? 0 : (pick == 1 ? zk : static_cast<int32_t>(static_cast<uint32_t>(zk) + static_cast<uint32_t>(rng() % 5) - 2u));
  }
  return depth;
}

// The run loop's z-test of fragment k, with its writes of depth and tag where it passes (and
// the count of pixels it covers first): true where it passes.
bool zTestWrite(const fixed_simd::RunPixels& px, size_t k, int32_t tag, std::vector<int32_t>& depth,
                std::vector<int32_t>& tri, uint64_t& fresh) {
  const int32_t zk = depthCode(px, k);
  const size_t p = px.p + k;
  if (zk <= depth[p]) return false;
  fresh += depth[p] == 0 ? 1 : 0;
  depth[p] = zk;
  tri[p] = tag;
  return true;
}

}  // namespace

// fixed_simd::bufferRun and bufferRunAvx2 (each where the CPU has its instructions) and
// bufferRunScalar against the run loop they replace, fragment by fragment: runs of 1 to 40 pixels
// from every start offset, over depth buffers holding codes above, below and equal to the run's
// (and 0, not covered), with depth codes and steps that wrap mod 2^32, squared norms from
// SquaredNormRecurrence and dot products that wrap mod 2^64, into batches filled to every level (a
// batch with room for fewer than 8 stops the run; the rest follows after the batch is emptied).
static void checkBufferKernel(const char* name, fixed_simd::BufferKernel buffer_run) {
  SCOPED_TRACE(name);
  std::mt19937_64 rng(21);
  auto batch = std::make_unique<fixed_simd::Batch>();
  uint64_t fragments = 0, passed = 0, stops = 0;
  for (int t = 0; t < 20000; ++t) {
    fixed_simd::Run r;
    r.px = randomRunPixels(rng, t);
    // The room to the row's end (the AVX2 kernel's blends): the buffer's, the run's own, or none.
    const size_t room_pick = rng() % 3;
    r.room = room_pick == 0 ? kRunBuffer - r.px.p : (room_pick == 1 ? r.px.count : 0);
    std::array<int64_t, 3> n0{}, dn{};
    for (size_t k = 0; k < 3; ++k) {
      n0[k] = static_cast<int64_t>(rng() % (uint64_t{1} << 32)) - (int64_t{1} << 31);
      dn[k] = static_cast<int64_t>(rng() % (uint64_t{1} << (1 + rng() % 32))) - (int64_t{1} << 20);
    }
    const SquaredNormRecurrence::Terms sq = SquaredNormRecurrence::terms(n0, dn);
    r.a = sq.a;
    r.two_b = sq.two_b;
    r.c = sq.c;
    r.l = rng();
    r.dl = rng();
    r.h = rng();
    r.dh = rng();
    std::vector<int32_t> depth = depthAround(rng, r.px), tri(depth.size(), -1);
    std::vector<int32_t> want_depth = depth, want_tri = tri;
    // The run loop: z-test, write, and the passing fragments' inputs in order.
    std::vector<std::array<uint64_t, 4>> want;  // sq, l, h, pixel
    uint64_t want_fresh = 0;
    SquaredNormRecurrence rec;
    uint64_t f = rec.start(n0, dn);
    for (size_t k = 0; k < r.px.count; ++k) {
      if (k > 0) f = rec.next();
      if (zTestWrite(r.px, k, 7, want_depth, want_tri, want_fresh))
        want.push_back({f, r.l + k * r.dl, r.h + k * r.dh, r.px.p + k});
    }
    // bufferRun, from a batch already filled to a random level, emptied when it stops.
    const fixed_simd::Target target{depth.data(), tri.data(), 7, kRunWidth};
    batch->n = rng() % (fixed_simd::Batch::kCap + 1);
    if (batch->n > fixed_simd::Batch::kCap - 8 && t % 2 == 0) batch->n = fixed_simd::Batch::kCap - 8 - rng() % 16;
    std::vector<std::array<uint64_t, 4>> got;
    uint64_t fresh = 0;
    for (size_t k = 0;;) {
      const size_t n0_batch = batch->n;
      const size_t next = buffer_run(r, k, target, *batch, fresh);
      ASSERT_GE(next, k);
      ASSERT_LE(next, r.px.count);
      ASSERT_LE(batch->n, fixed_simd::Batch::kCap);
      for (size_t i = n0_batch; i < batch->n; ++i) got.push_back({batch->sq[i], batch->l[i], batch->h[i], batch->pixel[i]});
      if (next == r.px.count) break;
      ASSERT_GT(batch->n + 8, fixed_simd::Batch::kCap) << "stopped with room for 8";
      ++stops;
      batch->n = 0;
      k = next;
    }
    ASSERT_EQ(depth, want_depth) << "run " << t;
    ASSERT_EQ(tri, want_tri) << "run " << t;
    ASSERT_EQ(fresh, want_fresh) << "run " << t;
    ASSERT_EQ(got.size(), want.size()) << "run " << t;
    for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], want[i]) << "run " << t << " fragment " << i;
    fragments += r.px.count;
    passed += want.size();
  }
  // Both outcomes of the z-test and of the batch's room, many times each.
  EXPECT_GT(passed, fragments / 4);
  EXPECT_LT(passed, fragments * 3 / 4);
  EXPECT_GT(stops, 500u);
}

TEST(FixedSimd, BufferRunEqualsTheRunLoop) {
  if (fixed_simd::cpuHasAvx512()) checkBufferKernel("avx512", fixed_simd::bufferRun);
  if (fixed_simd::cpuHasAvx2()) checkBufferKernel("avx2", fixed_simd::bufferRunAvx2);
  checkBufferKernel("scalar", fixed_simd::bufferRunScalar);
}

// fixed_simd::bufferSpans, bufferSpansAvx2 and bufferSpansScalar against what phong-fixed did
// before them with a triangle's rows' spans: the walk's runs of the rows (emitRowSpans), each made
// a Run as batchRun makes it (dot58 of the codes at its first pixel, SquaredNormRecurrence::terms)
// and buffered by the kernel's bufferRun, already held to the run loop above. Random rows' spans of
// up to 64 rows, with rows without a pixel and rows of one, attribute codes within int32_t and past
// it (the dot products and squared norms wrap mod 2^64), random subsets of the rows (RowShare),
// depth buffers around the codes, and batches filled to every level: the same entries in the same
// order, depth and tag buffers and fresh pixels.
static void checkSpansKernel(const char* name, fixed_simd::SpansBufferKernel spans, fixed_simd::BufferKernel runs) {
  SCOPED_TRACE(name);
  std::mt19937_64 rng(23);
  constexpr size_t W = 80, H = 80;  // rows y0 + 64 and the prefetches of the row after next
  auto batch = std::make_unique<fixed_simd::Batch>();
  uint64_t fragments = 0, passed = 0, stops = 0, masked = 0;
  for (int t = 0; t < 4000; ++t) {
    RowSpans s;
    s.rows = 1 + static_cast<int32_t>(t % 4 == 0 ? rng() % RowSpans::kMaxRows : rng() % 10);
    s.y0 = static_cast<int32_t>(rng() % (H - 2 - static_cast<size_t>(s.rows)));
    for (int32_t i = 0; i < s.rows; ++i) {
      // No pixel, one pixel, or up to 40 (to the row's end).
      const size_t lo = rng() % W, pick = rng() % 8;
      const size_t hi = pick == 0 ? lo - 1 : (pick == 1 ? lo : std::min<size_t>(W - 1, lo + rng() % 40));
      s.span[static_cast<size_t>(i)] = {static_cast<int16_t>(lo), static_cast<int16_t>(hi)};
    }
    s.x0 = std::max<int32_t>(0, s.span[0][0]);
    // Odd triangles: codes within int32_t at every pixel, as RowSpans promises (|a0| <= 2^29,
    // gradients below 2^23: |u didx| < 80 2^23 and |i didy| < 64 2^23, the sum below 2^31), the
    // AVX-512 kernel's vector case. Even ones: codes over the whole int32_t range and past it,
    // where the kernels' arithmetic wraps (the AVX-512 kernel's scalar rows).
    const bool within = t % 2 == 1;
    for (size_t k = 0; k < 4; ++k) {
      if (within) {
        s.a0[k] = static_cast<int64_t>(rng() % (uint64_t{1} << 30)) - (int64_t{1} << 29);
        s.didx[k] = static_cast<int64_t>(rng() % (uint64_t{1} << (1 + rng() % 23))) - (int64_t{1} << 21);
        s.didy[k] = static_cast<int64_t>(rng() % (uint64_t{1} << (1 + rng() % 23))) - (int64_t{1} << 21);
        continue;
      }
      // (One in 4 of them with gradients past int32_t as well, up to 2^34.)
      const uint64_t widest = t % 8 == 0 ? 34 : 31;
      s.a0[k] = static_cast<int64_t>(static_cast<int32_t>(rng()));
      s.didx[k] = static_cast<int64_t>(rng() % (uint64_t{1} << (1 + rng() % widest))) - (int64_t{1} << 20);
      s.didy[k] = static_cast<int64_t>(rng() % (uint64_t{1} << (1 + rng() % widest))) - (int64_t{1} << 20);
    }
    fixed_simd::NhSpans r{&s, ~uint64_t{0}, {}, {}, W};
    for (size_t k = 0; k < 3; ++k) {
      r.l[k] = static_cast<int32_t>(rng());
      r.h[k] = static_cast<int32_t>(rng());
    }
    if (t % 3 == 0) {
      r.rows = rng();
      masked += static_cast<uint64_t>(s.rows - __builtin_popcountll(r.rows & (~uint64_t{0} >> (64 - s.rows))));
    }
    // Depth: around each fragment's code (below, equal, above, or 0), random elsewhere.
    std::vector<int32_t> depth(W * H);
    for (int32_t& d : depth) d = static_cast<int32_t>(rng());
    for (int32_t i = 0; i < s.rows; ++i)
      for (int64_t x = s.span[static_cast<size_t>(i)][0]; x <= s.span[static_cast<size_t>(i)][1]; ++x) {
        const uint32_t z = static_cast<uint32_t>(s.at(3, x, i));
        const uint64_t pick = rng() % 4;
        depth[static_cast<size_t>(s.y0 + i) * W + static_cast<size_t>(x)] =
            static_cast<int32_t>(pick == 0 ? 0u : (pick == 1 ? z : z + static_cast<uint32_t>(rng() % 5) - 2u));
      }
    std::vector<int32_t> tri(depth.size(), -1), want_depth = depth, want_tri = tri;
    const size_t level = rng() % (fixed_simd::Batch::kCap + 1);
    // The reference: the rows' runs, one bufferRun call after another.
    std::vector<std::array<uint64_t, 4>> want, got;  // sq, l, h, pixel
    uint64_t want_fresh = 0, fresh = 0;
    batch->n = level;
    auto take = [&](std::vector<std::array<uint64_t, 4>>& out, size_t from) {
      for (size_t i = from; i < batch->n; ++i) out.push_back({batch->sq[i], batch->l[i], batch->h[i], batch->pixel[i]});
    };
    auto row_run = [&](const RowRun& rr) {
      const SquaredNormRecurrence::Terms sq =
          SquaredNormRecurrence::terms({rr.a0[0], rr.a0[1], rr.a0[2]}, {rr.da[0], rr.da[1], rr.da[2]});
      fixed_simd::Run run{{static_cast<size_t>(rr.y) * W + static_cast<size_t>(rr.x0), static_cast<size_t>(rr.count),
                           static_cast<uint32_t>(rr.a0[3]), static_cast<uint32_t>(rr.da[3])},
                          sq.a, sq.two_b, sq.c,
                          static_cast<uint64_t>(fixed_detail::dot58(rr.a0, r.l)),
                          static_cast<uint64_t>(fixed_detail::dot58(rr.da, r.l)),
                          static_cast<uint64_t>(fixed_detail::dot58(rr.a0, r.h)),
                          static_cast<uint64_t>(fixed_detail::dot58(rr.da, r.h)),
                          W - static_cast<size_t>(rr.x0)};
      const fixed_simd::Target target{want_depth.data(), want_tri.data(), 5, W};
      for (size_t k = 0;;) {
        const size_t from = batch->n;
        k = runs(run, k, target, *batch, want_fresh);
        take(want, from);
        if (k >= run.px.count) break;
        batch->n = 0;
      }
      fragments += static_cast<uint64_t>(rr.count);
    };
    emitRowSpans(s, row_run, [&](int32_t y) { return ((r.rows >> (y - s.y0)) & 1) != 0; });
    // The kernel, from the same batch level.
    batch->n = level;
    const fixed_simd::Target target{depth.data(), tri.data(), 5, W};
    fixed_simd::SpanCursor at;
    for (;;) {
      const size_t from = batch->n;
      const bool done = spans(r, at, target, *batch, fresh);
      take(got, from);
      if (done) break;
      ASSERT_GT(batch->n + 8, fixed_simd::Batch::kCap) << "stopped with room for 8, triangle " << t;
      ++stops;
      batch->n = 0;
    }
    ASSERT_EQ(depth, want_depth) << "triangle " << t;
    ASSERT_EQ(tri, want_tri) << "triangle " << t;
    ASSERT_EQ(fresh, want_fresh) << "triangle " << t;
    ASSERT_EQ(got.size(), want.size()) << "triangle " << t;
    for (size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got[i], want[i]) << "triangle " << t << " fragment " << i;
    passed += want.size();
  }
  // Both outcomes of the z-test, stops for a full batch, and rows left out, many times each.
  EXPECT_GT(passed, fragments / 4);
  EXPECT_LT(passed, fragments * 3 / 4);
  EXPECT_GT(stops, 200u);
  EXPECT_GT(masked, 1000u);
}

TEST(FixedSimd, BufferSpansEqualsTheRowsRuns) {
  if (fixed_simd::cpuHasAvx512()) checkSpansKernel("avx512", fixed_simd::bufferSpans, fixed_simd::bufferRun);
  if (fixed_simd::cpuHasAvx2()) checkSpansKernel("avx2", fixed_simd::bufferSpansAvx2, fixed_simd::bufferRunAvx2);
  checkSpansKernel("scalar", fixed_simd::bufferSpansScalar, fixed_simd::bufferRunScalar);
}

// The colour-run kernels (fixed_simd::colourRunsAvx512, colourRunsAvx2) against the flat/Gouraud
// run loop, pixel by pixel: calls of 1 to 4 runs with the same steps, each run of 1 to 40 pixels
// from every start offset in a buffer of its own, over depth buffers holding codes above, below
// and equal to the run's (and 0), with colour codes below 0, within [0, 255 2^frac] and above
// (the clamp), for fraction bits 1 to 23. The pixels that fail the z-test keep their depth, tag
// and colour, and no other byte changes (the AVX2 kernel's blends: the room to the row's end is
// the buffer's, the run's own or none, at random).
static void checkColourKernel(const char* name, fixed_simd::ColourKernel kernel) {
  std::mt19937_64 rng(22);
  uint64_t fragments = 0, passed = 0, clamped = 0, calls_of_many = 0;
  for (int t = 0; t < 20000; ++t) {
    fixed_simd::ColourRuns r;
    r.frac = std::array<int, 5>{1, 5, 12, 12, 23}[rng() % 5];
    r.n = 1 + rng() % 4;
    calls_of_many += r.n > 1 ? 1 : 0;
    const int64_t top = int64_t{255} << r.frac;
    std::vector<uint8_t> rgb(3 * kRunBuffer * r.n);
    for (uint8_t& b : rgb) b = static_cast<uint8_t>(rng());
    std::vector<int32_t> depth, tri(kRunBuffer * r.n, -1);
    std::array<int64_t, 3> step{};
    std::vector<fixed_simd::RunPixels> px(r.n);
    for (size_t i = 0; i < r.n; ++i) {
      fixed_simd::ColourRuns::Row& row = r.rows[i];
      px[i] = randomRunPixels(rng, t);
      if (i > 0) {  // the first run's steps, and no more pixels than it has (its codes fit int32_t)
        px[i].dz = px[0].dz;
        px[i].count = std::min(px[i].count, px[0].count);
      }
      const std::vector<int32_t> d = depthAround(rng, px[i]);
      depth.insert(depth.end(), d.begin(), d.end());
      row.p = px[i].p + i * kRunBuffer;
      row.count = px[i].count;
      row.z = px[i].z;
      row.room = std::array<size_t, 3>{kRunBuffer - px[i].p, px[i].count, 0}[rng() % 3];
      for (size_t ch = 0; ch < 3; ++ch) {
        if (i > 0) {  // the first run's codes moved by up to a quarter of the range, where they still fit
          const int64_t delta = static_cast<int64_t>(rng() % static_cast<uint64_t>(top / 2 + 1)) - top / 4;
          const int64_t c0 = int64_t{r.rows[0].c[ch]} + delta, c1 = c0 + step[ch] * static_cast<int64_t>(row.count - 1);
          const bool fits = std::min(c0, c1) >= INT32_MIN && std::max(c0, c1) <= INT32_MAX;
          row.c[ch] = static_cast<int32_t>(fits ? c0 : r.rows[0].c[ch]);
          continue;
        }
        // Start and end around [0, top]: the codes are affine along the run, as the span unit's.
        const int64_t lo = -top / 4 - 2, span = top + top / 2 + 4;
        // (and within int32_t, as the span unit's codes are).
        auto pick = [&] {
          return std::clamp<int64_t>(lo + static_cast<int64_t>(rng() % static_cast<uint64_t>(span)), INT32_MIN, INT32_MAX);
        };
        const int64_t c0 = pick(), c1 = pick();
        // The step mod 2^32, as the span unit's (exact where the codes are: they fit int32_t).
        step[ch] = row.count > 1 ? (c1 - c0) / static_cast<int64_t>(row.count - 1) : 0;
        row.c[ch] = static_cast<int32_t>(c0);
        r.dc[ch] = static_cast<int32_t>(static_cast<uint32_t>(step[ch]));
      }
    }
    r.dz = px[0].dz;
    std::vector<int32_t> want_depth = depth, want_tri = tri;
    std::vector<uint8_t> want_rgb = rgb;
    uint64_t want_fresh = 0, want_passed = 0;
    for (size_t i = 0; i < r.n; ++i) {
      fixed_simd::RunPixels at = px[i];
      at.p = r.rows[i].p;
      for (size_t k = 0; k < at.count; ++k) {
        if (!zTestWrite(at, k, 9, want_depth, want_tri, want_fresh)) continue;
        ++want_passed;
        const size_t p = at.p + k;
        for (size_t ch = 0; ch < 3; ++ch) {
          const int64_t code = int64_t{r.rows[i].c[ch]} + static_cast<int64_t>(k) * step[ch];
          clamped += code < 0 || code > top ? 1 : 0;
          want_rgb[3 * p + ch] = unorm8FromCode(code, r.frac);
        }
        ++passed;
      }
      fragments += at.count;
    }
    const fixed_simd::Target target{depth.data(), tri.data(), 9, kRunWidth};
    uint64_t got_passed = 0;
    const uint64_t fresh = kernel(r, target, rgb.data(), got_passed);
    ASSERT_EQ(depth, want_depth) << name << " call " << t;
    ASSERT_EQ(tri, want_tri) << name << " call " << t;
    for (size_t i = 0; i < rgb.size(); ++i)
      ASSERT_EQ(int{rgb[i]}, int{want_rgb[i]}) << name << " call " << t << " frac " << r.frac << " byte " << i;
    ASSERT_EQ(fresh, want_fresh) << name << " call " << t;
    ASSERT_EQ(got_passed, want_passed) << name << " call " << t;
  }
  EXPECT_GT(passed, fragments / 4);
  EXPECT_LT(passed, fragments * 3 / 4);
  EXPECT_GT(clamped, passed / 10);
  EXPECT_GT(calls_of_many, 10000u);
}

TEST(FixedSimd, ColourRunEqualsTheRunLoop) {
  if (!fixed_simd::cpuHasAvx512() && !fixed_simd::cpuHasAvx2()) GTEST_SKIP() << "no AVX-512 or AVX2 here";
  if (fixed_simd::cpuHasAvx512()) checkColourKernel("AVX-512", fixed_simd::colourRunsAvx512);
  if (fixed_simd::cpuHasAvx2()) checkColourKernel("AVX2", fixed_simd::colourRunsAvx2);
}
