// Sweeps (model/sweep/): the grid, shards, a point's evaluation, and the sweep directory
// (resume, shards joined, refusals).
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>

#include <fmt/format.h>

#include "config/registry.h"
#include "report/spec_error.h"
#include "sweep/grid.h"
#include "sweep/spec_sweep.h"
#include "sweep/sweep_run.h"
#include "test_util.h"

using namespace shd;
using shd::testutil::errorOf;
namespace fs = std::filesystem;

namespace {

const std::vector<std::string> kNames = {"Alpha", "Beta", "Gamma"};

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

}  // namespace

TEST(Grid, RangesStepsAndLists) {
  EXPECT_EQ(parseGridAxis("Alpha=8:12", kNames).values, (std::vector<int>{8, 9, 10, 11, 12}));
  EXPECT_EQ(parseGridAxis("Alpha=8:13:2", kNames).values, (std::vector<int>{8, 10, 12}));
  EXPECT_EQ(parseGridAxis("Beta=5:5", kNames).values, (std::vector<int>{5}));
  EXPECT_EQ(parseGridAxis("Gamma=9,4,6", kNames).values, (std::vector<int>{9, 4, 6}));
  const GridAxis a = parseGridAxis("Gamma=1,2", kNames);
  EXPECT_EQ(a.name, "Gamma");
  EXPECT_EQ(a.text, "1,2");
}

TEST(Grid, BadAxesNameTheProblem) {
  auto err = [](const std::string& t) { return errorOf<std::invalid_argument>([&] { parseGridAxis(t, kNames); }); };
  EXPECT_NE(err("Delta=1:2").find("no parameter Delta (it has Alpha, Beta, Gamma)"), std::string::npos);
  EXPECT_NE(err("Alpha=9:8").find("reversed"), std::string::npos);
  EXPECT_NE(err("Alpha=1:8:0").find("step is 0"), std::string::npos);
  EXPECT_NE(err("Alpha=1,2,1").find("1 is given twice"), std::string::npos);
  for (const char* t : {"Alpha", "Alpha=", "=3", "Alpha=1:", "Alpha=:3", "Alpha=-1:3", "Alpha=1:2:3:4", "Alpha=x",
                        "Alpha=1,,2", "Alpha=99999999", "Alpha=1.5"})
    EXPECT_FALSE(err(t).empty()) << t;
  EXPECT_NE(errorOf<std::invalid_argument>([] {
              Grid({parseGridAxis("Alpha=1:2", kNames), parseGridAxis("Alpha=3", kNames)});
            }).find("Alpha is given twice"),
            std::string::npos);
  EXPECT_NE(errorOf<std::invalid_argument>([] {
              Grid({parseGridAxis("Alpha=0:999", kNames), parseGridAxis("Beta=0:999", kNames),
                    parseGridAxis("Gamma=0:1", kNames)});
            }).find("more than 1000000 points"),
            std::string::npos);
}

TEST(Grid, PointsInOrderTheLastAxisFastest) {
  const Grid g({parseGridAxis("Alpha=1:2", kNames), parseGridAxis("Beta=7,5,6", kNames)});
  ASSERT_EQ(g.size(), 6u);
  std::vector<std::pair<int, int>> seen;
  for (uint64_t k = 0; k < g.size(); ++k) {
    const auto p = g.point(k);
    ASSERT_EQ(p.size(), 2u);
    EXPECT_EQ(p[0].first, "Alpha");
    EXPECT_EQ(p[1].first, "Beta");
    seen.emplace_back(p[0].second, p[1].second);
  }
  EXPECT_EQ(seen, (std::vector<std::pair<int, int>>{{1, 7}, {1, 5}, {1, 6}, {2, 7}, {2, 5}, {2, 6}}));
  EXPECT_THROW(g.point(6), std::out_of_range);
}

TEST(Shard, PartsAreDisjointAndCoverTheGrid) {
  for (uint64_t n : {1, 2, 3, 7}) {
    std::vector<int> owners(50, 0);
    for (uint64_t i = 1; i <= n; ++i) {
      const Shard s = Shard::parse(fmt::format("{}/{}", i, n));
      for (uint64_t k = 0; k < owners.size(); ++k) owners[k] += s.holds(k) ? 1 : 0;
    }
    for (int o : owners) EXPECT_EQ(o, 1) << n;
  }
  for (const char* bad : {"0/2", "3/2", "1/0", "2", "1/", "/2", "a/b", "1/10001", "-1/2", "1/2/3"})
    EXPECT_THROW(Shard::parse(bad), std::invalid_argument) << bad;
}

TEST(TextHash, IsFnv1a64) {
  EXPECT_EQ(textHash(""), "cbf29ce484222325");
  EXPECT_EQ(textHash("a"), "af63dc4c8601ec8c");
  EXPECT_NE(textHash("ab"), textHash("ba"));
}

TEST(SpecSweep, PointParamsAndTheirDerivations) {
  const SpecUnitParams base = specConfig("narrow").rtl;
  const SpecUnitParams p = specPointParams(base, {{"CoefFracBits", 9}, {"DiffFracBits", 14}});
  EXPECT_EQ(p.CoefFracBits, 9);
  EXPECT_EQ(p.DiffFracBits, 14);
  EXPECT_EQ(p.CosFracBits, base.CosFracBits);
  const std::string e = errorOf<std::invalid_argument>([&] { specPointParams(base, {{"DiffFracBits", 21}}); });
  EXPECT_NE(e.find("point DiffFracBits=21"), std::string::npos) << e;
  EXPECT_NE(e.find("c^2 - c is exact at 2*CosFracBits"), std::string::npos) << e;
  const auto names = specParamNames();
  EXPECT_EQ(names.size(), 13u);
  EXPECT_NE(std::find(names.begin(), names.end(), "SpecFracBits"), names.end());
}

// A point's record holds the exhaustive report's worst figures, and nothing that varies from run
// to run.
TEST(SpecSweep, PointRecordIsTheErrorReportsSummary) {
  SpecUnitConfig cfg = specConfig("narrow");
  PromRequest req = PromRequest::fromContent(cfg.prom);
  req.n = NSpec::parse("1,8,64,500", true);
  const SpecUnitParams p = specPointParams(cfg.rtl, {{"CoefFracBits", 8}});
  const nlohmann::json r = evaluateSpecPoint(3, p, req);
  const SpecErrorReport rep = computeSpecError("x", buildPromTable(req, p));
  EXPECT_EQ(r.at("index"), 3);
  EXPECT_EQ(r.at("hash"), specPointHash(p));
  EXPECT_EQ(r.at("rtl"), p.toJson());
  EXPECT_EQ(r.at("error").at("total_max_lsb").get<double>(), rep.summary.total_max_lsb.value);
  EXPECT_EQ(r.at("error").at("total_worst_n").get<double>(), rep.summary.total_max_lsb.n);
  EXPECT_EQ(r.at("error").at("datapath_max_lsb").get<double>(), rep.summary.datapath_max_lsb.value);
  EXPECT_EQ(r.at("latency"), 2);
  EXPECT_EQ(r.at("prom_bits"), 1024 * p.promWordBits());
  EXPECT_EQ(r.at("inputs"), 4 * 1025);
  EXPECT_EQ(r.dump(), evaluateSpecPoint(3, p, req).dump());
  EXPECT_GT(r.at("error").at("total_max_lsb").get<double>(), 0.5);  // the final rounding alone
  EXPECT_EQ(r.at("rom_bits"), r.at("prom_bits"));                     // no fixed tables
}

// Minimality (sweep --target-lsb) narrows the widths the unit's kind has: never a width its
// datapath does not read (DiffFracBits outside the poly kind), always the tables' TableBits.
TEST(SpecSweep, EachKindNarrowsItsOwnWidths) {
  const std::map<std::string, std::vector<std::string>> want = {
      {"default", {"CoefIntBits", "CoefFracBits", "DiffFracBits", "SpecFracBits"}},
      {"cubic", {"CoefIntBits", "CoefFracBits", "DiffFracBits", "SpecFracBits", "HornerFracBits"}},
      {"table", {"SpecFracBits", "TableBits"}},
      {"schlick", {"CoefIntBits", "CoefFracBits", "SpecFracBits"}},
      {"explog", {"CoefIntBits", "CoefFracBits", "SpecFracBits", "TableBits"}},
      {"piecewise", {"CoefIntBits", "CoefFracBits", "SpecFracBits"}},
  };
  for (const auto& [name, widths] : want) {
    const SpecUnitConfig c = specConfig(name);
    EXPECT_EQ(specSweepUnit(specSweepBase(name, c.rtl, c.prom)).widths, widths) << name;
  }
}

// The explog kind's ROM bits count its log and exp tables: 2^T words of {g step, g} and
// {e step, e} (rtl/shd_spec_explog.v), so a finer table costs bits the PROM alone does not show.
TEST(SpecSweep, ExpLogRomBitsCountTheTables) {
  SpecUnitConfig cfg = specConfig("explog");
  PromRequest req = PromRequest::fromContent(cfg.prom);
  req.n = NSpec::parse("8,100", true);
  for (int T : {4, 8}) {
    const SpecUnitParams p = specPointParams(cfg.rtl, {{"TableBits", T}});
    const nlohmann::json r = evaluateSpecPoint(0, p, req);
    const int gf = p.SpecFracBits + 6, ef = p.SpecFracBits + 4;  // Ci = 10 <= Wc + 4
    const int64_t tables = (int64_t{1} << T) * ((gf - T + 1) + (gf + 2) + (ef - T + 1) + (ef + 1));
    EXPECT_EQ(r.at("prom_bits"), 1024 * p.promWordBits()) << T;
    EXPECT_EQ(r.at("rom_bits").get<int64_t>(), r.at("prom_bits").get<int64_t>() + tables) << T;
  }
}

namespace {

// A plan of `points` points and an evaluation that counts its calls (the directory logic does
// not depend on what a point holds).
SweepPlan fakePlan(uint64_t points, const std::string& tag = "t") {
  return SweepPlan::make({{"format", "test"},
                          {"tag", tag},
                          {"points", points},
                          {"params", "rtl"},
                          {"front", {{"error", "datapath_max_lsb"}, {"costs", {"latency", "prom_bits"}}}},
                          {"area", "none"}});
}

nlohmann::json fakeRecord(uint64_t k) {
  return {{"index", k},
          {"hash", textHash(std::to_string(k))},
          {"rtl", {{"A", static_cast<int>(k % 3)}, {"B", static_cast<int>(k / 3)}}},
          {"error", {{"datapath_max_lsb", 0.5 + static_cast<double>((k * 7) % 5) / 4}}},
          {"latency", 2 + static_cast<int>(k % 2)},
          {"prom_bits", 1000 + static_cast<int>(k % 4) * 10}};
}

void runAll(const fs::path& dir, const SweepPlan& plan, const Shard& shard, std::atomic<int>& calls,
            unsigned jobs = 2) {
  claimSweepDir(dir.string(), plan);
  SweepRecords done = readSweepRecords(dir.string(), plan);
  runSweepJobs(dir.string(), plan, "point", shardPoints(plan, shard), jobs, [&](uint64_t k) { ++calls; return fakeRecord(k); },
               done, {});
  if (missingPoints(plan, done).empty()) writeSweepResults(dir.string(), plan, sweepResults(plan, done));
}

}  // namespace

TEST(SweepDir, ResumesSkippingRecordedPoints) {
  const fs::path dir = testutil::freshTestDir("sweep");
  const SweepPlan plan = fakePlan(12);
  std::atomic<int> calls{0};
  runAll(dir, plan, Shard{}, calls);
  EXPECT_EQ(calls, 12);
  const std::string csv = slurp(dir / "sweep.csv"), json = slurp(dir / "sweep.json");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 13);
  // Killed after some points: those missing are evaluated again, the others not.
  fs::remove(dir / "point-0000004.json");
  fs::remove(dir / "point-0000011.json");
  fs::remove(dir / "sweep.csv");
  calls = 0;
  runAll(dir, plan, Shard{}, calls, 1);
  EXPECT_EQ(calls, 2);
  EXPECT_EQ(slurp(dir / "sweep.csv"), csv);
  EXPECT_EQ(slurp(dir / "sweep.json"), json);
}

TEST(SweepDir, ShardsMergedEqualTheUnshardedRunByteForByte) {
  const fs::path root = testutil::freshTestDir("sweep");
  const SweepPlan plan = fakePlan(11);
  std::atomic<int> calls{0};
  for (const char* d : {"whole", "s1", "s2", "s3", "merged"}) fs::create_directory(root / d);
  runAll(root / "whole", plan, Shard{}, calls);
  for (int i = 1; i <= 3; ++i) runAll(root / fmt::format("s{}", i), plan, Shard::parse(fmt::format("{}/3", i)), calls);
  EXPECT_EQ(calls, 22);
  EXPECT_FALSE(fs::exists(root / "s1" / "sweep.csv"));  // a shard alone is incomplete
  const std::vector<std::string> shards = {(root / "s1").string(), (root / "s2").string(), (root / "s3").string()};
  // One shard missing: refused, naming the missing points.
  const std::string e = errorOf<std::runtime_error>([&] { mergeSweeps({shards[0], shards[2]}, (root / "merged").string()); });
  EXPECT_NE(e.find("4 of the sweep's 11 points are in none of the directories (1, 4, 7, 10)"), std::string::npos) << e;
  EXPECT_EQ(testutil::dirEntries(root / "merged"), std::vector<std::string>{});
  const auto [plan_m, records_m] = mergeSweeps(shards, (root / "merged").string());
  writeSweepResults((root / "merged").string(), plan_m, sweepResults(plan_m, records_m));
  for (const char* f : {"sweep.csv", "sweep.json", "pareto.csv", "sweep-plan.json"})
    EXPECT_EQ(slurp(root / "merged" / f), slurp(root / "whole" / f)) << f;
}

TEST(SweepDir, ParetoFrontsOfErrorAgainstEachCost) {
  const fs::path dir = testutil::freshTestDir("sweep");
  std::atomic<int> calls{0};
  runAll(dir, fakePlan(12), Shard{}, calls);
  // datapath_max_lsb by k: 0.5 + ((7k) mod 5)/4: k = 0, 5, 10 reach 0.5; latency 2 at even k, so
  // the latency front is k = 0 or 10 (0.5 at latency 2), of which the fewer parameter bits: k = 0
  // (A + B = 0; k = 10 has 4); prom_bits 1000 at k mod 4 = 0: k = 0.
  const std::string pareto = slurp(dir / "pareto.csv");
  EXPECT_EQ(pareto.substr(0, pareto.find('\n')), "front,index,hash,A,B,datapath_max_lsb,latency,prom_bits");
  std::set<std::string> rows;
  size_t at = pareto.find('\n') + 1;
  while (at < pareto.size()) {
    const size_t end = pareto.find('\n', at);
    const std::string line = pareto.substr(at, end - at);
    rows.insert(line.substr(0, line.find(',', line.find(',') + 1)));
    at = end + 1;
  }
  EXPECT_EQ(rows, (std::set<std::string>{"error-latency,0", "error-prom_bits,0"}));
}

namespace {

// A 3 x 3 grid, A = 1:3 and B = 3,1,2 (a list out of order), error max(3 - A, 3 - B).
SweepPlan areaPlan() {
  return SweepPlan::make({{"format", "test"},
                          {"points", 9},
                          {"params", "rtl"},
                          {"front", {{"error", "datapath_max_lsb"}, {"costs", {"latency"}}}},
                          {"area", "ice40 (test)"},
                          {"axes",
                           {{{"name", "A"}, {"text", "1:3"}, {"values", {1, 2, 3}}},
                            {{"name", "B"}, {"text", "3,1,2"}, {"values", {3, 1, 2}}}}}});
}

SweepRecords areaRecords(const SweepPlan& plan) {
  SweepRecords r;
  const Grid g = planGrid(plan);
  for (uint64_t k = 0; k < 9; ++k) {
    const int a = g.point(k)[0].second, b = g.point(k)[1].second;
    r[k] = {{"index", k}, {"hash", "h"}, {"rtl", {{"A", a}, {"B", b}}},
            {"error", {{"datapath_max_lsb", std::max(3 - a, 3 - b)}}}, {"latency", 2}};
  }
  return r;
}

}  // namespace

// A point is synthesised only when no point no wider on every axis has at most its error.
TEST(SweepArea, PointsThatCannotReachAFrontAreNotSynthesised) {
  const SweepPlan plan = areaPlan();
  const SweepRecords records = areaRecords(plan);
  // (1,1) error 2, (2,2) error 1, (3,3) error 0 are synthesised; (3,2) [index 8] and (2,3) [3]
  // are matched by (2,2) [5]; every other point by (1,1) [1].
  EXPECT_EQ(areaDominators(plan, records), (std::vector<int64_t>{1, -1, 1, 5, 1, -1, -1, 1, 5}));
  nlohmann::json all = plan.json;
  all["area_all"] = true;
  EXPECT_EQ(areaDominators(SweepPlan::make(all), records), std::vector<int64_t>(9, -1));
  // The results: the pruned points with area_pruned_by, the front over the synthesised ones.
  const fs::path dir = testutil::freshTestDir("sweep");
  SweepRecords areas;
  for (uint64_t k : {1, 5, 6}) areas[k] = {{"index", k}, {"area", {{"ice40", {{"luts", 100 * (k + 1)}}}}}};
  const std::vector<int64_t> dominator = areaDominators(plan, records);
  EXPECT_THROW(sweepResults(plan, records, {}, dominator), std::logic_error);
  EXPECT_THROW(sweepResults(plan, records, areas, {}), std::logic_error);
  writeSweepResults(dir.string(), plan, sweepResults(plan, records, areas, dominator));
  const std::string csv = slurp(dir / "sweep.csv");
  EXPECT_EQ(csv.substr(0, csv.find('\n')), "index,hash,A,B,datapath_max_lsb,latency,ice40_luts,area_pruned_by");
  EXPECT_NE(csv.find("\n5,h,2,2,1,2,600,\n"), std::string::npos) << csv;
  EXPECT_NE(csv.find("\n8,h,3,2,1,2,,5\n"), std::string::npos) << csv;
  const std::string pareto = slurp(dir / "pareto.csv");
  for (const char* row : {"error-ice40_luts,1,", "error-ice40_luts,5,", "error-ice40_luts,6,"})
    EXPECT_NE(pareto.find(row), std::string::npos) << row << "\n" << pareto;
  EXPECT_NE(pareto.find("error-latency,6,"), std::string::npos) << pareto;
  EXPECT_EQ(std::count(pareto.begin(), pareto.end(), '\n'), 5);
}

// A point is matched only by points of its class (multipliers mapped alike), reached through
// points of its class.
TEST(SweepArea, OnlyPointsOfTheSameClassMatch) {
  const SweepPlan plan = areaPlan();
  const SweepRecords records = areaRecords(plan);
  // Class "y" at A = 2 [indices 3, 4, 5] cuts A = 3 off from A = 1: (3,1) [7] and (3,2) [8],
  // matched by (1,1) [1] and (2,2) [5] before, are now synthesised, and so is (2,1) [4]; (2,3)
  // [3] is still matched by (2,2) [5], within its class.
  std::vector<std::string> classes(9, "x");
  for (uint64_t k : {3, 4, 5}) classes[k] = "y";
  EXPECT_EQ(areaDominators(plan, records, classes), (std::vector<int64_t>{1, -1, 1, 5, -1, -1, -1, -1, -1}));
  EXPECT_THROW(areaDominators(plan, records, std::vector<std::string>(8, "x")), std::logic_error);
}

TEST(SweepDir, RefusesAnotherSweepAndForeignOrCorruptedPoints) {
  const fs::path root = testutil::freshTestDir("sweep");
  std::atomic<int> calls{0};
  fs::create_directory(root / "a");
  runAll(root / "a", fakePlan(4, "one"), Shard{}, calls);
  const std::string e = errorOf<std::runtime_error>([&] { claimSweepDir((root / "a").string(), fakePlan(4, "two")); });
  EXPECT_NE(e.find("holds another sweep"), std::string::npos) << e;
  EXPECT_NE(errorOf<std::runtime_error>([&] { claimSweepDir((root / "missing").string(), fakePlan(4)); })
                .find("no such directory"),
            std::string::npos);
  // A point of another sweep, a corrupted point, an edited plan.
  fs::create_directory(root / "b");
  runAll(root / "b", fakePlan(4, "two"), Shard{}, calls);
  fs::copy_file(root / "b" / "point-0000002.json", root / "a" / "point-0000002.json",
                fs::copy_options::overwrite_existing);
  const SweepPlan one = readSweepPlan((root / "a").string());
  EXPECT_NE(errorOf<std::runtime_error>([&] { readSweepRecords((root / "a").string(), one); })
                .find("point-0000002.json: not a point of sweep"),
            std::string::npos);
  std::ofstream(root / "a" / "point-0000002.json") << "{\"index\": 2, \"plan\":";
  EXPECT_NE(errorOf<std::runtime_error>([&] { readSweepRecords((root / "a").string(), one); }).find("not a point record"),
            std::string::npos);
  std::string plan = slurp(root / "b" / "sweep-plan.json");
  plan.replace(plan.find("two"), 3, "six");
  std::ofstream(root / "b" / "sweep-plan.json") << plan;
  EXPECT_NE(errorOf<std::runtime_error>([&] { readSweepPlan((root / "b").string()); }).find("edited or corrupted"),
            std::string::npos);
  // Shards of different sweeps are not merged.
  fs::create_directory(root / "c");
  fs::create_directory(root / "m");
  runAll(root / "c", fakePlan(4, "three"), Shard{}, calls);
  fs::remove(root / "a" / "point-0000002.json");
  EXPECT_NE(errorOf<std::runtime_error>([&] {
              mergeSweeps({(root / "a").string(), (root / "c").string()}, (root / "m").string());
            }).find("hold different sweeps"),
            std::string::npos);
}

// Beyond 2^28 inputs a point is evaluated on a seeded sample of cosine codes with the corners.
TEST(SpecSweep, SampleCodesAboveTheExhaustiveLimit) {
  SpecUnitParams p = specConfig("default").rtl;
  EXPECT_TRUE(specSampleCodes(p, 1000, kSpecSampleSeed).empty());  // 1000 x 32769 inputs: all
  p.CosFracBits = 20;
  p.DiffFracBits = 28;
  const std::vector<int64_t> codes = specSampleCodes(p, 1000, kSpecSampleSeed);
  ASSERT_EQ(codes.size(), kSpecExhaustiveInputs / 1000);
  EXPECT_TRUE(std::is_sorted(codes.begin(), codes.end()));
  EXPECT_EQ(std::adjacent_find(codes.begin(), codes.end()), codes.end());
  EXPECT_EQ(codes.front(), 0);
  EXPECT_EQ(codes.back(), p.cosOne());
  for (int64_t corner : {int64_t{1}, int64_t{2}, p.cosOne() / 2, p.cosOne() - 1})
    EXPECT_TRUE(std::binary_search(codes.begin(), codes.end(), corner)) << corner;
  EXPECT_EQ(codes, specSampleCodes(p, 1000, kSpecSampleSeed));
  EXPECT_NE(codes, specSampleCodes(p, 1000, kSpecSampleSeed + 1));
  EXPECT_EQ(specSampleCodes(p, 10000000, 1).size(), 64u);  // at least 64 per shininess
}

// The report over an explicit list of every code equals the exhaustive one.
TEST(SpecSweep, ErrorOverListedCodesEqualsTheExhaustiveReport) {
  SpecUnitConfig cfg = specConfig("narrow");
  PromRequest req = PromRequest::fromContent(cfg.prom);
  req.n = NSpec::parse("1,8,64,500", true);
  const PromTable t = buildPromTable(req, cfg.rtl);
  std::vector<int64_t> all(static_cast<size_t>(cfg.rtl.cosOne() + 1));
  for (size_t k = 0; k < all.size(); ++k) all[k] = static_cast<int64_t>(k);
  const SpecErrorReport a = computeSpecError("x", t), b = computeSpecError("x", t, {}, all);
  nlohmann::json ja = toJson(a).at("summary"), jb = toJson(b).at("summary");
  ja.erase("seconds");
  jb.erase("seconds");
  EXPECT_EQ(ja, jb);
  const SpecErrorReport c = computeSpecError("x", t, {}, {0, 512, 1024});
  EXPECT_LE(c.summary.datapath_max_lsb.value, a.summary.datapath_max_lsb.value);
}
