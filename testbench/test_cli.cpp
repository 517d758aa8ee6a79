// The shadesim command line as a user runs it: outputs, JSON keys, and bad input (a clear
// error naming the argument, a non-zero exit, no output file left behind).
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#ifndef SHADESIM_BIN
#error "SHADESIM_BIN must name the shadesim executable"
#endif

namespace fs = std::filesystem;

namespace {

struct CmdResult {
  int code = -1;
  std::string out, err;
};

// ctest runs the tests of this file as parallel processes: each keeps its files apart.
fs::path testDir() {
  const fs::path dir = fs::path(testing::TempDir()) / ("cli_" + std::to_string(getpid()));
  fs::create_directories(dir);
  return dir;
}

CmdResult run(const std::string& args) {
  const std::string err_file = (testDir() / "stderr.txt").string();
  const std::string cmd = std::string(SHADESIM_BIN) + " " + args + " 2>" + err_file;
  CmdResult r;
  FILE* p = popen(cmd.c_str(), "r");
  if (p == nullptr) return r;
  std::array<char, 4096> buf{};
  size_t n;
  while ((n = fread(buf.data(), 1, buf.size(), p)) > 0) r.out.append(buf.data(), n);
  const int status = pclose(p);
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream e(err_file);
  std::stringstream ss;
  ss << e.rdbuf();
  r.err = ss.str();
  return r;
}

std::string tmp(const std::string& name) {
  const fs::path p = testDir() / name;
  fs::remove(p);
  return p.string();
}

// A failing command: non-zero exit, `needle` in the message, `out` not created.
void expectRejected(const std::string& args, const std::string& needle, const std::string& out) {
  const CmdResult r = run(args + " -o " + out);
  EXPECT_NE(r.code, 0) << args;
  EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\nstderr: " << r.err;
  EXPECT_FALSE(fs::exists(out)) << args << " left " << out;
  // Nor a temporary beside it.
  for (const auto& e : fs::directory_iterator(fs::path(out).parent_path()))
    EXPECT_EQ(e.path().filename().string().find(fs::path(out).filename().string() + ".tmp"), std::string::npos)
        << e.path();
}

}  // namespace

TEST(CliProm, WritesHexWithProvenanceAndAddressMap) {
  const std::string out = tmp("list.hex");
  const CmdResult r = run("prom --fit minimax --n-list 8,32,200 --format hex -o " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  std::ifstream f(out);
  std::string first;
  std::getline(f, first);
  EXPECT_NE(first.find("shadesim"), std::string::npos) << first;
  int words = 0;
  for (std::string l; std::getline(f, l);)
    if (!l.empty() && l[0] != '/') ++words;
  EXPECT_EQ(words, 4);  // 3 codes in a 2-bit address space
  std::ifstream map(out + ".map.csv");
  std::string header, row;
  std::getline(map, header);
  EXPECT_EQ(header, "address,n");
  std::getline(map, row);
  EXPECT_EQ(row.rfind("0,8", 0), 0u) << row;
}

TEST(CliProm, StdoutWithoutOutputFile) {
  const CmdResult r = run("prom --fit inflection --n 1:4 --format csv");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(r.out.rfind("n,address,a_real,a_code\n1,0,0,0\n2,1,1,16384\n", 0), 0u) << r.out;
}

TEST(CliProm, BadInputIsNamedAndLeavesNoFile) {
  const std::string out = tmp("bad.hex");
  expectRejected("prom --fit bogus --format hex", "--fit", out);
  expectRejected("prom --fit level --n 0:1000 --format hex", "--n", out);
  expectRejected("prom --fit level --n 1:1001 --format hex", "--n", out);
  expectRejected("prom --fit level --n-list 8,x --format hex", "--n-list", out);
  expectRejected("prom --fit level --n 1:10 --n-list 8 --format hex", "--n", out);
  expectRejected("prom --fit level --coef-format uQ10.x --format hex", "--coef-format", out);
  expectRejected("prom --fit level --coef-format uQ30.30 --format hex", "--coef-format", out);
  expectRejected("prom --fit inflection --coef-format uQ9.14 --format hex", "uQ9.14", out);
  expectRejected("prom --fit level --coef-format sQ10.14 --format hex", "--coef-format", out);
  expectRejected("prom --fit shortcut --degree 3 --coef-format sQ16.12 --format hex", "shortcut", out);
  expectRejected("prom --fit level --format bin", "--format", out);
  expectRejected("prom --fit level --level 1.5 --format hex", "--level", out);
  expectRejected("prom --fit level --config nosuch --format hex", "--config", out);
  // An output directory that does not exist: an error, nothing created.
  const CmdResult r = run("prom --fit level --format hex -o " + tmp("nodir") + "/x.hex");
  EXPECT_NE(r.code, 0);
  EXPECT_FALSE(fs::exists(testDir() / "nodir"));
}

TEST(CliCosim, JsonKeysAndZeroMismatches) {
  const CmdResult r = run("cosim --unit spec --config narrow --vectors 20000 --seed 3 --json --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k : {"unit", "config", "vectors", "cycles", "mismatches", "seed", "vectors_per_second"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["vectors"], 20000);
  EXPECT_EQ(j["mismatches"], 0);
}

TEST(CliCosim, BadInput) {
  CmdResult r = run("cosim --unit spec --config nosuch --vectors 10");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--config"), std::string::npos) << r.err;
  r = run("cosim --unit spec --config narrow --prom /nonexistent/p.hex --vectors 10 --quiet");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("cannot read PROM file /nonexistent/p.hex: no such file"), std::string::npos) << r.err;
  r = run("cosim --unit texture --vectors 10");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("--unit"), std::string::npos) << r.err;
  // Widths that differ from the verilated configuration cannot be co-simulated.
  r = run("cosim --unit spec --config narrow --coef-format uQ10.8 --vectors 10 --quiet");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("differ from the verilated"), std::string::npos) << r.err;
  // A PROM made for another fit: the table check names the word.
  const std::string other = tmp("other.hex");
  ASSERT_EQ(run("prom --config narrow --fit minimax --format hex -o " + other).code, 0);
  r = run("cosim --unit spec --config narrow --prom " + other + " --vectors 10 --quiet");
  EXPECT_NE(r.code, 0);
  EXPECT_NE(r.err.find("word"), std::string::npos) << r.err;
}

TEST(CliSpecError, JsonHoldsPerNAndSummary) {
  const CmdResult r = run("spec-error --config narrow --n-list 1,8,32,1000 --json --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j["per_n"].size(), 4u);
  for (const auto& row : j["per_n"])
    for (const char* k : {"n", "approx_lobe_max_abs", "approx_peak_max_rel", "datapath_max_lsb", "total_max_lsb"})
      EXPECT_TRUE(row.contains(k)) << k;
  EXPECT_TRUE(j.contains("summary"));
  EXPECT_TRUE(j.contains("compare"));  // the minimax fit beside the configuration's fit
  EXPECT_EQ(j["compare"]["fit"], "minimax");
  // n = 1 is exact: the only error is the final rounding, at most half an output LSB.
  EXPECT_LE(j["per_n"][0]["total_max_lsb"].get<double>(), 0.5 + 1e-9);
  // The minimax fit is no worse on the whole lobe than the configuration's fit, n by n.
  for (size_t i = 0; i < 4; ++i)
    EXPECT_LE(j["compare"]["per_n"][i]["approx_lobe_max_abs"].get<double>(),
              j["per_n"][i]["approx_lobe_max_abs"].get<double>() + 1e-12);
}

TEST(CliSpecError, TableShowsBothFits) {
  const CmdResult r = run("spec-error --config narrow --n-list 8,32 --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("fit level"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("fit minimax"), std::string::npos) << r.out;
}

TEST(CliCosim, SpanJsonKeys) {
  const CmdResult r = run("cosim --unit span --mode sierpinski --triangles 3000 --seed 4 --json --quiet");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* k : {"mode", "triangles", "fragments", "cycles", "mismatches"}) EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["mode"], "sierpinski");
  EXPECT_EQ(j["mismatches"], 0);
  EXPECT_GT(j["fragments"].get<long>(), 10000);
  const CmdResult bad = run("cosim --unit span --mode zigzag --triangles 10");
  EXPECT_NE(bad.code, 0);
  EXPECT_NE(bad.err.find("--mode"), std::string::npos) << bad.err;
}

TEST(CliSpanCycles, ReportChecksTheRtlCycles) {
  const CmdResult r = run("span-cycles --triangles 400 --soft-repeats 1 --rtl --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  // Every span configuration of the registry is measured, the serial unit first.
  const auto configs = nlohmann::json::parse(run("configs --unit span --json").out);
  ASSERT_GE(configs.size(), 2u);
  ASSERT_EQ(j["sets"].size(), 8u);  // five size classes, the mixed stream, the sphere and the torus
  EXPECT_EQ(j["sets"][6]["set"], "builtin:sphere");
  EXPECT_EQ(j["sets"][7]["set"], "builtin:torus");
  for (const auto& set : j["sets"]) {
    ASSERT_EQ(set["modes"].size(), configs.size());
    EXPECT_EQ(set["modes"][0]["lanes"], 1);
    const double serial = set["modes"][0]["cycles"].get<double>();
    for (const auto& m : set["modes"]) {
      EXPECT_EQ(m["rtl_cycles"], m["cycles"]) << set["set"] << " " << m["mode"];
      EXPECT_EQ(m["rtl_mismatches"], 0);
      EXPECT_EQ(m["fragments"], set["modes"][0]["fragments"]);  // every mode draws the same pixels
      // No lane mode is slower than the serial unit, or faster than its lane groups alone.
      EXPECT_LE(m["cycles"].get<double>(), serial) << set["set"] << " " << m["mode"];
      EXPECT_GE(m["cycles"], m["no_overhead_bound"]) << set["set"] << " " << m["mode"];
    }
  }
}

// A configuration file of the user's own, outside the registry: every command that needs no
// verilated model takes it; those that do refuse it and say how to add a model.
TEST(CliConfig, AUsersFileWorksWithoutTheRtlAndIsRefusedWithIt) {
  const std::string spec = tmp("my_spec.json"), span = tmp("my_span.json");
  std::ofstream(spec) << R"({"name": "mine", "rtl": {"Degree": 2, "CosFracBits": 12, "ShinBits": 10, "CoefIntBits": 10,
    "CoefFracBits": 9, "DiffFracBits": 20, "HornerFracBits": 9, "SpecFracBits": 12, "LightBits": 8, "PipeStages": 1},
    "prom": {"fit": "level", "level": 0.5, "n": "1:1000"}})";
  std::ofstream(span) << R"({"name": "mylanes", "rtl": {"NumTri": 1, "LanesPerTri": 4, "AlignLanes": 1, "NumAttr": 4,
    "AttrBits": 32, "CoordBits": 16, "RemBits": 27, "PixBits": 12, "TagBits": 32}})";
  const std::string hex = tmp("mine.hex"), vec = tmp("mine.vec"), svec = tmp("mylanes.vec"), png = tmp("mine.png");
  CmdResult r = run("prom --config " + spec + " --format hex -o " + hex);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("spec-error --config " + spec + " --n-list 8,32 --quiet --json");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(r.out)["config"], "mine");
  r = run("vectors --unit spec --config " + spec + " --cycles 200 -o " + vec + " --prom " + hex);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("vectors --unit span --config " + span + " --cycles 200 -o " + svec);
  ASSERT_EQ(r.code, 0) << r.err;
  r = run("render --quiet --scene builtin:sphere --method phong-fixed --brdf quadratic --mode " + span +
          " --quadratic-config " + spec + " -o " + png);
  ASSERT_EQ(r.code, 0) << r.err;
  // The RTL needs a verilated model of the configuration.
  for (const std::string& args : {"cosim --unit spec --config " + spec + " --vectors 10 --quiet",
                                  "cosim --unit span --mode " + span + " --triangles 10 --quiet", "replay " + vec,
                                  "render --quiet --rtl --scene builtin:sphere --mode " + span + " -o " + png}) {
    r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    const bool explained = r.err.find("add the file to the registry") != std::string::npos ||
                           r.err.find("is not verilated into this build") != std::string::npos;
    EXPECT_TRUE(explained) << args << "\nstderr: " << r.err;
  }
  // A quadratic-lobe configuration must be of degree 2.
  r = run("render --quiet --scene builtin:sphere --method phong --brdf quadratic --quadratic-config cubic -o " + png);
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("degree-2"), std::string::npos) << r.err;
}

TEST(CliRender, WritesImagesAndStats) {
  const std::string out = tmp("sphere.png"), js = tmp("sphere.json");
  const CmdResult r = run("render --scene builtin:sphere --method gouraud --brdf quadratic --rtl --quiet -o " + out +
                          " --json " + js);
  ASSERT_EQ(r.code, 0) << r.err;
  for (const fs::path& f : {fs::path(out), testDir() / "sphere_reference.png", testDir() / "sphere_error.png", fs::path(js)})
    EXPECT_TRUE(fs::exists(f)) << f;
  std::ifstream in(js);
  const auto j = nlohmann::json::parse(in);
  for (const char* k : {"triangles", "culled", "fragments", "pixels_covered", "cycles", "ms", "max_abs_lsb", "psnr_db",
                        "pixel_mismatches"})
    EXPECT_TRUE(j.contains(k)) << k;
  EXPECT_EQ(j["pixel_mismatches"], 0);
  EXPECT_EQ(j["triangles"], 8190);
}

TEST(CliRender, BadInputIsNamedAndLeavesNoImage) {
  const std::string out = tmp("bad.png");
  auto rejected = [&](const std::string& args, const std::string& needle) {
    const CmdResult r = run("render --quiet " + args + " -o " + out);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_NE(r.err.find(needle), std::string::npos) << args << "\nstderr: " << r.err;
    EXPECT_FALSE(fs::exists(out)) << args;
    EXPECT_FALSE(fs::exists(testDir() / "bad_reference.png")) << args;  // (tmp() would delete it first)
    EXPECT_FALSE(fs::exists(testDir() / "bad_error.png")) << args;
  };
  rejected("--scene /nonexistent/scene.json", "/nonexistent/scene.json");
  rejected("--scene builtin:teapot", "builtin:teapot");
  rejected("--scene /usr/share/assimp/models/invalid/empty.obj", "empty.obj");
  rejected("--method toon", "--method");
  rejected("--brdf glossy", "--brdf");
  // The materials row uses n up to 1000; the cubic unit's PROM holds 1..256.
  rejected("--scene builtin:materials --brdf cubic", "shininess 1000");
  // A scene file with an unknown key, and one with shininess out of range.
  const std::string bad_key = tmp("bad_key.json"), bad_n = tmp("bad_n.json");
  std::ofstream(bad_key) << R"({"objects": [{"mesh": "builtin:sphere", "colour": [1,0,0]}]})";
  std::ofstream(bad_n) << R"({"materials": [{"name": "m", "shininess": 5000}], "objects": [{"mesh": "builtin:sphere", "material": "m"}]})";
  rejected("--scene " + bad_key, "objects[0]");
  rejected("--scene " + bad_n, "shininess");
  // An output directory that does not exist.
  const CmdResult r = run("render --quiet --scene builtin:sphere -o " + tmp("nodir") + "/x.png");
  EXPECT_NE(r.code, 0);
  EXPECT_FALSE(fs::exists(testDir() / "nodir"));
}
