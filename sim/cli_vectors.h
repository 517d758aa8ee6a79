// The vector-file commands of the shadesim program (included by main.cpp only):
//   shadesim vectors --unit spec|span --config NAME --cycles N [--seed S] -o FILE [--prom FILE]
//   shadesim replay FILE [--fst out.fst] [--prom FILE] [--json]
// Exit status: 0 pass, 1 replay mismatch, 2 bad input (main.cpp prints "shadesim <cmd>: error").
#pragma once

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/spec_params.h"
#include "replay.h"
#include "vector_file.h"
#include "vector_gen.h"

namespace shd::cli {

struct VectorsCmd {
  std::string unit, config, output, prom;
  uint64_t cycles = 0, seed = 1;

  void add(CLI::App& app) {
    app.add_option("--unit", unit, "spec (specular unit) or span (span unit)")
        ->required()
        ->check(CLI::IsMember({"spec", "span"}));
    app.add_option("--config", config,
                   "spec: default | narrow | wide | cubic; span: serial | evenodd | seg2 | seg4 | seg8 | sierpinski")
        ->required();
    app.add_option("--cycles", cycles, "clock cycles after reset (the file holds exactly this many)")
        ->required()
        ->check(CLI::Range(uint64_t{1}, uint64_t{100'000'000}));
    app.add_option("--seed", seed, "stimulus seed");
    app.add_option("-o,--output", output, "the vector file to write")->required();
    app.add_option("--prom", prom,
                   "spec: the PROM file the vectors refer to (default: vectors/prom/spec_<config>.hex of the source "
                   "tree); it must hold the configuration's table");
  }

  int run() {
    namespace fs = std::filesystem;
    const std::string out_dir = fs::absolute(output).parent_path().string();
    VectorGenSummary s;
    if (unit == "spec") {
      const std::string prom_file =
          prom.empty() ? fmt::format("{}/vectors/prom/spec_{}.hex", SHD_SOURCE_DIR, config) : prom;
      writeSpecVectors(output, generateSpecVectors(config, cycles, seed, prom_file, out_dir, &s));
    } else {
      if (!prom.empty()) throw std::invalid_argument("--prom: the span unit has no PROM");
      const std::vector<std::string> names = builtinSpanConfigNames();
      if (std::find(names.begin(), names.end(), config) == names.end())
        throw std::invalid_argument(
            fmt::format("--config {}: no span-unit configuration of that name (known: {})", config, fmt::join(names, ", ")));
      writeSpanVectors(output, generateSpanVectors(config, cycles, seed, &s));
    }
    std::fprintf(stderr, "wrote %s: %s/%s seed %llu, %s, %llu bytes\n", output.c_str(), unit.c_str(), config.c_str(),
                 static_cast<unsigned long long>(seed), s.text().c_str(),
                 static_cast<unsigned long long>(fs::file_size(output)));
    return 0;
  }
};

struct ReplayCmd {
  std::string file, fst, prom;
  bool json = false;

  void add(CLI::App& app) {
    app.add_option("file", file, "the vector file (vectors/cycles/*.vec, or a failing case saved by cosim)")->required();
    app.add_option("--fst", fst, "write an FST waveform of the replay (open it with gtkwave)");
    app.add_option("--prom", prom, "spec: the PROM file to load instead of the file's '# prom'");
    app.add_flag("--json", json, "print the result as one JSON object on stdout");
  }

  int run() {
    ReplayOptions o;
    o.fst_path = fst;
    o.prom_path = prom;
    const ReplayResult r = replayVectorFile(file, o);
    if (json) {
      nlohmann::json j = {{"file", file},           {"unit", r.unit},         {"config", r.config},
                          {"cycles", r.cycles},     {"results", r.results},   {"compared", r.compared},
                          {"mismatches", r.mismatches}, {"mismatching_cycles", r.mismatching_cycles}};
      if (!fst.empty()) j["fst"] = fst;
      if (r.first) j["first_mismatch"] = {{"cycle", r.first->cycle}, {"signal", r.first->signal},
                                          {"expected", r.first->expected}, {"rtl", r.first->got}};
      std::cout << j.dump(2) << "\n";
    } else {
      std::printf("replay %s: %s/%s, %llu cycles, %llu %s, %llu output values compared, %llu mismatches\n", file.c_str(),
                  r.unit.c_str(), r.config.c_str(), static_cast<unsigned long long>(r.cycles),
                  static_cast<unsigned long long>(r.results), r.unit == "spec" ? "valid results" : "valid lane outputs",
                  static_cast<unsigned long long>(r.compared), static_cast<unsigned long long>(r.mismatches));
    }
    if (r.first) {
      std::fprintf(stderr, "MISMATCH (first of %llu, in %llu cycles) %s\n", static_cast<unsigned long long>(r.mismatches),
                   static_cast<unsigned long long>(r.mismatching_cycles), r.first->describe().c_str());
      for (size_t i = 1; i < r.listed.size(); ++i) std::fprintf(stderr, "  then %s\n", r.listed[i].describe().c_str());
      if (!fst.empty()) std::fprintf(stderr, "waveform: %s\n", fst.c_str());
      return 1;
    }
    return 0;
  }
};

}  // namespace shd::cli
