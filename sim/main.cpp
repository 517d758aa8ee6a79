// shadesim: the command-line program.
//   shadesim prom        coefficient PROM tables for simulators and FPGA tools
//   shadesim cosim       verilated RTL against the golden model, cycle by cycle
//   shadesim spec-error  approximation, datapath and total error of the specular unit
//   shadesim vectors     a vector file of a unit from the golden model (sim/vector_file.h)
//   shadesim replay      a vector file replayed on the verilated RTL, compared every cycle
// Every failure prints "shadesim <command>: error: ..." naming the argument and exits non-zero;
// files are written atomically, so a failed run leaves no partial output.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <fmt/ranges.h>
#include <nlohmann/json.hpp>
#include <unistd.h>

#include "device/prom.h"
#include "device/prom_io.h"
#include "progress.h"
#include "report/spec_error.h"
#include "image/image.h"
#include "image/metrics.h"
#include "raster/desc_stream.h"
#include "render/fixed_simd.h"
#include "render/render.h"
#include "render_rtl.h"
#include "scene/scene.h"
#include "report/span_cycles.h"
#include "scene/sphere.h"
#include "cli_vectors.h"
#include "span_cosim.h"
#include "spec_cosim.h"

namespace fs = std::filesystem;
using namespace shd;

namespace {

// A usage error: the message names the argument.
struct ArgError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// --config takes a checked-in configuration name or a JSON file.
SpecUnitConfig resolveConfig(const std::string& arg) {
  if (fs::is_regular_file(arg)) return SpecUnitConfig::load(arg);
  for (const std::string& name : builtinConfigNames())
    if (arg == name) return SpecUnitConfig::load(configPath(name));
  throw ArgError(fmt::format("--config {}: neither a file nor one of the configurations {}", arg,
                             fmt::join(builtinConfigNames(), ", ")));
}

// The options that choose a PROM's contents, shared by prom, cosim and spec-error.
struct TableOptions {
  std::string config = "default";
  std::string fit, n, n_list, coef_format;
  std::optional<double> level;
  int degree = 0;  // 0: the configuration's

  void add(CLI::App& app) {
    app.add_option("--config", config, "configuration: default|narrow|wide|cubic or a JSON file")
        ->default_val("default");
    app.add_option("--fit", fit, "inflection | level | shortcut | minimax (default: the configuration's)")
        ->check(CLI::IsMember({"inflection", "level", "shortcut", "minimax"}));
    app.add_option("--level", level, "level q (degree 2) or Q (degree 3) of the level fit, in (0, 1)");
    app.add_option("--degree", degree, "2 (quadratic) or 3 (cubic)")->check(CLI::IsMember({2, 3}));
    auto* n_opt = app.add_option("--n", n, "shininess range lo:hi[:step], each in [1, 1000]");
    auto* list_opt = app.add_option("--n-list", n_list, "explicit shininess list, e.g. 8,32,200");
    n_opt->excludes(list_opt);
    app.add_option("--coef-format", coef_format, "coefficient format, e.g. uQ10.14 (degree 3: sQm.f)");
  }

  // The unit parameters and the table request after applying the overrides. With size_to_n the
  // PROM is as deep as the n list needs (a table made without naming a configuration);
  // otherwise it keeps the configuration's ShinBits.
  PromTable build(SpecUnitConfig& cfg_out, bool size_to_n) const {
    SpecUnitConfig cfg = resolveConfig(config);
    PromContent content = cfg.prom;
    if (!fit.empty()) content.fit = fit;
    if (level) {
      if (!(*level > 0 && *level < 1)) throw ArgError(fmt::format("--level {}: must lie in (0, 1)", *level));
      content.level = *level;
    }
    if (!n.empty()) content = PromContent{content.fit, content.level, n, false};
    if (!n_list.empty()) content = PromContent{content.fit, content.level, n_list, true};
    PromRequest req;
    try {
      req = PromRequest::fromContent(content);
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("{}: {}", !n_list.empty() ? "--n-list" : (!n.empty() ? "--n" : "--fit"), e.what()));
    }
    SpecUnitParams& p = cfg.rtl;
    if (degree != 0) p.Degree = degree;
    if (!coef_format.empty()) {
      FixedFormat f;
      try {
        f = FixedFormat::parse(coef_format);
      } catch (const std::invalid_argument& e) {
        throw ArgError(fmt::format("--coef-format: {}", e.what()));
      }
      if (f.is_signed != (p.Degree == 3))
        throw ArgError(fmt::format("--coef-format {}: degree {} coefficients are {}; use {}Qm.f", coef_format,
                                   p.Degree, p.Degree == 3 ? "signed" : "unsigned (a >= 0)",
                                   p.Degree == 3 ? 's' : 'u'));
      p.CoefIntBits = f.int_bits;
      p.CoefFracBits = f.frac_bits;
    }
    // A table made without a configuration is as deep as its n list needs.
    if (size_to_n) p.ShinBits = addressBitsFor(req.n.values.size());
    try {
      p.validate();
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("{}: {}", !coef_format.empty() ? "--coef-format " + coef_format : "--config " + config,
                                 e.what()));
    }
    try {
      PromTable t = buildPromTable(req, p);
      cfg_out = cfg;
      cfg_out.rtl = p;
      cfg_out.prom = content;
      return t;
    } catch (const std::invalid_argument& e) {
      throw ArgError(fmt::format("{}: {}",
                                 !coef_format.empty() ? "--coef-format " + coef_format
                                                      : fmt::format("coefficient format {} of --config {} (choose one "
                                                                    "with --coef-format)",
                                                                    p.coefFormat().str(), config),
                                 e.what()));
    }
  }
};

void writeOut(const std::string& path, const std::string& text) {
  if (path.empty() || path == "-") {
    std::fwrite(text.data(), 1, text.size(), stdout);
    return;
  }
  writeFileAtomic(path, text);
}

// ---------------------------------------------------------------- prom
struct PromCmd {
  TableOptions table;
  std::string format, output;

  void add(CLI::App& app) {
    table.add(app);
    app.add_option("--format", format, "hex ($readmemh) | mem (Lattice) | coe (Xilinx) | mif (Intel) | csv")
        ->required()
        ->check(CLI::IsMember({"hex", "mem", "coe", "mif", "csv"}));
    app.add_option("-o,--output", output, "output file (default stdout); with --n-list also <file>.map.csv, "
                                          "with csv also <file>.json (provenance)");
  }

  int run(const CLI::App& app) {
    SpecUnitConfig cfg;
    const PromTable t = table.build(cfg, app.count("--config") == 0);
    const PromFormat f = parsePromFormat(format);
    // Render everything first, then write: an error leaves no file behind.
    const std::string body = renderProm(t, f);
    const std::string map = t.request.n.is_list ? renderAddressMap(t) : "";
    const std::string side = f == PromFormat::Csv ? renderProvenanceJson(t) : "";
    writeOut(output, body);
    if (!output.empty() && output != "-") {
      if (!map.empty()) writeFileAtomic(output + ".map.csv", map);
      if (!side.empty()) writeFileAtomic(output + ".json", side);
      std::fprintf(stderr, "wrote %s: %zu codes, %d words of %d bits (%s)\n", output.c_str(), t.entries.size(),
                   t.unit.promDepth(), t.unit.promWordBits(), t.request.describe().c_str());
    }
    return 0;
  }
};

// ---------------------------------------------------------------- cosim
struct CosimCmd {
  TableOptions table;
  std::string unit = "spec", prom, fail_dir = ".", mode = "serial";
  uint64_t triangles = 100000;
  double ready_prob = 0.8;
  bool exhaustive = false, json = false, quiet = false;
  uint64_t vectors = 1'000'000, seed = 1;
  double gap = 0.2;

  void add(CLI::App& app) {
    app.add_option("--unit", unit, "unit under test: spec (specular unit) or span (span unit)")
        ->check(CLI::IsMember({"spec", "span"}))
        ->default_val("spec");
    app.add_option("--mode", mode, "span unit: serial | evenodd | seg2 | seg4 | seg8 | sierpinski")
        ->check(CLI::IsMember({"serial", "evenodd", "seg2", "seg4", "seg8", "sierpinski"}));
    app.add_option("--triangles", triangles, "span unit: seeded random triangles (raster/trigen.h classes)")
        ->check(CLI::PositiveNumber);
    app.add_option("--ready", ready_prob, "span unit: probability that the consumer is ready on a cycle")
        ->check(CLI::Range(0.05, 1.0));
    table.add(app);
    app.add_option("--prom", prom, "PROM hex file the RTL loads (default: the table written to a temporary file); "
                                   "it must hold the table the options describe");
    app.add_flag("--exhaustive", exhaustive, "every (shininess code, cos code) pair, valid on every cycle");
    app.add_option("--vectors", vectors, "random vectors (without --exhaustive)")->check(CLI::PositiveNumber);
    app.add_option("--seed", seed, "random seed");
    app.add_option("--gap", gap, "probability of dropping valid_i for 1..3 cycles (random mode)")
        ->check(CLI::Range(0.0, 0.9));
    app.add_option("--fail-dir", fail_dir, "where a failing case's FST waveform and vector file go");
    app.add_flag("--json", json, "print the result as one JSON object on stdout");
    app.add_flag("--quiet", quiet, "no progress on stderr");
  }

  int run() { return unit == "span" ? runSpan() : runSpec(); }

  int runSpan() {
    const SpanMode m = parseSpanMode(mode);
    RasterConfig rc;
    rc.unit = SpanParams::forMode(m);
    DescriptorStream descs(seed, triangles, rc);
    auto next = [&](SpanDesc& d) { return descs.next(d); };
    Progress progress(fmt::format("cosim span/{}", mode), !quiet);
    SpanCosimOptions o;
    o.seed = seed;
    o.ready_prob = ready_prob;
    o.fail_dir = fs::absolute(fail_dir).string();
    o.progress = [&](uint64_t) { progress.update(static_cast<double>(descs.generated()), static_cast<double>(triangles), "triangles"); };
    const SpanCosimResult r = runSpanCosim(mode, next, o);
    if (json) {
      nlohmann::json j = {{"unit", "span"},
                          {"mode", mode},
                          {"seed", seed},
                          {"triangles", r.triangles},
                          {"generated", descs.generated()},
                          {"dropped_at_setup", descs.dropped()},
                          {"fragments", r.fragments},
                          {"cycles", r.cycles},
                          {"mismatches", r.mismatches},
                          {"seconds", r.seconds},
                          {"fragments_per_second", r.seconds > 0 ? r.fragments / r.seconds : 0.0}};
      if (r.first)
        j["first_mismatch"] = {{"cycle", r.first->cycle}, {"triangle", r.first->tag}, {"what", r.first->what},
                               {"fst", r.fst_path}, {"case", r.case_path}, {"vectors", r.vector_path}};
      std::cout << j.dump(2) << "\n";
    } else {
      std::printf("cosim span/%s seed %llu: %llu triangles drawn (%llu generated, %llu dropped by setup), %llu fragments, "
                  "%llu cycles, %llu mismatches, %.2f s (%.1f M fragments/s)\n",
                  mode.c_str(), static_cast<unsigned long long>(seed), static_cast<unsigned long long>(r.triangles),
                  static_cast<unsigned long long>(descs.generated()), static_cast<unsigned long long>(descs.dropped()),
                  static_cast<unsigned long long>(r.fragments), static_cast<unsigned long long>(r.cycles),
                  static_cast<unsigned long long>(r.mismatches), r.seconds, r.seconds > 0 ? r.fragments / r.seconds / 1e6 : 0.0);
    }
    if (r.first) {
      std::fprintf(stderr, "MISMATCH (first of %llu) cycle %llu, triangle %u: %s\nwaveform: %s\nvectors:  %s\ncase:     %s\n",
                   static_cast<unsigned long long>(r.mismatches), static_cast<unsigned long long>(r.first->cycle),
                   r.first->tag, r.first->what.c_str(), r.fst_path.c_str(), r.vector_path.c_str(), r.case_path.c_str());
      return 1;
    }
    return 0;
  }

  int runSpec() {
    SpecUnitConfig cfg;
    const PromTable t = table.build(cfg, false);
    // The RTL side is the configuration verilated into this binary: its parameters must be the
    // ones the model is built with.
    const std::vector<std::string> built = rtlSpecConfigs();
    if (std::find(built.begin(), built.end(), cfg.name) == built.end())
      throw ArgError(fmt::format("--config {}: no verilated unit named '{}' in this build (built: {}); add its JSON "
                                 "to vectors/config and SHD_SPEC_CONFIGS",
                                 table.config, cfg.name, fmt::join(built, ", ")));
    if (SpecUnitConfig::load(configPath(cfg.name)).rtl.toJson() != t.unit.toJson())
      throw ArgError(fmt::format("--config {}: its RTL parameters (after --degree/--coef-format) differ from the "
                                 "verilated '{}' unit {}",
                                 table.config, cfg.name, SpecUnitConfig::load(configPath(cfg.name)).rtl.toJson().dump()));
    std::string prom_path = prom;
    fs::path tmp_dir;
    if (prom_path.empty()) {
      tmp_dir = fs::temp_directory_path() / fmt::format("shadesim-{}", getpid());
      fs::create_directories(tmp_dir);
      prom_path = (tmp_dir / fmt::format("spec_{}.hex", cfg.name)).string();
      writeFileAtomic(prom_path, renderProm(t, PromFormat::Hex));
    }
    prom_path = fs::absolute(prom_path).string();
    SpecUnitModel model(t.unit, t.words);
    std::unique_ptr<SpecStimulus> stim;
    if (exhaustive) stim = std::make_unique<ExhaustiveSpecStimulus>(t.unit, seed);
    else stim = std::make_unique<RandomSpecStimulus>(t.unit, seed, vectors, gap);
    Progress progress(fmt::format("cosim spec/{}", cfg.name), !quiet);
    SpecCosimOptions o;
    o.prom_path = prom_path;
    o.fail_dir = fs::absolute(fail_dir).string();
    o.progress = [&](uint64_t done, uint64_t total) { progress.update(done, total, "vectors"); };
    SpecCosimResult r;
    try {
      r = runSpecCosim(cfg.name, model, *stim, o);
    } catch (...) {
      if (!tmp_dir.empty()) fs::remove_all(tmp_dir);
      throw;
    }
    if (!tmp_dir.empty()) fs::remove_all(tmp_dir);
    const double rate = r.seconds > 0 ? r.vectors / r.seconds : 0;
    if (json) {
      nlohmann::json j = {{"unit", "spec"},
                          {"config", r.config},
                          {"mode", exhaustive ? "exhaustive" : "random"},
                          {"seed", seed},
                          {"prom", prom.empty() ? std::string("(temporary)") : prom_path},
                          {"table", t.request.describe()},
                          {"vectors", r.vectors},
                          {"cycles", r.cycles},
                          {"mismatches", r.mismatches},
                          {"seconds", r.seconds},
                          {"vectors_per_second", rate}};
      if (r.first) {
        j["first_mismatch"] = {{"cycle", r.first->cycle},
                               {"description", r.first->describe(t.unit)},
                               {"fst", r.fst_path},
                               {"vectors", r.vector_path}};
      }
      std::cout << j.dump(2) << "\n";
    } else {
      std::printf("cosim spec/%s %s seed %llu: %llu vectors, %llu cycles, %llu mismatches, %.2f s (%.1f M vectors/s)\n",
                  r.config.c_str(), exhaustive ? "exhaustive" : "random", static_cast<unsigned long long>(seed),
                  static_cast<unsigned long long>(r.vectors), static_cast<unsigned long long>(r.cycles),
                  static_cast<unsigned long long>(r.mismatches), r.seconds, rate / 1e6);
    }
    if (r.first) {
      std::fprintf(stderr, "MISMATCH (first of %llu) %s\nwaveform: %s\nvectors:  %s\n",
                   static_cast<unsigned long long>(r.mismatches), r.first->describe(t.unit).c_str(),
                   r.fst_path.c_str(), r.vector_path.c_str());
      return 1;
    }
    return 0;
  }
};

// ---------------------------------------------------------------- spec-error
struct SpecErrorCmd {
  TableOptions table;
  std::string compare = "auto", json_out;
  bool json = false, quiet = false;

  void add(CLI::App& app) {
    table.add(app);
    app.add_option("--compare", compare, "second fit shown beside the first: auto (minimax, or inflection when the "
                                         "first is minimax), none, or a fit name")
        ->check(CLI::IsMember({"auto", "none", "inflection", "level", "shortcut", "minimax"}));
    app.add_flag("--json", json, "print one JSON object on stdout instead of the table");
    app.add_option("--json-out", json_out, "also write the JSON object to this file");
    app.add_flag("--quiet", quiet, "no progress on stderr");
  }

  int run() {
    SpecUnitConfig cfg;
    const PromTable t = table.build(cfg, false);
    Progress progress(fmt::format("spec-error {}", toString(t.request.fit)), !quiet);
    auto prog = [&](size_t done, size_t total) { progress.update(static_cast<double>(done), static_cast<double>(total), "n"); };
    const SpecErrorReport primary = computeSpecError(cfg.name, t, prog);
    std::optional<SpecErrorReport> second;
    std::string cmp = compare;
    if (cmp == "auto") cmp = t.request.fit == FitKind::Minimax ? "inflection" : "minimax";
    if (cmp != "none" && cmp != toString(t.request.fit)) {
      PromRequest req2 = t.request;
      req2.fit = parseFitKind(cmp);
      Progress p2(fmt::format("spec-error {}", cmp), !quiet);
      try {
        second = computeSpecError(cfg.name, buildPromTable(req2, t.unit),
                                  [&](size_t d, size_t n) { p2.update(static_cast<double>(d), static_cast<double>(n), "n"); });
      } catch (const std::invalid_argument& e) {
        throw ArgError(fmt::format("--compare {}: {}", cmp, e.what()));
      }
    }
    nlohmann::json j = toJson(primary);
    if (second) j["compare"] = toJson(*second);
    if (!json_out.empty()) writeFileAtomic(json_out, j.dump(2) + "\n");
    if (json) std::cout << j.dump(2) << "\n";
    else std::cout << renderSpecErrorTable(primary, second ? &*second : nullptr, representativeN(t));
    return 0;
  }
};

// ---------------------------------------------------------------- span-cycles
struct SpanCyclesCmd {
  uint64_t triangles = 20000, seed = 1;
  std::vector<int> divider_latency{1, 4, 8, 16, 32};
  int soft_repeats = 5;
  bool json = false, rtl = false;
  std::string json_out;

  void add(CLI::App& app) {
    app.add_option("--triangles", triangles,
                   "triangles per size class and for the mixed stream; large: 1/20 of it, screen-filling: 1/2000 "
                   "(at least 5), so that every set costs about the same")
        ->check(CLI::PositiveNumber);
    app.add_option("--seed", seed, "generator seed");
    app.add_option("--divider-latency", divider_latency, "divider latencies (cycles) of the classical unit")
        ->delimiter(',')
        ->check(CLI::NonNegativeNumber);
    app.add_option("--soft-repeats", soft_repeats, "repeats of the software timing (median)")->check(CLI::Range(1, 1000));
    app.add_flag("--json", json, "print one JSON object instead of the tables");
    app.add_option("--json-out", json_out, "also write the JSON object to this file");
    app.add_flag("--rtl", rtl, "also run every set through the verilated unit of every mode and check its cycles");
  }

  int run() {
    RasterConfig rc;
    std::vector<std::pair<std::string, TriangleList>> lists;
    std::vector<TriangleSetCycles> sets;
    auto classStream = [&](const char* name, int cls) {
      uint64_t count = triangles;
      if (cls == static_cast<int>(SizeClass::Large)) count = std::max<uint64_t>(5, triangles / 20);
      if (cls == static_cast<int>(SizeClass::Screen)) count = std::max<uint64_t>(5, triangles / 2000);
      TriGenOptions g;
      if (cls >= 0) {
        g.size_weight = {0, 0, 0, 0, 0};
        g.size_weight[static_cast<size_t>(cls)] = 1;
      }
      TriangleGenerator gen(seed, g);
      TriangleList list;
      for (uint64_t i = 0; i < count; ++i) list.push_back(toSetupVertices(gen.next(), rc.unit.NumAttr));
      lists.emplace_back(name, std::move(list));
    };
    const char* names[] = {"pixel1", "small", "mesh 10-100px", "large", "screen"};
    for (int cls = 0; cls < kNumSizeClasses; ++cls) classStream(names[cls], cls);
    classStream("mixed", -1);
    // The built-in sphere (DESIGN.md): idx3d SPHERE(1, 64) seen from (0, 0, -3), front faces;
    // attributes: the normal mapped to colour, and depth.
    TriangleList sphere;
    for (const ScreenTriangle& t : projectFrontFaces(idx3dSphere(1, 64), Camera{})) {
      std::array<SetupVertex, 3> v;
      for (size_t i = 0; i < 3; ++i)
        v[i] = {t.v[i].x, t.v[i].y, {127.5 * (t.v[i].n.x + 1), 127.5 * (t.v[i].n.y + 1), 127.5 * (t.v[i].n.z + 1), t.v[i].z / 4}};
      sphere.push_back(v);
    }
    lists.emplace_back("builtin:sphere", std::move(sphere));
    for (const auto& [name, list] : lists) {
      std::fprintf(stderr, "span-cycles: %s (%zu triangles)\n", name.c_str(), list.size());
      sets.push_back(measureSpanCycles(name, list, rc, divider_latency, soft_repeats));
    }
    nlohmann::json j = {{"seed", seed}, {"triangles_per_class", triangles}, {"sets", nlohmann::json::array()}};
    for (const auto& s : sets) j["sets"].push_back(toJson(s));
    // The cycle counts checked against the RTL: the same triangles through the verilated unit
    // of each mode, consumer always ready, compared cycle by cycle with the model.
    bool rtl_ok = true;
    std::string rtl_lines;
    for (size_t si = 0; rtl && si < lists.size(); ++si)
      for (size_t mi = 0; mi < sets[si].modes.size(); ++mi) {
        const SpanMode m = sets[si].modes[mi].mode;
        RasterConfig c = rc;
        c.unit = SpanParams::forMode(m);
        size_t next_tri = 0;
        const TriangleList& list = lists[si].second;
        SpanCosimOptions o;
        o.ready_prob = 1.0;
        o.desc_gap_prob = 0.0;
        const SpanCosimResult r = runSpanCosim(toString(m), [&](SpanDesc& d) {
          while (next_tri < list.size()) {
            SetupResult s = setupTriangle(list[next_tri], static_cast<uint32_t>(next_tri), c);
            ++next_tri;
            if (s.desc) {
              d = std::move(*s.desc);
              return true;
            }
          }
          return false;
        }, o);
        const bool ok = r.mismatches == 0 && r.cycles == sets[si].modes[mi].cycles;
        rtl_ok = rtl_ok && ok;
        j["sets"][si]["modes"][mi]["rtl_cycles"] = r.cycles;
        j["sets"][si]["modes"][mi]["rtl_mismatches"] = r.mismatches;
        rtl_lines += fmt::format("{:<16} {:<11} model {:>10} rtl {:>10} cycles, {} mismatches{}\n", lists[si].first,
                                 toString(m), sets[si].modes[mi].cycles, r.cycles, r.mismatches, ok ? "" : "  <-- FAIL");
      }
    if (!json_out.empty()) writeFileAtomic(json_out, j.dump(2) + "\n");
    if (json) std::cout << j.dump(2) << "\n";
    else std::cout << renderSpanCyclesTable(sets) << (rtl ? "\nChecked against the RTL (verilated, cycle by cycle):\n" + rtl_lines : "");
    return rtl_ok ? 0 : 1;
  }
};

// ---------------------------------------------------------------- render
struct RenderCmd {
  std::string scene = "builtin:sphere", method = "gouraud", brdf, mode = "serial", output, json_path, heatmap;
  bool rtl = false, quiet = false;
  int bench = 0;
  double heat_scale = 8, highlight_lsb = 32;

  void add(CLI::App& app) {
    app.add_option("--scene", scene, "builtin:sphere | builtin:plane | builtin:torus | builtin:materials or a JSON file");
    std::vector<std::string> methods;
    for (const Method m : allMethods()) methods.emplace_back(toString(m));
    app.add_option("--method", method, fmt::format("{}", fmt::join(methods, " | ")))->check(CLI::IsMember(methods));
    app.add_option("--brdf", brdf, "override every material's brdf: phong | blinn | normalized-blinn | schlick | "
                                   "quadratic | cubic | cook-torrance | pow")
        ->check(CLI::IsMember({"phong", "blinn", "normalized-blinn", "schlick", "quadratic", "cubic", "cook-torrance", "pow"}));
    app.add_option("--mode", mode, "span unit lane mode")
        ->check(CLI::IsMember({"serial", "evenodd", "seg2", "seg4", "seg8", "sierpinski"}));
    app.add_flag("--rtl", rtl, "also render with the verilated span and specular units; the images must be identical");
    app.add_option("-o,--output", output, "the image (PNG); beside it <name>_reference.png and <name>_error.png")
        ->required();
    app.add_option("--json", json_path, "write the statistics as JSON to this file");
    app.add_option("--heat-scale", heat_scale, "error (LSB) shown white in the heat map")->check(CLI::PositiveNumber);
    app.add_option("--highlight", highlight_lsb, "the highlight: pixels whose reference specular part exceeds this many LSBs")
        ->check(CLI::NonNegativeNumber);
    app.add_option("--bench", bench, "render this many frames and report the median time")->check(CLI::Range(0, 10000));
    app.add_flag("--quiet", quiet, "no progress lines");
  }

  // The engines of one path (model or RTL) for the device lobes the scene uses.
  struct Engines {
    std::unique_ptr<SpanEngine> span;
    std::vector<std::unique_ptr<SpecEngine>> spec;
    SpecEngines view;
  };

  Engines makeEngines(const Scene& sc, const RenderOptions& ro, bool with_rtl, const fs::path& tmp) {
    Engines e;
    const SpanMode m = parseSpanMode(mode);
    // A disagreement between a unit and its model saves the failing case beside the image.
    const std::string fail_dir = fs::path(output).parent_path().empty() ? "." : fs::path(output).parent_path().string();
    if (with_rtl) e.span = std::make_unique<RtlSpanEngine>(m, fail_dir);
    else e.span = std::make_unique<ModelSpanEngine>(SpanParams::forMode(m));
    for (Lobe l : deviceLobesUsed(sc, ro)) {
      const std::string cfg_name = specConfigForLobe(l);
      const SpecUnitConfig cfg = SpecUnitConfig::load(configPath(cfg_name));
      PromTable t = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
      if (with_rtl) {
        fs::create_directories(tmp);
        e.spec.push_back(
            std::make_unique<RtlSpecEngine>(cfg_name, std::move(t), (tmp / ("spec_" + cfg_name + ".hex")).string(), fail_dir));
      } else {
        e.spec.push_back(std::make_unique<ModelSpecEngine>(std::move(t)));
      }
      (l == Lobe::Cubic ? e.view.cubic : e.view.quadratic) = e.spec.back().get();
    }
    return e;
  }

  static Image toImage(const Framebuffer& fb) {
    Image img(fb.width, fb.height);
    img.rgb = fb.rgb;
    return img;
  }

  int run() {
    const Scene sc = loadScene(scene);
    RenderOptions ro;
    ro.method = parseMethod(method);
    ro.brdf = brdf;
    ro.span_mode = parseSpanMode(mode);
    const fs::path tmp = fs::temp_directory_path() / fmt::format("shadesim-render-{}", getpid());
    auto say = [&](const std::string& m) {
      if (!quiet) std::fprintf(stderr, "render: %s\n", m.c_str());
    };
    // The golden model.
    Engines model = makeEngines(sc, ro, false, tmp);
    say(fmt::format("{} with {} ({}), model", sc.name, method, mode));
    RenderResult res = render(sc, ro, *model.span, model.view);
    std::vector<double> frame_ms{res.stats.ms};
    RenderResult frame;  // the frame loop reuses its buffers, as a renderer does
    for (int i = 1; i < bench; ++i) {
      render(sc, ro, *model.span, model.view, frame);
      frame_ms.push_back(frame.stats.ms);
    }
    std::sort(frame_ms.begin(), frame_ms.end());
    const Image img = toImage(res.fb);
    // The reference and the error against it.
    RenderOptions rref = ro;
    rref.method = Method::Reference;
    Engines none;
    none.span = std::make_unique<ModelSpanEngine>(SpanParams::forMode(SpanMode::Serial));
    say("reference (double precision, exact pow)");
    const RenderResult ref = render(sc, rref, *none.span, none.view);
    ImageF reff(ref.fb.width, ref.fb.height), spec_ref(ref.fb.width, ref.fb.height);
    // What a display shows: the reference clamped to the output range (an over-exposed
    // highlight is 255, not its unclamped value).
    reff.rgb = ref.fb.lsb;
    for (double& v : reff.rgb) v = std::clamp(v, 0.0, 255.0);
    spec_ref.rgb = ref.fb.spec_lsb;
    PixelMask covered(img.width, img.height), highlight;
    for (int y = 0; y < img.height; ++y)
      for (int x = 0; x < img.width; ++x)
        if (res.fb.covered(x, y) && ref.fb.covered(x, y)) covered.set(x, y);
    highlight = intersect(covered, thresholdMask(spec_ref, highlight_lsb));
    const ImageMetrics all = imageMetrics(img, reff, covered);
    const ImageMetrics hl = imageMetrics(img, reff, highlight);
    const Image heat = errorHeatmap(img, reff, heat_scale, covered);
    const Image ref_img = roundToUnorm8(reff);
    // The RTL in the loop.
    nlohmann::json rtl_json;
    uint64_t mismatches = 0;
    std::string first_mismatch;
    if (rtl) {
      say("the same frame with the verilated span and specular units");
      Engines hw = makeEngines(sc, ro, true, tmp);
      const RenderResult hres = render(sc, ro, *hw.span, hw.view);
      fs::remove_all(tmp);
      const Image himg = toImage(hres.fb);
      mismatches = differingPixels(img, himg).count();
      if (auto d = firstDifference(img, himg)) {
        const int32_t tm = res.fb.tri[static_cast<size_t>(d->y) * img.width + d->x];
        const int32_t th = hres.fb.tri[static_cast<size_t>(d->y) * img.width + d->x];
        auto who = [&](const RenderResult& r, int32_t t) {
          if (t < 0) return std::string("no triangle");
          const ScreenTriangleInfo& i = r.triangles[static_cast<size_t>(t)];
          return fmt::format("triangle {} of object '{}' (mesh triangle {}, screen ({:.2f},{:.2f}) ({:.2f},{:.2f}) ({:.2f},{:.2f}))",
                             t, sc.objects[static_cast<size_t>(i.object)].name, i.mesh_triangle, i.xy[0][0], i.xy[0][1],
                             i.xy[1][0], i.xy[1][1], i.xy[2][0], i.xy[2][1]);
        };
        first_mismatch = fmt::format("pixel ({}, {}): model ({}, {}, {}) written by {}; rtl ({}, {}, {}) written by {}", d->x,
                                     d->y, d->a.r, d->a.g, d->a.b, who(res, tm), d->b.r, d->b.g, d->b.b, who(hres, th));
      }
      rtl_json = {{"ms", hres.stats.ms},
                  {"span_cycles", hres.stats.span_cycles},
                  {"spec_cycles", hres.stats.spec_cycles},
                  {"cycles_equal", hres.stats.span_cycles == res.stats.span_cycles &&
                                       hres.stats.spec_cycles == res.stats.spec_cycles}};
    }
    const RenderStats& st = res.stats;
    nlohmann::json j = {{"scene", sc.name},
                        {"method", method},
                        {"brdf", brdf.empty() ? "per material" : brdf},
                        {"mode", mode},
                        {"width", img.width},
                        {"height", img.height},
                        {"triangles", st.triangles},
                        {"culled", st.culled},
                        {"clipped", st.clipped},
                        {"drawn", st.drawn},
                        {"fragments", st.fragments},
                        {"pixels_covered", st.pixels_covered},
                        {"cycles", st.span_cycles},
                        {"spec_cycles", st.spec_cycles},
                        {"spec_evaluations", st.spec_evaluations},
                        {"divisions", st.divisions},
                        {"split_parts", st.split_parts},
                        {"normalisations", st.normalisations},
                        {"adaptive_gouraud", st.adaptive_gouraud},
                        {"adaptive_phong", st.adaptive_phong},
                        {"ms", frame_ms[frame_ms.size() / 2]},
                        {"frames", frame_ms.size()},
                        {"max_abs_lsb", all.max_abs_lsb},
                        {"psnr_db", toJson(all)["psnr_db"]},
                        {"metrics", toJson(all)},
                        {"highlight_lsb_threshold", highlight_lsb},
                        {"highlight", toJson(hl)}};
    // phong-fixed: whether the AVX-512 kernel shades its one-light N.H-lobe fragments here.
    if (ro.method == Method::PhongFixed) j["fixed_kernel"] = fixed_simd::available() ? "avx512" : "scalar";
    if (rtl) {
      j["pixel_mismatches"] = mismatches;
      j["rtl"] = rtl_json;
      if (!first_mismatch.empty()) j["first_mismatch"] = first_mismatch;
    }
    // Every output is written only now, each atomically: a failure above leaves nothing.
    const fs::path out(output);
    const std::string stem = (out.parent_path() / out.stem()).string();
    writePng(output, img);
    writePng(stem + "_reference.png", ref_img);
    writePng(heatmap.empty() ? stem + "_error.png" : heatmap, heat);
    if (!json_path.empty()) writeFileAtomic(json_path, j.dump(2) + "\n");
    std::printf("%s %s %s: %llu triangles (%llu culled), %llu fragments, %llu pixels, %llu span cycles, %.2f ms; "
                "vs reference: max %.2f LSB, PSNR %s dB, %.2f%% of pixels over 1 LSB; highlight (%llu px): max %.2f LSB\n",
                sc.name.c_str(), method.c_str(), mode.c_str(), static_cast<unsigned long long>(st.triangles),
                static_cast<unsigned long long>(st.culled), static_cast<unsigned long long>(st.fragments),
                static_cast<unsigned long long>(st.pixels_covered), static_cast<unsigned long long>(st.span_cycles),
                frame_ms[frame_ms.size() / 2], all.max_abs_lsb, toJson(all)["psnr_db"].dump().c_str(),
                100 * all.share_over_1lsb, static_cast<unsigned long long>(hl.pixels), hl.max_abs_lsb);
    if (rtl) {
      std::printf("rtl in the loop: %llu pixel mismatches, %.1f ms per frame, span cycles %s\n",
                  static_cast<unsigned long long>(mismatches), rtl_json["ms"].get<double>(),
                  rtl_json["cycles_equal"].get<bool>() ? "equal" : "DIFFERENT");
      if (mismatches > 0 || !rtl_json["cycles_equal"].get<bool>()) {
        std::fprintf(stderr, "MISMATCH: %s\n", first_mismatch.c_str());
        return 1;
      }
    }
    return 0;
  }
};

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{fmt::format("shadesim {}: cycle-accurate models and RTL of the shading hardware", SHD_VERSION)};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("shadesim ") + SHD_VERSION);
  PromCmd prom;
  CosimCmd cosim;
  SpecErrorCmd spec_error;
  CLI::App* prom_app = app.add_subcommand("prom", "write the coefficient PROM of the specular unit");
  CLI::App* cosim_app = app.add_subcommand("cosim", "run the verilated RTL against the golden model");
  CLI::App* err_app = app.add_subcommand("spec-error", "error report of the specular unit");
  SpanCyclesCmd span_cycles;
  RenderCmd render_cmd;
  CLI::App* render_app = app.add_subcommand("render", "render a scene with a shading method (and the RTL in the loop)");
  render_cmd.add(*render_app);
  CLI::App* cyc_app = app.add_subcommand("span-cycles", "cycles of the span unit per mode, and the paper's speed-up claims");
  span_cycles.add(*cyc_app);
  prom.add(*prom_app);
  cosim.add(*cosim_app);
  spec_error.add(*err_app);
  shd::cli::VectorsCmd vectors_cmd;
  shd::cli::ReplayCmd replay_cmd;
  CLI::App* vectors_app = app.add_subcommand("vectors", "write a vector file (inputs and the golden model's outputs, cycle by cycle)");
  CLI::App* replay_app = app.add_subcommand("replay", "replay a vector file on the verilated RTL, comparing every cycle");
  vectors_cmd.add(*vectors_app);
  replay_cmd.add(*replay_app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  CLI::App* cmd = app.get_subcommands().front();
  try {
    if (cmd == prom_app) return prom.run(*prom_app);
    if (cmd == cosim_app) return cosim.run();
    if (cmd == err_app) return spec_error.run();
    if (cmd == cyc_app) return span_cycles.run();
    if (cmd == render_app) return render_cmd.run();
    if (cmd == vectors_app) return vectors_cmd.run();
    if (cmd == replay_app) return replay_cmd.run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "shadesim %s: error: %s\n", cmd->get_name().c_str(), e.what());
    return 2;
  }
  return 2;
}
