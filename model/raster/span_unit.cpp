#include "raster/span_unit.h"
#include "raster/span_walk.h"

#include <algorithm>
#include <array>
#include <stdexcept>

#include <fmt/format.h>

#include "config/params_json.h"

namespace shd {

using namespace span_detail;

void SpanParams::validate() const {
  auto need = [](bool ok, const char* name, int v, const char* rule) {
    if (!ok) throw std::invalid_argument(fmt::format("span parameter {} = {}: {}", name, v, rule));
  };
  need(NumTri == 1 || NumTri == 4, "NumTri", NumTri, "must be 1 or 4");
  need(LanesPerTri == 1 || LanesPerTri == 2 || LanesPerTri == 4 || LanesPerTri == 8, "LanesPerTri", LanesPerTri,
       "must be 1, 2, 4 or 8");
  need(AlignLanes == 0 || AlignLanes == 1, "AlignLanes", AlignLanes, "must be 0 or 1");
  need(NumAttr >= 1 && NumAttr <= static_cast<int>(kMaxAttr), "NumAttr", NumAttr, "must be in 1..16");
  need(AttrBits >= 8 && AttrBits <= 62, "AttrBits", AttrBits, "must be in 8..62");
  need(CoordBits >= 8 && CoordBits <= 30, "CoordBits", CoordBits, "must be in 8..30");
  need(RemBits >= 2 && RemBits <= 60, "RemBits", RemBits, "must be in 2..60");
  need(PixBits >= 1 && PixBits < CoordBits, "PixBits", PixBits, "must be in 1..CoordBits-1");
  need(TagBits >= 1 && TagBits <= 32, "TagBits", TagBits, "must be in 1..32");
  need(RowAhead == 0 || RowAhead == 1, "RowAhead", RowAhead, "must be 0 or 1");
  need(Interleave == 0 || (Interleave == 1 && NumTri == 4), "Interleave", Interleave,
       "must be 0, or 1 with NumTri 4 (rows interleaved over the four lane-triangles)");
}

namespace {

// In the vector files' order (sim/vectors/vector_file.h).
constexpr ParamMember<SpanParams> kSpanMembers[] = {
    {"NumTri", &SpanParams::NumTri},         {"LanesPerTri", &SpanParams::LanesPerTri},
    {"AlignLanes", &SpanParams::AlignLanes}, {"NumAttr", &SpanParams::NumAttr},
    {"AttrBits", &SpanParams::AttrBits},     {"CoordBits", &SpanParams::CoordBits},
    {"RemBits", &SpanParams::RemBits},       {"PixBits", &SpanParams::PixBits},
    {"TagBits", &SpanParams::TagBits},       {"RowAhead", &SpanParams::RowAhead, true},
    {"Interleave", &SpanParams::Interleave, true}};

}  // namespace

SpanParams SpanParams::fromJson(const nlohmann::json& rtl, const std::string& where) {
  return paramsFromJson(rtl, kSpanMembers, true, where);
}

nlohmann::json SpanParams::toJson() const { return paramsToJson(*this, kSpanMembers); }

SpanUnitModel::SpanUnitModel(SpanParams p) : p_(p) {
  p_.validate();
  reset();
}

int64_t SpanUnitModel::wrapAttr(uint64_t v) const { return wrapTo(v, p_.AttrBits); }
int64_t SpanUnitModel::wrapCoord(int64_t v) const { return wrapTo(u(v), p_.CoordBits); }

void SpanUnitModel::reset() {
  state_ = State::Idle;
  f_busy_ = f_held_ = q_valid_ = b_valid_ = e_valid_ = false;
  f_slot_ = q_slot_ = 0;
  b_ = er_ = f_row_ = RowRec{};
  e_.fill(SpanDdaState{});
  irow_.fill(0);
  icur_.fill(0);
  cycle_ = row_cycles_ = span_cycles_ = 0;
}

void SpanUnitModel::outputs(SpanOut& o) const {
  o.desc_ready = p_.RowAhead ? !q_valid_ : state_ == State::Idle;
  o.out_valid = false;
  o.tag = 0;
  const size_t lanes = static_cast<size_t>(p_.lanes());
  o.lane.resize(lanes);  // no-op (no allocation) after the first cycle
  if (p_.RowAhead ? !e_valid_ : state_ != State::Span) {
    for (SpanLaneOut& l : o.lane) l.valid = false;
    return;
  }
  const SpanDesc& d = slot_[p_.RowAhead ? er_.slot : 0];  // the paper's unit: slot 0
  o.tag = d.tag;
  const int L = p_.LanesPerTri;
  const size_t K = static_cast<size_t>(p_.NumAttr);
  for (int j = 0; j < p_.NumTri; ++j) {
    const size_t ju = static_cast<size_t>(j);
    const SpanLaneTri& t = d.tri[ju];
    for (int i = 0; i < L; ++i) {
      SpanLaneOut& lane = o.lane[static_cast<size_t>(j * L + i)];
      const int64_t x = xg_ + i;  // CoordBits + 1 bits: no wrap
      lane.valid = er_.ne[ju] && er_.lo[ju] <= x && x <= er_.hi[ju];
      if (!lane.valid) continue;
      lane.attr.resize(K);
      laneFragment(p_, d, t, x, er_.wspan, icur_.data(), i, lane.x, lane.y, lane.attr.data());
      o.out_valid = true;
    }
  }
}

SpanOut SpanUnitModel::tick(const SpanIn& in) {
  SpanOut out;
  tick(in, out);
  return out;
}

void SpanUnitModel::tick(const SpanIn& in, SpanOut& out) {
  outputs(out);
  if (in.desc_valid && out.desc_ready) {
    if (in.desc == nullptr) throw std::invalid_argument("span descriptor missing");
    checkDescriptor(p_, *in.desc);
  }
  if (p_.RowAhead) tickRowAhead(in, out);
  else tickPaper(in, out);
  ++cycle_;
}

bool SpanUnitModel::formRow(RowRec& r) const {
  const SpanDesc& d = slot_[f_slot_];
  int64_t xs = 0, xe = 0;
  if (!unionRowBounds(d.tri.data(), p_.NumTri, w_, e_.data(), r.lo.data(), r.hi.data(), r.ne.data(), xs, xe))
    return false;
  r.xe = xe;
  r.xg0 = firstGroup(p_, xs);
  for (int a = 0; a < p_.NumAttr; ++a) {
    const size_t ai = static_cast<size_t>(a);
    r.icur0[ai] = wrapAttr(u(irow_[ai]) + u(d.didx[ai]) * u(r.xg0 - d.xref));
  }
  r.wspan = w_;
  r.slot = f_slot_;
  return true;
}

void SpanUnitModel::stepRow() {
  const SpanDesc& d = slot_[f_slot_];
  // DDA steps of the edges active at w that stay active.
  for (int j = 0; j < p_.NumTri; ++j)
    stepEdges(d.tri[static_cast<size_t>(j)], w_, &e_[static_cast<size_t>(j) * 3], p_.CoordBits);
  for (int a = 0; a < p_.NumAttr; ++a) {
    const size_t ai = static_cast<size_t>(a);
    irow_[ai] = wrapAttr(u(irow_[ai]) + u(d.didy[ai]));
  }
  w_ = wrapCoord(w_ + 1);
}

void SpanUnitModel::startDescriptor(size_t slot) {
  f_slot_ = slot;
  const SpanDesc& d = slot_[slot];
  w_ = d.row_first;
  for (int j = 0; j < p_.NumTri; ++j)
    for (int s = 0; s < 3; ++s) {
      const SpanEdge& e = d.tri[static_cast<size_t>(j)].edge[s];
      e_[static_cast<size_t>(j * 3 + s)] = {e.q, e.r};
    }
  std::copy(d.iref.begin(), d.iref.end(), irow_.begin());
}

size_t SpanUnitModel::freeSlot() const {
  for (size_t s = 0; s < slot_.size(); ++s)
    if (!(e_valid_ && er_.slot == s) && !(b_valid_ && b_.slot == s) && !(f_busy_ && f_slot_ == s) &&
        !(q_valid_ && q_slot_ == s))
      return s;
  throw std::logic_error("SpanUnitModel: every descriptor slot is held");  // E, B, F and Q hold at most 4
}

void SpanUnitModel::tickPaper(const SpanIn& in, const SpanOut& out) {
  const int L = p_.LanesPerTri;
  if (state_ == State::Row) ++row_cycles_;
  if (state_ == State::Span) ++span_cycles_;
  switch (state_) {
    case State::Idle:
      if (in.desc_valid) {
        slot_[0] = *in.desc;
        startDescriptor(0);
        state_ = State::Row;
      }
      break;
    case State::Row: {
      const int64_t w = w_;
      if (formRow(er_)) {
        xg_ = er_.xg0;
        std::copy_n(er_.icur0.begin(), p_.NumAttr, icur_.begin());
        state_ = State::Span;
      } else {
        state_ = (w == slot_[0].row_last) ? State::Idle : State::Row;
      }
      stepRow();
      break;
    }
    case State::Span:
      if (!out.out_valid || in.out_ready) {
        if (xg_ + L > er_.xe) {
          state_ = (er_.wspan == slot_[0].row_last) ? State::Idle : State::Row;
        } else {
          xg_ += L;
          for (int a = 0; a < p_.NumAttr; ++a) {
            const size_t ai = static_cast<size_t>(a);
            icur_[ai] = wrapAttr(u(icur_[ai]) + static_cast<uint64_t>(L) * u(slot_[0].didx[ai]));
          }
        }
      }
      break;
  }
}

void SpanUnitModel::tickRowAhead(const SpanIn& in, const SpanOut& out) {
  const int L = p_.LanesPerTri;
  if (e_valid_) ++span_cycles_;
  // E: its lane group leaves (or shows nothing); the row's last group frees E.
  bool e_done = false, e_step = false;
  if (e_valid_ && (!out.out_valid || in.out_ready)) (xg_ + L > er_.xe ? e_done : e_step) = true;
  const bool e_free = !e_valid_ || e_done;
  const bool take_b = b_valid_ && e_free;
  const bool b_free = !b_valid_ || take_b;
  // F: row w formed; it goes to E when E is free and B empty, else to B when B is free; F moves
  // on unless the row has pixels and B stays full. A row F stalled on is the one it formed last.
  const RowRec& formed = f_row_;
  bool f_moves = false, f_puts = false, bypass = false;
  if (f_busy_) {
    const bool any = f_held_ || formRow(f_row_);
    bypass = any && e_free && !b_valid_;
    f_puts = any && b_free && !bypass;
    f_moves = !any || b_free;
  }
  const bool f_takes = !f_busy_ || (f_moves && w_ == slot_[f_slot_].row_last);
  const bool accept = in.desc_valid && out.desc_ready;
  f_held_ = f_busy_ && !f_moves;
  // E, B, then F and Q (each from the values before the edge).
  if (take_b || bypass) {
    er_ = take_b ? b_ : formed;
    xg_ = er_.xg0;
    std::copy_n(er_.icur0.begin(), p_.NumAttr, icur_.begin());
    e_valid_ = true;
  } else if (e_done) {
    e_valid_ = false;
  } else if (e_step) {
    xg_ += L;
    for (int a = 0; a < p_.NumAttr; ++a) {
      const size_t ai = static_cast<size_t>(a);
      icur_[ai] = wrapAttr(u(icur_[ai]) + static_cast<uint64_t>(L) * u(slot_[er_.slot].didx[ai]));
    }
  }
  if (f_puts) {
    b_ = formed;
    b_valid_ = true;
  } else if (take_b) {
    b_valid_ = false;
  }
  if (f_moves) {
    ++row_cycles_;
    stepRow();
  }
  bool accepted_by_f = false;
  if (f_takes) {
    f_busy_ = false;  // its descriptor's slot is free unless B or E holds a row of it
    if (q_valid_) {
      q_valid_ = false;
      startDescriptor(q_slot_);
      f_busy_ = true;
    } else if (accept) {
      const size_t s = freeSlot();
      slot_[s] = *in.desc;
      startDescriptor(s);
      f_busy_ = accepted_by_f = true;
    }
  }
  if (accept && !accepted_by_f) {
    q_slot_ = freeSlot();
    slot_[q_slot_] = *in.desc;
    q_valid_ = true;
  }
}

SpanRun runSpanUnit(SpanUnitModel& m, const SpanDesc& d) {
  SpanRun run;
  runSpanUnit(m, d, run);
  return run;
}

void runSpanUnit(SpanUnitModel& m, const SpanDesc& d, SpanRun& run) {
  if (!m.idle()) throw std::logic_error("runSpanUnit: the unit is busy");
  run.fragments.clear();  // its capacity kept
  run.cycles = 0;
  const uint64_t rows0 = m.rowCycles(), spans0 = m.spanCycles();
  SpanIn in;
  in.desc_valid = true;
  in.desc = &d;
  in.out_ready = true;
  bool accepted = false;
  // Reused: no allocation per cycle, nor per descriptor (a SpanOut made per call allocated and
  // constructed its lanes for each one: 2-3 % of the samples of the million-triangle mode test,
  // test_span_unit).
  thread_local SpanOut o;
  for (;;) {
    m.tick(in, o);
    ++run.cycles;
    if (!accepted) {
      accepted = o.desc_ready;
      in.desc_valid = false;
      continue;
    }
    for (const SpanLaneOut& l : o.lane) {
      if (!l.valid) continue;
      // The fragment added without attributes, which are then copied in place: one copy of
      // them instead of two (into a temporary fragment, then into the vector).
      run.fragments.push_back({o.tag, l.x, l.y, {}});
      run.fragments.back().attr = l.attr;
    }
    if (m.idle()) break;
  }
  run.valid_lanes = run.fragments.size();
  run.row_cycles = m.rowCycles() - rows0;
  run.span_cycles = m.spanCycles() - spans0;
}

SpanWalk walkSpanUnit(const SpanParams& p, const SpanDesc& d, std::vector<SpanFragment>& out, SpanStream* stream) {
  SpanFragment f;
  f.tag = d.tag;
  f.attr.resize(static_cast<size_t>(p.NumAttr));
  return walkSpanUnit(p, d, [&](int32_t x, int32_t y, const int64_t* attr) {
    f.x = x;
    f.y = y;
    std::copy(attr, attr + p.NumAttr, f.attr.begin());
    out.push_back(f);
  }, span_detail::NoRuns{}, stream);
}

}  // namespace shd
