// shadesim vectors: a unit's vector file (vectors/vector_file.h) from the golden model: inputs
// and expected outputs, cycle by cycle from reset.
#include <cstdio>
#include <filesystem>

#include <fmt/format.h>

#include "cli/command.h"
#include "device/prom_io.h"
#include "vectors/vector_file.h"
#include "vectors/vector_gen.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd::cli {

namespace {

class VectorsCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    app.add_option("--unit", unit_, "spec (specular unit) or span (span unit)")
        ->required()
        ->check(CLI::IsMember({"spec", "span"}));
    app.add_option("--config", config_,
                   "spec: " + configChoices("spec") + "; span: " + configChoices("span"))
        ->required();
    app.add_option("--cycles", cycles_, "clock cycles after reset (the file holds exactly this many)")
        ->required()
        ->check(countIn(1, 10'000'000));
    app.add_option("--seed", seed_, "stimulus seed")->check(countIn(0, UINT64_MAX));
    app.add_option("-o,--output", output_, "the vector file to write")->required();
    app.add_option("--prom", prom_,
                   "spec: the PROM file the vectors refer to, which must hold the configuration's table (default: "
                   "the table is written beside the output as <output>.hex)");
  }

  int run(const CLI::App&) override {
    const std::string out_dir = fs::absolute(output_).parent_path().string();
    VectorGenSummary s;
    std::string name;
    if (unit_ == "spec") {
      const SpecUnitConfig cfg = specConfigArg("--config", config_);
      name = cfg.name;
      std::string prom_file = prom_;
      if (!prom_file.empty()) requirePromFileHoldsTable(cfg, prom_file);  // an input: never an output
      outputTarget(output_);  // refused before the work, not after it
      if (prom_file.empty())
        writeSpecVectorsWithProm(cfg, cycles_, seed_, output_, &s);
      else
        writeFileAtomic(output_, renderSpecVectors(generateSpecVectors(cfg, cycles_, seed_, prom_file, out_dir, &s)));
    } else {
      if (!prom_.empty()) throw ArgError("--prom: the span unit has no PROM");
      const SpanUnitConfig cfg = spanConfigArg("--config", config_);
      outputTarget(output_);
      name = cfg.name;
      writeSpanVectors(output_, generateSpanVectors(cfg, cycles_, seed_, &s));
    }
    std::fprintf(stderr, "wrote %s: %s/%s seed %llu, %s, %llu bytes\n", output_.c_str(), unit_.c_str(), name.c_str(),
                 static_cast<unsigned long long>(seed_), s.text().c_str(),
                 static_cast<unsigned long long>(fs::file_size(output_)));
    return 0;
  }

 private:
  std::string unit_, config_, output_, prom_;
  uint64_t cycles_ = 0, seed_ = 1;
};

}  // namespace

std::unique_ptr<Command> makeVectorsCmd() { return std::make_unique<VectorsCmd>(); }

}  // namespace shd::cli
