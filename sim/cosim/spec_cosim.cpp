#include "cosim/spec_cosim.h"

#include <chrono>
#include <filesystem>
#include <fstream>
#include <iterator>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "io/files.h"

namespace fs = std::filesystem;

namespace shd {

std::string SpecMismatch::describe(const SpecUnitParams& p) const {
  auto out = [](const SpecOut& o) {
    return fmt::format("valid={} spec={:#x} rgb=({}, {}, {})", o.valid ? 1 : 0, o.spec, o.rgb[0], o.rgb[1], o.rgb[2]);
  };
  const std::string in = input.valid
      ? fmt::format("shin={} cos={:#x} ({:.9f}) light=({}, {}, {})", input.shin, input.cos,
                    std::ldexp(static_cast<double>(input.cos), -p.CosFracBits), input.light[0], input.light[1],
                    input.light[2])
      : std::string("no valid input (a control mismatch)");
  return fmt::format("cycle {}: input {}\n  model: {}\n  rtl:   {}", cycle, in, out(expected), out(got));
}

void verifyLoadedProm(SpecDut& dut, const RomImage& expected, const std::string& prom_path, const SpecUnitParams& p) {
  const std::string d = romImageDiff({dut.romWords(), dut.segRomWords()}, expected, p);
  if (!d.empty())
    throw std::runtime_error(fmt::format("the simulator loaded from {}: {}: the PROM file is missing, short, corrupt or "
                                         "made for another fit",
                                         prom_path, d));
}

SpecCosimResult runSpecCosim(const std::string& config, SpecUnitModel& model, SpecStimulus& stim,
                             const SpecCosimOptions& opts) {
  const SpecUnitParams& p = model.params();
  SpecCosimResult res;
  res.config = config;
  // The file first (strict parse: clear messages for missing, short or corrupt files), then
  // what the simulator made of it.
  const RomImage want{model.prom(), model.segRom()};
  const std::string d = romImageDiff(readPromHexFiles(opts.prom_path, p), want, p);
  if (!d.empty())
    throw std::runtime_error(fmt::format("PROM file {}: {} (the model's table): the file is corrupt or made for another "
                                         "fit or format",
                                         opts.prom_path, d));
  auto dut = makeSpecDut(config, SpecDutOptions{opts.prom_path, ""});
  verifyLoadedProm(*dut, want, opts.prom_path, p);

  const size_t window = static_cast<size_t>(p.latency()) + 8;
  std::vector<SpecIn> history(window);  // ring: the inputs of the last `window` cycles
  size_t filled = 0;                     // cycles recorded, at most window
  std::vector<SpecIn> fail_window;
  dut->reset();
  model.reset();
  const auto t0 = std::chrono::steady_clock::now();
  SpecIn in;
  bool more = true;
  int drain = p.latency();
  uint64_t next_progress = uint64_t{1} << 20;
  while (more || drain > 0) {
    if (more) more = stim.next(in);
    if (!more) {
      in = SpecIn{};
      --drain;
    }
    if (in.valid) ++res.vectors;
    const SpecOut got = dut->tick(in);
    const SpecOut exp = model.tick(in);
    const uint64_t cyc = model.cycle();  // 1-based index of this cycle
    history[cyc % window] = in;
    filled = std::min(filled + 1, window);
    if (got != exp) {
      ++res.mismatches;
      if (!res.first) {
        SpecMismatch m;
        m.cycle = cyc;
        const size_t back = static_cast<size_t>(p.latency()) - 1;
        if (filled > back) m.input = history[(cyc - back) % window];
        m.expected = exp;
        m.got = got;
        res.first = m;
        for (uint64_t k = cyc + 1 - filled; k <= cyc; ++k) fail_window.push_back(history[k % window]);
      }
      if (res.mismatches >= opts.max_mismatches) break;
    }
    if (opts.progress && res.vectors >= next_progress) {
      opts.progress(res.vectors, stim.total());
      next_progress += uint64_t{1} << 20;
    }
  }
  res.cycles = model.cycle();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dut->finish();

  if (res.first) {
    // Replay the failing window from reset into a traced instance, with the model's expected
    // outputs for the same window, so the case reproduces alone.
    std::filesystem::create_directories(opts.fail_dir);
    res.fst_path = fmt::format("{}/spec_{}_fail.fst", opts.fail_dir, config);
    res.vector_path = fmt::format("{}/spec_{}_fail.vec", opts.fail_dir, config);
    res.prom_copy_path = fmt::format("{}/spec_{}_fail.hex", opts.fail_dir, config);
    auto traced = makeSpecDut(config, SpecDutOptions{opts.prom_path, res.fst_path});
    SpecUnitModel replay(p, model.prom(), model.segRom());
    traced->reset();
    SpecVectors v;
    v.config = config;
    // The header names the verilated configuration's parameters (the model's may differ: that
    // is what fault injection does), so that the file replays on that configuration.
    v.params = specConfig(config).rtl;
    v.prom = fs::path(res.prom_copy_path).filename().string();
    v.source = fmt::format("shadesim cosim: the failing window, cycles {}..{} of the run, replayed from reset",
                           res.first->cycle + 1 - fail_window.size(), res.first->cycle);
    for (const SpecIn& w : fail_window) {
      traced->tick(w);
      v.in.push_back(w);
      v.expected.push_back(replay.tick(w));
    }
    traced->finish();
    // The PROM the simulator loaded (the run's file may be a temporary one), then the vectors.
    for (const char* suffix : {"", kSegRomSuffix}) {
      if (*suffix != '\0' && p.segDepth() == 0) continue;
      const std::string from = opts.prom_path + suffix;
      std::ifstream prom_in(from, std::ios::binary);
      if (!prom_in) throw std::runtime_error(fmt::format("cannot read back PROM file {}", from));
      const std::string prom_text((std::istreambuf_iterator<char>(prom_in)), std::istreambuf_iterator<char>());
      writeFileAtomic(res.prom_copy_path + suffix, prom_text);
    }
    writeSpecVectors(res.vector_path, v);
  }
  return res;
}

}  // namespace shd
