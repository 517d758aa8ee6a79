#include "cosim/span_cosim.h"

#include <array>
#include <chrono>
#include <filesystem>
#include <random>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "device/prom_io.h"
#include "io/files.h"

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

SpanCosimResult runSpanCosim(const std::string& mode, const std::function<bool(SpanDesc&)>& next,
                             const SpanCosimOptions& opts) {
  SpanCosimResult res;
  res.mode = mode;
  auto dut = makeSpanDut(mode, "");
  const SpanParams model_params = opts.model_params ? *opts.model_params : dut->params();
  SpanUnitModel model(model_params);
  std::mt19937_64 rng(opts.seed);
  const ReadyDraw ready(opts.ready_prob);
  std::bernoulli_distribution gap(opts.desc_gap_prob);

  dut->reset();
  model.reset();
  // The failing case is the run's inputs from the last cycle that began with the unit idle,
  // with the descriptors accepted since (`held`): from reset they reproduce the unit's state.
  // The paper's unit is idle when it accepts each descriptor; the full-rate unit, which takes
  // the next one while it works, is idle only where the stream lets it drain (opts.drain_every).
  // Past kMaxHeld descriptors or kMaxWindow cycles without an idle cycle the window is dropped
  // (a failure there is reported without a saved case).
  constexpr size_t kMaxHeld = 64, kMaxWindow = size_t{1} << 20;
  struct WindowCycle {
    bool desc_valid, out_ready, accepted, unused;  // 4 bytes: size() without a division
  };
  std::vector<WindowCycle> window;  // from window_begin on (the prefix is dropped now and then)
  size_t window_begin = 0;
  bool window_lost = false;
  // The descriptors in a ring, read into place (no copy per triangle): accepted ones from
  // held_begin to accepted (the window's), then the pending one.
  std::vector<SpanDesc> ring(kMaxHeld + 2);
  uint64_t held_begin = 0, accepted = 0;
  auto slot = [&](uint64_t i) -> SpanDesc& { return ring[i % ring.size()]; };
  SpanDesc* pending = &slot(0);
  bool have_pending = next(*pending);
  int wait = have_pending && gap(rng) ? 1 + static_cast<int>(rng() % 3) : 0;
  uint64_t since_drain = 0;
  bool draining = false;  // desc_valid held low until the unit is idle
  SpanOut exp, got;
  std::vector<WindowCycle> fail_window;
  std::vector<SpanDesc> fail_held;
  SpanDesc fail_next;
  bool fail_saved = false;
  const auto t0 = std::chrono::steady_clock::now();
  for (;;) {
    bool idle = false;  // before this cycle's edge
    if (model.idle()) {
      if (!have_pending) break;
      idle = true;
      draining = false;
    }
    SpanIn in;
    in.out_ready = ready(rng);
    in.desc_valid = have_pending && wait == 0 && !draining;
    in.desc = pending;
    if (wait > 0) --wait;
    model.tick(in, exp);
    // The comparison is done on the ports (SpanDut::tickCheck, equal to compareSpanOutputs);
    // the RTL's outputs are read out for the message only when they differ.
    const bool same = dut->tickCheck(in, exp, got);
    const bool taken = in.desc_valid && exp.desc_ready;
    window.push_back({in.desc_valid, in.out_ready, taken, false});
    if (exp.out_valid && in.out_ready)
      for (const SpanLaneOut& l : exp.lane) res.fragments += l.valid ? 1 : 0;
    if (!same) {
      const std::string diff = compareSpanOutputs(exp, got);
      if (diff.empty())
        throw std::logic_error(fmt::format("span {}: tickCheck and compareSpanOutputs disagree at cycle {}", mode,
                                           model.cycle()));
      ++res.mismatches;
      if (!res.first) {
        res.first = SpanMismatch{model.cycle(), accepted > 0 ? slot(accepted - 1).tag : 0, diff};
        if (window_lost) {
          res.case_note = fmt::format("no failing case saved: the unit was not idle in the {} descriptors or {} cycles "
                                      "before the mismatch (set a drain interval)", kMaxHeld, kMaxWindow);
        } else {
          fail_window.assign(window.begin() + static_cast<ptrdiff_t>(window_begin), window.end());
          fail_held.clear();
          for (uint64_t i = held_begin; i < accepted + (taken ? 1 : 0); ++i) fail_held.push_back(slot(i));
          fail_next = *pending;
          fail_saved = true;
        }
      }
      if (res.mismatches >= opts.max_mismatches) break;
    }
    // The window starts again at an idle cycle, after its comparison: a mismatch in that cycle
    // keeps the cycles before it, which may be what the RTL still shows.
    if (idle) {
      window_begin = window.size() - 1;
      held_begin = accepted;  // this cycle's descriptor, if it takes one, is the window's first
      window_lost = false;
      if (window_begin >= 4096) {  // drop the prefix now and then, not at every idle cycle
        window.erase(window.begin(), window.begin() + static_cast<ptrdiff_t>(window_begin));
        window_begin = 0;
      }
    }
    if (window.size() - window_begin > kMaxWindow || (taken && accepted + 1 - held_begin > kMaxHeld)) {
      window_lost = true;  // until the unit is idle again
      window.clear();
      window_begin = 0;
    }
    if (taken) {
      pending = &slot(++accepted);
      ++res.triangles;
      if (opts.progress && (res.triangles & 4095) == 0) opts.progress(res.triangles);
      have_pending = next(*pending);
      wait = have_pending && gap(rng) ? 1 + static_cast<int>(rng() % 3) : 0;
      if (opts.drain_every > 0 && ++since_drain == opts.drain_every) {
        since_drain = 0;
        draining = true;
      }
    }
  }
  res.cycles = model.cycle();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dut->finish();
  if (fail_saved) saveSpanFailingCase(mode, model_params, *res.first, fail_window, fail_held, fail_next, opts, res);
  return res;
}

}  // namespace shd
