// Co-simulation of the verilated shd_spec_unit against SpecUnitModel, cycle by cycle.
#include <gtest/gtest.h>

#include "test_util.h"

#include <filesystem>
#include <fstream>

#include <fmt/format.h>

#include "config/registry.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "cosim/replay.h"
#include "cosim/spec_cosim.h"
#include "vectors/vector_gen.h"
#include "io/files.h"

using namespace shd;
namespace fs = std::filesystem;

namespace {

struct CosimSetup {
  SpecUnitConfig cfg;
  PromTable table;
  std::string prom_path;
};

// The configuration's table, written as the hex file the simulator loads.
CosimSetup setup(const std::string& name) {
  CosimSetup s;
  s.cfg = specConfig(name);
  s.table = buildPromTable(PromRequest::fromContent(s.cfg.prom), s.cfg.rtl);
  const fs::path dir = shd::testutil::freshTestDir("spec_cosim");
  fs::create_directories(dir);
  s.prom_path = (dir / fmt::format("spec_{}.hex", name)).string();
  writePromHexFiles(s.prom_path, s.table);
  return s;
}

SpecCosimOptions options(const CosimSetup& s) {
  SpecCosimOptions o;
  o.prom_path = s.prom_path;
  o.fail_dir = fs::path(s.prom_path).parent_path().string();  // the test's directory
  return o;
}

void expectClean(const SpecCosimResult& r, const CosimSetup& s) {
  EXPECT_EQ(r.mismatches, 0u) << (r.first ? r.first->describe(s.cfg.rtl) : "")
                              << "\nwaveform: " << r.fst_path << "\nvectors: " << r.vector_path;
}

}  // namespace

// Every input of the paper's device (default) and of each alternative kind (table, schlick, explog,
// piecewise).
class SpecCosimExhaustive : public testing::TestWithParam<std::string> {};

TEST_P(SpecCosimExhaustive, EveryInput) {
  const std::string name = GetParam();
  const CosimSetup s = setup(name);
  SpecUnitModel model(s.table.unit, s.table.words, s.table.seg_words);
  const uint64_t seed = 1;
  ExhaustiveSpecStimulus stim(s.table.unit, seed);
  const SpecCosimResult r = runSpecCosim(name, model, stim, options(s));
  std::printf("exhaustive %s: seed %llu, %llu vectors, %llu cycles, %llu mismatches, %.2f s (%.1f M vectors/s)\n",
              name.c_str(), static_cast<unsigned long long>(seed), static_cast<unsigned long long>(r.vectors),
              static_cast<unsigned long long>(r.cycles), static_cast<unsigned long long>(r.mismatches), r.seconds,
              r.vectors / r.seconds / 1e6);
  EXPECT_EQ(r.vectors, static_cast<uint64_t>(s.table.unit.shinCodes()) << (s.table.unit.CosFracBits + 1));
  expectClean(r, s);
}

INSTANTIATE_TEST_SUITE_P(Configs, SpecCosimExhaustive, testing::Values("default", "table", "schlick", "explog", "piecewise"));

class SpecCosimRandom : public testing::TestWithParam<std::string> {};

TEST_P(SpecCosimRandom, SeededWithValidGaps) {
  const CosimSetup s = setup(GetParam());
  SpecUnitModel model(s.table.unit, s.table.words, s.table.seg_words);
  const uint64_t seed = 20261122;
  RandomSpecStimulus stim(s.table.unit, seed, 2'000'000, 0.2);
  const SpecCosimResult r = runSpecCosim(GetParam(), model, stim, options(s));
  std::printf("random %s: seed %llu, %llu vectors over %llu cycles, %llu mismatches\n", GetParam().c_str(),
              static_cast<unsigned long long>(seed), static_cast<unsigned long long>(r.vectors),
              static_cast<unsigned long long>(r.cycles), static_cast<unsigned long long>(r.mismatches));
  EXPECT_EQ(r.vectors, 2'000'000u);
  EXPECT_GT(r.cycles, r.vectors + r.vectors / 10);  // the gaps happened
  expectClean(r, s);
}

INSTANTIATE_TEST_SUITE_P(Configs, SpecCosimRandom, testing::Values("narrow", "default", "wide", "cubic", "table", "schlick", "explog",
                                                                "piecewise"));

TEST(SpecCosim, DetectsADatapathDifferenceAndDumpsTheWindow) {
  // The checker must be able to fail: the model truncates c^2 - c one bit earlier than the RTL.
  const CosimSetup s = setup("narrow");
  SpecUnitParams wrong = s.table.unit;
  wrong.DiffFracBits -= 1;
  SpecUnitModel model(wrong, s.table.words, s.table.seg_words);  // same PROM words, different datapath
  RandomSpecStimulus stim(s.table.unit, 5, 200000, 0.1);
  const SpecCosimResult r = runSpecCosim("narrow", model, stim, options(s));
  ASSERT_GT(r.mismatches, 0u);
  ASSERT_TRUE(r.first.has_value());
  std::printf("as expected, MISMATCH (first of %llu) %s\nwaveform: %s\nvectors:  %s\n",
              static_cast<unsigned long long>(r.mismatches), r.first->describe(s.table.unit).c_str(),
              r.fst_path.c_str(), r.vector_path.c_str());
  EXPECT_TRUE(r.first->input.valid);
  EXPECT_TRUE(r.first->got.valid && r.first->expected.valid);
  EXPECT_NE(r.first->got.spec, r.first->expected.spec);
  const std::string text = r.first->describe(s.table.unit);
  EXPECT_NE(text.find(fmt::format("cycle {}", r.first->cycle)), std::string::npos) << text;
  EXPECT_NE(text.find(fmt::format("shin={}", r.first->input.shin)), std::string::npos) << text;
  ASSERT_TRUE(fs::exists(r.fst_path));
  EXPECT_GT(fs::file_size(r.fst_path), 100u);
  ASSERT_TRUE(fs::exists(r.vector_path));
  std::ifstream vec(r.vector_path);
  int data_lines = 0;
  for (std::string line; std::getline(vec, line);)
    if (!line.empty() && line[0] != '#') ++data_lines;
  // The window: the last latency + 8 cycles up to the failing one (fewer if it failed earlier).
  EXPECT_EQ(data_lines, std::min<int>(s.table.unit.latency() + 8, static_cast<int>(r.first->cycle)));
  // The saved case alone, replayed on the real RTL (with the PROM copied beside it), reproduces
  // the mismatch: at the window's last cycle, on spec_o, with the run's two values.
  ASSERT_TRUE(fs::exists(r.prom_copy_path));
  const ReplayResult rr = replayVectorFile(r.vector_path);
  EXPECT_EQ(rr.cycles, static_cast<uint64_t>(data_lines));
  ASSERT_TRUE(rr.first.has_value()) << "the saved window replays clean: it does not reproduce the mismatch";
  EXPECT_EQ(rr.first->cycle, rr.cycles);
  EXPECT_EQ(rr.first->signal, "spec_o");
  EXPECT_EQ(rr.first->expected, r.first->expected.spec);
  EXPECT_EQ(rr.first->got, r.first->got.spec);
}

TEST(SpecCosim, AGeneratedVectorFileOfTheRealModelReplaysClean) {
  // The counterpart of the saved failing window: the correct model's expectations pass.
  const CosimSetup s = setup("narrow");
  const std::string vec = (fs::path(s.prom_path).parent_path() / "narrow.vec").string();
  writeSpecVectors(vec, generateSpecVectors(specConfig("narrow"), 2000, 5, s.prom_path, fs::path(vec).parent_path().string()));
  const ReplayResult rr = replayVectorFile(vec);
  EXPECT_EQ(rr.cycles, 2000u);
  EXPECT_GT(rr.results, 1000u);
  EXPECT_EQ(rr.mismatches, 0u) << (rr.first ? rr.first->describe() : "");
}

TEST(SpecCosim, DetectsALatencyDifference) {
  const CosimSetup s = setup("narrow");
  SpecUnitParams wrong = s.table.unit;
  wrong.PipeStages += 1;
  SpecUnitModel model(wrong, s.table.words, s.table.seg_words);
  RandomSpecStimulus stim(s.table.unit, 9, 1000, 0.0);
  const SpecCosimResult r = runSpecCosim("narrow", model, stim, options(s));
  ASSERT_TRUE(r.first.has_value());
  EXPECT_NE(r.first->got.valid, r.first->expected.valid);  // a control mismatch, found at once
  EXPECT_EQ(r.first->cycle, static_cast<uint64_t>(s.table.unit.latency()));
  // The saved window (from reset to the failing cycle) replays to the same mismatch.
  const ReplayResult rr = replayVectorFile(r.vector_path);
  ASSERT_TRUE(rr.first.has_value());
  EXPECT_EQ(rr.first->cycle, r.first->cycle);
  EXPECT_EQ(rr.first->signal, "valid_o");
}

TEST(SpecCosim, CorruptShortOrMissingPromFailsLoudly) {
  const CosimSetup s = setup("narrow");
  SpecUnitModel model(s.table.unit, s.table.words, s.table.seg_words);
  auto run = [&](const std::string& path) {
    SpecCosimOptions o = options(s);
    o.prom_path = path;
    RandomSpecStimulus stim(s.table.unit, 5, 100, 0.0);
    runSpecCosim("narrow", model, stim, o);
  };
  auto expectFailure = [&](const std::string& path, const std::string& needle) {
    try {
      run(path);
      ADD_FAILURE() << path << " must not pass";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  // One flipped bit in the word of address 500.
  PromTable bad = s.table;
  bad.words[500] ^= 1;
  writeFileAtomic(s.prom_path + ".flip.hex", renderProm(bad, PromFormat::Hex));
  expectFailure(s.prom_path + ".flip.hex", "word 500");
  // Missing.
  expectFailure(s.prom_path + ".missing.hex", "missing.hex: no such file");
  // Short: the last 24 lines cut off.
  std::ifstream full(s.prom_path);
  std::vector<std::string> lines;
  for (std::string l; std::getline(full, l);) lines.push_back(l);
  std::ofstream shortf(s.prom_path + ".short.hex");
  for (size_t i = 0; i + 24 < lines.size(); ++i) shortf << lines[i] << "\n";
  shortf.close();
  expectFailure(s.prom_path + ".short.hex", "1000 words");
}
