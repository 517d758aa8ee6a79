// Co-simulation of the verilated shd_span_unit against SpanUnitModel, cycle by cycle, for
// every mode, with random back-pressure and descriptor gaps.
#include <gtest/gtest.h>

#include "test_util.h"

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <memory>
#include <random>
#include <stdexcept>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "raster/desc_stream.h"
#include "cosim/replay.h"
#include "cosim/span_cosim.h"
#include "io/files.h"
#include "vectors/vector_gen.h"
// Verilator's own headers are not -Wextra clean (verilated_types.h:1127, an unused parameter).
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-parameter"
#include "harness/verilated_ports.h"
#pragma GCC diagnostic pop

using namespace shd;
using shd::testutil::spanModes;
using shd::testutil::spanParams;
namespace fs = std::filesystem;

namespace {

// Generator triangles through setup for `mode`; triangles setup drops are skipped.
std::function<bool(SpanDesc&)> stream(const std::string& mode, uint64_t seed, long count) {
  RasterConfig cfg;
  cfg.unit = spanParams(mode);
  auto s = std::make_shared<DescriptorStream>(seed, static_cast<uint64_t>(count), cfg);
  return [s](SpanDesc& d) { return s->next(d); };
}

// Whether units of two parameter sets show a descriptor alike: each alone, every output equal on
// every cycle (compareSpanOutputs).
bool showAlike(const SpanParams& a, const SpanParams& b, const SpanDesc& d) {
  SpanUnitModel ua(a), ub(b);
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  SpanOut oa, ob;
  do {
    ua.tick(in, oa);
    ub.tick(in, ob);
    in.desc_valid = false;
    if (!compareSpanOutputs(oa, ob).empty()) return false;
  } while (!ua.idle() || !ub.idle());
  return true;
}

// The stream of `rtl`'s generator triangles whose first `alike` descriptors are ones the units
// of `rtl` and `model` show alike (the others of the stream's start skipped): a run comparing the
// two then fails after them. Their tags are appended to *alike_tags.
std::function<bool(SpanDesc&)> alikeFirst(const std::string& rtl, const std::string& model, int alike, uint64_t seed,
                                          long count, std::shared_ptr<std::vector<uint32_t>> alike_tags) {
  auto next = std::make_shared<std::function<bool(SpanDesc&)>>(stream(rtl, seed, count));
  auto left = std::make_shared<int>(alike);
  const SpanParams a = spanParams(rtl), b = spanParams(model);
  return [=](SpanDesc& d) {
    while ((*next)(d))
      if (*left == 0 || showAlike(a, b, d)) {
        if (*left > 0) {
          --*left;
          alike_tags->push_back(d.tag);
        }
        return true;
      }
    return false;
  };
}

// That stream offered to a unit cycle by cycle: the descriptor on offer, if any, and the next
// one once the unit has accepted it.
struct Offer {
  Offer(const std::string& mode, uint64_t seed, long count) : next(stream(mode, seed, count)) { have = next(pending); }
  void accepted() { have = next(pending); }
  std::function<bool(SpanDesc&)> next;
  SpanDesc pending;
  bool have = false;
};

}  // namespace

class SpanCosimModes : public testing::TestWithParam<std::string> {};

TEST_P(SpanCosimModes, RandomTrianglesWithBackPressure) {
  const std::string mode = GetParam();
  SpanCosimOptions o;
  o.seed = 31;
  o.fail_dir = shd::testutil::freshTestDir("span_cosim").string();
  const SpanCosimResult r = runSpanCosim(GetParam(), stream(mode, 20261122, 30000), o);
  std::printf("span %s: %llu triangles, %llu fragments, %llu cycles, %llu mismatches, %.2f s\n", GetParam().c_str(),
              static_cast<unsigned long long>(r.triangles), static_cast<unsigned long long>(r.fragments),
              static_cast<unsigned long long>(r.cycles), static_cast<unsigned long long>(r.mismatches), r.seconds);
  EXPECT_GT(r.triangles, 24000u);  // of 30,000: setup drops those with no pixel centre inside
  EXPECT_GT(r.fragments, 1000000u);
  EXPECT_EQ(r.mismatches, 0u) << (r.first ? r.first->what : "") << "\nwaveform " << r.fst_path << "\ncase " << r.case_path;
}

INSTANTIATE_TEST_SUITE_P(Modes, SpanCosimModes,
                         testing::ValuesIn(shd::testutil::spanModes()));

// The checker must be able to fail: seg2 and evenodd draw the same pixels with the same values
// but put them in different lanes and cycles; so do their full-rate units. The stream starts
// with `alike` descriptors both show alike, so the run fails after them. The full-rate unit,
// draining every `drain_every` descriptors (SpanCosimOptions::drain_every), then saves a case
// that starts at its last idle cycle with the descriptors accepted since; the paper's unit one
// that starts at the failing triangle's acceptance.
struct WrongModelCase {
  const char* rtl;
  const char* model;
  int alike;
  uint64_t drain_every;
};

class SpanCosimWrongModel : public testing::TestWithParam<WrongModelCase> {};

TEST_P(SpanCosimWrongModel, IsDetectedAndItsSavedCaseFailsAloneAtItsLastCycle) {
  const WrongModelCase w = GetParam();
  SpanCosimOptions o;
  o.fail_dir = shd::testutil::freshTestDir("span_cosim").string();
  o.model_params = spanParams(w.model);
  o.drain_every = w.drain_every;
  auto alike_tags = std::make_shared<std::vector<uint32_t>>();
  const SpanCosimResult r = runSpanCosim(w.rtl, alikeFirst(w.rtl, w.model, w.alike, 5, 400, alike_tags), o);
  ASSERT_GT(r.mismatches, 0u);
  ASSERT_TRUE(r.first.has_value());
  std::printf("as expected: cycle %llu triangle %u: %s\n", static_cast<unsigned long long>(r.first->cycle),
              r.first->tag, r.first->what.c_str());
  ASSERT_TRUE(r.case_note.empty()) << r.case_note;
  ASSERT_TRUE(fs::exists(r.fst_path));
  EXPECT_GT(fs::file_size(r.fst_path), 100u);
  std::ifstream c(r.case_path);
  std::string text((std::istreambuf_iterator<char>(c)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("\"descriptor\""), std::string::npos);
  EXPECT_NE(text.find("out_ready_after_accept"), std::string::npos);
  // The failing case saved as a vector file: replayed alone on the real RTL it fails at its last
  // cycle (the run's failing one), and nowhere before.
  ASSERT_TRUE(fs::exists(r.vector_path));
  const ReplayResult rr = replayVectorFile(r.vector_path);
  ASSERT_TRUE(rr.first.has_value()) << "the saved case replays clean: it does not reproduce the mismatch";
  EXPECT_EQ(rr.first->cycle, rr.cycles);
  EXPECT_EQ(rr.mismatching_cycles, 1u);
  EXPECT_LT(rr.cycles, r.first->cycle + 1) << "the saved case starts at reset";
  EXPECT_EQ(alike_tags->size(), static_cast<size_t>(w.alike));
  EXPECT_EQ(std::count(alike_tags->begin(), alike_tags->end(), r.first->tag), 0)
      << "the run fails after the alike descriptors, not in one of them";
  std::printf("replayed alone: %llu cycles, first mismatch %s\n", static_cast<unsigned long long>(rr.cycles),
              rr.first->describe().c_str());
}

const WrongModelCase kWrongModels[] = {{"seg2", "evenodd", 8, 32}, {"seg2full", "evenoddfull", 8, 3}};

INSTANTIATE_TEST_SUITE_P(Pairs, SpanCosimWrongModel, testing::ValuesIn(kWrongModels),
                         [](const testing::TestParamInfo<WrongModelCase>& i) { return std::string(i.param.rtl); });

namespace {

std::string fileText(const std::string& path) { return readInputFile(path, uint64_t{1} << 30); }

// The same run on one thread and on two (SpanCosimOptions::threads), each with a fail directory
// of its own under `dir`.
std::array<SpanCosimResult, 2> oneAndTwoThreads(const std::string& mode,
                                                const std::function<std::function<bool(SpanDesc&)>()>& make_stream,
                                                SpanCosimOptions o, const fs::path& dir) {
  std::array<SpanCosimResult, 2> r;
  for (int t = 1; t <= 2; ++t) {
    o.threads = t;
    o.fail_dir = (dir / std::to_string(t)).string();
    fs::create_directories(o.fail_dir);
    r[static_cast<size_t>(t - 1)] = runSpanCosim(mode, make_stream(), o);
  }
  return r;
}

}  // namespace

// Two threads (the stimulus and the model ahead of the RTL) give one thread's result: every
// mode's counts on a stream, and with a wrong model the first mismatch, the count of them up to
// the limit and the saved case, byte for byte; also with one-pixel triangles back to back. A limit of one mismatch stops the checker while
// the stimulus, 20,000 triangles from its end, waits for room in the ring.
TEST(SpanCosim, TwoThreadsEqualOneThread) {
  const fs::path dir = shd::testutil::freshTestDir("span_cosim");
  for (const std::string& mode : rtlSpanConfigs()) {  // every mode of a full build
    SpanCosimOptions o;
    o.seed = 9;
    const auto r = oneAndTwoThreads(mode, [&] { return stream(mode, 20261126, 3000); }, o, dir / mode);
    EXPECT_GT(r[0].triangles, 2000u) << mode;
    EXPECT_EQ(r[0].mismatches, 0u) << mode << ": " << (r[0].first ? r[0].first->what : "");
    EXPECT_EQ(r[1].triangles, r[0].triangles) << mode;
    EXPECT_EQ(r[1].fragments, r[0].fragments) << mode;
    EXPECT_EQ(r[1].cycles, r[0].cycles) << mode;
    EXPECT_EQ(r[1].mismatches, r[0].mismatches) << mode;
  }
  // One-pixel triangles back to back, the consumer always ready: a descriptor every few cycles,
  // the most the stimulus can take ahead of the checker (SpanStimulus' ring of descriptors).
  const std::vector<std::string> built = rtlSpanConfigs();
  for (const std::string mode : {"serialfull", "seg8full", "sierpinskifull"}) {
    if (std::find(built.begin(), built.end(), mode) == built.end()) continue;  // not in a subset build
    SpanCosimOptions o;
    o.ready_prob = 1;
    o.desc_gap_prob = 0;
    o.drain_every = 0;
    const auto tiny = [&] {
      RasterConfig cfg;
      cfg.unit = spanParams(mode);
      TriGenOptions g;
      g.size_weight = {1, 0, 0, 0, 0};
      auto s = std::make_shared<DescriptorStream>(77, 20000, cfg, g);
      return std::function<bool(SpanDesc&)>([s](SpanDesc& d) { return s->next(d); });
    };
    const auto r = oneAndTwoThreads(mode, tiny, o, dir / (mode + "_tiny"));
    EXPECT_GT(r[0].triangles, 5000u) << mode;
    EXPECT_LT(r[0].cycles, 4 * r[0].triangles) << mode;
    EXPECT_EQ(r[0].mismatches, 0u) << mode << ": " << (r[0].first ? r[0].first->what : "");
    EXPECT_EQ(r[1].mismatches, 0u) << mode << ": " << (r[1].first ? r[1].first->what : "");
    EXPECT_EQ(r[1].triangles, r[0].triangles) << mode;
    EXPECT_EQ(r[1].fragments, r[0].fragments) << mode;
    EXPECT_EQ(r[1].cycles, r[0].cycles) << mode;
  }
  for (const uint64_t limit : {uint64_t{16}, uint64_t{1}}) {
    for (const WrongModelCase& w : kWrongModels) {
      SpanCosimOptions o;
      o.model_params = spanParams(w.model);
      o.drain_every = w.drain_every;
      o.max_mismatches = limit;
      const auto r = oneAndTwoThreads(
          w.rtl,
          [&] {
            return alikeFirst(w.rtl, w.model, w.alike, 5, 20000, std::make_shared<std::vector<uint32_t>>());
          },
          o, dir / fmt::format("{}_{}", w.rtl, limit));
      ASSERT_TRUE(r[0].first.has_value()) << w.rtl;
      ASSERT_TRUE(r[1].first.has_value()) << w.rtl;
      EXPECT_EQ(r[0].mismatches, limit) << w.rtl;
      EXPECT_EQ(r[1].mismatches, r[0].mismatches) << w.rtl;
      EXPECT_EQ(r[1].first->cycle, r[0].first->cycle) << w.rtl;
      EXPECT_EQ(r[1].first->tag, r[0].first->tag) << w.rtl;
      EXPECT_EQ(r[1].first->what, r[0].first->what) << w.rtl;
      EXPECT_EQ(r[1].cycles, r[0].cycles) << w.rtl;
      EXPECT_EQ(r[1].triangles, r[0].triangles) << w.rtl;
      EXPECT_EQ(r[1].fragments, r[0].fragments) << w.rtl;
      ASSERT_TRUE(r[0].case_note.empty() && r[1].case_note.empty()) << r[0].case_note << r[1].case_note;
      EXPECT_EQ(fileText(r[1].vector_path), fileText(r[0].vector_path)) << w.rtl;
      EXPECT_GT(fileText(r[0].vector_path).size(), 100u);
      nlohmann::json c0 = nlohmann::json::parse(fileText(r[0].case_path));
      nlohmann::json c1 = nlohmann::json::parse(fileText(r[1].case_path));
      c0.erase("vectors");
      c1.erase("vectors");
      EXPECT_EQ(c1, c0) << w.rtl;
    }
  }
}

// An error of the stream (the stimulus' thread) reaches the caller, as on one thread; so does a
// thread count other than 1 or 2.
TEST(SpanCosim, TwoThreadsPassTheStreamsErrorOn) {
  for (int threads : {1, 2}) {
    auto next = stream("serialfull", 3, 5000);
    auto count = std::make_shared<int>(0);
    SpanCosimOptions o;
    o.threads = threads;
    o.fail_dir = shd::testutil::freshTestDir("span_cosim").string();
    try {
      runSpanCosim("serialfull", [=](SpanDesc& d) {
        if (++*count == 700) throw std::runtime_error("descriptor 700 is unreadable");
        return next(d);
      }, o);
      ADD_FAILURE() << threads << " threads: no error";
    } catch (const std::runtime_error& e) {
      EXPECT_STREQ(e.what(), "descriptor 700 is unreadable") << threads << " threads";
    }
  }
  for (int threads : {0, 3}) {
    SpanCosimOptions o;
    o.threads = threads;
    EXPECT_THROW(runSpanCosim("serial", stream("serial", 3, 10), o), std::invalid_argument) << threads;
  }
}

TEST(SpanCosim, AGeneratedVectorFileOfTheRealModelReplaysClean) {
  // The counterpart of the saved failing case: the correct model's expectations pass.
  const fs::path dir = shd::testutil::freshTestDir("span_cosim");
  const std::string vec = (dir / "seg2.vec").string();
  writeSpanVectors(vec, generateSpanVectors(spanConfig("seg2"), 2000, 5));
  const ReplayResult rr = replayVectorFile(vec);
  EXPECT_EQ(rr.cycles, 2000u);
  EXPECT_GT(rr.results, 1000u);
  EXPECT_EQ(rr.mismatches, 0u) << (rr.first ? rr.first->describe() : "");
}

TEST(SpanCosim, TickCheckFindsEveryDifferenceTheComparisonFinds) {
  // The co-simulation compares on the ports (SpanDut::tickCheck) and calls compareSpanOutputs
  // only for the message: on real runs of every mode, each cycle's expected outputs are given
  // either as the model has them (tickCheck must pass) or with one compared field changed, in
  // turn: desc_ready, out_valid, the tag, a lane's valid bit, a valid lane's x, y, an
  // attribute (by one, and by 2^AttrBits: the same low bits), the lane and attribute counts.
  // tickCheck must then fail, and the outputs it reads out must show the difference to
  // compareSpanOutputs and equal the model's.
  enum Kind { kNone, kDescReady, kOutValid, kTag, kLaneValid, kX, kY, kAttr, kAttrHigh, kLanes, kAttrCount, kKinds };
  for (const std::string& mode : rtlSpanConfigs()) {
    auto dut = makeSpanDut(mode, "");
    const SpanParams p = dut->params();
    SpanUnitModel model(p);
    dut->reset();
    model.reset();
    Offer offer(mode, 9, 400);
    std::mt19937_64 rng(4);
    std::array<int, kKinds> changed{};
    SpanOut exp, bad, got;
    for (uint64_t c = 0; offer.have || !model.idle(); ++c) {
      SpanIn in;
      in.desc_valid = offer.have;
      in.desc = &offer.pending;
      in.out_ready = rng() % 4 != 0;
      model.tick(in, exp);
      bad = exp;
      SpanLaneOut* valid_lane = nullptr;  // the last valid lane of `bad`, if any
      for (SpanLaneOut& l : bad.lane)
        if (l.valid) valid_lane = &l;
      Kind kind = static_cast<Kind>(c % kKinds);
      const size_t a = c % static_cast<size_t>(p.NumAttr);
      if ((kind == kTag && !exp.out_valid) || (kind >= kX && kind != kLanes && valid_lane == nullptr)) kind = kNone;
      switch (kind) {
        case kDescReady: bad.desc_ready = !bad.desc_ready; break;
        case kOutValid: bad.out_valid = !bad.out_valid; break;
        case kTag: bad.tag += 1; break;
        case kLaneValid: bad.lane[c % bad.lane.size()].valid ^= true; break;
        case kX: valid_lane->x += 1; break;
        case kY: valid_lane->y ^= 1; break;
        case kAttr: valid_lane->attr[a] -= 1; break;
        case kAttrHigh: valid_lane->attr[a] += int64_t{1} << p.AttrBits; break;
        case kLanes: bad.lane.pop_back(); break;
        case kAttrCount: valid_lane->attr.resize(a); break;
        default: break;
      }
      got = SpanOut{};
      const bool same = dut->tickCheck(in, bad, got);
      if (kind == kNone) {
        ASSERT_TRUE(same) << mode << " cycle " << c << ": the model's own outputs do not pass";
      } else {
        ASSERT_FALSE(same) << mode << " cycle " << c << ": change " << kind << " not found";
        EXPECT_NE(compareSpanOutputs(bad, got), "") << mode << " cycle " << c << " change " << kind;
        ASSERT_EQ(compareSpanOutputs(exp, got), "") << mode << " cycle " << c;
        ++changed[kind];
      }
      if (in.desc_valid && exp.desc_ready) offer.accepted();
    }
    for (int k = kDescReady; k < kKinds; ++k) EXPECT_GT(changed[static_cast<size_t>(k)], 10) << mode << " change " << k;
  }
}

TEST(SpanCosim, OneEvalCyclesEqualTwoEvalCycles) {
  // Untraced, the harness clocks a cycle with one eval (VerilatedHarness::cycle); traced, with
  // a falling and a rising edge. On every mode, from reset, with back-pressure and descriptor
  // gaps, both instances give the same outputs on every cycle, and those are the model's.
  const fs::path dir = shd::testutil::freshTestDir("span_cosim");
  for (const std::string& mode : rtlSpanConfigs()) {
    auto fast = makeSpanDut(mode, "");
    auto traced = makeSpanDut(mode, (dir / (mode + ".fst")).string());
    SpanUnitModel model(fast->params());
    fast->reset();
    traced->reset();
    model.reset();
    Offer offer(mode, 13, 150);
    std::mt19937_64 rng(8);
    SpanOut exp, a, b;
    uint64_t cycles = 0;
    while (offer.have || !model.idle()) {
      SpanIn in;
      in.desc_valid = offer.have && rng() % 5 != 0;
      in.desc = &offer.pending;
      in.out_ready = rng() % 3 != 0;
      model.tick(in, exp);
      fast->tick(in, a);
      traced->tick(in, b);
      ++cycles;
      ASSERT_EQ(compareSpanOutputs(exp, a), "") << mode << " untraced, cycle " << cycles;
      ASSERT_EQ(compareSpanOutputs(exp, b), "") << mode << " traced, cycle " << cycles;
      if (in.desc_valid && exp.desc_ready) offer.accepted();
    }
    EXPECT_EQ(fast->cycle(), traced->cycle());
    traced->finish();
    EXPECT_GT(fs::file_size(dir / (mode + ".fst")), 100u);
    std::printf("%s: %llu cycles equal\n", mode.c_str(), static_cast<unsigned long long>(cycles));
  }
}

TEST(SpanCosim, ReadyDrawEqualsTheBernoulliDistribution) {
  for (double p : {0.0, 0.05, 0.3, 0.5, 0.8, 0.999, 1.0}) {
    std::mt19937_64 a(11), b(11);
    std::bernoulli_distribution ref(p);
    const ReadyDraw fast(p);
    uint64_t ones = 0;
    for (int i = 0; i < 200000; ++i) {
      const bool r = ref(a);
      ASSERT_EQ(fast(b), r) << "p " << p << " draw " << i;
      ones += r;
    }
    std::printf("p %.3f: %llu of 200000 draws true\n", p, static_cast<unsigned long long>(ones));
  }
}

TEST(VerilatedPorts, WideFieldsReadBackAsWrittenAndLeaveTheRestAlone) {
  // get/put on a 160-bit port against a bit-by-bit reference, fields of 1..64 bits anywhere.
  VlWide<5> port;
  std::array<bool, 160> ref{};
  for (int w = 0; w < 5; ++w) port[static_cast<size_t>(w)] = 0;
  std::mt19937_64 rng(3);
  for (int i = 0; i < 20000; ++i) {
    const int width = 1 + static_cast<int>(rng() % 64);
    const int lsb = static_cast<int>(rng() % static_cast<uint64_t>(160 - width + 1));
    const uint64_t v = rng();
    ports::put(port, lsb, width, v);
    for (int b = 0; b < width; ++b) ref[static_cast<size_t>(lsb + b)] = (v >> b) & 1;
    const uint64_t mask = width == 64 ? ~uint64_t{0} : (uint64_t{1} << width) - 1;
    ASSERT_EQ(ports::get(port, lsb, width), v & mask) << "lsb " << lsb << " width " << width;
    for (int b = 0; b < 160; ++b)
      ASSERT_EQ((port[static_cast<size_t>(b / 32)] >> (b % 32)) & 1, ref[static_cast<size_t>(b)] ? 1u : 0u) << b;
    // A read of any other field agrees with the reference too.
    const int w2 = 1 + static_cast<int>(rng() % 64);
    const int l2 = static_cast<int>(rng() % static_cast<uint64_t>(160 - w2 + 1));
    uint64_t expect = 0;
    for (int b = 0; b < w2; ++b) expect |= uint64_t{ref[static_cast<size_t>(l2 + b)]} << b;
    ASSERT_EQ(ports::get(port, l2, w2), expect) << "lsb " << l2 << " width " << w2;
  }
}
