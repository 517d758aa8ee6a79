#include "spec_tb.h"

#include <cmath>
#include <ostream>

#include <fmt/format.h>

namespace shd {

using sc_core::sc_time;
using sc_core::sc_time_stamp;

std::ostream& operator<<(std::ostream& os, const SpecExpect& e) {
  return os << "{" << scWhen(e.time) << " valid=" << e.out.valid << " spec=" << e.out.spec << "}";
}

// ---------------------------------------------------------------- sources

FileSpecSource::FileSpecSource(const SpecVectors& v) : v_(v) {
  for (const SpecIn& in : v_.in) valid_ += in.valid ? 1 : 0;
}

bool FileSpecSource::next(SpecIn& in) {
  if (next_ >= v_.in.size()) return false;
  in = v_.in[next_++];
  return true;
}

std::optional<SpecOut> FileSpecSource::expected() const {
  if (next_ == 0 || next_ > v_.expected.size()) return std::nullopt;
  return v_.expected[next_ - 1];
}

// ---------------------------------------------------------------- driver

SpecDriver::SpecDriver(const sc_core::sc_module_name& name, SpecSource& src, int drain_cycles, ScRunControl& ctl)
    : sc_module(name), src_(src), file_(dynamic_cast<FileSpecSource*>(&src)), drain_left_(drain_cycles), ctl_(ctl) {
  SC_METHOD(onEdge);
  sensitive << clk.pos() << rst_n.pos();
  dont_initialize();
}

void SpecDriver::drive(const SpecIn& in) {
  valid_i.write(in.valid);
  shin_i.write(in.shin);
  cos_i.write(in.cos);
  light_r_i.write(in.light[0]);
  light_g_i.write(in.light[1]);
  light_b_i.write(in.light[2]);
}

void SpecDriver::onEdge() {
  if (!rst_n.read()) {
    drive(SpecIn{});
    return;
  }
  if (!src_done_) {
    SpecIn in;
    if (src_.next(in)) {
      drive(in);  // sampled by the unit at the next rising edge
      if (in.valid) ++driven_;
      if (const std::optional<SpecOut> e = src_.expected()) {
        // The file's outputs after the edge that samples this line: the sample one cycle later.
        const sc_time sampled = sc_time_stamp() + scPeriod();
        SpecExpect x{sampled + scPeriod(), *e, std::nullopt, sampled, -1};
        if (in.valid) x.src = in;
        if (file_) x.cycle = static_cast<int64_t>(file_->cycle());
        if (!file_expect.nb_write(x)) SC_REPORT_FATAL("shadesim/spec_driver", "vector-file expectation FIFO full");
      }
      return;
    }
    src_done_ = true;
  }
  drive(SpecIn{});
  if (drain_left_-- <= 0) ctl_.finish();
}

// ---------------------------------------------------------------- golden model

SpecGolden::SpecGolden(const sc_core::sc_module_name& name, SpecUnitModel& model, SpecFault fault, bool record,
                       size_t capture)
    : sc_module(name), model_(model), fault_(fault), record_(record), capture_(capture) {
  SC_METHOD(onEdge);
  sensitive << clk.pos();
  dont_initialize();
}

void SpecGolden::put(const SpecExpect& e) {
  if (!expect.nb_write(e)) SC_REPORT_FATAL("shadesim/spec_golden", "expectation FIFO full");
}

void SpecGolden::onEdge() {
  if (!rst_n.read()) {
    model_.reset();
    started_ = false;
    history_.clear();
    delayed_ = SpecIn{};
    return;
  }
  const sc_time now = sc_time_stamp();
  SpecIn in;
  in.valid = valid_i.read();
  in.shin = shin_i.read();
  in.cos = cos_i.read();
  in.light = {light_r_i.read(), light_g_i.read(), light_b_i.read()};
  ++active_edges_;
  if (capture_ > 0) {
    cap_.push_back(Captured{now, active_edges_, in});
    if (cap_.size() > capture_ + 1) cap_.pop_front();
  }
  sc_time in_time = now;
  if (fault_ == SpecFault::Latency) {
    std::swap(in, delayed_);
    std::swap(in_time, delayed_time_);
  }
  if (!started_) {
    // The sample at the first active edge shows the state reset left: rtl/shd_spec_unit.v resets
    // valid_q, spec_q and rgb_q to 0, SpecUnitModel::reset() its outputs to SpecOut{}.
    started_ = true;
    put(SpecExpect{now, SpecOut{}, std::nullopt, sc_time(), -1});
  }
  const size_t latency = static_cast<size_t>(model_.params().latency());
  history_.emplace_back(in_time, in);
  if (history_.size() > latency) history_.pop_front();
  const SpecOut o = model_.tick(in);  // the outputs after this edge: the sample at now + 1 cycle
  SpecExpect e{now + scPeriod(), o, std::nullopt, sc_time(), -1};
  if (o.valid && history_.size() == latency && history_.front().second.valid) {
    e.src = history_.front().second;  // sampled latency - 1 edges ago
    e.src_time = history_.front().first;
  }
  put(e);
  if (record_) {
    rec_in_.push_back(SpecIn{valid_i.read(), shin_i.read(), cos_i.read(),
                             {light_r_i.read(), light_g_i.read(), light_b_i.read()}});
    rec_out_.push_back(o);
  }
}

std::vector<SpecIn> SpecGolden::capturedWindow(const sc_time& last_edge, uint64_t& first_cycle) const {
  std::vector<SpecIn> w;
  size_t end = cap_.size();
  while (end > 0 && cap_[end - 1].edge > last_edge) --end;
  const size_t begin = end > capture_ ? end - capture_ : 0;
  for (size_t i = begin; i < end; ++i) w.push_back(cap_[i].in);
  first_cycle = begin < end ? cap_[begin].cycle : 0;
  return w;
}

std::vector<SpecOut> specGoldenReplay(const SpecUnitModel& model, SpecFault fault, const std::vector<SpecIn>& in) {
  SpecUnitModel m(model.params(), model.prom(), model.segRom());
  m.reset();
  SpecIn delayed;  // the Latency fault's register, reset to no input as in SpecGolden
  std::vector<SpecOut> out;
  out.reserve(in.size());
  for (SpecIn x : in) {
    if (fault == SpecFault::Latency) std::swap(x, delayed);
    out.push_back(m.tick(x));
  }
  return out;
}

// ---------------------------------------------------------------- scoreboard

SpecScoreboard::SpecScoreboard(const sc_core::sc_module_name& name, const SpecUnitParams& p, ScRunControl& ctl)
    : sc_module(name), p_(p), ctl_(ctl) {
  SC_METHOD(sample);
  sensitive << clk.pos();
  dont_initialize();
  SC_METHOD(compare);
  sensitive << clk.neg();
  dont_initialize();
}

void SpecScoreboard::sample() {
  if (!rst_n.read()) return;
  // The values before this edge: the outputs of the cycle that ends here.
  Sample s{sc_time_stamp(), {}};
  s.out.valid = valid_o.read();
  s.out.spec = spec_o.read();
  s.out.rgb = {spec_r_o.read(), spec_g_o.read(), spec_b_o.read()};
  samples_.push_back(s);
}

std::string SpecScoreboard::describe(const SpecExpect& e) const {
  if (!e.src) return "";
  const SpecIn& in = *e.src;
  return fmt::format("; the result of shin={} cos={:#x} ({:.9f}) light=({}, {}, {}) sampled at {}", in.shin, in.cos,
                     std::ldexp(static_cast<double>(in.cos), -p_.CosFracBits), in.light[0], in.light[1], in.light[2],
                     scWhen(e.src_time));
}

void SpecScoreboard::check(const Sample& got, const SpecExpect& exp, const char* who) {
  const SpecOut &e = exp.out, &g = got.out;
  static const char* const kRgb[] = {"spec_r_o", "spec_g_o", "spec_b_o"};
  std::string diff;
  if (e.valid != g.valid) diff = fmt::format("valid_o: {} {}, rtl {}", who, e.valid ? 1 : 0, g.valid ? 1 : 0);
  else if (e.spec != g.spec) diff = fmt::format("spec_o: {} {:#x}, rtl {:#x}", who, e.spec, g.spec);
  else
    for (size_t k = 0; k < 3 && diff.empty(); ++k)
      if (e.rgb[k] != g.rgb[k]) diff = fmt::format("{}: {} {}, rtl {}", kRgb[k], who, e.rgb[k], g.rgb[k]);
  if (diff.empty()) return;
  ++s_.sample_mismatches;
  const bool from_file = exp.cycle >= 0;
  if (from_file && s_.first_file_cycle < 0) s_.first_file_cycle = exp.cycle;
  if (s_.firstSample(got.time, fmt::format("at {}{}: {}{}", scWhen(got.time),
                                           from_file ? fmt::format(", vector file cycle {}", exp.cycle + 1) : std::string(),
                                           diff, describe(exp))) &&
      on_first_mismatch)
    on_first_mismatch(got.time, exp.out, from_file);
}

void SpecScoreboard::pairResults() {
  auto show = [](const SpecOut& o) { return fmt::format("spec={:#x} rgb=({}, {}, {})", o.spec, o.rgb[0], o.rgb[1], o.rgb[2]); };
  while (!exp_results_.empty() && !got_results_.empty()) {
    const SpecExpect e = exp_results_.front();
    const Sample g = got_results_.front();
    exp_results_.pop_front();
    got_results_.pop_front();
    const uint64_t n = s_.matched_items + s_.item_mismatches;
    if (e.time == g.time && e.out == g.out) {
      ++s_.matched_items;
      continue;
    }
    ++s_.item_mismatches;
    if (s_.first_item.empty())
      s_.first_item = fmt::format("result #{}: model {} at {}, rtl {} at {}{}", n, show(e.out), scWhen(e.time), show(g.out),
                                  scWhen(g.time), describe(e));
  }
}

void SpecScoreboard::compare() {
  SpecExpect x;
  while (expect.nb_read(x)) expected_.push_back(x);
  while (file_expect.nb_read(x)) file_expected_.push_back(x);
  while (!samples_.empty()) {
    const Sample got = samples_.front();
    samples_.pop_front();
    ++s_.samples;
    if (expected_.empty() || expected_.front().time != got.time) {
      // The golden module predicts every active cycle; a gap is a testbench error, reported as a
      // mismatch so that it cannot pass unnoticed.
      ++s_.sample_mismatches;
      s_.firstSample(got.time, fmt::format("at {}: no prediction of the golden model for this sample (next one at {})",
                                           scWhen(got.time),
                                           expected_.empty() ? std::string("none") : scWhen(expected_.front().time)));
    } else {
      const SpecExpect exp = expected_.front();
      expected_.pop_front();
      check(got, exp, "model");
      if (exp.out.valid) {
        exp_results_.push_back(exp);
        ++s_.expected_items;
      }
    }
    if (!file_expected_.empty() && file_expected_.front().time < got.time) {
      // Every file expectation falls on an active cycle; one left behind is a testbench error.
      ++s_.sample_mismatches;
      s_.firstSample(got.time, fmt::format("at {}: the vector file's expectation for {} was never compared",
                                           scWhen(got.time), scWhen(file_expected_.front().time)));
      file_expected_.pop_front();
    }
    if (!file_expected_.empty() && file_expected_.front().time == got.time) {
      check(got, file_expected_.front(), "vector file");
      file_expected_.pop_front();
      ++file_checks_;
    }
    if (got.out.valid) {
      got_results_.push_back(got);
      ++s_.observed_items;
    }
    pairResults();
  }
  if (s_.mismatches() >= ctl_.max_mismatches) ctl_.finish();
}

void SpecScoreboard::finish() {
  auto unpaired = [&](const std::string& what) {
    ++s_.item_mismatches;
    if (s_.first_item.empty()) s_.first_item = what;
  };
  for (const SpecExpect& e : exp_results_)
    unpaired(fmt::format("the model predicts a result at {} (spec={:#x}) that the RTL never delivered{}", scWhen(e.time),
                         e.out.spec, describe(e)));
  for (const Sample& g : got_results_)
    unpaired(fmt::format("the RTL delivered a result at {} (spec={:#x}) the model does not predict", scWhen(g.time),
                         g.out.spec));
  exp_results_.clear();
  got_results_.clear();
}

}  // namespace shd
