// Co-simulation of the verilated shd_span_unit against SpanUnitModel, cycle by cycle, for
// every mode, with random back-pressure and descriptor gaps.
#include <gtest/gtest.h>

#include "test_util.h"

#include <filesystem>
#include <fstream>

#include "raster/desc_stream.h"
#include "replay.h"
#include "span_cosim.h"
#include "vector_gen.h"

using namespace shd;
namespace fs = std::filesystem;

namespace {

// Generator triangles through setup for `mode`; triangles setup drops are skipped.
std::function<bool(SpanDesc&)> stream(SpanMode mode, uint64_t seed, long count) {
  RasterConfig cfg;
  cfg.unit = SpanParams::forMode(mode);
  auto s = std::make_shared<DescriptorStream>(seed, static_cast<uint64_t>(count), cfg);
  return [s](SpanDesc& d) { return s->next(d); };
}

}  // namespace

class SpanCosimModes : public testing::TestWithParam<std::string> {};

TEST_P(SpanCosimModes, RandomTrianglesWithBackPressure) {
  const SpanMode mode = parseSpanMode(GetParam());
  SpanCosimOptions o;
  o.seed = 31;
  o.fail_dir = shd::testutil::freshTestDir("span_cosim").string();
  const SpanCosimResult r = runSpanCosim(GetParam(), stream(mode, 20261122, 30000), o);
  std::printf("span %s: %llu triangles, %llu fragments, %llu cycles, %llu mismatches, %.2f s\n", GetParam().c_str(),
              static_cast<unsigned long long>(r.triangles), static_cast<unsigned long long>(r.fragments),
              static_cast<unsigned long long>(r.cycles), static_cast<unsigned long long>(r.mismatches), r.seconds);
  EXPECT_GT(r.triangles, 25000u);
  EXPECT_GT(r.fragments, 1000000u);
  EXPECT_EQ(r.mismatches, 0u) << (r.first ? r.first->what : "") << "\nwaveform " << r.fst_path << "\ncase " << r.case_path;
}

INSTANTIATE_TEST_SUITE_P(Modes, SpanCosimModes,
                         testing::Values("serial", "evenodd", "seg2", "seg4", "seg8", "sierpinski"));

TEST(SpanCosim, DetectsAModelOfAnotherLaneLayout) {
  // The checker must be able to fail: seg2 and evenodd draw the same pixels with the same
  // values but put them in different lanes and cycles.
  SpanCosimOptions o;
  o.fail_dir = shd::testutil::freshTestDir("span_cosim").string();
  o.model_params = SpanParams::forMode(SpanMode::EvenOdd);
  const SpanCosimResult r = runSpanCosim("seg2", stream(SpanMode::Seg2, 5, 200), o);
  ASSERT_GT(r.mismatches, 0u);
  ASSERT_TRUE(r.first.has_value());
  std::printf("as expected: cycle %llu triangle %u: %s\n", static_cast<unsigned long long>(r.first->cycle),
              r.first->tag, r.first->what.c_str());
  ASSERT_TRUE(fs::exists(r.fst_path));
  EXPECT_GT(fs::file_size(r.fst_path), 100u);
  std::ifstream c(r.case_path);
  std::string text((std::istreambuf_iterator<char>(c)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"descriptor\""), std::string::npos);
  EXPECT_NE(text.find("out_ready_after_accept"), std::string::npos);
  // The failing triangle saved as a vector file: replayed alone on the real seg2 RTL it fails
  // at its last cycle (the run's failing one), and nowhere before.
  ASSERT_TRUE(fs::exists(r.vector_path));
  const ReplayResult rr = replayVectorFile(r.vector_path);
  ASSERT_TRUE(rr.first.has_value()) << "the saved case replays clean: it does not reproduce the mismatch";
  EXPECT_EQ(rr.first->cycle, rr.cycles);
  EXPECT_EQ(rr.mismatching_cycles, 1u);
  std::printf("replayed alone: %llu cycles, first mismatch %s\n", static_cast<unsigned long long>(rr.cycles),
              rr.first->describe().c_str());
}

TEST(SpanCosim, AGeneratedVectorFileOfTheRealModelReplaysClean) {
  // The counterpart of the saved failing case: the correct model's expectations pass.
  const fs::path dir = shd::testutil::freshTestDir("span_cosim");
  const std::string vec = (dir / "seg2.vec").string();
  writeSpanVectors(vec, generateSpanVectors("seg2", 2000, 5));
  const ReplayResult rr = replayVectorFile(vec);
  EXPECT_EQ(rr.cycles, 2000u);
  EXPECT_GT(rr.results, 1000u);
  EXPECT_EQ(rr.mismatches, 0u) << (rr.first ? rr.first->describe() : "");
}
