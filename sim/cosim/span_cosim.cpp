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
          {"iref", d.iref}, {"didx", d.didx},           {"didy", d.didy},         {"tri", tris}};
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
  // The accepted descriptor and the pending one, in two buffers that swap roles on accepting
  // (no copy per triangle).
  std::array<SpanDesc, 2> desc_buf;
  SpanDesc* cur = &desc_buf[0];
  SpanDesc* pending = &desc_buf[1];
  bool have_cur = false;  // a descriptor has been accepted
  bool have_pending = next(*pending);
  int wait = have_pending && gap(rng) ? 1 + static_cast<int>(rng() % 3) : 0;
  // The inputs (desc_valid, out_ready) from the cycle that accepted `cur` (from reset before
  // the first one) to now: with `cur` and `pending` they reproduce the unit's state, because
  // the unit loads every register it uses when it accepts a descriptor.
  std::vector<std::pair<bool, bool>> window;
  SpanOut exp, got;
  bool failed_triangle_saved = false;
  SpanDesc fail_desc, fail_next;
  bool fail_has_cur = false;
  std::vector<std::pair<bool, bool>> fail_window;
  const auto t0 = std::chrono::steady_clock::now();
  while (have_pending || !model.idle()) {
    SpanIn in;
    in.out_ready = ready(rng);
    in.desc_valid = have_pending && wait == 0;
    in.desc = pending;
    if (wait > 0) --wait;
    model.tick(in, exp);
    // The comparison is done on the ports (SpanDut::tickCheck, equal to compareSpanOutputs);
    // the RTL's outputs are read out for the message only when they differ.
    const bool same = dut->tickCheck(in, exp, got);
    window.emplace_back(in.desc_valid, in.out_ready);
    if (exp.out_valid && in.out_ready)
      for (const SpanLaneOut& l : exp.lane) res.fragments += l.valid ? 1 : 0;
    if (!same) {
      const std::string diff = compareSpanOutputs(exp, got);
      if (diff.empty())
        throw std::logic_error(fmt::format("span {}: tickCheck and compareSpanOutputs disagree at cycle {}", mode,
                                           model.cycle()));
      ++res.mismatches;
      if (!res.first) {
        res.first = SpanMismatch{model.cycle(), cur->tag, diff};
        fail_desc = *cur;
        fail_has_cur = have_cur;
        fail_next = *pending;
        fail_window = window;
        failed_triangle_saved = true;
      }
      if (res.mismatches >= opts.max_mismatches) break;
    }
    if (in.desc_valid && exp.desc_ready) {  // accepted at this edge
      std::swap(cur, pending);
      have_cur = true;
      window.assign(1, {true, in.out_ready});
      ++res.triangles;
      if (opts.progress && (res.triangles & 4095) == 0) opts.progress(res.triangles);
      have_pending = next(*pending);
      wait = have_pending && gap(rng) ? 1 + static_cast<int>(rng() % 3) : 0;
    }
  }
  res.cycles = model.cycle();
  res.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  dut->finish();

  if (failed_triangle_saved) {
    // The failing triangle alone: from reset, the cycle that accepted it, then the run's inputs
    // up to the failing cycle (the next descriptor too if it was offered meanwhile), into a
    // traced instance (FST) and, with the model's expected outputs, a vector file that
    // `shadesim replay` and the Icarus testbench replay.
    std::filesystem::create_directories(opts.fail_dir);
    res.fst_path = fmt::format("{}/span_{}_fail.fst", opts.fail_dir, mode);
    res.case_path = fmt::format("{}/span_{}_fail.json", opts.fail_dir, mode);
    res.vector_path = fmt::format("{}/span_{}_fail.vec", opts.fail_dir, mode);
    SpanVectors v;
    v.config = mode;
    v.params = dut->params();
    v.source = fmt::format("shadesim cosim: the failing triangle (tag {}), cycles {}..{} of the run, replayed from reset",
                           fail_desc.tag, res.first->cycle + 1 - fail_window.size(), res.first->cycle);
    if (fail_has_cur) v.descs.push_back(fail_desc);
    bool next_on_ports = false;
    for (size_t i = 0; i < fail_window.size(); ++i) {
      SpanVectorCycle c;
      c.desc_valid = fail_window[i].first;
      c.out_ready = fail_window[i].second;
      if (c.desc_valid && !(fail_has_cur && i == 0) && !next_on_ports) {
        v.descs.push_back(fail_next);
        next_on_ports = true;
      }
      c.desc = static_cast<int>(v.descs.size()) - 1;
      v.cycles.push_back(std::move(c));
    }
    auto traced = makeSpanDut(mode, res.fst_path);
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
    for (size_t i = fail_has_cur ? 1 : 0; i < fail_window.size(); ++i) ready_after_accept.push_back(fail_window[i].second);
    nlohmann::json j = {{"mode", mode},
                        {"mismatch", {{"cycle", res.first->cycle}, {"what", res.first->what}}},
                        {"descriptor", toJson(fail_desc)},
                        {"out_ready_after_accept", ready_after_accept},
                        {"vectors", res.vector_path}};
    writeFileAtomic(res.case_path, j.dump(1) + "\n");
  }
  return res;
}

}  // namespace shd
