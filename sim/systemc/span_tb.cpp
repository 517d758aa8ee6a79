#include "span_tb.h"

#include <ostream>

#include <fmt/format.h>

namespace shd {

using sc_core::sc_time;
using sc_core::sc_time_stamp;

std::ostream& operator<<(std::ostream& os, const DescToken& t) {
  return os << "{descriptor " << (t.desc ? static_cast<int64_t>(t.desc->tag) : -1) << "}";
}

std::ostream& operator<<(std::ostream& os, const SpanExpect& e) {
  return os << "{" << scWhen(e.time) << " desc_ready=" << e.out.desc_ready << " out_valid=" << e.out.out_valid << "}";
}

// ---------------------------------------------------------------- driver

SpanDriver::SpanDriver(const sc_core::sc_module_name& name, std::function<bool(SpanDesc&)> next,
                       const SpanDriverOptions& opt, ScRunControl& ctl)
    : sc_module(name), next_(std::move(next)), rng_(opt.seed), ready_(opt.ready_prob), gap_(opt.desc_gap_prob),
      ctl_(ctl), drain_every_(opt.drain_every) {
  SC_METHOD(onEdge);
  sensitive << clk.pos() << rst_n.pos();
  dont_initialize();
  have_pending_ = fetch();
}

bool SpanDriver::fetch() {
  auto d = std::make_shared<SpanDesc>();
  if (!next_(*d)) return false;
  pending_ = std::move(d);
  wait_ = gap_(rng_) ? 1 + static_cast<int>(rng_() % 3) : 0;
  return true;
}

void SpanDriver::onEdge() {
  if (!rst_n.read()) {
    desc_valid_i.write(false);
    out_ready_i.write(false);
    return;
  }
  out_ready_i.write(ready_(rng_));
  // The handshake of this edge, from the values before it: the RTL took the descriptor.
  if (offering_ && desc_valid_i.read() && desc_ready_o.read()) {
    offering_ = false;
    ++accepted_;
    have_pending_ = fetch();
    draining_ = draining_ || (drain_every_ > 0 && accepted_ % drain_every_ == 0);
  }
  if (offering_) return;  // valid/ready: the descriptor stays on the pins until accepted
  if (draining_ && model_idle.read()) draining_ = false;
  if (draining_) {
    desc_valid_i.write(false);
    return;
  }
  if (have_pending_ && wait_ == 0) {
    pins->driveDesc(*pending_);
    if (!offered.nb_write(DescToken{pending_})) SC_REPORT_FATAL("shadesim/span_driver", "descriptor FIFO full");
    desc_valid_i.write(true);
    offering_ = true;
    ++offered_;
    return;
  }
  desc_valid_i.write(false);
  if (have_pending_) {
    --wait_;
    return;
  }
  // Nothing left to offer: end two cycles after the model went idle (their samples compared).
  if (model_idle.read() && ++idle_edges_ > 2) ctl_.finish();
}

// ---------------------------------------------------------------- vector-file driver

SpanFileDriver::SpanFileDriver(const sc_core::sc_module_name& name, const SpanVectors& v, ScRunControl& ctl)
    : sc_module(name), v_(v), ctl_(ctl) {
  for (const SpanDesc& d : v_.descs) descs_.push_back(std::make_shared<const SpanDesc>(d));
  SC_METHOD(onEdge);
  sensitive << clk.pos() << rst_n.pos();
  dont_initialize();
}

void SpanFileDriver::onEdge() {
  if (!rst_n.read()) {
    desc_valid_i.write(false);
    out_ready_i.write(true);  // the files' reset convention
    return;
  }
  if (next_ >= v_.cycles.size()) {
    desc_valid_i.write(false);
    out_ready_i.write(true);
    if (++tail_ > 2) ctl_.finish();  // the last cycle's sample has been compared
    return;
  }
  const SpanVectorCycle& c = v_.cycles[next_];
  if (c.desc >= 0 && c.desc != on_pins_) {  // a D record: on the ports from this cycle on
    pins->driveDesc(*descs_.at(static_cast<size_t>(c.desc)));
    on_pins_ = c.desc;
  }
  if (c.desc_valid && !offering_) {  // a new offer: the model gets the descriptor
    if (!offered.nb_write(DescToken{descs_.at(static_cast<size_t>(c.desc))}))
      SC_REPORT_FATAL("shadesim/span_file_driver", "descriptor FIFO full");
    offering_ = true;
    ++offered_;
  }
  if (c.desc_valid && c.expected.desc_ready) offering_ = false;  // taken at the edge sampling this cycle
  desc_valid_i.write(c.desc_valid);
  out_ready_i.write(c.out_ready);
  // The file's outputs during this cycle: the sample at the edge that ends it.
  if (!file_expect.nb_write(SpanExpect{sc_time_stamp() + scPeriod(), c.expected, c.out_ready, static_cast<int64_t>(next_)}))
    SC_REPORT_FATAL("shadesim/span_file_driver", "vector-file expectation FIFO full");
  ++next_;
}

// ---------------------------------------------------------------- golden model

void SpanGoldenCore::offer(std::shared_ptr<const SpanDesc> d) {
  if (fault_ == SpanFault::Value && !d->iref.empty()) {
    auto f = std::make_shared<SpanDesc>(*d);
    f->iref[0] += 1;
    d = std::move(f);
  }
  queue_.push_back(std::move(d));
}

void SpanGoldenCore::reset() {
  model_.reset();
  delayed_valid_ = delayed_ready_ = false;
}

const SpanOut& SpanGoldenCore::tick(bool valid, bool ready) {
  if (fault_ == SpanFault::Latency) {
    std::swap(valid, delayed_valid_);
    std::swap(ready, delayed_ready_);
  }
  SpanIn in;
  // desc_valid with no descriptor left for the model happens only after the model took one the
  // RTL did not (the scoreboard has reported that desc_ready mismatch already): the model then
  // sees no offer.
  in.desc_valid = valid && !queue_.empty();
  in.desc = in.desc_valid ? queue_.front().get() : nullptr;
  in.out_ready = ready;
  ready_taken_ = ready;
  model_.tick(in, out_);  // the outputs before this edge: the sample at this edge
  if (in.desc_valid && out_.desc_ready) {
    queue_.pop_front();
    ++accepted_;
  }
  return out_;
}

void spanGoldenReplay(SpanVectors& v, SpanParams model_params, SpanFault fault) {
  SpanGoldenCore core(model_params, fault);
  core.reset();
  std::vector<std::shared_ptr<const SpanDesc>> descs;
  for (const SpanDesc& d : v.descs) descs.push_back(std::make_shared<const SpanDesc>(d));
  bool offering = false;
  for (SpanVectorCycle& c : v.cycles) {
    if (c.desc_valid && !offering && c.desc >= 0) {  // a new offer (as SpanFileDriver makes it)
      core.offer(descs.at(static_cast<size_t>(c.desc)));
      offering = true;
    }
    c.expected = core.tick(c.desc_valid, c.out_ready);
    if (c.desc_valid && c.expected.desc_ready) offering = false;
  }
}

SpanGolden::SpanGolden(const sc_core::sc_module_name& name, SpanParams p, SpanFault fault, bool record, bool capture)
    : sc_module(name), core_(p, fault), record_(record), capture_(capture) {
  SC_METHOD(onEdge);
  sensitive << clk.pos();
  dont_initialize();
}

SpanVectors SpanGolden::recorded() const {
  SpanVectors v;
  v.params = core_.model().params();
  v.descs = rec_descs_;
  v.cycles = rec_cycles_;
  return v;
}

SpanVectors SpanGolden::capturedCase(const sc_time& last_edge, uint64_t& first_cycle, bool& from_idle) const {
  SpanVectors v;
  v.params = core_.model().params();
  const SpanDesc* last = nullptr;
  first_cycle = cap_.empty() ? 0 : cap_.front().cycle;
  from_idle = cap_from_idle_;
  for (const Captured& e : cap_) {
    if (e.edge > last_edge) break;
    if (e.on_ports && e.on_ports.get() != last) {  // a D record: on the ports from this cycle on
      v.descs.push_back(*e.on_ports);
      last = e.on_ports.get();
    }
    SpanVectorCycle c;
    c.desc_valid = e.desc_valid;
    c.out_ready = e.out_ready;
    c.desc = static_cast<int>(v.descs.size()) - 1;
    v.cycles.push_back(std::move(c));
  }
  return v;
}

void SpanGolden::onEdge() {
  DescToken t;
  while (offered.nb_read(t)) {
    if (record_) rec_descs_.push_back(*t.desc);  // on the ports from this cycle on
    if (capture_) on_ports_ = t.desc;
    core_.offer(t.desc);
  }
  if (!rst_n.read()) {
    core_.reset();
    model_idle.write(true);
    return;
  }
  const bool pin_valid = desc_valid_i.read(), pin_ready = out_ready_i.read();
  const bool was_idle = core_.idle();
  const SpanOut& out = core_.tick(pin_valid, pin_ready);
  if (!expect.nb_write(SpanExpect{sc_time_stamp(), out, core_.readyTaken(), -1}))
    SC_REPORT_FATAL("shadesim/span_golden", "expectation FIFO full");
  ++active_edges_;
  if (capture_) {
    if (idle_at_ >= 0) {  // the model was idle before the previous edge: start there
      cap_.erase(cap_.begin(), cap_.begin() + idle_at_);
      cap_from_idle_ = true;
      idle_at_ = -1;
    }
    cap_.push_back(Captured{sc_time_stamp(), active_edges_, pin_valid, pin_ready, on_ports_});
    // From an idle state the inputs from this cycle on reproduce the unit's (the paper's unit is
    // idle in the cycle that accepts each triangle).
    if (was_idle) idle_at_ = static_cast<int64_t>(cap_.size()) - 1;
  }
  if (record_) {
    SpanVectorCycle c;
    c.desc_valid = pin_valid;
    c.out_ready = pin_ready;
    c.desc = static_cast<int>(rec_descs_.size()) - 1;
    c.expected = out;
    rec_cycles_.push_back(std::move(c));
  }
  model_idle.write(core_.idle());
}

// ---------------------------------------------------------------- scoreboard

namespace {

// The first difference between two samples, or "" (the data of a lane only where it is valid,
// the tag only while out_valid: the RTL drives them from registers that mean nothing otherwise).
std::string firstDifference(const SpanOut& exp, const SpanOut& got, const char* who) {
  if (exp.desc_ready != got.desc_ready)
    return fmt::format("desc_ready_o: {} {}, rtl {}", who, exp.desc_ready, got.desc_ready);
  if (exp.out_valid != got.out_valid) return fmt::format("out_valid_o: {} {}, rtl {}", who, exp.out_valid, got.out_valid);
  if (exp.out_valid && exp.tag != got.tag) return fmt::format("out_tag_o: {} {}, rtl {}", who, exp.tag, got.tag);
  if (exp.lane.size() != got.lane.size())
    return fmt::format("lane count: {} {}, rtl {}", who, exp.lane.size(), got.lane.size());
  for (size_t l = 0; l < exp.lane.size(); ++l) {
    const SpanLaneOut &e = exp.lane[l], &g = got.lane[l];
    if (e.valid != g.valid) return fmt::format("out_lane_valid_o[{}]: {} {}, rtl {}", l, who, e.valid, g.valid);
    if (!e.valid) continue;
    if (e.x != g.x || e.y != g.y)
      return fmt::format("out_x_o/out_y_o lane {}: {} ({}, {}), rtl ({}, {})", l, who, e.x, e.y, g.x, g.y);
    for (size_t a = 0; a < e.attr.size(); ++a)
      if (e.attr[a] != g.attr[a])
        return fmt::format("out_attr_o lane {} attribute {} at pixel ({}, {}): {} {}, rtl {}", l, a, e.x, e.y, who,
                           e.attr[a], g.attr[a]);
  }
  return "";
}

}  // namespace

SpanScoreboard::SpanScoreboard(const sc_core::sc_module_name& name, ScRunControl& ctl) : sc_module(name), ctl_(ctl) {
  SC_METHOD(sample);
  sensitive << clk.pos();
  dont_initialize();
  SC_METHOD(compare);
  sensitive << clk.neg();
  dont_initialize();
}

void SpanScoreboard::sample() {
  if (!rst_n.read()) return;
  Sample s;
  s.time = sc_time_stamp();
  rtl->sampleOutputs(s.out);  // the values before this edge
  s.out_ready = out_ready_i.read();
  samples_.push_back(std::move(s));
}

void SpanScoreboard::handedOver(const sc_time& t, const SpanOut& o, bool ready, std::deque<Fragment>& q, uint64_t& n) {
  if (!o.out_valid || !ready) return;
  for (size_t l = 0; l < o.lane.size(); ++l)
    if (o.lane[l].valid) {
      q.push_back(Fragment{t, o.tag, l, o.lane[l]});
      ++n;
    }
}

std::string SpanScoreboard::show(const Fragment& f) {
  return fmt::format("triangle {} lane {} pixel ({}, {}) attributes ({}) at {}", f.tag, f.lane, f.px.x, f.px.y,
                     fmt::join(f.px.attr, ", "), scWhen(f.time));
}

void SpanScoreboard::pairFragments() {
  while (!exp_frags_.empty() && !got_frags_.empty()) {
    const Fragment e = std::move(exp_frags_.front()), g = std::move(got_frags_.front());
    exp_frags_.pop_front();
    got_frags_.pop_front();
    const uint64_t n = s_.matched_items + s_.item_mismatches;
    if (e.time == g.time && e.tag == g.tag && e.lane == g.lane && e.px.x == g.px.x && e.px.y == g.px.y &&
        e.px.attr == g.px.attr) {
      ++s_.matched_items;
      continue;
    }
    ++s_.item_mismatches;
    if (s_.first_item.empty()) s_.first_item = fmt::format("fragment #{}: model {}; rtl {}", n, show(e), show(g));
  }
}

void SpanScoreboard::check(const Sample& got, const SpanExpect& exp, const char* who) {
  const std::string diff = firstDifference(exp.out, got.out, who);
  if (diff.empty()) return;
  ++s_.sample_mismatches;
  const bool from_file = exp.cycle >= 0;
  if (from_file && s_.first_file_cycle < 0) s_.first_file_cycle = exp.cycle;
  if (s_.firstSample(got.time, fmt::format("at {}{}: {} (the current triangle: {})", scWhen(got.time),
                                           from_file ? fmt::format(", vector file cycle {}", exp.cycle + 1) : std::string(),
                                           diff, exp.out.tag)) &&
      on_first_mismatch)
    on_first_mismatch(got.time, exp.out, from_file);
}

void SpanScoreboard::compare() {
  SpanExpect x;
  while (expect.nb_read(x)) expected_.push_back(std::move(x));
  while (file_expect.nb_read(x)) file_expected_.push_back(std::move(x));
  while (!samples_.empty()) {
    Sample got = std::move(samples_.front());
    samples_.pop_front();
    ++s_.samples;
    if (expected_.empty() || expected_.front().time != got.time) {
      ++s_.sample_mismatches;  // a testbench error, reported so that it cannot pass unnoticed
      s_.firstSample(got.time, fmt::format("at {}: no prediction of the golden model for this sample (next one at {})",
                                           scWhen(got.time),
                                           expected_.empty() ? std::string("none") : scWhen(expected_.front().time)));
    } else {
      const SpanExpect exp = std::move(expected_.front());
      expected_.pop_front();
      check(got, exp, "model");
      handedOver(exp.time, exp.out, exp.out_ready, exp_frags_, s_.expected_items);
    }
    if (!file_expected_.empty() && file_expected_.front().time < got.time) {
      ++s_.sample_mismatches;  // every file cycle falls on an active cycle: a testbench error
      s_.firstSample(got.time, fmt::format("at {}: the vector file's expectation for {} was never compared",
                                           scWhen(got.time), scWhen(file_expected_.front().time)));
      file_expected_.pop_front();
    }
    if (!file_expected_.empty() && file_expected_.front().time == got.time) {
      check(got, file_expected_.front(), "vector file");
      file_expected_.pop_front();
      ++file_checks_;
    }
    handedOver(got.time, got.out, got.out_ready, got_frags_, s_.observed_items);
    pairFragments();
  }
  if (s_.mismatches() >= ctl_.max_mismatches) ctl_.finish();
}

void SpanScoreboard::finish() {
  for (const Fragment& f : exp_frags_) {
    ++s_.item_mismatches;
    if (s_.first_item.empty()) s_.first_item = fmt::format("the model predicts {}, the RTL never delivered it", show(f));
  }
  for (const Fragment& f : got_frags_) {
    ++s_.item_mismatches;
    if (s_.first_item.empty()) s_.first_item = fmt::format("the RTL delivered {}, the model does not predict it", show(f));
  }
  exp_frags_.clear();
  got_frags_.clear();
}

}  // namespace shd
