// Vector files (sim/vectors/vector_file.h): generation from the model, the strict readers, and the replay
// on the verilated configurations, which passes on a correct file and fails on a wrong one.
#include <gtest/gtest.h>

#include "test_util.h"

#include <algorithm>
#include <filesystem>
#include <set>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "config/registry.h"
#include "device/prom.h"
#include "device/prom_io.h"
#include "cosim/replay.h"
#include "vectors/vector_file.h"
#include "vectors/vector_gen.h"
#include "io/files.h"

using namespace shd;
using shd::testutil::errorOf;
namespace fs = std::filesystem;

namespace {

// Every occurrence of `from` (a literal string) replaced by `to`.
std::string replaceAll(std::string s, const std::string& from, const std::string& to) {
  for (size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + to.size())) s.replace(at, from.size(), to);
  return s;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void spit(const fs::path& p, const std::string& text) { std::ofstream(p) << text; }

// A spec-unit vector file of `config` in dir, with its PROM beside it.
fs::path specFile(const fs::path& dir, const std::string& config, uint64_t cycles, uint64_t seed) {
  const SpecUnitConfig cfg = specConfig(config);
  const PromTable t = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
  writePromHexFiles((dir / (config + ".hex")).string(), t);
  const fs::path vec = dir / ("spec_" + config + ".vec");
  writeSpecVectors(vec.string(), generateSpecVectors(specConfig(config), cycles, seed, (dir / (config + ".hex")).string(), dir.string()));
  return vec;
}

fs::path spanFile(const fs::path& dir, const std::string& config, uint64_t cycles, uint64_t seed,
                  VectorGenSummary* summary = nullptr) {
  const fs::path vec = dir / ("span_" + config + ".vec");
  writeSpanVectors(vec.string(), generateSpanVectors(spanConfig(config), cycles, seed, summary));
  return vec;
}

}  // namespace

TEST(VectorFile, SpecRoundTripsExactly) {
  const fs::path dir = testutil::freshTestDir("vectors");
  const fs::path vec = specFile(dir, "cubic", 500, 7);
  const SpecVectors v = loadSpecVectors(vec.string());
  EXPECT_EQ(v.config, "cubic");
  EXPECT_EQ(v.prom, "cubic.hex");  // relative to the file's directory
  ASSERT_EQ(v.in.size(), 500u);
  // Rendering what was read gives the file back, byte for byte (notes are not read back; the
  // spec files have none).
  EXPECT_EQ(renderSpecVectors(v), slurp(vec));
}

TEST(VectorFile, SpanRoundTripsExactly) {
  const fs::path dir = testutil::freshTestDir("vectors");
  for (const std::string& mode : builtinConfigNames("span")) {
    const fs::path vec = spanFile(dir, mode, 1500, 3);
    SpanVectors v = loadSpanVectors(vec.string());
    EXPECT_EQ(v.config, mode);
    ASSERT_EQ(v.cycles.size(), 1500u);
    EXPECT_GT(v.descs.size(), 10u) << mode;
    // Re-render with the generator's notes: identical text (every field survives the trip,
    // signed ones through their port width).
    v.notes = generateSpanVectors(spanConfig(mode), 1500, 3).notes;
    EXPECT_EQ(renderSpanVectors(v), slurp(vec)) << mode;
  }
}

TEST(VectorFile, SpanStimulusCoversEveryClassAndShapeAndBackPressure) {
  const fs::path dir = testutil::freshTestDir("vectors");
  VectorGenSummary s;
  const fs::path vec = spanFile(dir, "serial", 4000, 1, &s);
  EXPECT_EQ(s.phases_done, 3) << s.text();
  const SpanVectors v = loadSpanVectors(vec.string());
  uint64_t stalled = 0, waiting_offer = 0, gaps = 0;
  for (size_t i = 0; i < v.cycles.size(); ++i) {
    const SpanVectorCycle& c = v.cycles[i];
    stalled += c.expected.out_valid && !c.out_ready;
    waiting_offer += c.desc_valid && !c.expected.desc_ready;
    gaps += !c.desc_valid && c.expected.desc_ready;
  }
  EXPECT_GT(stalled, 100u);        // out_ready back-pressure on valid outputs
  EXPECT_GT(waiting_offer, 100u);  // descriptors offered while the unit is busy
  EXPECT_GT(gaps, 10u);            // an idle unit with no descriptor offered
  const std::string text = slurp(vec);
  EXPECT_NE(text.find("25 of 25 descriptors accepted"), std::string::npos);  // 5 classes x 5 drawable shapes
}

TEST(VectorFile, CheckedInSpanFilesCoverTheDirectedPhasesAndTheControlCorners) {
  // vectors_fresh proves the checked-in files are what the generator makes; this proves that
  // the cycle counts of scripts/regen_vectors.sh are long enough for the directed phases, and
  // counts the control corners again by running the model on each file's inputs (the file alone
  // cannot tell a ROW cycle from a SPAN cycle without a valid lane).
  for (const std::string& mode : builtinConfigNames("span")) {
    const fs::path path = fs::path(SHD_SOURCE_DIR) / "vectors/cycles" / ("span_" + mode + ".vec");
    const std::string text = slurp(path);
    ASSERT_FALSE(text.empty()) << mode;
    const SpanVectors v = loadSpanVectors(path.string());
    // Lines "# coverage: phase <1..3>, ... all done by cycle <n>".
    long done = 0;
    std::istringstream lines(text);
    for (std::string line; std::getline(lines, line);)
      if (line.rfind("# coverage: phase ", 0) == 0 && line.size() > 19 && line[18] >= '1' && line[18] <= '3' &&
          line[19] == ',' && line.find("all done by cycle ") != std::string::npos)
        ++done;
    const long directed = v.params.NumTri > 1 ? 3 : 2;  // phase 2 exists with several lane-triangles
    EXPECT_EQ(done, directed) << mode;
    SpanUnitModel model(v.params);
    model.reset();
    SpanOut o;
    uint64_t stalled = 0, waiting = 0, idle_gap = 0, empty_stalled = 0, differ = 0;
    for (const SpanVectorCycle& c : v.cycles) {
      SpanIn in;
      in.desc_valid = c.desc_valid;
      in.out_ready = c.out_ready;
      in.desc = c.desc >= 0 ? &v.descs[static_cast<size_t>(c.desc)] : nullptr;
      const uint64_t span_before = model.spanCycles();
      model.tick(in, o);
      differ += o.desc_ready != c.expected.desc_ready || o.out_valid != c.expected.out_valid;
      stalled += o.out_valid && !c.out_ready;
      waiting += c.desc_valid && !o.desc_ready;
      idle_gap += !c.desc_valid && o.desc_ready;
      empty_stalled += model.spanCycles() > span_before && !o.out_valid && !c.out_ready;
    }
    EXPECT_EQ(differ, 0u) << mode;
    EXPECT_GT(stalled, 500u) << mode;   // valid outputs held by out_ready low
    EXPECT_GT(waiting, 500u) << mode;   // descriptors offered while the unit is busy
    EXPECT_GT(idle_gap, 10u) << mode;   // the unit idle with nothing offered
    if (v.params.NumTri > 1) {
      EXPECT_GT(empty_stalled, 0u) << mode;  // a lane group without a valid lane, out_ready low
    }
    // A unit that may interleave rows gets descriptors of both assignments.
    const auto interleaved = std::count_if(v.descs.begin(), v.descs.end(), [](const SpanDesc& d) { return d.interleave; });
    if (v.params.Interleave) {
      EXPECT_GT(interleaved, 10) << mode;
      EXPECT_LT(interleaved, static_cast<long>(v.descs.size()) - 10) << mode;
    } else {
      EXPECT_EQ(interleaved, 0) << mode;
    }
  }
}

TEST(VectorFile, CheckedInSpecFilesCoverTheCorners) {
  for (const std::string& config : builtinConfigNames("spec")) {
    const fs::path path = fs::path(SHD_SOURCE_DIR) / "vectors/cycles" / ("spec_" + config + ".vec");
    const SpecVectors v = loadSpecVectors(path.string());
    const SpecUnitParams& p = v.params;
    const RomImage rom = readPromHexFiles((path.parent_path() / v.prom).string(), p);
    const std::vector<PromWord>& words = rom.prom;
    const uint32_t one = static_cast<uint32_t>(p.cosOne()), lmax = static_cast<uint32_t>(p.lightMax());
    uint64_t shin0 = 0, shin_max = 0, cos0 = 0, cos_one = 0, cos_above = 0, cos_max = 0, dark = 0, full = 0;
    uint64_t gaps = 0, below_cut = 0, at_cut = 0;
    std::set<std::pair<uint32_t, uint32_t>> inputs;  // (shin, cos) of the valid cycles
    for (size_t i = 0; i < v.in.size(); ++i) {
      const SpecIn& in = v.in[i];
      if (!in.valid) {
        gaps += i > 0 && v.in[i - 1].valid;
        continue;
      }
      shin0 += in.shin == 0;
      shin_max += in.shin == static_cast<uint32_t>(p.shinCodes() - 1);
      cos0 += in.cos == 0;
      cos_one += in.cos == one;
      cos_above += in.cos > one;
      cos_max += in.cos == 2 * one - 1;
      dark += in.light == std::array<uint32_t, 3>{0, 0, 0};
      full += in.light == std::array<uint32_t, 3>{lmax, lmax, lmax};
      const bool cubic = p.kind() == SpecKind::Poly && p.Degree == 3;
      const int64_t cut = cubic ? decodePromWord(words[in.shin], p).cut : 0;
      below_cut += cut > 0 && in.cos + 1 == cut;
      at_cut += cut > 0 && in.cos == cut;
      inputs.insert({in.shin, in.cos});
    }
    for (uint64_t n : {shin0, shin_max, cos0, cos_one, cos_above, cos_max, dark, full}) EXPECT_GT(n, 0u) << config;
    EXPECT_GT(gaps, 100u) << config;  // valid dropped between valid inputs
    const uint32_t last = static_cast<uint32_t>(
        buildPromTable(PromRequest::fromContent(specConfig(config).prom), p).entries.size() - 1);
    if (p.kind() == SpecKind::Table) {
      // Every 16th bucket edge of the last entry's row from both sides (random cosines hit an
      // edge of a given row about once in 2^(Wc+1) draws).
      for (uint32_t k = 1; k < (1u << p.TableBits); k += 16) {
        const uint32_t edge = k << (p.CosFracBits - p.TableBits);
        EXPECT_TRUE(inputs.count({last, edge - 1}) && inputs.count({last, edge})) << config << " bucket edge " << k;
      }
    }
    if (p.kind() == SpecKind::ExpLog) {  // the normalisation's steps: every power of two and its neighbours
      for (uint32_t k = 0; k <= static_cast<uint32_t>(p.CosFracBits); ++k) {
        const bool all = inputs.count({last, (1u << k) - 1}) && inputs.count({last, 1u << k}) && inputs.count({last, (1u << k) + 1});
        EXPECT_TRUE(all) << config << " 2^" << k;
      }
    }
    if (p.kind() == SpecKind::Piecewise) {  // each segment's first code and its neighbours, every 8th n
      for (uint32_t shin = 0; shin <= last; shin += 8) {
        const PiecewiseCodes q = decodePiecewise(words[shin], &rom.seg[size_t{shin} * static_cast<size_t>(p.Segments)], p);
        for (const PiecewiseCodes::Seg& g : q.segs)
          for (int64_t c = std::max<int64_t>(g.B - 1, 0); c <= std::min<int64_t>(g.B + 1, 2 * int64_t{one} - 1); ++c)
            EXPECT_TRUE(inputs.count({shin, static_cast<uint32_t>(c)})) << config << " n " << shin << " code " << c;
      }
    }
    if (p.kind() == SpecKind::Poly && p.Degree == 3) {
      EXPECT_GT(below_cut, 10u) << config;  // f cut to 0 one code below the cut-off ...
      EXPECT_GT(at_cut, 10u) << config;     // ... and not at it
    }
  }
}

TEST(VectorFile, ReadersRejectMalformedFilesNamingTheLine) {
  const fs::path dir = testutil::freshTestDir("vectors");
  const std::string spec = slurp(specFile(dir, "narrow", 50, 1));
  const std::string span = slurp(spanFile(dir, "seg2", 200, 1));
  auto withLine = [](const std::string& text, const std::string& from, const std::string& to) {
    const size_t at = text.find(from);
    EXPECT_NE(at, std::string::npos) << from;
    return text.substr(0, at) + to + text.substr(at + from.size());
  };
  // Span: lines inserted before the first D record (the first record of a generated file).
  const size_t d_at = span.find("\nD ") + 1;
  const std::string first_d = span.substr(d_at, span.find('\n', d_at) - d_at);
  auto before = [&](const std::string& lines) { return span.substr(0, d_at) + lines + span.substr(d_at); };
  struct Case {
    std::string name, text, needle;
    bool spec;
  };
  // The first cycle line of the spec file is "1 0 0 0 0 0  0 0 0 0 0" (the corners).
  const std::vector<Case> cases = {
      {"not hex", withLine(spec, "\n1 0 0 0 0 0  0 0 0 0 0\n", "\n1 0 0 0 0 g  0 0 0 0 0\n"), "not a hex value", true},
      {"too wide", withLine(spec, "\n1 0 0 0 0 0  0 0 0 0 0\n", "\n1 0 0 100 0 0  0 0 0 0 0\n"), "does not fit its 8-bit port", true},
      {"short", withLine(spec, "\n1 0 0 0 0 0  0 0 0 0 0\n", "\n1 0 0 0 0 0  0 0 0 0\n"), "before field exp_b", true},
      {"long", withLine(spec, "\n1 0 0 0 0 0  0 0 0 0 0\n", "\n1 0 0 0 0 0  0 0 0 0 0 0\n"), "12 fields, 11 expected", true},
      {"params", withLine(spec, "# params 2 10", "# params 2 11"), "differ from the rtl object", true},
      {"latency", withLine(spec, "# latency 2", "# latency 3"), "latency 3, the parameters give 2", true},
      {"no prom", withLine(spec, "# prom ", "# from "), "no '# prom ...' header line", true},
      {"unit", withLine(spec, "# unit spec", "# unit span"), "unit 'span', a spec-unit file expected", true},
      {"record", before("X 1\n"), "unknown record 'X'", false},
      {"offer", before(first_d + "\nC 1 1  0 0 0 0\n"), "while the previous descriptor is offered", false},
      {"first offer", before("C 1 1  1 0 0 0\n"), "desc_valid is 1 before any D record", false},
      {"lane mask", before("C 0 1  1 0 0 4\n"), "does not fit its 2-bit port", false},
      {"or", before("C 0 1  1 1 0 0\n"), "exp_out_valid 1 with exp_lane_valid 0", false},
      {"short D", before(first_d.substr(0, first_d.rfind(' ')) + "\n"), "the record ends before field", false},
  };
  for (const Case& c : cases) {
    const fs::path p = dir / ("bad_" + std::to_string(&c - cases.data()) + ".vec");
    spit(p, c.text);
    const std::string err =
        errorOf([&] { c.spec ? (void)loadSpecVectors(p.string()) : (void)loadSpanVectors(p.string()); });
    EXPECT_NE(err.find(c.needle), std::string::npos) << c.name << ": " << err;
    EXPECT_NE(err.find(p.string() + ":"), std::string::npos) << c.name << ": " << err;  // path:line
  }
  EXPECT_NE(errorOf([&] { vectorFileUnit((dir / "missing.vec").string()); }).find("missing.vec: no such file"),
            std::string::npos);
  spit(dir / "plain.txt", "1 0 0\n");
  EXPECT_NE(errorOf([&] { vectorFileUnit((dir / "plain.txt").string()); }).find("not a shadesim vector file"),
            std::string::npos);
}

TEST(Replay, CorrectFilesPassAndOneWrongValueFailsThere) {
  const fs::path dir = testutil::freshTestDir("vectors");
  for (const char* unit : {"spec", "span"}) {
    const fs::path vec = std::string(unit) == "spec" ? specFile(dir, "wide", 800, 11) : spanFile(dir, "evenodd", 800, 11);
    const ReplayResult ok = replayVectorFile(vec.string());
    EXPECT_EQ(ok.cycles, 800u);
    EXPECT_EQ(ok.mismatches, 0u) << (ok.first ? ok.first->describe() : "");
    EXPECT_GT(ok.results, 100u);
    // One expected value wrong at a known cycle: the replay must name that cycle and signal.
    uint64_t cycle = 0;
    std::string signal;
    if (std::string(unit) == "spec") {
      SpecVectors v = loadSpecVectors(vec.string());
      for (size_t i = 400; i < v.in.size() && !cycle; ++i)
        if (v.expected[i].valid && v.expected[i].rgb[1] > 0) {
          v.expected[i].rgb[1] ^= 1;
          cycle = i + 1;
          signal = "spec_g_o";
        }
      writeSpecVectors(vec.string(), v);
    } else {
      SpanVectors v = loadSpanVectors(vec.string());
      v.notes = generateSpanVectors(spanConfig("evenodd"), 800, 11).notes;
      for (size_t i = 400; i < v.cycles.size() && !cycle; ++i)
        if (v.cycles[i].expected.lane[1].valid) {
          v.cycles[i].expected.lane[1].y ^= 1;
          cycle = i + 1;
          signal = "out_y_o[lane 1]";
        }
      writeSpanVectors(vec.string(), v);
    }
    ASSERT_NE(cycle, 0u) << unit;
    const ReplayResult bad = replayVectorFile(vec.string());
    EXPECT_EQ(bad.mismatches, 1u) << unit;
    ASSERT_TRUE(bad.first.has_value()) << unit;
    EXPECT_EQ(bad.first->cycle, cycle) << unit;
    EXPECT_EQ(bad.first->signal, signal) << unit;
    EXPECT_EQ(bad.first->expected, bad.first->got ^ 1) << unit;  // the flipped bit, nothing else
  }
}

TEST(Replay, WritesAnFstWaveform) {
  const fs::path dir = testutil::freshTestDir("vectors");
  ReplayOptions o;
  o.fst_path = (dir / "wave.fst").string();
  const ReplayResult r = replayVectorFile(spanFile(dir, "seg4", 300, 2).string(), o);
  EXPECT_EQ(r.mismatches, 0u);
  ASSERT_TRUE(fs::exists(o.fst_path));
  EXPECT_GT(fs::file_size(o.fst_path), 1000u);
}

TEST(Replay, RefusesFilesItCannotReplayFaithfully) {
  const fs::path dir = testutil::freshTestDir("vectors");
  const fs::path spec = specFile(dir, "default", 50, 1);
  const std::string text = slurp(spec);
  // Parameters other than the verilated configuration's (consistent within the file).
  std::string other = replaceAll(text, "\"PipeStages\":1", "\"PipeStages\":2");
  other = replaceAll(other, "# params 2 15 10 10 14 28 14 16 8 1", "# params 2 15 10 10 14 28 14 16 8 2");
  other = replaceAll(other, "# latency 3", "# latency 4");
  spit(dir / "other.vec", other);
  EXPECT_NE(errorOf([&] { replayVectorFile((dir / "other.vec").string()); }).find("made for parameters"),
            std::string::npos);
  // A configuration that is not verilated.
  spit(dir / "unknown.vec", replaceAll(text, "# config default", "# config nosuch"));
  EXPECT_NE(errorOf([&] { replayVectorFile((dir / "unknown.vec").string()); }).find("not verilated"), std::string::npos);
  // A PROM that is missing, or holds another configuration's table.
  fs::remove(dir / "default.hex");
  EXPECT_NE(errorOf([&] { replayVectorFile(spec.string()); }).find("cannot read PROM file"), std::string::npos);
  const SpecUnitConfig narrow = specConfig("narrow");
  writeFileAtomic((dir / "default.hex").string(),
                  renderProm(buildPromTable(PromRequest::fromContent(narrow.prom), narrow.rtl), PromFormat::Hex));
  // It parses (16-bit words fit the 24-bit ones), loads, and must not pass.
  EXPECT_GT(replayVectorFile(spec.string()).mismatches, 0u);
}

TEST(VectorGen, RefusesAStalePromAndUnknownConfigurations) {
  const fs::path dir = testutil::freshTestDir("vectors");
  const SpecUnitConfig cfg = specConfig("default");
  PromTable t = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
  t.words[17] ^= 1;
  writeFileAtomic((dir / "stale.hex").string(), renderProm(t, PromFormat::Hex));
  EXPECT_NE(errorOf([&] { requirePromFileHoldsTable(cfg, (dir / "stale.hex").string()); })
                .find("word 17"),
            std::string::npos);
  // Unknown names: the registry's message, which lists its names.
  const std::string spec_err = errorOf([&] { specConfig("nosuch"); });
  EXPECT_NE(spec_err.find("no specular-unit configuration 'nosuch'"), std::string::npos) << spec_err;
  EXPECT_NE(spec_err.find("default"), std::string::npos) << spec_err;
  const std::string span_err = errorOf([&] { spanConfig("nosuch"); });
  EXPECT_NE(span_err.find("no span-unit configuration 'nosuch'"), std::string::npos) << span_err;
  EXPECT_NE(span_err.find("serial"), std::string::npos) << span_err;
}
