#include "vectors/vector_gen.h"

#include <algorithm>
#include <filesystem>
#include <functional>
#include <optional>
#include <random>
#include <stdexcept>

#include <fmt/format.h>

#include "device/prom.h"
#include "device/prom_io.h"
#include "io/files.h"
#include "raster/desc_stream.h"
#include "raster/setup.h"
#include "raster/trigen.h"
#include "device/spec_stimulus.h"

namespace fs = std::filesystem;

namespace shd {

std::string VectorGenSummary::text() const {
  if (fragments == 0 && dropped == 0) return fmt::format("{} cycles, {} valid inputs", cycles, valid_inputs);
  return fmt::format("{} cycles, {} descriptors accepted, {} lane fragments handed over, {} generator triangles dropped "
                     "by setup, directed phases done: {} of 3",
                     cycles, valid_inputs, fragments, dropped, phases_done);
}

// ------------------------------------------------------------------ spec

namespace {

// `output` (the vector file `make(prom_file, out_dir)` gives) and the configuration's PROM beside
// it as `output`.hex, written together.
void writeWithProm(const SpecUnitConfig& cfg, const std::string& output,
                   const std::function<SpecVectors(const std::string&, const std::string&)>& make) {
  const std::string prom_file = output + ".hex";
  OutputFiles files;
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
  for (const auto& [suffix, text] : renderPromFiles(table, PromFormat::Hex)) files.add(prom_file + suffix, text);
  files.add(output, renderSpecVectors(make(prom_file, std::filesystem::absolute(output).parent_path().string())));
  files.commit();
}

// A vector file's header fields: the configuration, its parameters, the PROM relative to out_dir.
SpecVectors specVectorsHeader(const SpecUnitConfig& cfg, const std::string& prom_file, const std::string& out_dir) {
  SpecVectors v;
  v.config = cfg.name;
  v.params = cfg.rtl;
  v.prom = fs::absolute(prom_file).lexically_normal().lexically_relative(fs::absolute(out_dir).lexically_normal())
               .generic_string();
  return v;
}

}  // namespace

void writeSpecVectorsWithProm(const SpecUnitConfig& cfg, uint64_t cycles, uint64_t seed, const std::string& output,
                              VectorGenSummary* summary) {
  writeWithProm(cfg, output, [&](const std::string& prom_file, const std::string& out_dir) {
    return generateSpecVectors(cfg, cycles, seed, prom_file, out_dir, summary);
  });
}

void writeSpecInputVectorsWithProm(const SpecUnitConfig& cfg, const std::vector<SpecIn>& inputs,
                                   const std::string& source, const std::string& output) {
  writeWithProm(cfg, output, [&](const std::string& prom_file, const std::string& out_dir) {
    SpecVectors v = specVectorsHeader(cfg, prom_file, out_dir);
    v.source = source;
    const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), cfg.rtl);
    SpecUnitModel model(cfg.rtl, table.words, table.seg_words);
    model.reset();
    std::vector<SpecIn> stream = inputs;
    stream.resize(inputs.size() + static_cast<size_t>(cfg.rtl.latency()));  // idle: the last results leave
    for (const SpecIn& in : stream) {
      v.in.push_back(in);
      v.expected.push_back(model.tick(in));
    }
    return v;
  });
}

void requirePromFileHoldsTable(const SpecUnitConfig& cfg, const std::string& prom_file) {
  const SpecUnitParams& p = cfg.rtl;
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), p);
  const std::string d = romImageDiff(readPromHexFiles(prom_file, p), RomImage::of(table), p);
  if (!d.empty())
    throw std::runtime_error(fmt::format("PROM file {}: {} (configuration {}'s table): regenerate it "
                                         "(scripts/regen_vectors.sh)",
                                         prom_file, d, cfg.name));
}

SpecVectors generateSpecVectors(const SpecUnitConfig& cfg, uint64_t cycles, uint64_t seed, const std::string& prom_file,
                                const std::string& out_dir, VectorGenSummary* summary) {
  const SpecUnitParams& p = cfg.rtl;
  const PromTable table = buildPromTable(PromRequest::fromContent(cfg.prom), p);

  SpecVectors v = specVectorsHeader(cfg, prom_file, out_dir);
  v.source = fmt::format("shadesim vectors --unit spec --config {} --cycles {} --seed {}", cfg.ref(), cycles, seed);

  // The corners, valid on every cycle.
  std::vector<SpecIn> corners;
  const uint32_t depth = static_cast<uint32_t>(p.shinCodes());
  const uint32_t last_entry = static_cast<uint32_t>(std::max<size_t>(table.entries.size(), 1) - 1);
  const uint32_t one = static_cast<uint32_t>(p.cosOne()), lmax = static_cast<uint32_t>(p.lightMax());
  // One valid input; cosines outside the port's codes are left out.
  auto corner = [&](uint32_t shin, int64_t cos, const std::array<uint32_t, 3>& light) {
    if (cos < 0 || cos > 2 * int64_t{one} - 1) return;
    SpecIn in;
    in.valid = true;
    in.shin = shin;
    in.cos = static_cast<uint32_t>(cos);
    in.light = light;
    corners.push_back(in);
  };
  for (uint32_t shin : {0u, 1u, depth / 2, last_entry, depth - 1})
    for (uint32_t cos : {0u, 1u, one / 2, one - 1, one, one + 1, 2 * one - 1})
      for (const std::array<uint32_t, 3>& light : {std::array<uint32_t, 3>{0, 0, 0}, std::array<uint32_t, 3>{lmax, lmax, lmax},
                                                   std::array<uint32_t, 3>{1, lmax / 2, lmax - 1}})
        corner(shin, cos, light);

  // Degree 3: the cut-off boundary, cos one code below, at and above the cut of every eighth
  // table entry and the last (the exact boundary is one code in 2^(Wc+1): random cosines miss it).
  // The table: both sides of every 16th bucket edge of the last entry's row (the index is the
  // cosine's top TableBits bits).
  if (p.kind() == SpecKind::Table)
    for (int64_t k = 1; k < (int64_t{1} << p.TableBits); k += 16) {
      const int64_t edge = k << (p.CosFracBits - p.TableBits);
      corner(last_entry, edge - 1, {lmax, lmax / 2, 1});
      corner(last_entry, edge, {lmax, lmax / 2, 1});
    }
  // Explog: the cosine's normalisation changes at powers of two (one code below, at, above).
  if (p.kind() == SpecKind::ExpLog)
    for (int k = 0; k <= p.CosFracBits; ++k)
      for (int64_t cos = (int64_t{1} << k) - 1; cos <= (int64_t{1} << k) + 1; ++cos) corner(last_entry, cos, {lmax, lmax / 2, 1});
  if (p.kind() == SpecKind::Poly && p.Degree == 3)
    for (uint32_t shin = 0; shin <= last_entry; shin = shin + 8 > last_entry && shin != last_entry ? last_entry : shin + 8) {
      const int64_t cut = decodePromWord(table.words[shin], p).cut;
      for (int64_t cos = cut - 1; cos <= cut + 1; ++cos) corner(shin, cos, {lmax, lmax / 2, 1});
    }

  if (p.kind() == SpecKind::Piecewise)  // each segment's first codes and their neighbours
    for (uint32_t shin = 0; shin <= last_entry; shin = shin + 8 > last_entry && shin != last_entry ? last_entry : shin + 8) {
      const PiecewiseCodes q = decodePiecewise(table.words[shin], &table.seg_words[size_t{shin} * static_cast<size_t>(p.Segments)], p);
      for (const PiecewiseCodes::Seg& g : q.segs)
        for (int64_t cos = g.B - 1; cos <= g.B + 1; ++cos) corner(shin, cos, {lmax, lmax / 2, 1});
    }

  SpecUnitModel model(p, table.words, table.seg_words);
  model.reset();
  RandomSpecStimulus stim(p, seed, cycles, 0.2);
  VectorGenSummary s;
  for (uint64_t c = 0; c < cycles; ++c) {
    SpecIn in;
    if (c < corners.size()) in = corners[c];
    else if (!stim.next(in)) in = SpecIn{};  // cannot happen: the stream holds `cycles` valid vectors
    s.valid_inputs += in.valid ? 1 : 0;
    v.in.push_back(in);
    v.expected.push_back(model.tick(in));
  }
  s.cycles = cycles;
  if (summary) *summary = s;
  return v;
}

// ------------------------------------------------------------------ span

namespace {

// The wide viewport: all PixBits of the fragment ports, within the guard band.
int wide_size(const SpanParams& p) { return static_cast<int>(std::min<int64_t>(int64_t{1} << p.PixBits, 4096)); }

// The descriptors of the three phases (vector_gen.h), one at a time.
class SpanVectorStimulus {
 public:
  SpanVectorStimulus(const SpanParams& p, uint64_t seed) : rng_(seed), hunting_(p.NumTri > 1) {
    tiny_.width = 16;
    tiny_.height = 12;
    tiny_.unit = p;
    small_.width = 40;
    small_.height = 30;
    small_.unit = p;
    wide_.width = wide_.height = wide_size(p);
    wide_.unit = p;
    // Colour with 12 fraction bits, the rest with 24: the codes fit 32-bit attributes on a
    // 4096-wide viewport, where the default rule would ask 31 bits for depth.
    for (int k = 0; k < p.NumAttr; ++k) wide_.attr_frac_bits.push_back(k < 3 ? 12 : 24);
    tiny_.validate();
    small_.validate();
    wide_.validate();
    // Phase 1: every size class x every shape, each from its own generator.
    for (int c = 0; c < kNumSizeClasses; ++c)
      for (int sh = 0; sh < kNumStreamShapes; ++sh) {
        TriGenOptions g = options(tiny_);
        g.size_weight.fill(0);
        g.size_weight[static_cast<size_t>(c)] = 1;
        g.shape_weight.fill(0);
        g.shape_weight[static_cast<size_t>(sh)] = 1;
        directed_.push_back(TriangleGenerator(rng_(), g));
      }
    // Phase 2 (more than one lane-triangle): large and screen-filling off-screen triangles and
    // slivers, the shapes whose lane-triangles' spans most often leave a lane group without a
    // valid lane.
    TriGenOptions h = options(tiny_);
    h.size_weight = {0, 0, 0, 1, 1};
    h.shape_weight = {0, 1, 0, 0, 1, 0};
    hunt_gen_.emplace(rng_(), h);
    TriGenOptions w = options(wide_);
    w.size_weight = {1, 1, 1, 0, 0};
    wide_gen_.emplace(rng_(), w);
    mixed_.emplace(rng_(), options(small_));
  }

  // The next descriptor and its phase (1 to 4).
  bool next(SpanDesc& d, int& phase) {
    for (;;) {
      std::optional<SpanDesc> got;
      if (directed_next_ < directed_.size()) {
        // Up to 8 draws, so that an off-screen draw without pixels is replaced; zero-area
        // triangles never give a descriptor.
        phase = 1;
        TriangleGenerator& g = directed_[directed_next_++];
        for (int attempt = 0; attempt < 8 && !got; ++attempt) got = setup(g.next(), tiny_);
      } else if (hunting_ && hunt_count_ < kHuntTriangles) {
        // Only triangles that the model, run alone, shows with an empty lane group (about one
        // draw in six); up to 256 draws.
        phase = 2;
        ++hunt_count_;
        for (int attempt = 0; attempt < 256 && !got; ++attempt) {
          got = setup(hunt_gen_->next(), tiny_);
          if (got && !hasEmptyLaneGroup(*got)) got.reset();
        }
        if (!got) hunting_ = false;
      } else if (wide_count_ < kWideTriangles) {
        phase = 3;
        ++wide_count_;
        got = setup(wide_gen_->next(), wide_);
      } else {
        phase = 4;
        got = setup(mixed_->next(), small_);
      }
      if (got) {
        ++made_[phase];
        d = std::move(*got);
        return true;
      }
    }
  }
  uint64_t dropped() const { return dropped_; }
  // Descriptors of a phase made so far.
  uint64_t made(int phase) const { return made_[phase]; }
  // Ends phase 2: the corner it hunts for has been seen.
  void stopHunting() { hunting_ = false; }
  static constexpr int kHuntTriangles = 8;
  static constexpr int kWideTriangles = 24;

 private:
  static TriGenOptions options(const RasterConfig& rc) {
    TriGenOptions g;
    g.width = rc.width;
    g.height = rc.height;
    g.subpixel_bits = rc.subpixel_bits;
    g.num_attr = rc.unit.NumAttr;
    return g;
  }
  // A SPAN cycle without a valid lane when the descriptor runs alone, consumer always ready.
  bool hasEmptyLaneGroup(const SpanDesc& d) const {
    SpanUnitModel m(tiny_.unit);
    m.reset();
    SpanIn in;
    in.desc_valid = true;
    in.desc = &d;
    SpanOut o;
    m.tick(in, o);
    in.desc_valid = false;
    while (!m.idle()) {
      const uint64_t before = m.spanCycles();
      m.tick(in, o);
      if (m.spanCycles() > before && !o.out_valid) return true;
    }
    return false;
  }
  std::optional<SpanDesc> setup(const GenTriangle& t, const RasterConfig& rc) {
    // Tags spread over all 32 bits (a multiplicative hash of the count), so that every bit of
    // the tag path toggles (the coverage run found its upper bits never did with tags 0, 1, ...).
    SetupResult s = setupTriangle(toSetupVertices(t, rc.unit.NumAttr), 0x9E3779B1u * tag_++, rc);
    if (!s.desc) {
      ++dropped_;
      return std::nullopt;
    }
    return std::move(*s.desc);
  }

  std::mt19937_64 rng_;
  RasterConfig tiny_, small_, wide_;
  std::vector<TriangleGenerator> directed_;
  size_t directed_next_ = 0;
  std::optional<TriangleGenerator> hunt_gen_, wide_gen_, mixed_;
  bool hunting_;
  int hunt_count_ = 0, wide_count_ = 0;
  uint32_t tag_ = 0;
  uint64_t dropped_ = 0;
  uint64_t made_[5] = {0, 0, 0, 0, 0};  // [phase]
};

}  // namespace

SpanVectors generateSpanVectors(const SpanUnitConfig& cfg, uint64_t cycles, uint64_t seed, VectorGenSummary* summary) {
  SpanVectors v;
  v.config = cfg.name;
  v.params = cfg.rtl;
  v.source = fmt::format("shadesim vectors --unit span --config {} --cycles {} --seed {}", cfg.ref(), cycles, seed);
  SpanVectorStimulus stim(v.params, seed);
  SpanUnitModel model(v.params);
  model.reset();
  std::mt19937_64 rng(seed ^ 0x5eed5eed5eed5eedULL);
  const double ready_choices[] = {1.0, 0.75, 0.3};
  auto draw_ready = [&] { return ready_choices[rng() % 3]; };
  auto draw_wait = [&] { return std::bernoulli_distribution(0.3)(rng) ? 1 + static_cast<int>(rng() % 3) : 0; };

  VectorGenSummary s;
  SpanDesc pending;
  int phase = 0, busy_phase = 0;  // of the pending descriptor; of the one being processed
  stim.next(pending, phase);
  int wait = draw_wait();
  double ready_prob = draw_ready();
  bool on_ports = false;  // `pending` is in v.descs (it has been offered)
  uint64_t accepted[5] = {0, 0, 0, 0, 0}, done_at[5] = {0, 0, 0, 0, 0};  // [phase]
  // Control corners met, counted from the model (the vector file cannot tell a ROW cycle from
  // a SPAN cycle without a valid lane).
  uint64_t stalled = 0, waiting = 0, idle_gap = 0, empty_groups = 0, empty_stalled = 0;
  for (uint64_t c = 0; c < cycles; ++c) {
    SpanVectorCycle cyc;
    cyc.out_ready = std::bernoulli_distribution(ready_prob)(rng);
    // A gap counts idle cycles: the unit waits, idle, with nothing offered.
    cyc.desc_valid = wait == 0;
    if (wait > 0 && model.idle()) --wait;
    if (cyc.desc_valid && !on_ports) {
      v.descs.push_back(pending);
      on_ports = true;
    }
    cyc.desc = static_cast<int>(v.descs.size()) - 1;
    SpanIn in;
    in.desc_valid = cyc.desc_valid;
    in.desc = &pending;
    in.out_ready = cyc.out_ready;
    const uint64_t span_before = model.spanCycles();
    model.tick(in, cyc.expected);
    const SpanOut& o = cyc.expected;
    if (o.out_valid && cyc.out_ready)
      for (const SpanLaneOut& l : o.lane) s.fragments += l.valid ? 1 : 0;
    stalled += o.out_valid && !cyc.out_ready;
    waiting += cyc.desc_valid && !o.desc_ready;
    idle_gap += !cyc.desc_valid && o.desc_ready;
    if (model.spanCycles() > span_before && !o.out_valid) {
      ++empty_groups;
      if (!cyc.out_ready) {
        ++empty_stalled;
        stim.stopHunting();
      }
    }
    if (cyc.desc_valid && o.desc_ready) {  // accepted at this edge
      ++s.valid_inputs;
      ++accepted[phase];
      // The unit accepts only when idle: a triangle of a later phase accepted means the
      // earlier phases are done.
      for (int k = 1; k < phase; ++k)
        if (done_at[k] == 0) done_at[k] = c + 1;
      busy_phase = phase;
      stim.next(pending, phase);
      on_ports = false;
      wait = draw_wait();
      // Phase 2 hunts for a lane group without a valid lane while out_ready is low.
      ready_prob = busy_phase == 2 ? 0.3 : draw_ready();
    }
    v.cycles.push_back(std::move(cyc));
  }
  auto done = [&](int ph) {
    return done_at[ph] ? fmt::format("all done by cycle {}", done_at[ph]) : std::string("NOT all done");
  };
  v.notes.push_back(fmt::format("coverage: phase 1, one triangle of every size class x shape (16x12 viewport): {} of {} "
                                "descriptors accepted, {}",
                                accepted[1], stim.made(1), done(1)));
  v.notes.push_back(
      v.params.NumTri > 1
          ? fmt::format("coverage: phase 2, large off-screen triangles and slivers that have a lane group without a "
                        "valid lane, out_ready 30 %, until such a group met out_ready low: {} descriptors accepted, {}",
                        accepted[2], done(2))
          : std::string("coverage: phase 2, not needed: with one lane-triangle every lane group holds a valid lane"));
  v.notes.push_back(fmt::format("coverage: phase 3, {} pixel- to mesh-sized generator triangles in a {}x{} viewport: "
                                "{} of the {} descriptors setup made accepted, {}",
                                SpanVectorStimulus::kWideTriangles, wide_size(v.params), wide_size(v.params),
                                accepted[3], stim.made(3), done(3)));
  v.notes.push_back(fmt::format("coverage: phase 4, the generator's mix (40x30 viewport): {} descriptors accepted",
                                accepted[4]));
  v.notes.push_back(fmt::format("coverage: cycles with a valid output stalled by out_ready {}, a descriptor offered "
                                "while the unit is busy {}, the unit idle with nothing offered {}, a lane group "
                                "without a valid lane {} (with out_ready low {})",
                                stalled, waiting, idle_gap, empty_groups, empty_stalled));
  s.phases_done = (done_at[1] != 0) + (done_at[3] != 0) + (v.params.NumTri > 1 ? done_at[2] != 0 : 1);
  s.cycles = cycles;
  s.dropped = stim.dropped();
  if (summary) *summary = s;
  return v;
}

}  // namespace shd
