// shadesim prom: the coefficient PROM of the specular unit in a simulator's or an FPGA tool's
// format (hex for $readmemh, mem, coe, mif, csv).
#include <cstdio>

#include "cli/command.h"
#include "cli/table_options.h"
#include "device/prom_io.h"
#include "io/files.h"

namespace shd::cli {

namespace {

class PromCmd final : public Command {
 public:
  void add(CLI::App& app) override {
    table_.add(app);
    app.add_option("--format", format_, "hex ($readmemh) | mem (Lattice) | coe (Xilinx) | mif (Intel) | csv")
        ->required()
        ->check(CLI::IsMember({"hex", "mem", "coe", "mif", "csv"}));
    app.add_option("-o,--output", output_, "output file (default stdout); with --n-list also <file>.map.csv, "
                                           "with csv also <file>.json (provenance), for the piecewise kind "
                                           "also <file>.seg (its segment ROM)");
  }

  int run(const CLI::App& app) override {
    SpecUnitConfig cfg;
    const PromTable t = table_.build(cfg, app.count("--config") == 0);
    const PromFormat f = parsePromFormat(format_);
    // Render everything first, then write: an error leaves no file behind.
    const auto bodies = renderPromFiles(t, f);
    const std::string map = t.request.n.is_list ? renderAddressMap(t) : "";
    const std::string side = f == PromFormat::Csv ? renderProvenanceJson(t) : "";
    if (output_.empty() || output_ == "-") {
      if (bodies.size() > 1)
        throw std::invalid_argument(fmt::format("the {} kind has a segment ROM beside the PROM: name the files with -o",
                                                specKindInfo(t.unit.kind()).name));
      std::fwrite(bodies[0].second.data(), 1, bodies[0].second.size(), stdout);
    } else {
      OutputFiles files;  // the table and its sidecars together, or none of them
      for (const auto& [suffix, body] : bodies) files.add(output_ + suffix, body);
      if (!map.empty()) files.add(output_ + ".map.csv", map);
      if (!side.empty()) files.add(output_ + ".json", side);
      files.commit();
      std::fprintf(stderr, "wrote %s: %zu codes, %d words of %d bits (%s)\n", output_.c_str(), t.entries.size(),
                   t.unit.promDepth(), t.unit.promWordBits(), t.request.describe().c_str());
      if (t.unit.segDepth() > 0 && f != PromFormat::Csv)
        std::fprintf(stderr, "wrote %s%s: the segment ROM, %d words of %d bits\n", output_.c_str(), kSegRomSuffix,
                     t.unit.segDepth(), t.unit.segWordBits());
    }
    return 0;
  }

 private:
  TableOptions table_;
  std::string format_, output_;
};

}  // namespace

std::unique_ptr<Command> makePromCmd() { return std::make_unique<PromCmd>(); }

}  // namespace shd::cli
