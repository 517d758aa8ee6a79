#include "cosim/span_cosim.h"

#include <array>
#include <chrono>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "io/files.h"
#include "io/spsc_ring.h"

namespace shd {

nlohmann::json toJson(const SpanDesc& d) {
  nlohmann::json tris = nlohmann::json::array();
  for (const SpanLaneTri& t : d.tri) {
    nlohmann::json edges = nlohmann::json::array();
    for (const SpanEdge& e : t.edge)
      edges.push_back({{"row_first", e.row_first}, {"row_last", e.row_last}, {"right", e.right}, {"q", e.q},
                       {"r", e.r}, {"div", e.div}, {"k", e.k}, {"m", e.m}});
    tris.push_back({{"row_first", t.row_first}, {"row_last", t.row_last}, {"clip_x0", t.clip_x0},
                    {"clip_x1", t.clip_x1}, {"flip", t.flip}, {"ox", t.ox}, {"oy", t.oy}, {"aoff", t.aoff},
                    {"edges", edges}});
  }
  return {{"tag", d.tag},   {"row_first", d.row_first}, {"row_last", d.row_last}, {"xref", d.xref},
          {"iref", d.iref}, {"didx", d.didx},           {"didy", d.didy},         {"interleave", d.interleave},
          {"tri", tris}};
}

ReadyDraw::ReadyDraw(double p) {
  // The distribution's answer when the generator returns x.
  struct Fixed {
    using result_type = std::mt19937_64::result_type;
    static constexpr result_type min() { return std::mt19937_64::min(); }
    static constexpr result_type max() { return std::mt19937_64::max(); }
    result_type x;
    result_type operator()() { return x; }
  };
  auto answer = [p](uint64_t x) {
    Fixed g{x};
    return std::bernoulli_distribution(p)(g);
  };
  if (answer(Fixed::max())) {
    always_ = true;
    return;
  }
  // answer(hi) is false; find the least such hi.
  uint64_t lo = 0, hi = Fixed::max();
  if (!answer(lo)) return;  // threshold 0: never
  while (hi - lo > 1) {
    const uint64_t mid = lo + (hi - lo) / 2;
    (answer(mid) ? lo : hi) = mid;
  }
  threshold_ = hi;
}

std::string compareSpanOutputs(const SpanOut& exp, const SpanOut& got) {
  if (exp.desc_ready != got.desc_ready)
    return fmt::format("desc_ready: model {} rtl {}", exp.desc_ready, got.desc_ready);
  if (exp.out_valid != got.out_valid) return fmt::format("out_valid: model {} rtl {}", exp.out_valid, got.out_valid);
  if (exp.out_valid && exp.tag != got.tag) return fmt::format("tag: model {} rtl {}", exp.tag, got.tag);
  if (exp.lane.size() != got.lane.size())
    return fmt::format("lanes: model {} rtl {}", exp.lane.size(), got.lane.size());
  for (size_t l = 0; l < exp.lane.size(); ++l) {
    const SpanLaneOut &e = exp.lane[l], &g = got.lane[l];
    if (e.valid != g.valid) return fmt::format("lane {} valid: model {} rtl {}", l, e.valid, g.valid);
    if (!e.valid) continue;
    if (e.x != g.x || e.y != g.y)
      return fmt::format("lane {} pixel: model ({}, {}) rtl ({}, {})", l, e.x, e.y, g.x, g.y);
    if (e.attr.size() != g.attr.size())
      return fmt::format("lane {} attributes: model {} rtl {}", l, e.attr.size(), g.attr.size());
    for (size_t a = 0; a < e.attr.size(); ++a)
      if (e.attr[a] != g.attr[a])
        return fmt::format("lane {} pixel ({}, {}) attribute {}: model {} rtl {}", l, e.x, e.y, a, e.attr[a], g.attr[a]);
  }
  return "";
}

namespace {

// The failing case from reset: the window's inputs with the descriptors accepted in it (`held`,
// in order) and `next`, offered and not yet accepted when the run failed, replayed into a traced
// instance (FST) and, with the model's expected outputs, a vector file that `shadesim replay`
// and the Icarus testbench replay; the descriptor accepted last and the out_ready pattern as
// JSON.
template <class Window>
void saveSpanFailingCase(const std::string& mode, const SpanParams& model_params, const SpanMismatch& first,
                         const Window& window, const std::vector<SpanDesc>& held, const SpanDesc& next,
                         const SpanCosimOptions& opts, SpanCosimResult& res) {
  std::filesystem::create_directories(opts.fail_dir);
  res.fst_path = fmt::format("{}/span_{}_fail.fst", opts.fail_dir, mode);
  res.case_path = fmt::format("{}/span_{}_fail.json", opts.fail_dir, mode);
  res.vector_path = fmt::format("{}/span_{}_fail.vec", opts.fail_dir, mode);
  auto traced = makeSpanDut(mode, res.fst_path);
  SpanVectors v;
  v.config = mode;
  v.params = traced->params();
  v.source = fmt::format("shadesim cosim: the failing triangle (tag {}), cycles {}..{} of the run, replayed from reset",
                         first.tag, first.cycle + 1 - window.size(), first.cycle);
  v.descs = held;
  size_t on_ports = 0;  // the descriptor offered in the current cycle: accepted ones so far
  for (const auto& w : window) {
    SpanVectorCycle c;
    c.desc_valid = w.desc_valid;
    c.out_ready = w.out_ready;
    if (w.desc_valid && on_ports == v.descs.size()) v.descs.push_back(next);  // offered, not accepted
    c.desc = v.descs.empty() ? -1 : static_cast<int>(std::min(on_ports, v.descs.size() - 1));
    on_ports += w.accepted ? 1 : 0;
    v.cycles.push_back(std::move(c));
  }
  SpanUnitModel replay(model_params);
  traced->reset();
  replay.reset();
  SpanOut ignored;
  for (SpanVectorCycle& c : v.cycles) {
    SpanIn in;
    in.desc_valid = c.desc_valid;
    in.out_ready = c.out_ready;
    in.desc = c.desc >= 0 ? &v.descs[static_cast<size_t>(c.desc)] : nullptr;
    replay.tick(in, c.expected);
    traced->tick(in, ignored);
  }
  traced->finish();
  writeSpanVectors(res.vector_path, v);
  std::vector<bool> ready_after_accept;
  bool after = false;
  for (const auto& w : window) {
    if (after) ready_after_accept.push_back(w.out_ready);
    after = after || w.accepted;
  }
  nlohmann::json j = {{"mode", mode},
                      {"mismatch", {{"cycle", first.cycle}, {"what", first.what}}},
                      {"descriptor", held.empty() ? toJson(next) : toJson(held.back())},
                      {"descriptors_replayed", v.descs.size()},
                      {"out_ready_after_accept", ready_after_accept},
                      {"vectors", res.vector_path}};
  writeFileAtomic(res.case_path, j.dump(1) + "\n");
}

}  // namespace

namespace {

// One cycle's inputs, and what the failing case's window needs; the model's outputs beside it.
struct CycleInputs {
  bool desc_valid = false, out_ready = false;
  bool idle = false;   // the unit was idle before this cycle's edge
  bool taken = false;  // the descriptor was accepted at this cycle's edge
};

// The failing case is the run's inputs from the last cycle that began with the unit idle,
// with the descriptors accepted since (`held`): from reset they reproduce the unit's state.
// The paper's unit is idle when it accepts each descriptor; the full-rate unit, which takes
// the next one while it works, is idle only where the stream lets it drain (opts.drain_every).
// Past kMaxHeld descriptors or kMaxWindow cycles without an idle cycle the window is dropped
// (a failure there is reported without a saved case).
constexpr size_t kMaxHeld = 64, kMaxWindow = size_t{1} << 20;

// On two threads the cycles go from the stimulus to the checker packed, kChunkCycles to a chunk
// (CycleChunk), through a ring of kChunks.
constexpr uint32_t kChunkCycles = 64;
constexpr size_t kChunks = 8;

// The descriptors in a ring, read into place (no copy per triangle), indexed by the count of
// descriptors accepted before them. The checker reads the pending one and the kMaxHeld before
// it; the stimulus, up to (kChunks + 1) * kChunkCycles cycles ahead (the ring's chunks and the
// one it fills), accepts at most one per cycle, and writes each once, when the one before is
// accepted.
constexpr size_t kDescSlots = kMaxHeld + (kChunks + 1) * kChunkCycles + 2;

// The stimulus and the model: the stream's descriptors, the random out_ready and descriptor
// gaps, the drain, and the model's outputs, cycle by cycle. It calls `next` and
// opts.progress. In cache lines of its own (as SpanChecker), apart from what the checker's
// thread writes.
class alignas(64) SpanStimulus {
 public:
  SpanStimulus(const SpanParams& p, const std::function<bool(SpanDesc&)>& next, const SpanCosimOptions& opts,
               std::vector<SpanDesc>& descs)
      : model_(p), next_(next), opts_(opts), descs_(descs), rng_(opts.seed), ready_(opts.ready_prob),
        gap_(opts.desc_gap_prob) {
    model_.reset();
    have_pending_ = next_(*pending_);
    wait_ = drawWait();
  }
  // The next cycle: its inputs and the model's outputs; false once the stream has ended and
  // the unit is idle.
  bool step(CycleInputs& c, SpanOut& exp) {
    c.idle = false;
    if (model_.idle()) {
      if (!have_pending_) return false;
      c.idle = true;
      draining_ = false;
    }
    SpanIn in;
    in.out_ready = ready_(rng_);
    in.desc_valid = have_pending_ && wait_ == 0 && !draining_;
    in.desc = pending_;
    if (wait_ > 0) --wait_;
    model_.tick(in, exp);
    c.desc_valid = in.desc_valid;
    c.out_ready = in.out_ready;
    c.taken = in.desc_valid && exp.desc_ready;
    if (c.taken) {
      pending_ = &slot(++accepted_);
      if (opts_.progress && (accepted_ & 4095) == 0) opts_.progress(accepted_);
      have_pending_ = next_(*pending_);
      wait_ = drawWait();
      if (opts_.drain_every > 0 && ++since_drain_ == opts_.drain_every) {
        since_drain_ = 0;
        draining_ = true;  // desc_valid held low until the unit is idle
      }
    }
    return true;
  }
  uint64_t cycle() const { return model_.cycle(); }

 private:
  SpanDesc& slot(uint64_t i) { return descs_[i % descs_.size()]; }
  int drawWait() { return have_pending_ && gap_(rng_) ? 1 + static_cast<int>(rng_() % 3) : 0; }

  SpanUnitModel model_;
  const std::function<bool(SpanDesc&)>& next_;
  const SpanCosimOptions& opts_;
  std::vector<SpanDesc>& descs_;
  std::mt19937_64 rng_;
  const ReadyDraw ready_;
  std::bernoulli_distribution gap_;
  uint64_t accepted_ = 0, since_drain_ = 0;
  SpanDesc* pending_ = &slot(0);  // slot(accepted_)
  bool have_pending_ = false, draining_ = false;
  int wait_ = 0;
};

// The checker: the verilated unit, given each cycle's inputs, against the model's outputs, and
// the window of the failing case.
class alignas(64) SpanChecker {
 public:
  SpanChecker(SpanDut& dut, const std::string& mode, const SpanCosimOptions& opts, const std::vector<SpanDesc>& descs)
      : dut_(dut), opts_(opts), descs_(descs) {
    res_.mode = mode;
  }
  // Checks one cycle, the model's `cycle`-th; false once the run is to stop (opts.max_mismatches
  // reached).
  bool check(const CycleInputs& c, const SpanOut& exp, uint64_t cycle) {
    SpanIn in;
    in.desc_valid = c.desc_valid;
    in.desc = pending_;
    in.out_ready = c.out_ready;
    // The comparison is done on the ports (SpanDut::tickCheck, equal to compareSpanOutputs);
    // the RTL's outputs are read out for the message only when they differ.
    const bool same = dut_.tickCheck(in, exp, got_);
    window_.push_back({c.desc_valid, c.out_ready, c.taken, false});
    if (exp.out_valid && c.out_ready)
      for (const SpanLaneOut& l : exp.lane) res_.fragments += l.valid ? 1 : 0;
    if (!same && !mismatch(c, exp, cycle)) return false;
    // The window starts again at an idle cycle, after its comparison: a mismatch in that cycle
    // keeps the cycles before it, which may be what the RTL still shows.
    if (c.idle) {
      window_begin_ = window_.size() - 1;
      held_begin_ = res_.triangles;  // this cycle's descriptor, if it takes one, is the window's first
      window_lost_ = false;
      if (window_begin_ >= 4096) {  // drop the prefix now and then, not at every idle cycle
        window_.erase(window_.begin(), window_.begin() + static_cast<ptrdiff_t>(window_begin_));
        window_begin_ = 0;
      }
    }
    if (window_.size() - window_begin_ > kMaxWindow || (c.taken && res_.triangles + 1 - held_begin_ > kMaxHeld)) {
      window_lost_ = true;  // until the unit is idle again
      window_.clear();
      window_begin_ = 0;
    }
    if (c.taken) pending_ = &slot(++res_.triangles);
    return true;
  }
  // After the run: the result, with the first mismatch's case replayed and saved, if it was
  // kept.
  SpanCosimResult finish(const SpanParams& model_params) {
    if (fail_saved_)
      saveSpanFailingCase(res_.mode, model_params, *res_.first, fail_window_, fail_held_, fail_next_, opts_, res_);
    return std::move(res_);
  }

 private:
  struct WindowCycle {
    bool desc_valid, out_ready, accepted, unused;  // 4 bytes: size() without a division
  };
  const SpanDesc& slot(uint64_t i) const { return descs_[i % descs_.size()]; }
  // Counts the cycle's mismatch and keeps the first's case; false at opts.max_mismatches.
  bool mismatch(const CycleInputs& c, const SpanOut& exp, uint64_t cycle) {
    const std::string diff = compareSpanOutputs(exp, got_);
    if (diff.empty())
      throw std::logic_error(
          fmt::format("span {}: tickCheck and compareSpanOutputs disagree at cycle {}", res_.mode, cycle));
    ++res_.mismatches;
    if (!res_.first) {
      const uint64_t accepted = res_.triangles;
      res_.first = SpanMismatch{cycle, accepted > 0 ? slot(accepted - 1).tag : 0, diff};
      if (window_lost_) {
        res_.case_note = fmt::format("no failing case saved: the unit was not idle in the {} descriptors or {} cycles "
                                     "before the mismatch (set a drain interval)", kMaxHeld, kMaxWindow);
      } else {
        fail_window_.assign(window_.begin() + static_cast<ptrdiff_t>(window_begin_), window_.end());
        fail_held_.clear();
        for (uint64_t i = held_begin_; i < accepted + (c.taken ? 1 : 0); ++i) fail_held_.push_back(slot(i));
        fail_next_ = slot(accepted);
        fail_saved_ = true;
      }
    }
    return res_.mismatches < opts_.max_mismatches;
  }

  SpanDut& dut_;
  const SpanCosimOptions& opts_;
  const std::vector<SpanDesc>& descs_;
  SpanCosimResult res_;  // triangles: the descriptors accepted before the cycle checked
  const SpanDesc* pending_ = &slot(0);  // slot(res_.triangles)
  SpanOut got_;
  std::vector<WindowCycle> window_;  // from window_begin_ on (the prefix is dropped now and then)
  size_t window_begin_ = 0;
  uint64_t held_begin_ = 0;  // the window's first descriptor
  bool window_lost_ = false;
  std::vector<WindowCycle> fail_window_;
  std::vector<SpanDesc> fail_held_;
  SpanDesc fail_next_;
  bool fail_saved_ = false;
};

// A chunk of cycles packed for the checker's thread: per cycle what SpanDut::tickCheck
// compares, in 64-bit words. A word of the inputs, desc_ready, out_valid, the attributes per
// valid lane and the lanes' valid bits; the tag when out_valid; per valid lane a word of its
// pixel and one per attribute (serial: 7 words on a cycle with a fragment, against 200 bytes
// of SpanOut with its lanes' room for 16 attributes). Each chunk in cache lines of its own:
// chunks side by side in a line put the writer's stores to one (each word appended moves its
// vector's end) under the reader's loads from the one before, and the line's trips between the
// cores slowed both (docs/span-unit.md, "Two threads").
struct alignas(64) CycleChunk {
  std::vector<uint64_t> words;
  uint64_t first_cycle = 0;  // the model's cycles before the chunk's first
  uint32_t cycles = 0;
  bool end = false;  // the stream ended after these cycles
};

void packCycle(const CycleInputs& c, const SpanOut& exp, std::vector<uint64_t>& w) {
  uint64_t mask = 0, nattr = 0;
  for (size_t l = 0; l < exp.lane.size(); ++l)
    if (exp.lane[l].valid) {
      mask |= uint64_t{1} << l;
      nattr = exp.lane[l].attr.size();
    }
  w.push_back(uint64_t{c.desc_valid} | uint64_t{c.out_ready} << 1 | uint64_t{c.idle} << 2 | uint64_t{c.taken} << 3 |
              uint64_t{exp.desc_ready} << 4 | uint64_t{exp.out_valid} << 5 | nattr << 8 | mask << 32);
  if (exp.out_valid) w.push_back(exp.tag);
  for (size_t l = 0; l < exp.lane.size(); ++l) {
    const SpanLaneOut& o = exp.lane[l];
    if (!o.valid) continue;
    if (o.attr.size() != nattr) throw std::logic_error("span co-simulation: lanes with different attribute counts");
    w.push_back(uint64_t{static_cast<uint32_t>(o.x)} | uint64_t{static_cast<uint32_t>(o.y)} << 32);
    for (const int64_t a : o.attr) w.push_back(static_cast<uint64_t>(a));
  }
}

// The cycle packed at w into c and exp (its lanes() lanes; a lane not valid keeps its old
// pixel and attributes, which tickCheck does not read); returns the next cycle's word.
const uint64_t* unpackCycle(const uint64_t* w, CycleInputs& c, SpanOut& exp) {
  const uint64_t h = *w++;
  c.desc_valid = h & 1;
  c.out_ready = h >> 1 & 1;
  c.idle = h >> 2 & 1;
  c.taken = h >> 3 & 1;
  exp.desc_ready = h >> 4 & 1;
  exp.out_valid = h >> 5 & 1;
  const size_t nattr = h >> 8 & 0xff;
  exp.tag = exp.out_valid ? static_cast<uint32_t>(*w++) : 0;
  for (size_t l = 0; l < exp.lane.size(); ++l) {
    SpanLaneOut& o = exp.lane[l];
    o.valid = h >> (32 + l) & 1;
    if (!o.valid) continue;
    o.x = static_cast<int32_t>(static_cast<uint32_t>(*w));
    o.y = static_cast<int32_t>(static_cast<uint32_t>(*w++ >> 32));
    o.attr.resize(nattr);
    for (size_t a = 0; a < nattr; ++a) o.attr[a] = static_cast<int64_t>(*w++);
  }
  return w;
}

// The run on two threads: the stimulus and the model on a thread of their own, up to the ring's
// chunks ahead, and the checker (the verilated unit) on this one. Returns the run's cycles.
uint64_t runTwoThreads(SpanStimulus& stim, SpanChecker& checker, const SpanParams& p) {
  SpscRing<CycleChunk, kChunks, 1> ring;
  std::exception_ptr stim_error;
  std::thread stimulus([&] {
    try {
      CycleInputs c;
      SpanOut exp;
      for (bool more = true; more;) {
        CycleChunk& k = ring.slot();
        k.words.clear();
        // Its lines fetched for writing all at once, before the cycles are packed into them. With
        // this VM's cores far apart (a core-to-core round trip of about 550 ns instead of 120)
        // that made serial's two threads 1.94-2.00x as fast, interleaved, and 0.99-1.02x with
        // them near (docs/span-unit.md, "Two threads").
        prefetchForWrite(k.words.data(), k.words.data() + k.words.capacity());
        k.first_cycle = stim.cycle();
        k.cycles = 0;
        while (k.cycles < kChunkCycles && (more = stim.step(c, exp))) {
          packCycle(c, exp, k.words);
          ++k.cycles;
        }
        k.end = !more;
        ring.push(true);
      }
    } catch (const decltype(ring)::ReaderStopped&) {
      // the checker stopped
    } catch (...) {
      stim_error = std::current_exception();
      ring.abort();
    }
  });
  uint64_t cycles = 0;
  try {
    CycleInputs c;
    SpanOut exp;
    exp.lane.resize(static_cast<size_t>(p.lanes()));
    bool go_on = true;
    while (const CycleChunk* k = ring.next()) {
      const uint64_t* w = k->words.data();
      const uint32_t n = k->cycles;
      for (uint32_t i = 0; i < n && go_on; ++i) {
        w = unpackCycle(w, c, exp);
        cycles = k->first_cycle + i + 1;
        go_on = checker.check(c, exp, cycles);
      }
      const bool end = k->end;
      ring.release();
      if (!go_on) ring.stop();
      if (!go_on || end) break;
    }
  } catch (...) {
    ring.stop(std::current_exception());
    stimulus.join();
    throw;
  }
  stimulus.join();
  if (stim_error) std::rethrow_exception(stim_error);
  return cycles;
}

}  // namespace

SpanCosimResult runSpanCosim(const std::string& mode, const std::function<bool(SpanDesc&)>& next,
                             const SpanCosimOptions& opts) {
  if (opts.threads < 1 || opts.threads > 2)
    throw std::invalid_argument(fmt::format("span co-simulation: {} threads (1 or 2)", opts.threads));
  auto dut = makeSpanDut(mode, "");
  const SpanParams model_params = opts.model_params ? *opts.model_params : dut->params();
  std::vector<SpanDesc> descs(kDescSlots);
  dut->reset();
  SpanStimulus stim(model_params, next, opts, descs);
  SpanChecker checker(*dut, mode, opts, descs);
  const auto t0 = std::chrono::steady_clock::now();
  uint64_t cycles = 0;
  if (opts.threads == 2) {
    cycles = runTwoThreads(stim, checker, model_params);
  } else {
    CycleInputs c;
    SpanOut exp;
    while (stim.step(c, exp) && checker.check(c, exp, stim.cycle())) {
    }
    cycles = stim.cycle();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dut->finish();
  SpanCosimResult res = checker.finish(model_params);
  res.cycles = cycles;
  res.seconds = seconds;
  return res;
}

}  // namespace shd
